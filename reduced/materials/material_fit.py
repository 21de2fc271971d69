r"""Fit a rubber model (:mod:`softhand.reduced.materials.rubber`) to nominal stress vs stretch test data
(:mod:`softhand.reduced.materials.stress_data`, which reads and checks them).

Refused (one :class:`~softhand.reduced.vocabulary.errors.InputError`): data the
:mod:`softhand.reduced.materials.stress_data` checks refuse, and fewer distinct (mode, stretch)
points other than stretch 1 than the model has parameters (repeats only measure the scatter;
at stretch 1 every model has zero stress). Data the model's numerics cannot fit (no finite
optimum) are refused too, never printed.

Least squares in the stress itself (MPa), all rows with equal weight:

.. math:: S(p) = \sum_i (P^{model}_{m_i}(\lambda_i; p) - P_i)^2 .

NH, Mooney-Rivlin and Yeoh are linear in their parameters: solved directly. Gent and
Ogden are fitted by :func:`scipy.optimize.least_squares` from several starts (Ogden:
exponents on a grid, the moduli for each by linear least squares; Gent: locking
parameters on a grid) and refined. Standard errors and correlations come from the
Jacobian at the optimum as in :func:`softhand.reduced.fitting.lsq.diagnose`: Cov = S/(N - k) (J^T J)^{-1}.
Ogden's terms are reported in ascending alpha_p (W does not depend on their order). A
standard error never drops below :data:`PRECISION` of its parameter's scale: with
data without scatter the statistical error is round-off, the solver's precision is not.

Drucker stability (incompressible): the Hessian of W in the log strains
(:meth:`softhand.reduced.materials.rubber_base.Rubber.drucker_hessian`) must be positive definite. It is checked
in uniaxial, equibiaxial and pure-shear deformation at stretches over a stated range
(tension above 1, compression below), by default 1/lambda_max .. lambda_max of the data.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from softhand.reduced.materials import rubber, rubber_base, rubber_parameters
from softhand.reduced.materials.stress_data import StressData, check_data
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.fitting.lsq import FitOptions, diagnose, jacobian

#: ``--model`` -> (rubber model, Ogden terms)
FIT_MODELS = {"neo-hookean": ("neo-hookean", 0), "mooney-rivlin": ("mooney-rivlin", 0),
              "yeoh": ("yeoh", 0), "gent": ("gent", 0), "ogden2": ("ogden", 2),
              "ogden3": ("ogden", 3)}
#: relative precision to which the solvers determine a parameter (of its value, or of mu0 for
#: a modulus near zero); added in quadrature to the standard errors, so that data without
#: scatter (S ~ round-off) do not report errors below what the numbers can resolve
PRECISION = 1e-10


@dataclass(frozen=True)
class MaterialFit:
    """A fitted rubber model with its uncertainty and how it matches the data."""

    fit_model: str  #: the ``--model`` name (ogden2, ogden3, ...)
    material: rubber_base.Rubber
    names: tuple  #: public parameter names
    values: np.ndarray
    stderr: np.ndarray
    correlation: np.ndarray
    residuals: np.ndarray  #: model - data [MPa]
    data: StressData
    warnings: tuple = ()

    def rms_by_mode(self) -> dict:
        return {m: float(np.sqrt(np.mean(self.residuals[self.data.mode == m] ** 2)))
                for m in rubber_base.MODES if np.any(self.data.mode == m)}

    @property
    def rms(self) -> float:
        return float(np.sqrt(np.mean(self.residuals**2)))


def model_residual_fn(fit_model: str, data: StressData):
    """(names, x -> residuals [MPa], x -> material) of a ``--model`` on the data."""
    if fit_model not in FIT_MODELS:
        raise InputError("--model", fit_model, f"must be one of {', '.join(FIT_MODELS)}")
    model, terms = FIT_MODELS[fit_model]
    names = rubber_parameters.parameter_names(model, terms)

    def material(x):
        if model == "ogden":
            return rubber.Ogden(tuple(x[0::2]), tuple(x[1::2]))
        field = {"mu_MPa": "mu", "C10_MPa": "C10", "C01_MPa": "C01", "C20_MPa": "C20",
                 "C30_MPa": "C30", "Jm": "Jm"}
        return rubber.MODELS[model](**{field[k]: float(v) for k, v in zip(names, x)})

    return names, (lambda x: data.predict(material(x)) - data.stress), material


def fit_material(data: StressData, fit_model: str, options: FitOptions = FitOptions()) -> MaterialFit:
    """Least-squares fit of ``fit_model`` to the data with standard errors (see the module)."""
    names, residual, material = model_residual_fn(fit_model, data)
    if len(data) <= len(names):
        raise InputError("--data", f"{len(data)} points",
                         f"need more points than the {len(names)} parameters of {fit_model}")
    check_data(data)
    moved = data.stretch != 1.0
    distinct = len(set(zip(data.mode[moved], data.stretch[moved])))
    if distinct < len(names):
        raise InputError("--data", f"{distinct} distinct stretch" + ("" if distinct == 1 else "es"),
                         f"need at least {len(names)} distinct (mode, stretch) points other than "
                         f"stretch 1 for the {len(names)} parameters of {fit_model} (repeats only "
                         "measure the scatter; stretch 1 carries no information)")
    try:
        x, r, diag = _solve(data, fit_model, names, residual, material, options)
    except InputError:
        raise
    except (np.linalg.LinAlgError, ValueError, ArithmeticError):  # the numerics failed on these data
        raise InputError("--data", data.source, f"cannot be fitted by {fit_model}: the least "
                         "squares have no finite solution for these data") from None
    fitted = material(x)
    scale = np.array([max(abs(v), fitted.mu0 if k.endswith("_MPa") else 1.0) for k, v in zip(names, x)])
    stderr = np.hypot(diag.stderr, PRECISION * scale)
    return MaterialFit(fit_model, fitted, names, x, stderr, diag.correlation, r, data, diag.warnings)


def _solve(data, fit_model, names, residual, material, options):
    """Parameters, residuals and their diagnosis; ValueError unless all are finite."""
    model = FIT_MODELS[fit_model][0]
    if model in ("neo-hookean", "mooney-rivlin", "yeoh"):
        x = _linear_fit(data, names, material)
        lo, hi = np.full(x.size, -np.inf), np.full(x.size, np.inf)
    elif model == "gent":
        x, lo, hi = _gent_fit(data, residual)
    else:
        x, lo, hi = _ogden_fit(data, names, residual)
        order = np.argsort(x[1::2])  # terms in ascending alpha (W does not depend on the order)
        x = np.column_stack([x[0::2][order], x[1::2][order]]).ravel()
    if not np.all(np.isfinite(x)):
        raise ValueError("non-finite parameters")
    J = jacobian(residual, x, lo, hi, options.rel_step)
    r = residual(x)
    if not (np.all(np.isfinite(J)) and np.all(np.isfinite(r))):
        raise ValueError("non-finite residuals or Jacobian")
    return x, r, diagnose(names, J, r, x, options)


def _linear_fit(data, names, material):
    """Stress is linear in the parameters: the columns are the stresses of unit parameters."""
    k = len(names)
    A = np.column_stack([data.predict(material(np.eye(k)[j])) for j in range(k)])
    if not np.all(np.isfinite(A)):
        raise ValueError("non-finite model stresses")
    return np.linalg.lstsq(A, data.stress, rcond=None)[0]


def _refine(residual, x0, lo, hi):
    sol = least_squares(residual, x0, bounds=(lo, hi), method="trf", x_scale="jac",
                        ftol=1e-14, xtol=1e-14, gtol=1e-14, max_nfev=2000)
    return sol.x, float(sol.fun @ sol.fun)


def _gent_fit(data, residual):
    """Starts: Jm on a log grid above the data's largest I1 - 3, mu linear for each."""
    I1 = sum(s**2 for s in _stretch_triples(data))
    jm_min = float(np.max(I1) - 3.0) * (1.0 + 1e-9) + 1e-12
    if not np.isfinite(jm_min):
        raise ValueError("no finite locking limit")
    lo, hi = np.array([1e-12, jm_min]), np.array([np.inf, np.inf])
    starts = []
    for jm in jm_min * np.geomspace(1.01, 1e4, 41):
        unit = residual(np.array([1.0, jm])) + data.stress  # stress of mu = 1
        if not (np.all(np.isfinite(unit)) and unit @ unit > 0):
            continue
        mu = max(float(unit @ data.stress / (unit @ unit)), 1e-6)
        r = mu * unit - data.stress
        starts.append((float(r @ r), np.array([mu, jm])))
    return _best_refined(residual, starts, lo, hi, 3), lo, hi


