"""Pressure sweeps of the finger FEM: each pressure one load step from the last converged state."""
from __future__ import annotations

import copy
import math
import time
from dataclasses import dataclass

import numpy as np

from softhand.fem.linsolve import make_solver
from softhand.fem.newton import NewtonOptions, NotConverged, newton
from softhand.fem.newton_path import PathOptions, solve_path
from softhand.fem.newton_steps import factored_size

#: quasi-Newton on the last factorisation (:func:`softhand.fem.newton.newton`, ``refactor="adaptive"``),
#: re-factorised only when a step lowers the residual by less than half: on the default mesh,
#: 0-0.8 MPa in 0.1 MPa steps, 35 factorisations and tangent assemblies (97 cheap
#: iterations; 37 and 102 in double precision) against Newton's 51 and 51 (51 iterations),
#: theta equal to 1e-8 deg; a step then needs up to ~18 iterations, hence max_iter 40.
#: contraction 0.9 (max_iter 80) saves 4-6 factorisations for ~35 more iterations and was
#: not faster (2026-12-03); the windings' tension-only jump keeps 3-8 per pressure. No
#: ``diverge``: the failed steps of the calibration's harder designs mostly stall rather than
#: diverge (a = 6 mm face centre, 0.2-0.8 MPa, four runs each: 23-83 factorisations on failed
#: tries with diverge=100, 47-79 without; PARDISO's threads make every run's path differ)
SWEEP_NEWTON = NewtonOptions(rtol=1e-9, max_iter=40, refactor="adaptive", contraction=0.5, memory=20)

#: the rubber's bulk modulus over its shear modulus on the way to a pressure the direct load step
#: would bend too far (:data:`BEND_STEP`) or fails to reach: the step runs on the finger with this
#: softer rubber, then one (quasi-)Newton solve at the rubber's own bulk modulus (1000 mu) lands
#: on the same equilibrium (to the Newton tolerance). Not every step's way: where the direct
#: step converges (the paper's finger, 0-0.8 MPa) the correction from 100 to 1000 mu costs as
#: many factorisations as the step. The nearly incompressible rubber's volume energy along an
#: accurate predictor rises a hundredfold and more in a few elements of the end cap, so the line
#: search cuts Newton's steps to a few per cent on compliant designs; at 100 mu the same steps
#: are taken whole. On the compliant design of ``benchmarks/bench_newton_compliant.py`` (a 6,
#: b 3, d 10.14, l0 180 mm, 0.6 MPa), direct: 88-162 factorisations, 4-7 cut-backs; this way:
#: 46, none. 10 mu is too soft (the correction then needs cut-backs itself), 300 mu still cuts back
PATH_KAPPA_RATIO = 100.0
#: the largest bend [rad] the tangent predictor may add in one load step of the finger itself;
#: above it the step runs on the softer rubber. The bend, not the pressure, limits a Newton
#: step, and the softer rubber's path plus the correction costs more than a direct step that
#: converges: the paper's finger on the CI mesh, 0-0.8 MPa in 0.2 MPa steps (~5 deg each), took
#: 70 factorisations with a 5 deg threshold against 43 direct
BEND_STEP = math.radians(10.0)
#: the predicted bend [rad] of one load step on the softer rubber (its steps then cut back or
#: grow as :func:`softhand.fem.newton_path.solve_path` does). The predictor, tangent at the
#: start, under-predicts a softening finger's bend about threefold (the compliant design, 0-0.6
#: MPa: 27 deg predicted, 70 reached); there at 100 mu 1, 2, 3, 4, 6 steps took 65, 64, 48, 52,
#: 42 factorisations (3, 2, 1, 1, 0 cut-backs)
SOFT_BEND = math.radians(5.0)
#: the softer rubber's load steps where the predictor failed (a singular tangent)
SOFT_STEPS = 6


@dataclass(frozen=True)
class SweepStats:
    """Cost of a pressure sweep."""

    wall_seconds: float
    assembly_seconds: float
    solve_seconds: float
    newton_iterations: int
    cutbacks: int
    solver: str
    factorizations: int = 0  #: tangents factorised (fewer than iterations with refactor="adaptive")


def solve_pressures(model, pressures, *, link_load=None, y0=None, callback=None,
                    newton_options: NewtonOptions = SWEEP_NEWTON, continuation: bool = True):
    """Follow increasing pressures [MPa] from the state y0 (default: unloaded, P = 0).

    Each pressure is one load step of :func:`softhand.fem.newton_path.solve_path` from the last converged
    state; where its predictor bends the finger by more than :data:`BEND_STEP`, or where it
    fails, the path of the finger with a softer rubber (:data:`PATH_KAPPA_RATIO`) to that
    pressure, then a (quasi-)Newton solve of the finger itself; where that fails too (or
    ``continuation=False``), the load step cut back (halved) until Newton converges. Returns
    ([FingerState], SweepStats); raises :class:`softhand.fem.newton.NotConverged` with the last
    converged state when even the cut-back fails.
    """
    # mixed precision: a single-precision factor, refined in double only as far as each use needs
    # (a Newton system to its forcing term, a quasi-Newton direction likewise, the predictor to
    # 1e-2). Refined to 1e-10 every time, as before the quasi-Newton directions and the
    # predictor passed their tolerances, it stalled near 1e-10 (the fibers are 1000 mu stiffer
    # than the rubber) and fell back to double after one wasted factorisation. On the default
    # mesh, 0-0.8 MPa: 11.6-12.4 s against 14.1-14.2 s in double, theta equal to 1e-8 deg
    solver = make_solver(symmetric=True, precision="mixed")
    soft = softened(model) if continuation else None
    t0, factorizations0 = time.perf_counter(), solver.n_factorizations
    history = [(0.0, model.constraint.zero() if y0 is None else np.array(y0, dtype=float))]
    states, totals = [], np.zeros(4)  # assembly s, solve s, iterations, cutbacks
    scale = model.design.mu_sf * model.design.a ** 2 * model.design.l0  # [N] residual scale
    for P in (float(p) for p in pressures):
        y, its = _solve_one(model, soft, P, history, link_load, solver, newton_options, scale, totals)
        if P != history[-1][0]:
            history.append((P, y))
        states.append(model.state(y, P, its))
        if callback is not None:
            callback(states[-1])
    stats = SweepStats(time.perf_counter() - t0, totals[0], totals[1], int(totals[2]),
                       int(totals[3]), solver.describe(), solver.n_factorizations - factorizations0)
    return states, stats


