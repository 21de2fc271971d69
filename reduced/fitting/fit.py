r"""Calibrate design parameters to measurements: bounded nonlinear least squares.

Given measured points (:class:`~softhand.reduced.fitting.csvdata.Measurements`) and a model that predicts
the measured quantity from a :class:`~softhand.reduced.vocabulary.design.HandDesign`, find the named public
design parameters :math:`p` (e.g. ``V0_mm3``, ``mu_sf_MPa``) that minimise

.. math:: S(p) = \sum_i r_i(p)^2, \qquad r_i = y_i^{model}(p) - y_i^{measured}

in the data's own units (degrees for free bending, newtons for grasp forces), as the
paper does for V0 (section III-B). Parameters are scaled by their starting values,
:math:`x = p / p_0`, so the optimiser sees numbers of order one.

Uncertainty and identifiability: :mod:`softhand.reduced.fitting.lsq` (standard errors, correlations, the
parameter combinations the data cannot see); nothing is returned silently.
"""
from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from scipy.optimize import least_squares

from softhand.reduced.fitting.csvdata import Measurements
from softhand.reduced.fitting.fit_result import FitResult
from softhand.reduced.fitting.lsq import FitOptions, diagnose, jacobian
from softhand.reduced.vocabulary.design import PUBLIC_KEYS, HandDesign
from softhand.reduced.vocabulary.design_files import design_from_dict
from softhand.reduced.vocabulary.errors import InputError

#: public design keys a fit may vary (numbers; not counts, lists or names)
FITTABLE = ("theta0_deg", "l0_mm", "a_mm", "b_mm", "d_mm", "R_mm", "t_mm", "V0_mm3",
            "mu_sf_MPa", "mu_sr_MPa", "base_offset_mm", "g_N_per_kg")

#: a predictor maps a design to the model's value of each measured point (data units)
Predictor = Callable[[HandDesign], np.ndarray]
#: models a fit can use (``--model``)
MODELS = ("reduced",)


def fit(data: Measurements, params, predictor: Callable[[HandDesign], np.ndarray],
        design: HandDesign | None = None, *, bounds: dict | None = None,
        options: FitOptions = FitOptions()) -> FitResult:
    """Fit the public design keys ``params`` so that ``predictor(design)`` matches ``data.observed``.

    ``bounds`` maps a key to ``(low, high)`` in the key's units (default: see
    :func:`default_bounds`). Raises InputError for unknown keys or too few points.
    """
    design = design if design is not None else HandDesign()
    keys = check_params(params, len(data))
    _check_distinct(data, len(keys))
    p0 = np.array([design.to_dict()[k] for k in keys], dtype=float)
    lo, hi = _bounds(keys, p0, design, data, bounds, options)
    scale = np.where(p0 != 0.0, np.abs(p0), 1.0)
    observed = np.asarray(data.observed, dtype=float)

    failed = 1e3 * (1.0 + float(np.max(np.abs(observed))))

    def residual(x):  # a trial point where the model has no answer: a large residual, step rejected
        r = _try_predict(predictor, keys, x * scale, design, observed.shape) - observed
        return np.where(np.isnan(r), failed, r)

    x0 = np.clip(p0 / scale, lo / scale, hi / scale)
    sol = least_squares(residual, x0, bounds=(lo / scale, hi / scale), method="trf",
                        ftol=options.tol, xtol=options.tol, gtol=options.tol,
                        diff_step=1e-7)
    values = sol.x * scale
    predicted = _answered(predictor, keys, values, design, lo, hi, bounded=bool(bounds))
    J = jacobian(residual, sol.x, lo / scale, hi / scale, options.rel_step) / scale
    fitted = _with(keys, values, design)
    diag = diagnose(keys, J, sol.fun, values, options)
    at_bound = tuple(k for k, a in zip(keys, sol.active_mask) if a != 0)
    return FitResult(
        params=keys, initial=p0, values=values, stderr=diag.stderr,
        correlation=diag.correlation, observed=observed,
        predicted=predicted,
        initial_predicted=_try_predict(predictor, keys, p0, design, observed.shape), design=fitted,
        quantity=data.quantity, condition=diag.condition,
        singular_values=diag.singular_values, unidentifiable=diag.unidentifiable,
        at_bound=at_bound, warnings=diag.warnings + _fit_warnings(sol, keys, values, diag, at_bound),
        nfev=int(sol.nfev), finger=data.finger,
    )