def _best_refined(residual, starts, lo, hi, count):
    """Refine the ``count`` best (S, x0) starts; the x of the smallest S."""
    best = None
    for _, x0 in sorted(starts, key=lambda s: s[0])[:count]:
        x, S = _refine(residual, x0, lo, hi)
        if np.isfinite(S) and (best is None or S < best[1]):
            best = (x, S)
    if best is None:
        raise ValueError("no start converged to a finite sum of squares")
    return best[0]


def _ogden_fit(data, names, residual):
    """Starts: exponent sets from a grid, moduli by linear least squares; the best few refined."""
    n = len(names) // 2
    grid = [-4.0, -2.0, -1.0, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0]
    sets = [np.array(c) for c in _combinations(grid, n)]
    starts = []
    for alpha in sets:
        A = np.column_stack([data.predict(rubber.Ogden((1.0,), (a,))) for a in alpha])
        if not np.all(np.isfinite(A)):
            continue
        mu = np.linalg.lstsq(A, data.stress, rcond=None)[0]
        x = np.empty(2 * n)
        x[0::2], x[1::2] = mu, alpha
        r = A @ mu - data.stress
        starts.append((float(r @ r), x))
    lo, hi = np.full(2 * n, -np.inf), np.full(2 * n, np.inf)
    lo[1::2], hi[1::2] = -20.0, 20.0
    return _best_refined(residual, starts, lo, hi, 5), lo, hi


def _combinations(grid, n):
    if n == 0:
        yield ()
        return
    for i, a in enumerate(grid):
        for rest in _combinations(grid[i + 1:], n - 1):
            yield (a, *rest)


def _stretch_triples(data):
    l = np.empty((3, len(data)))
    for m in np.unique(data.mode):
        rows = data.mode == m
        l[:, rows] = rubber_base.stretches(m, data.stretch[rows])
    return l
