"""Pressure sweeps of the finger FEM: each pressure one load step from the last converged state."""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from softhand.fem.linsolve import make_solver
from softhand.fem.newton import NewtonOptions, NotConverged
from softhand.fem.newton_path import PathOptions, solve_path

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
                    newton_options: NewtonOptions = SWEEP_NEWTON):
    """Follow increasing pressures [MPa] from the state y0 (default: unloaded, P = 0).

    Each pressure is one load step of :func:`softhand.fem.newton_path.solve_path` from the last converged
    state, cut back (halved) when Newton fails. Returns
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
    t0 = time.perf_counter()
    history = [(0.0, model.constraint.zero() if y0 is None else np.array(y0, dtype=float))]
    states, totals = [], np.zeros(5)  # assembly s, solve s, iterations, cutbacks, factorisations
    scale = model.design.mu_sf * model.design.a ** 2 * model.design.l0  # [N] residual scale
    for P in (float(p) for p in pressures):
        y, its = _solve_one(model, P, history, link_load, solver, newton_options, scale, totals)
        if P != history[-1][0]:
            history.append((P, y))
        states.append(model.state(y, P, its))
        if callback is not None:
            callback(states[-1])
    stats = SweepStats(time.perf_counter() - t0, totals[0], totals[1], int(totals[2]),
                       int(totals[3]), solver.describe(), int(totals[4]))
    return states, stats


def _solve_one(model, P, history, link_load, solver, options, scale, totals):
    """The state at P from the last converged (P_i, y_i); updates totals in place.

    One load step from the last state with the tangent predictor of
    :func:`softhand.fem.newton_path.solve_path` (a secant predictor from the last two states made the
    chattering tension-only fibers fail more often than it saved iterations).
    """
    P1, y1 = history[-1]
    try:
        path = solve_path(lambda y, t: model.residual_tangent(y, P1 + t * (P - P1), link_load), y1,
                          PathOptions(steps=1, newton=options), solver=solver, scale_t=lambda t: scale,
                          residual_t=lambda y, t: model.residual(y, P1 + t * (P - P1), link_load))
    except NotConverged as exc:  # named by the pressures, not the step's load fraction
        t, y = exc.last_converged if exc.last_converged is not None else (0.0, y1)
        reached = P1 + t * (P - P1)
        error = NotConverged(f"Newton did not converge above P = {reached:.6g} MPa on the way to "
                             f"{P:.6g} MPa", exc.history, exc.x, last_converged=(reached, y))
        error.pressure = reached  #: the last converged pressure [MPa]
        raise error from None
    totals += (path.assembly_seconds, path.solve_seconds, path.total_iterations, path.cutbacks,
               path.factorizations)
    return path.x[-1], path.total_iterations