def softened(model, kappa_ratio: float = PATH_KAPPA_RATIO):
    """``model`` with its rubber's bulk modulus at ``kappa_ratio`` mu (mesh, windings, links and
    cavity shared), or None when the model's own rubber is no stiffer than that."""
    if model.options.kappa_ratio <= kappa_ratio:
        return None
    soft = copy.copy(model)
    soft.solid = model.solid.with_bulk_modulus(kappa_ratio * model.design.mu_sf)
    return soft


def predicted_bend(model, y, P1, P, link_load, solver, options):
    """(the bend [rad] (sum of hinge angles) the tangent predictor adds from the state y at P1 to
    P, the predictor's direction or None): solved with the solver's factorisation when it has one
    of this size, as the load step's predictor then is; the step starts along this direction."""
    eps = 1e-7 * max(abs(P - P1), 1e-3)
    if factored_size(solver) == len(y):
        R0 = model.residual(y, P1, link_load)
        solve = lambda b: solver.apply(b, rtol=options.forcing)  # noqa: E731
    else:
        R0, K0 = model.residual_tangent(y, P1, link_load)
        solve = lambda b: solver.solve(K0, b)  # noqa: E731
    rhs = R0 + (model.residual(y, P1 + eps, link_load) - R0) * ((P - P1) / eps)
    try:
        dy = solve(-rhs)
    except (RuntimeError, np.linalg.LinAlgError, ValueError):
        return np.inf, None
    return abs(float(np.sum(dy[len(model.constraint.free):]))), dy


def _solve_one(model, soft, P, history, link_load, solver, options, scale, totals):
    """The state at P from the last converged (P_i, y_i); updates totals in place.

    One load step from the last state with the tangent predictor of
    :func:`softhand.fem.newton_path.solve_path` (a secant predictor from the last two states
    made the chattering tension-only fibers fail more often than it saved iterations). With a
    softened model (:func:`softened`), where the predictor bends the finger by more than
    :data:`BEND_STEP`, or where the direct step fails: the softer rubber's path from y_i to P in
    steps of about :data:`SOFT_BEND` (cut back when one fails), then one (quasi-)Newton solve of the
    model itself from there; where that fails too, or without one, the direct step cut back
    (halved) until Newton converges.
    """
    P1, y1 = history[-1]

    def step(m, steps=1, min_dt=PathOptions.min_dt, direction=None):
        return solve_path(lambda y, t: m.residual_tangent(y, P1 + t * (P - P1), link_load), y1,
                          PathOptions(steps=steps, newton=options, min_dt=min_dt), solver=solver,
                          scale_t=lambda t: scale, residual_t=lambda y, t: m.residual(y, P1 + t * (P - P1), link_load),
                          first_direction=direction)

    def failed():  # counted as a cut-back; the failed solve's last factor is of an iterate off the path
        totals[3] += 1
        solver.forget()

    if soft is not None and P != P1:
        bend, direction = predicted_bend(model, y1, P1, P, link_load, solver, options)
        if bend <= BEND_STEP:
            try:
                path = step(model, min_dt=1.0, direction=direction)  # not cut back
                totals[:4] += (path.assembly_seconds, path.solve_seconds, path.total_iterations, 0)
                return path.x[-1], path.total_iterations
            except NotConverged:
                failed()
        try:
            path = step(soft, max(2, math.ceil(bend / SOFT_BEND)) if np.isfinite(bend) else SOFT_STEPS)
            last = newton(lambda y: model.residual_tangent(y, P, link_load), path.x[-1], options, solver=solver,
                          scale=scale, residual=lambda y: model.residual(y, P, link_load))
        except NotConverged:
            failed()
        else:
            its = path.total_iterations + last.iterations
            totals[:4] += (path.assembly_seconds + last.assembly_seconds, path.solve_seconds + last.solve_seconds,
                           its, path.cutbacks)
            return last.x, its
    try:
        path = step(model)
    except NotConverged as exc:  # named by the pressures, not the step's load fraction
        t, y = exc.last_converged if exc.last_converged is not None else (0.0, y1)
        reached = P1 + t * (P - P1)
        error = NotConverged(f"Newton did not converge above P = {reached:.6g} MPa on the way to "
                             f"{P:.6g} MPa", exc.history, exc.x, last_converged=(reached, y))
        error.pressure = reached  #: the last converged pressure [MPa]
        raise error from None
    totals[:4] += (path.assembly_seconds, path.solve_seconds, path.total_iterations, path.cutbacks)
    return path.x[-1], path.total_iterations