def _fit_warnings(sol, keys, values, diag, at_bound) -> tuple[str, ...]:
    """Non-convergence, parameters on a bound, errors larger than the value."""
    out = [] if sol.status > 0 else [f"the optimiser stopped without converging after "
                                     f"{sol.nfev} evaluations: {sol.message}"]
    out += [f"{k} ended on its bound {v:.6g}: widen the bound or fix it; its standard error "
            "is not meaningful" for k, v in zip(keys, values) if k in at_bound]
    out += [f"{k} is poorly determined: its standard error {se:.3g} exceeds its value {v:.6g}"
            for k, v, se in zip(keys, values, diag.stderr)
            if math.isfinite(se) and se > abs(v) and k not in at_bound]
    return tuple(out)


def make_predictor(data: Measurements, model: str = "reduced", *, reservoir: bool = True,
                   weights=None, normalise: bool = False,
                   design: HandDesign | None = None) -> Predictor:
    """The model's prediction of ``data.observed``: theta [deg] from the free-bending inverse
    of eq. (27) (or (28) without reservoir), or F_v [N] from eqs. (24), (25), (29).

    Free bending: theta is what was measured at set pump pressures (the paper raises P in
    0.1 MPa steps and reads the angles), so the residual is in theta. Grasp data: w comes from
    the ``diameter_mm`` column (the paper's presets, checked against ``design.n_s``) or else
    from ``weights`` (n_s numbers); a w whose sum is not 1 warns (eq. (23)), or is scaled to
    sum 1 with ``normalise``.
    """
    from softhand.reduced.equations import grasp, hand

    if model not in MODELS:
        raise InputError("--model", model, f"allowed: {', '.join(MODELS)}")
    if data.kind == "bending":
        if weights is not None:
            raise InputError("--weights", "given", "a weight vector is only for grasp data")
        return lambda design: np.degrees(hand.bend_angle(data.P, design, reservoir))
    groups = _weight_groups(data, weights, design if design is not None else HandDesign(),
                            normalise)

    def predict(design):
        F_v = np.empty(len(data))
        for w, rows in groups:
            F_v[rows] = grasp.grasp_forces(data.P[rows], data.theta[rows], data.mass[rows], w,
                                           design, reservoir=reservoir).F_v
        return F_v
    return predict


def _weight_groups(data: Measurements, weights, design: HandDesign, normalise: bool):
    """[(w, row mask)]: one weight vector per object diameter, or ``weights`` for all rows."""
    from softhand.reduced.equations.grasp import check_weights, weights_for_diameter

    if data.diameter is None:
        if weights is None:
            raise InputError("--data", data.source, "grasp data without a diameter_mm column "
                             "need the weight vector w: --diameter-mm D or --weights w1,..,wn")
        return [(check_weights(weights, design, normalise), np.ones(len(data), dtype=bool))]
    if weights is not None:
        raise InputError("--weights", "given", f"{data.source} has a diameter_mm column, "
                         "which picks w; drop --weights / --diameter-mm")
    # w does not depend on the fitted parameters (n_s is not fittable): looked up once here
    return [(check_weights(weights_for_diameter(D, design), design, normalise), data.diameter == D)
            for D in np.unique(data.diameter)]


def check_params(params, n_points: int) -> tuple[str, ...]:
    """Validate the names of the parameters to fit; a comma list or a sequence."""
    keys = tuple(k.strip() for k in (params.split(",") if isinstance(params, str) else params))
    if not any(keys):
        raise InputError("--params", params, f"name at least one of {', '.join(FITTABLE)}")
    for k in keys:
        if not k:
            raise InputError("--params", params, "a name in the list is empty")
        if k not in FITTABLE:
            why = "is not a number that can be fitted" if k in PUBLIC_KEYS else "unknown key"
            raise InputError("--params", k, f"{why}; allowed: {', '.join(FITTABLE)}")
    if len(set(keys)) != len(keys):
        raise InputError("--params", ",".join(keys), "a parameter appears twice")
    if n_points <= len(keys):
        raise InputError("--data", f"{n_points} points",
                         f"need more points than the {len(keys)} parameters fitted")
    return keys


