"""A design judged for a hold task by the fast hold model (:mod:`softhand.reduced.holding.hold`).

A hold task names an object of any shape, its friction, and the margin the hold must have
(the weight times ``margin`` borne along the pull, or a pull of ``pull_N`` beyond the weight).
For a design: the object at its default placement; the least pump pressure whose holding limit
reaches the margin (``P_grasp``; bisection on the cavity pressure between the first touch and
the pump's limit, to :data:`PRESSURE_TOL`), the holding limit at the pump's limit
(``F_v_at_limit``; its requirement is ``F_v``), the free hand's pump pressure where a pad first
touches (``P_contact``), and the tube's stretch and the oil at the least pressure. The
constraints are the design's (:func:`softhand.studies.design.constraints.design_constraints`); the opening
is met by construction (the placement refuses an object the open fingers do not clear, and the
evaluation then has no answer). Units: mm, N, MPa.
"""
from __future__ import annotations

import math

import numpy as np

from softhand.reduced.equations import finger, hand, reservoir
from softhand.reduced.holding import hold, hold_closing, hold_fast
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.holding.hand_layout import place_object
from softhand.studies.design.constraints import design_constraints
from softhand.studies.design.evaluate import Evaluation, peak_stretch
from softhand.studies.design.task import Task

#: the least pressure's bisection tolerance [MPa]
PRESSURE_TOL = 2e-3


def _limit(d, task, placed, P_cavity, enough_N=math.inf):
    """(holding limit along the pull, the raw LP pull (may be < 0), closed hand) at P_cavity; the
    object's slide followed until the limit reaches ``enough_N``."""
    closed = hold_fast.close_hand(P_cavity, placed, d)
    r = hold.solve_hold(d, task.obj, P_cavity_MPa=P_cavity, pull_direction=task.hold_pull, placed=placed,
                        closed=closed, enough_N=enough_N)
    raw = r.extra.get("limit_pull_N")
    return (r.holding_limit_N if r.held else -math.inf), (raw if raw is not None else -math.inf), closed


def evaluate_hold(design: HandDesign, task: Task) -> Evaluation:
    """The :class:`softhand.studies.design.evaluate.Evaluation` of ``design`` for a hold task (module doc)."""
    d = hold_fast.finger_design(design, "fem" if design.finger_model == "fem" else "paper")
    placed = place_object(task.obj, d)  # InputError: no answer for this design (the optimiser's refusal)
    Pc_top = hold.cavity_pressure(task.max_pressure, placed, d)
    F_lim, raw, closed_top = _limit(d, task, placed, Pc_top)
    theta_touch = _touch(d, placed)
    required = task.required_hold_N()
    P_grasp, theta_hold, shortfall, link = math.inf, float(np.mean([s.q.sum() for s in closed_top.fingers])), None, -1
    if F_lim >= required:
        lo, hi = float(hand.finger_pressure(theta_touch, d)), Pc_top
        f_lo, f_hi = -required - task.mass * d.g, F_lim - required  # below the touch: nothing held
        best = closed_top
        for n in range(40):  # regula falsi (Illinois) on the raw pull's surplus, kept bracketing
            if hi - lo <= PRESSURE_TOL:
                break
            mid = hi - f_hi * (hi - lo) / (f_hi - f_lo) if n % 3 != 2 else 0.5 * (lo + hi)
            mid = min(max(mid, lo + 0.1 * PRESSURE_TOL), hi - 0.1 * PRESSURE_TOL)
            F_mid, raw_mid, c_mid = _limit(d, task, placed, mid, required)
            f_mid = (F_mid if math.isfinite(F_mid) else raw_mid) - required
            if F_mid >= required:
                hi, f_hi, best = mid, f_mid, c_mid
                f_lo *= 0.5
            else:
                lo, f_lo = mid, f_mid
                f_hi *= 0.5
        P_grasp = best.P_pump
        theta_hold = float(np.mean([s.q.sum() for s in best.fingers]))
        link = int(np.argmax(best.fingers[0].N))
    else:
        weight = task.mass * d.g
        reached = (weight + raw) if math.isfinite(raw) else 0.0
        shortfall = min(1.0, max(1.0 - reached / max(weight + required, 1e-9), 1e-6))
    try:
        oil = d.n * float(finger.oil_taken(theta_hold, d))
        P_contact = float(hand.pressure(theta_touch, d))
    except InputError:
        oil, P_contact = math.inf, math.inf
    stretch = 1.0 + task.stretch_factor * (peak_stretch(theta_hold, d) - 1.0)
    sheet = float(reservoir.stretch(d.V0, d))
    cons = design_constraints(d, task, oil, stretch, sheet, P_grasp, P_contact,
                              F_lim if math.isfinite(F_lim) else raw, task.max_pressure, shortfall)
    cons = [c if not c.name.startswith("F_v at the pump limit") else
            type(c)("holding limit along the pull at the pump limit [N]", c.value, c.limit, c.sense, c.scale)
            for c in cons]
    return Evaluation(d, float(placed.centre[1]), theta_touch, link, np.zeros(d.n_s), P_grasp, P_contact,
                      required, F_lim if math.isfinite(F_lim) else raw, stretch, sheet, tuple(cons), theta_hold,
                      task.max_pressure, "", "" if math.isfinite(P_grasp) else
                      "the holding limit asked is not reached within the pump's limit")


