"""Where one pad stops holding the object alone (a second pad touches it, or the finger reaches
its largest bend): :func:`softhand.reduced.calibrated.grasp_hold_end.one_pad_end`, by one Newton
solve with the second pad's gap = 0 from a state near it, or else by stepping
:func:`softhand.reduced.calibrated.grasp_fem.grasp_state` up until it has no state and
bisecting. Units: mm, N, MPa, rad.
"""
from __future__ import annotations

import itertools

import numpy as np

from softhand.reduced.equations import contact, hand
from softhand.reduced.calibrated import finger_hinges, grasp_fem
from softhand.reduced.calibrated.grasp_hold_fast import nearest_pad, newton_start, next_to, pad_order, pad_solves
from softhand.reduced.calibrated.grasp_hold_solve import (LARGEST_BEND, ONE_PAD_END, PTOL, Hold, hold_of_state,
                                                          hold_on_pad, is_state, largest_pressure, pressure_grid,
                                                          reservoir_pressure, solve_on_pad)
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError

#: where one pad stops holding the object alone, the end is bisected to this [MPa] (after 0.05 MPa)
#: before the second Newton solve for it from there (:func:`end_between`)
BRACKET_RESOLUTION = 1e-3
#: how far above the one-pad model's end [MPa] :func:`one_pad_end` checks that it has no state
END_PROBE = 1e-4


def one_pad_end(design: HandDesign, diameter_mm: float, mass_kg: float, *, reservoir: bool = True,
                beyond: float | None = None) -> Hold | None:
    """The grasp at the highest cavity pressure up to which one pad holds the object alone, from
    the contact on (``Hold.edge``: :data:`softhand.reduced.calibrated.grasp_hold_solve.ONE_PAD_END`,
    or :data:`softhand.reduced.calibrated.grasp_hold_solve.LARGEST_BEND` if that is where it
    ends); None if the finger does not touch the object.

    The end is a state where pad k holds the object and another pad j just touches it: one
    Newton solve of the equations of :mod:`softhand.reduced.calibrated.grasp_hold` with the
    condition gap_j = 0 (the cavity pressure unknown) gives it, from a state near it. ``beyond``
    (a pump pressure the one-pad model does not reach): the start is the state of pad k (its
    face, then its far end) at that pump pressure (as
    :func:`softhand.reduced.calibrated.grasp_hold_fast.fast_hold`) in which pad j is inside the
    object, for the pads k in turn; the end is kept if it is
    :func:`softhand.reduced.calibrated.grasp_fem.grasp_state`'s state at its pressure and ``grasp_state`` has none
    :data:`END_PROBE` above it (a pad change is not an end). Otherwise ``grasp_state`` is
    stepped up through the slow path's grid
    (:func:`softhand.reduced.calibrated.grasp_hold_solve.pressure_grid`) until it has no state
    and the end found between (:func:`end_between`)."""
    design = finger_hinges.fem_finger(design)
    P_top = largest_pressure(design)
    depth = contact.object_depth(diameter_mm, design)
    theta_c, first = contact.contact_angle(diameter_mm, design, depth=depth)
    if first == 0:
        return None
    state = lambda P: grasp_fem.grasp_state(design, diameter_mm, P, mass_kg)  # noqa: E731
    lo = float(hand.finger_pressure(theta_c, design)) + 1e-9
    if beyond is not None:
        # a state of pad k at that pump pressure (or at 0.9 of the largest cavity pressure, if
        # lower: beyond it the free finger has no pressure), the object inside other pads or not
        P_start = min(float(beyond), 0.9 * P_top)
        P0 = max(lo + 0.1, P_start + float(reservoir_pressure(theta_c, design, reservoir)))
        solve = lambda k, corner: solve_on_pad(k, design, diameter_mm, depth, mass_kg, "P_pump", P_start,  # noqa: E731
                                               reservoir, newton_start(k, design.n_s, theta_c, 1.0, P0), corner)
        for k, corner, solved in pad_solves(pad_order(first, design.n_s), design.n_s, solve):
            if solved is None or solved[0][-2] < 0.0:
                continue
            end = _end_on_pad(k, nearest_pad(k, solved[1]), solved[0], design, diameter_mm, depth,
                              mass_kg, reservoir, P_top, corner)
            if end is not None:
                return end
    s_lo = state(lo)
    for P in itertools.islice(pressure_grid(lo, P_top), 1, None):
        try:
            s_lo = state(P)
        except InputError:
            return end_between(state, s_lo, P, design, diameter_mm, mass_kg, reservoir)
    return hold_of_state(s_lo, design, reservoir, LARGEST_BEND)


def end_between(state, s_lo: grasp_fem.GraspState, hi: float, design: HandDesign, diameter_mm: float,
                mass_kg: float, reservoir: bool) -> Hold:
    """The one-pad grasp's end between the state s_lo and the cavity pressure hi (no state there):
    bisected to 0.05 MPa and solved for from there (``_end_on_pad()``); failing that, bisected
    to :data:`BRACKET_RESOLUTION` and solved for; failing that, bisected to 1e-13 MPa."""
    for tol in (0.05, BRACKET_RESOLUTION):
        s_lo, hi = _bisect_end(state, s_lo, hi, tol)
        k = s_lo.link
        if k < 1:
            continue
        gaps = contact.pad_gaps(s_lo.q, (0.0, s_lo.depth), 0.5 * float(diameter_mm), design)
        gaps[k] = np.inf
        z0 = np.concatenate([s_lo.q[:k], s_lo.q[k:k + 1] if k < design.n_s else [], [s_lo.N, s_lo.P]])
        end = _end_on_pad(k, nearest_pad(k, gaps), z0, design, diameter_mm, s_lo.depth, mass_kg, reservoir, hi)
        if end is not None and end.P_cavity >= s_lo.P - 1e-9:
            return end
    return hold_of_state(_bisect_end(state, s_lo, hi, PTOL)[0], design, reservoir, ONE_PAD_END)


def _bisect_end(state, s_lo: grasp_fem.GraspState, hi: float, tol: float):
    """(the last state, the first pressure without one) to tol [MPa], bisecting from s_lo (a
    state) and hi (a cavity pressure with none)."""
    while hi - s_lo.P > tol:
        mid = 0.5 * (s_lo.P + hi)
        try:
            s_lo = state(mid)
        except InputError:
            hi = mid
    return s_lo, hi


def _end_on_pad(k: int, j: int, z0, design: HandDesign, diameter_mm: float, depth: float, mass_kg: float,
                reservoir: bool, P_top: float, corner: bool = False) -> Hold | None:
    """:func:`one_pad_end`'s Newton solve from z0: pad k (its far end if ``corner``) holds the
    object, pad j just touches it, at a cavity pressure up to P_top. None if it fails, or if it
    is not ``grasp_state``'s state at its pressure, or (j next to the contact: perhaps a change
    of pad) ``grasp_state`` has a state :data:`END_PROBE` above it."""
    end = hold_on_pad(k, design, diameter_mm, depth, mass_kg, "gap", j, reservoir, z0, corner=corner)
    if end is None or not end.P_cavity <= P_top:
        return None
    if not is_state(end, design, diameter_mm, mass_kg):
        return None
    if not next_to(j, k, corner):  # a pad beyond the next one on the object: two contacts
        return end._replace(edge=ONE_PAD_END)
    try:
        grasp_fem.grasp_state(design, diameter_mm, end.P_cavity + END_PROBE, mass_kg)
    except InputError:
        return end._replace(edge=ONE_PAD_END)
    return None
