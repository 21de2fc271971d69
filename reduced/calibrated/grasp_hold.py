r"""The FEM-informed grasp (:mod:`softhand.reduced.calibrated.grasp_fem`) posed for a design: the pump pressure that
holds the object with a given F_v, and F_v at a given pump pressure, each by one solve.

:func:`softhand.reduced.calibrated.grasp_fem.grasp_state` finds the finger's equilibrium at one cavity pressure P.
A design question fixes something else -- F_v (the pressure that holds the object) or the
pump's pressure (the force it gives) -- and a root finder on P around ``grasp_state`` costs a
dozen equilibria. Here P is one more unknown of the same equilibrium: with pad k touching
(hinges 1..k held, the distal hinges at one angle q_d, bent as the free finger's), the unknowns
z = (q_1..q_k, q_d, N, P) solve

.. math:: M_j(q, P) - N\,\partial_j g_k - T_j = 0 \ (j \le k), \quad M_{k+1}(q, P) = 0,
          \quad g_k(q) = 0, \quad c(q, N, P) = 0,

(M_{k+1} = 0 is P_free(n_s q_d) = P: the distal hinges as the free finger's), the first three exactly :func:`softhand.reduced.calibrated.grasp_fem.grasp_state`'s equations, and the last the
design's condition: F_v(q, N) = F_req, or P - p_r(theta) = P_pump, the pump pressure being the
cavity's less the reservoir's pressure at the oil the fingers have taken at the bend theta =
sum q (as ``softhand grasp --model fem`` and eq. (27)). The answer is accepted if it is the
state ``grasp_state`` reaches at that P (N >= 0, no other pad penetrating the object);
otherwise, or if the solve fails, the same numbers come from a bracketing root finder on
``grasp_state`` (the slow path, :func:`slow_hold`). The solve is Newton's method with one
batched evaluation of the equations per iteration (the state and its finite-difference
neighbours at once), 5-6 iterations from the contact state (the pump pressure given: at that
pressure, and on the later pads and their far ends in turn, see
:func:`softhand.reduced.calibrated.grasp_hold_fast.fast_hold`). Neither path answers above the
free finger's pressure at its largest bend, where ``grasp_state`` has no state. Where a second
pad touches the object, the one-pad model ends (the same equations with that pad's gap = 0
give the end, :func:`softhand.reduced.calibrated.grasp_hold_end.one_pad_end`; a task's margin is
measured there if the pump limit lies beyond, :func:`at_pump`) or the state snaps to another
pad (the state below the snap answers a pump pressure inside the jump). Units: mm, N, MPa, rad.

The equations and their Newton solve on one pad: :mod:`softhand.reduced.calibrated.grasp_hold_solve`;
the fast path: :mod:`softhand.reduced.calibrated.grasp_hold_fast`; the one-pad model's end:
:mod:`softhand.reduced.calibrated.grasp_hold_end`; here the slow path and the two questions a
design asks (:func:`hold`, :func:`at_pump`).
"""
from __future__ import annotations

import itertools

import numpy as np
from scipy.optimize import brentq

from softhand.reduced.equations import contact, hand
from softhand.reduced.calibrated import finger_hinges, grasp_fem, grasp_hold_fast
from softhand.reduced.calibrated.grasp_hold_end import end_between, one_pad_end
from softhand.reduced.calibrated.grasp_hold_solve import (LARGEST_BEND, PTOL, Hold, hold_of_state, largest_pressure,
                                                          pressure_grid, pump_pressure)
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError


class NotReached(InputError):
    """The force or pump pressure asked is not reached on one pad; ``reached`` is the grasp
    where one pad stops holding the object alone (or at the calibrated finger's highest
    pressure): how far it comes."""

    def __init__(self, target: str, value: float, allowed: str, reached: Hold):
        super().__init__(target, value, allowed)
        self.reached = reached


def _condition(target: str, value: float, design: HandDesign, reservoir: bool):
    """c(theta, P, F_v) of the module docstring: F_v - value [N], or P - p_r(theta) - value [MPa]."""
    if target == "F_v":
        return lambda theta, P, F_v: F_v - value
    if target == "P_pump":
        return lambda theta, P, F_v: float(pump_pressure(P, theta, design, reservoir)) - value
    raise ValueError(target)