def _check_distinct(data: Measurements, k: int) -> None:
    """More distinct rows than parameters: copies of one row (or rows all zero) add no
    information, and a fit through them would report errors of 0 that the data never measured."""
    columns = [c for c in (data.P, data.theta, data.finger, data.mass, data.F_v, data.diameter) if c is not None]
    rows = {tuple(str(c[i]) for c in columns) for i in range(len(data))}
    if len(rows) <= k:
        raise InputError("--data", f"{len(data)} points, {len(rows)} distinct",
                         f"the data cannot identify the {k} parameter{'s' if k > 1 else ''} fitted "
                         f"nor their errors: give more distinct points than parameters")


def default_bounds(key: str, p0: float, design: HandDesign, data: Measurements,
                   factor: float = 100.0) -> tuple[float, float]:
    """Bounds of one key: p0/factor .. p0*factor for positive quantities.

    ``theta0_deg`` stays in [0, 89.9]; ``base_offset_mm`` is free; ``V0_mm3`` stays above
    the oil the fingers take at 1.05 times the largest measured angle (eq. (15)).
    """
    if key == "theta0_deg":
        return 0.0, 89.9
    if key == "base_offset_mm":
        return -math.inf, math.inf
    lo, hi = p0 / factor, p0 * factor
    if key == "V0_mm3":
        theta_max = 1.05 * float(np.max(data.theta, initial=0.0))
        lo = max(lo, design.n * math.pi * design.a**2 * design.d * theta_max * 1.001)
    return lo, hi


def _bounds(keys, p0, design, data, bounds, options):
    bounds = dict(bounds or {})
    unknown = set(bounds) - set(keys)
    if unknown:
        raise InputError("--bounds", ",".join(sorted(unknown)), "bounds only for fitted parameters")
    pairs = [bounds.get(k) or default_bounds(k, p, design, data, options.bound_factor)
             for k, p in zip(keys, p0)]
    lo, hi = (np.array(v, dtype=float) for v in zip(*pairs))
    for k, a, b in zip(keys, lo, hi):
        if not a < b:
            raise InputError(f"--bounds {k}", f"{a:g}:{b:g}", "need low < high")
    return lo, hi


def _with(keys, values, design: HandDesign) -> HandDesign:
    return design_from_dict({k: float(v) for k, v in zip(keys, values)}, design)


def _answered(predictor, keys, values, design, lo, hi, bounded: bool) -> np.ndarray:
    """The prediction where the fit ended; InputError if the model has no answer there: the bounds
    held it where no design reaches the data (e.g. a V0 too small for the fingers' oil), or the
    design has none anywhere (e.g. a material past its limit); named ``--bounds`` if given."""
    try:
        predicted = _predict(predictor, keys, values, design)
        why = None if np.all(np.isfinite(predicted)) else "its prediction is not finite"
    except InputError as exc:
        why = str(exc)
    if why is not None:
        at = ", ".join(f"{k} = {v:.6g}" for k, v in zip(keys, values))
        box = ",".join(f"{k}={a:.6g}:{b:.6g}" for k, a, b in zip(keys, lo, hi))
        raise InputError("--bounds" if bounded else "--params", box, f"the fit ended at {at}, where "
                         f"the model has no answer for the data ({why}); move or widen the bounds, "
                         "or check --design")
    return predicted


def _predict(predictor, keys, values, design) -> np.ndarray:
    return np.asarray(predictor(_with(keys, values, design)), dtype=float)


def _try_predict(predictor, keys, values, design, shape) -> np.ndarray:
    """The prediction, or nan where the model has no answer (e.g. the starting design)."""
    try:
        return _predict(predictor, keys, values, design)
    except InputError:
        return np.full(shape, np.nan)

