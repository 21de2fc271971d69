"""The FEM runs of a design's proof (:func:`softhand.studies.design.proof.prove` builds their models
and chains them; its module doc describes the steps): the free bend to the grasp angle, the grasp's
secant on the required F_v, the grasp at a pump pressure and the FEM's margin, with the options
that set their steps and tolerances (:class:`~softhand.studies.design.proof_steps.ProofOptions`).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import PchipInterpolator

from softhand.reduced.equations import hand, reservoir
from softhand.studies.design.evaluate import Evaluation
from softhand.studies.design.task import Task


@dataclass(frozen=True)
class ProofOptions:
    mesh_size_mm: float = 6.0   #: finger element size (gmsh, graded as the grasp FEM) [mm]
    dP_mpa: float = 0.05        #: first secant step of the grasp's cavity pressure [MPa]
    rtol: float = 0.01          #: the verified grasp's F_v within this of the requirement
    max_secant: int = 2         #: secant steps at most
    max_step_mpa: float = 0.2   #: largest cavity-pressure step of the continuation from contact [MPa]
    edge_ratio: float = 0.5     #: finger mesh grading at the ring edges (1: uniform)
    sheet: dict = field(default_factory=dict)  #: sheet FEM mesh keywords (fem.reservoir.SheetModel)
    bend_factors: tuple = (1.0, 1.25, 1.5, 1.75, 2.0, 2.5, 3.0, 4.0)  #: free bend: x eq. (28)'s pressure
    pump_tol_mpa: float = 1e-3  #: margin: the state's pump pressure within this of the margin's [MPa]
    max_corrections: int = 4    #: margin: secant corrections of the cavity pressure at most


class _Past(Exception):
    """Raised by the free-bend callback once the finger has bent past the grasp angle."""


def sheet_pressure(sheet):
    """The sheet FEM's p(V) [MPa] along its path from flat to V0, linear between its converged
    states (exact at them; steps <= R^2 t / 2): the reservoir of :func:`softhand.reduced.equations.reservoir.pump_pressure`."""
    return lambda V: np.interp(V, sheet.path_volume, sheet.path_pressure)


def free_bend(finger, theta_g: float, options: ProofOptions, tick=None) -> dict:
    """The free finger FEM up to theta_g [rad]: cavity pressure, dQ, stretch at theta_g;
    ``tick(text)`` is told each converged state's bend."""
    from softhand.fem.hand.finger import solve_pressures
    from softhand.fem.newton import NotConverged

    design = finger.design
    P28 = float(hand.pressure(theta_g, design, reservoir=False))
    states = []

    def keep(state):
        states.append(state)
        if tick is not None:
            tick(f"free bend {math.degrees(state.theta):.1f} of {math.degrees(theta_g):.1f} deg")
        if state.theta > theta_g:
            raise _Past

    t0 = time.perf_counter()
    try:
        targets = P28 * np.asarray(options.bend_factors)
        ramp = np.arange(options.max_step_mpa, targets[0], options.max_step_mpa)  # no big first step
        solve_pressures(finger, np.concatenate([ramp, targets]), callback=keep)
    except _Past:
        pass
    except NotConverged as exc:
        last = states[-1] if states else None
        reached = f"{math.degrees(last.theta):.1f} deg at {last.P:.3g} MPa" if last else "nothing"
        raise RuntimeError(f"free-bend FEM: Newton failed on the way to the grasp angle "
                           f"{math.degrees(theta_g):.1f} deg (converged: {reached}): "
                           f"{str(exc).split(';')[0]}") from None
    if not states or states[-1].theta <= theta_g:
        raise RuntimeError(f"free-bend FEM: {math.degrees(states[-1].theta) if states else 0:.2f} deg "
                           f"at {states[-1].P if states else 0:.3g} MPa, below the grasp angle")
    theta = np.array([0.0, *(s.theta for s in states)])
    at = lambda values: float(PchipInterpolator(theta, values)(theta_g))  # noqa: E731
    share = np.array([s.q / s.theta for s in states])  # the hinges' shares of the bend
    return {"P_finger_MPa": at([0.0, *(s.P for s in states)]),
            "hinge_share": [at([share[0, i], *share[:, i]]) for i in range(share.shape[1])],
            "dQ_mm3": at([0.0, *(s.dQ for s in states)]),
            "rubber_stretch": at([1.0, *(s.rubber_stretch for s in states)]),
            "max_principal_stretch": at([1.0, *(s.max_principal_stretch for s in states)]),
            "pressures_MPa": [s.P for s in states], "theta_deg": np.degrees(theta[1:]).tolist(),
            "seconds": time.perf_counter() - t0}


def grasp_secant(model, ladder, F_req: float, options: ProofOptions, say=None) -> dict:
    """Grasp states up the cavity pressures ``ladder`` [MPa] (each from the last; the last is
    the start), then a secant on F_v_fem(P) = F_req [N]."""
    from softhand.fem.hand.grasp import weight_vector

    t0 = time.perf_counter()

    def solve(P, start=None):
        state = model.solve(P, start=start)
        if say is not None:
            say(f"  grasp state: cavity {state.P:.4g} MPa, theta {math.degrees(state.theta):.2f} deg, "
                f"F_v {state.F_v:.4g} N ({time.perf_counter() - t0:.0f} s)")
        return state

    P_start, first, known = ladder[-1], None, []
    for P in ladder:  # continuation through contact: the Uzawa loop fails on big jumps
        first = solve(P, start=first)
        known.append(first)
    second = solve(P_start + options.dP_mpa, start=first)
    pair, steps = [first, second], 0
    while abs(pair[-1].F_v - F_req) > options.rtol * F_req and steps < options.max_secant:
        a, b = pair[-2], pair[-1]
        if b.F_v == a.F_v:
            break
        P = max(b.P + (F_req - b.F_v) * (b.P - a.P) / (b.F_v - a.F_v), 0.5 * b.P)
        below = [s for s in known + pair if s.P <= P]  # continue from the nearest state below P
        pair.append(solve(P, start=max(below, key=lambda s: s.P) if below else None))
        steps += 1
    best = min(pair, key=lambda s: abs(s.F_v - F_req))
    near = min((s for s in pair if s is not best), key=lambda s: abs(s.P - best.P))
    w = weight_vector(*sorted((best, near), key=lambda s: s.P))
    return {"first": first, "best": best, "w": w, "states": pair, "secant_steps": steps,
            "seconds": time.perf_counter() - t0}