def slow_hold(design: HandDesign, diameter_mm: float, mass_kg: float, target: str, value: float, *,
              reservoir: bool = True) -> Hold:
    """The same grasp as :func:`softhand.reduced.calibrated.grasp_hold_fast.fast_hold`, by brentq
    on the cavity pressure around :func:`softhand.reduced.calibrated.grasp_fem.grasp_state` (from
    the contact pressure up to the free finger's pressure at its largest bend). Where one pad
    stops holding the object alone before the condition is met, the end is solved for
    (:func:`softhand.reduced.calibrated.grasp_hold_end.one_pad_end`'s way) and the refusal names
    it: its cavity and pump pressures and F_v."""
    design = finger_hinges.fem_finger(design)
    P_max = largest_pressure(design)
    depth = contact.object_depth(diameter_mm, design)
    theta_c, _ = contact.contact_angle(diameter_mm, design, depth=depth)
    state = lambda P: grasp_fem.grasp_state(design, diameter_mm, P, mass_kg)  # noqa: E731
    cond = _condition(target, value, design, reservoir)

    def f(P):
        s = state(P)
        return cond(s.theta, P, s.F_v)

    P_contact = float(hand.finger_pressure(theta_c, design)) + 1e-9
    lo, s_lo = P_contact, None
    if target == "P_pump" and value > lo:
        # the reservoir's pressure is not negative, so the cavity pressure of the answer is at
        # least the pump's: the bracket starts there (no root below it); and if one pad no longer
        # holds the object alone there, it does not at the answer either (a pump limit beyond
        # where a second pad touches: one equilibrium instead of a search for that end)
        try:
            lo, s_lo = float(value), state(float(value))
        except InputError:
            raise InputError(target, value, f"not reached by the finger on one pad: a second pad "
                                            f"touches below the cavity pressure {value:.4g} MPa, "
                                            "the least the pump pressure needs") from None
        if cond(s_lo.theta, lo, s_lo.F_v) > 0.0:  # p_r < 0 there (a tabulated model's round-off at
            lo, s_lo = P_contact, None           # a tiny reservoir): the answer lies below, from contact
    s_lo = state(lo) if s_lo is None else s_lo
    f_lo = cond(s_lo.theta, lo, s_lo.F_v)
    for hi in itertools.islice(pressure_grid(lo, P_max), 1, None):  # the first sign change above lo
        try:
            s_hi = state(hi)
        except InputError:  # one pad no longer holds the object alone below hi: up to its end
            end = end_between(state, s_lo, hi, design, diameter_mm, mass_kg, reservoir)
            hi, f_hi = end.P_cavity, cond(end.theta, end.P_cavity, end.F_v)
            if not f_lo * f_hi <= 0.0:
                raise NotReached(target, value, f"not reached by the finger on one pad, which holds the "
                                                f"object alone up to the cavity pressure {hi:.6g} MPa (pump "
                                                f"{end.P_pump:.4g} MPa, F_v {end.F_v:.4g} N): above, "
                                                "a second pad touches it", end) from None
            break
        f_hi = cond(s_hi.theta, hi, s_hi.F_v)
        if f_lo * f_hi <= 0.0:
            break
        lo, s_lo, f_lo = hi, s_hi, f_hi
    else:  # no sign change up to the largest pressure (or lo is that pressure already)
        raise NotReached(target, value, f"not reached by the finger on one pad up to the cavity pressure "
                                        f"{lo:.6g} MPa (F_v {s_lo.F_v:.4g} N), where {LARGEST_BEND}",
                         hold_of_state(s_lo, design, reservoir, LARGEST_BEND))
    P = brentq(f, lo, hi, xtol=PTOL, rtol=4 * np.finfo(float).eps)
    s = state(P)
    c = cond(s.theta, P, s.F_v)
    if abs(c) > 1e-8 * max(1.0, abs(value)) and (c > 0.0) == (target == "P_pump"):
        # a snap, not a root (the state, and the condition, jump): the state below it for the
        # pump pressure (the last one the pump reaches, as fast_hold's), above it for F_v (the
        # first that presses with F_v); brentq's P may lie on either side of the jump
        step = PTOL if target == "F_v" else -PTOL
        for _ in range(20):
            s = state(P + step)
            if (cond(s.theta, s.P, s.F_v) > 0.0) != (target == "P_pump"):
                P = P + step
                break
            step *= 2.0
        else:
            s = state(P)
    return Hold(float(P), float(pump_pressure(P, s.theta, design, reservoir)), s.F_v, s.theta,
                s.link, False)


def hold(design: HandDesign, diameter_mm: float, mass_kg: float, target: str, value: float, *,
         reservoir: bool = True) -> Hold:
    """The grasp with F_v = value [N] (``target="F_v"``) or at the pump pressure value [MPa]
    (``target="P_pump"``): :func:`softhand.reduced.calibrated.grasp_hold_fast.fast_hold`, else
    :func:`slow_hold`."""
    fast = grasp_hold_fast.fast_hold(design, diameter_mm, mass_kg, target, value, reservoir=reservoir)
    return fast if fast is not None else slow_hold(design, diameter_mm, mass_kg, target, value,
                                                   reservoir=reservoir)


def at_pump(design: HandDesign, diameter_mm: float, mass_kg: float, P_pump: float, *,
            reservoir: bool = True) -> Hold:
    """The grasp at pump pressure P_pump [MPa] (:func:`hold`) -- or, where the one-pad model
    ends at a lower pump pressure, the grasp at that end
    (:func:`softhand.reduced.calibrated.grasp_hold_end.one_pad_end`): a second pad touches the
    object, or the finger reaches its largest bend. ``Hold.edge`` then says which,
    and its ``P_pump`` is below the one asked. What a task's margin is measured at: the force
    the hand gives at the pump limit, or at the highest pump pressure this model answers for."""
    try:
        return hold(design, diameter_mm, mass_kg, "P_pump", P_pump, reservoir=reservoir)
    except InputError as refused:
        try:
            end = one_pad_end(design, diameter_mm, mass_kg, reservoir=reservoir, beyond=P_pump)
        except InputError:  # no one-pad state from the contact on
            end = None
        if end is None or not end.P_pump < P_pump:
            raise refused
        return end
