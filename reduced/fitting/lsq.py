r"""Least squares shared by the design fit (:mod:`softhand.reduced.fitting.fit`) and the material fit
(:mod:`softhand.reduced.materials.material_fit`): options, the finite-difference Jacobian, and what the
Jacobian at the optimum says about the parameters.

Uncertainty, with :math:`J = \partial r / \partial p` at the optimum (central
differences), :math:`N` points and :math:`k` parameters:

.. math:: \hat\sigma^2 = S / (N - k), \qquad \mathrm{Cov}(p) = \hat\sigma^2 (J^T J)^{-1},

standard errors are the square roots of its diagonal and the correlation matrix is the
covariance normalised by them. This linearised estimate assumes independent errors of
equal variance in the measured quantity.

Identifiability: the columns of J are normalised to unit length and decomposed by SVD.
A singular value below ``FitOptions.singular_tol`` (relative to the largest) is a
direction in parameter space that leaves every prediction unchanged, to the accuracy
of the Jacobian; the parameters taking part in it are reported as not identifiable
(standard error infinite) with the combination the data cannot see. A condition number
above ``FitOptions.cond_warn`` is reported as poorly determined. Nothing is returned
silently.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["FitOptions", "jacobian", "Diagnosis", "diagnose"]


@dataclass(frozen=True)
class FitOptions:
    """Tolerances of the fit and of its identifiability diagnosis."""

    rel_step: float = 1e-6  #: central-difference step for J, relative to each parameter
    singular_tol: float = 1e-6  #: s_min / s_max of the column-normalised J: below, singular
    cond_warn: float = 1e3  #: condition number above which parameters are poorly determined
    bound_factor: float = 100.0  #: default bounds p0 / factor .. p0 * factor (positive keys)
    tol: float = 1e-12  #: ftol, xtol and gtol of scipy.optimize.least_squares


def jacobian(residual, x, lo, hi, rel_step: float) -> np.ndarray:
    """d residual / d x by central differences (one-sided next to a bound), (N, k)."""
    columns = []
    for j in range(x.size):
        h = rel_step * max(abs(x[j]), 1.0)
        up, down = x.copy(), x.copy()
        up[j] = min(x[j] + h, hi[j])
        down[j] = max(x[j] - h, lo[j])
        columns.append((residual(up) - residual(down)) / (up[j] - down[j]))
    return np.column_stack(columns)


@dataclass(frozen=True)
class Diagnosis:
    stderr: np.ndarray
    correlation: np.ndarray
    condition: float
    singular_values: np.ndarray
    unidentifiable: tuple[str, ...]
    warnings: tuple[str, ...]


def diagnose(keys, J: np.ndarray, residuals: np.ndarray, values=None,
             options: FitOptions = FitOptions()) -> Diagnosis:
    """Standard errors, correlation and identifiability from J = d residual / d p [data unit / key unit].

    ``values`` (the parameters, default 1) only express a singular direction in per cent.
    """
    n, k = J.shape
    norms = np.linalg.norm(J, axis=0)
    dead = norms <= 1e-12 * max(norms.max(initial=0.0), 1e-300)
    Jn = J / np.where(dead, 1.0, norms)
    Jn[:, dead] = 0.0
    _, s, Vt = np.linalg.svd(Jn, full_matrices=False)
    rel = s / s[0] if s[0] > 0 else np.zeros_like(s)
    null = Vt[rel < options.singular_tol]
    involved = dead | np.any(np.abs(null) > 0.1, axis=0)
    sigma2 = float(residuals @ residuals) / max(n - k, 1)
    cov_n = np.linalg.pinv(Jn.T @ Jn, rcond=options.singular_tol**2, hermitian=True)
    cov = sigma2 * cov_n / np.outer(np.where(dead, 1.0, norms), np.where(dead, 1.0, norms))
    stderr = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    stderr[involved] = np.inf
    se = np.where(involved, np.nan, stderr)
    corr = cov / np.outer(se, se)
    np.fill_diagonal(corr, np.where(involved, np.nan, 1.0))
    condition = float(s[0] / s[-1]) if s[-1] > 0 else math.inf
    # a null direction of Jn is the change dp_j = v_j / |J_j| of the parameters; in per cent:
    values = np.ones(k) if values is None else np.asarray(values, dtype=float)
    rel_null = null / np.where(dead, 1.0, norms) / np.where(values != 0, np.abs(values), 1.0)
    warnings = _identifiability_warnings(keys, dead, rel_null, condition, corr, options)
    return Diagnosis(stderr, corr, condition, s, tuple(k_ for k_, i in zip(keys, involved) if i),
                     warnings)


def _identifiability_warnings(keys, dead, rel_null, condition, corr, options) -> tuple[str, ...]:
    out = [f"{k} does not change any prediction for these data: it cannot be fitted from them"
           for k, d in zip(keys, dead) if d]
    for v in rel_null:
        v = np.where(dead, 0.0, v)
        if not np.any(v):
            continue  # the direction of a parameter with no effect, reported above
        v = v / np.max(np.abs(v))
        shown = np.flatnonzero(np.abs(v) > 1e-3)
        if shown.size < 2:
            continue
        v = v * np.sign(v[shown[0]])  # the first parameter named goes up
        parts = " and ".join(f"{k} by {c:+.3g} %" for k, c in zip(keys, v) if abs(c) > 1e-3)
        out.append(f"not identifiable: changing {parts} leaves every prediction unchanged "
                   "(singular Jacobian); the data determine only that combination: "
                   "fit one of these and fix the others")
    if not out and condition > options.cond_warn:
        i, j = np.unravel_index(np.nanargmax(np.abs(corr - np.eye(len(keys)))), corr.shape)
        out.append(f"poorly determined: condition number {condition:.3g} of the scaled "
                   f"Jacobian; {keys[i]} and {keys[j]} are correlated {corr[i, j]:+.5f}")
    return tuple(out)