def grasp_at_pump(model, pump, start, P_pump: float, options: ProofOptions, say=None):
    """The grasp FEM state whose pump pressure ``pump(state)`` [MPa] is ``P_pump``: continued
    from the converged state ``start`` in cavity steps of at most ``max_step_mpa`` to P_pump
    plus the reservoir's pressure at ``start``, then secant corrections of the cavity pressure
    on the last two states (the pump pressure grows with the cavity's, at a slope near 1: the
    reservoir's pressure changes little with the oil the fingers take). RuntimeError if the
    pump pressure is not within ``pump_tol_mpa`` after ``max_corrections``."""
    t0 = time.perf_counter()
    states = [start]

    def solve(P):
        near = min(states, key=lambda s: abs(s.P - P))  # the nearest converged state
        state = model.solve(P, start=near)
        states.append(state)
        if say is not None:
            say(f"  grasp state: cavity {state.P:.4g} MPa, pump {pump(state):.4g} MPa, "
                f"F_v {state.F_v:.4g} N ({time.perf_counter() - t0:.0f} s)")
        return state

    target = P_pump + start.P - pump(start)  # the reservoir's pressure as at start
    steps = max(1, math.ceil(abs(target - start.P) / options.max_step_mpa - 1e-9))
    prev, state = None, start
    for P in np.linspace(start.P, target, steps + 1)[1:]:
        prev, state = state, solve(P)
    for _ in range(options.max_corrections):
        miss = pump(state) - P_pump
        if abs(miss) <= options.pump_tol_mpa:
            return state
        slope = (pump(state) - pump(prev)) / (state.P - prev.P) if state.P != prev.P else 1.0
        prev, state = state, solve(state.P - miss / (slope if slope > 0.5 else 1.0))
    if abs(pump(state) - P_pump) > options.pump_tol_mpa:
        raise RuntimeError(f"grasp FEM: the pump pressure {P_pump:.4g} MPa not reached within "
                           f"{options.pump_tol_mpa:g} MPa after {options.max_corrections} corrections "
                           f"(last {pump(state):.6g} MPa)")
    return state


def margin(model, sheet, best, ev: Evaluation, task: Task, options: ProofOptions, say=None) -> tuple[dict, list]:
    """The FEM's margin (:mod:`softhand.studies.design.proof`, 4.) from the verified grasp ``best``: the grasp at
    the reduced margin's pump pressure ev.P_margin, and at the pump limit if that is above it;
    (the record, those states). A grasp FEM that fails on the way is reported (``"error"``),
    not raised: the margin is the task's objective, which the verified grasp has already met
    (its F_v at P_grasp)."""
    from softhand.fem.newton import NotConverged

    finger, design = model.finger, model.design

    oil = {}  # id(state) -> (state, V): the cavity's volume integral once a state (the state kept: its id stays its own)

    def oil_left(state):
        if id(state) not in oil:
            oil[id(state)] = (state, float(reservoir.oil_left(finger.dQ(state.y), design)))
        V = oil[id(state)][1]
        if not V > 0:
            raise RuntimeError(f"grasp FEM: the fingers take all the oil (V0 = {design.V0:.0f} mm^3) "
                               f"at the cavity pressure {state.P:.4g} MPa")
        return V

    def pump(state):  # the hand's pump pressure: the cavity's less the reservoir's at the oil left
        return float(reservoir.pump_pressure(state.P, oil_left(state), design, sheet_pressure(sheet)))

    def row(state):
        return {"P_pump_MPa": pump(state), "P_cavity_MPa": state.P, "F_v_N": state.F_v,
                "oil_left_mm3": oil_left(state),
                "theta_deg": math.degrees(state.theta),
                "links_in_contact": [int(k) for k in np.flatnonzero(state.N > 0)],
                "contact_force_N": state.N.tolist()}

    F_req = task.required_F_v()
    try:
        at = grasp_at_pump(model, pump, best, ev.P_margin, options, say)
    except (NotConverged, RuntimeError) as exc:  # the margin is the objective, not a limit: reported
        return {"margin": {"error": str(exc).split(";")[0], "predicted_F_v_N": ev.F_v_at_limit,
                           "below_pump_limit": ev.margin_edge}}, []
    out = {"margin_N": at.F_v - F_req, "F_v_at_pump_limit_N": None if ev.margin_edge else at.F_v,
           "margin": {**row(at), "predicted_F_v_N": ev.F_v_at_limit, "below_pump_limit": ev.margin_edge}}
    if not ev.margin_edge:
        return out, [at]
    try:  # the FEM goes on to the pump limit, where the reduced model does not reach
        limit = grasp_at_pump(model, pump, at, task.max_pressure, options, say)
    except (NotConverged, RuntimeError) as exc:
        out["at_pump_limit"] = {"error": str(exc).split(";")[0]}
        return out, [at]
    out["F_v_at_pump_limit_N"] = limit.F_v
    out["at_pump_limit"] = {**row(limit), "margin_N": limit.F_v - F_req}
    return out, [at, limit]