def _touch(d: HandDesign, placed) -> float:
    """The bend [rad] at which the first finger closing with equal hinges touches the object."""
    theta_free = float(hand.bend_angle(hand.pressure_span(d, reservoir=False)[1] * 0.999, d, reservoir=False))
    bends = []
    for i in range(d.n):
        bends.append(_first_bend(i, theta_free, placed, d))
    found = [b for b in bends if b is not None]
    if not found:
        raise InputError("object", placed.obj.describe(), "is not reached by the fingers")
    return min(found)


def _first_bend(i, theta_free, placed, d):
    q = hold_closing.first_touch(i, np.full(d.n_s, theta_free / d.n_s), placed, d)
    return None if q is None else float(np.sum(q))


#: the FEM's holding limit must confirm the fast model's within this (relative)
PROOF_RTOL = 0.10


def prove_hold(ev: Evaluation, task: Task, say=print) -> dict:
    """The FEM proof of a hold task's optimum: the whole-hand FEM hold
    (``softhand.fem.hand.hold.solve_hold``) at the cavity pressure of the fast model's least pump
    pressure; proven when the FEM holds the object and its holding limit is the fast model's
    within :data:`PROOF_RTOL`. ``{"report": why}`` when it is not, or when the FEM hold does not
    answer (a closing that does not converge)."""
    d = ev.design
    placed = place_object(task.obj, d)
    P_cavity = hold.cavity_pressure(ev.P_grasp, placed, d)
    fast = hold.solve_hold(d, task.obj, P_cavity_MPa=P_cavity, pull_direction=task.hold_pull, placed=placed)
    out = {"P_pump_MPa": ev.P_grasp, "P_cavity_MPa": P_cavity, "reduced": fast.to_json()}
    from softhand.fem.hand.hold import solve_hold as fem_solve_hold
    from softhand.fem.newton import NotConverged

    say(f"FEM proof of the hold at P_cavity_MPa = {P_cavity:.4g}")
    try:
        fem = fem_solve_hold(d, task.obj, P_cavity_MPa=P_cavity, pull_direction=task.hold_pull)
    except (InputError, NotConverged) as exc:
        return {**out, "report": f"the whole-hand FEM hold did not answer ({str(exc)[:300]}): the hold is "
                                 f"not proven"}
    out["fem"] = fem.to_json()
    error = abs(fem.holding_limit_N - fast.holding_limit_N) / max(fast.holding_limit_N, 1e-9)
    out["holding_limit_error"] = error
    if not fem.held or error > PROOF_RTOL:
        out["report"] = (f"the FEM's holding limit {fem.holding_limit_N:.4g} N (held: {fem.held}) misses the fast "
                         f"model's {fast.holding_limit_N:.4g} N by {100 * error:.3g} % (allowed {100 * PROOF_RTOL:g} %)")
    return out
