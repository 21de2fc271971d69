"""Verification of the solid's tangent and of Newton's convergence on the tube problems of
:mod:`softhand.studies.verification.solid`: the tangent against central differences of the residual (O(eps^2) +
round-off: 1e-6), and the observed order of full Newton, at least 1.5 (quadratic: 2; an
inexact tangent: 1).
"""
from __future__ import annotations

import numpy as np

from softhand.fem.newton import NewtonOptions, NotConverged, newton
from softhand.studies.verification.registry import Check
from softhand.studies.verification.solid import linear_solver, plane_strain_tube

__all__ = ["tangent_and_newton", "newton_order"]


def tangent_and_newton(quick: bool) -> list[Check]:
    """Tangent (solid + hoop fibers + follower-pressure load stiffness) vs central differences
    of the residual at a state with the fibers stretched by about 1 % (away from their
    tension-only kink), and the observed order of full Newton on the tube (κ = 100 μ,
    p = 0.5 MPa in one step): at least 1.5, which separates quadratic convergence (2; the
    pre-asymptotic estimates from residuals scatter between 1.6 and 2.4) from the linear
    convergence (1) of an inexact tangent."""
    problem = plane_strain_tube(2.0, 0.3, fiber_ratio=10.0)
    X = problem.solid.dof_locations
    radial = (0.01 * np.stack([X[0], X[1], 0 * X[2]])).T.ravel()  # interleaved like the dofs
    rng = np.random.default_rng(3)
    q = problem.T.T @ radial + 1e-4 * rng.standard_normal(problem.T.shape[1])
    v, eps = rng.standard_normal(q.size), 1e-6
    fd = (problem.fun(q + eps * v)[0] - problem.fun(q - eps * v)[0]) / (2 * eps)
    Kv = problem.fun(q)[1] @ v
    mismatch = float(np.linalg.norm(Kv - fd) / np.linalg.norm(fd))
    return [Check("newton", "1 + ||K v - FD|| / ||FD|| (fibers, follower pressure)", 1.0, 1.0 + mismatch, 1e-6),
            Check("newton", "observed order of full Newton", 2.0, newton_order(), 0.25, at_least=True)]


def newton_order() -> float:
    """Slope of log r_k+1 against log r_k over the last, fast-falling residuals (each below
    half the previous, above 100 x the round-off floor) of full Newton on the tube."""
    problem = plane_strain_tube(2.0, 0.5, kappa_ratio=1e2)
    try:  # iterate down to round-off: the tolerance is out of reach on purpose
        history = newton(problem.fun, np.zeros(problem.T.shape[1]),
                         NewtonOptions(rtol=1e-16, atol=0.0, max_iter=10), solver=linear_solver()).history
    except NotConverged as err:
        history = err.history
    r = np.asarray(history)
    r = r[: np.flatnonzero(r > 100 * r.min())[-1] + 1]
    tail = len(r) - 1
    while tail > 0 and r[tail] < 0.5 * r[tail - 1]:
        tail -= 1
    r = np.log(r[tail:])
    return float(np.polyfit(r[:-1], r[1:], 1)[0]) if r.size >= 3 else float("nan")
