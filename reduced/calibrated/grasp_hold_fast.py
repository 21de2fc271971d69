"""The fast path of :mod:`softhand.reduced.calibrated.grasp_hold`: one Newton solve on each pad
in turn (its face, then its far end) from the contact, kept where it is
:func:`softhand.reduced.calibrated.grasp_fem.grasp_state`'s state; and, for a pump pressure
inside a snap of the grasp, the state just below it. Units: mm, N, MPa, rad.
"""
from __future__ import annotations

import numpy as np

from softhand.reduced.equations import contact, hand
from softhand.reduced.calibrated import finger_hinges, grasp_fem
from softhand.reduced.calibrated.grasp_hold_solve import (Hold, hold_of_solution, hold_on_pad, is_state,
                                                          largest_pressure, pressure_grid, pump_pressure,
                                                          reservoir_pressure, solve_on_pad)
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError


def fast_hold(design: HandDesign, diameter_mm: float, mass_kg: float, target: str, value: float, *,
              reservoir: bool = True) -> Hold | None:
    """The grasp with F_v = value [N] (``target="F_v"``) or pump pressure value [MPa]
    (``target="P_pump"``), by one Newton solve of the equations of
    :mod:`softhand.reduced.calibrated.grasp_hold` from the contact; None if that solve fails or
    is not the state :func:`softhand.reduced.calibrated.grasp_fem.grasp_state` reaches (see
    that module's doc).

    A pump pressure well above contact often presses a later pad than the one that touched
    first (the paper's hand at 2 MPa on 180 mm: pad 3, touching with pad 2), or a pad's far end
    (the hinge it shares with the next pad: ``grasp_state``'s corner contact): each pad with
    its face, then with its far end, is tried in turn, and an answer other than the first
    pad's face is kept only if ``grasp_state`` at its pressure is the same state (one
    equilibrium, against a dozen for the slow path). The pump pressure grows with the
    cavity's, so its answer is the only one; F_v need not (it drops where the touching pad
    changes): a later pad's F_v is kept only if it is the root the slow path finds, the one
    in the first interval of its grid (``_first_on_the_grid()``)."""
    design = finger_hinges.fem_finger(design)
    depth = contact.object_depth(diameter_mm, design)
    theta_c, first = contact.contact_angle(diameter_mm, design, depth=depth)
    if first == 0:
        return None
    P_c = float(hand.finger_pressure(theta_c, design))
    # the cavity pressure starts just past contact, or (pump pressure given) at the pump's
    # pressure plus the reservoir's at contact: a start 3 MPa below the answer often failed
    P0 = P_c + 0.1 if target == "F_v" else \
        max(P_c + 0.1, float(value) + float(reservoir_pressure(theta_c, design, reservoir)))
    # each pad with its face, then, if that put the next pad into the object, with its far end
    # (a corner, as grasp_state's)
    pads = pad_order(first, design.n_s)
    into = []  # the solves that put another pad into the object: a snap may lie below them
    N0 = max(float(value), 1.0) if target == "F_v" else 1.0
    solve = lambda k, corner: solve_on_pad(k, design, diameter_mm, depth, mass_kg, target, value, reservoir,  # noqa: E731
                                           newton_start(k, design.n_s, theta_c, N0, P0), corner)
    P_top = largest_pressure(design)
    for k, corner, solved in pad_solves(pads, design.n_s, solve):
        held = None if solved is None else hold_of_solution(k, solved, design, reservoir)
        if held is None and target == "P_pump" and solved is not None and solved[0][-2] >= 0.0:
            into.append((k, corner, solved))
        if held is None or not held.P_cavity <= P_top:  # grasp_state has no state there
            continue
        if (k, corner) == (first, False) or is_state(held, design, diameter_mm, mass_kg) and \
                (target == "P_pump" or _first_on_the_grid(held, P_c, design, diameter_mm, mass_kg, value)):
            return held
    for k, corner, (z, gaps, _) in into:
        j = nearest_pad(k, gaps)
        if next_to(j, k, corner):  # the contact moves on to a neighbour (a pad beyond: two contacts)
            snap = _snap_below(k, corner, z, j, design, diameter_mm, depth, mass_kg, value, reservoir, P_top)
            if snap is not None:
                return snap
    return None


def _first_on_the_grid(held: Hold, P_contact: float, design: HandDesign, diameter_mm: float, mass_kg: float,
                       F_v: float) -> bool:
    """Whether F_v at held (on a later pad than the first) is the root
    :func:`softhand.reduced.calibrated.grasp_hold.slow_hold` finds: F_v below the asked one at
    every point of its grid (:func:`softhand.reduced.calibrated.grasp_hold_solve.pressure_grid`
    from the contact pressure) below held's pressure, so that held lies in the grid's first
    interval where F_v reaches it. A few states at pressures of one pad, against the slow
    path's bracket and brentq."""
    for P in pressure_grid(P_contact + 1e-9, held.P_cavity):
        if P >= held.P_cavity:
            break
        try:
            if grasp_fem.grasp_state(design, diameter_mm, P, mass_kg).F_v >= F_v:
                return False
        except InputError:
            return False
    return True


def next_to(j: int, k: int, corner: bool) -> bool:
    """Whether pad j is next to the contact of pad k (its far end, the hinge with pad k+1, if
    ``corner``): touching it may move the contact there; a pad beyond makes two contacts."""
    return k - 1 <= j <= k + 1 + corner


def newton_start(k: int, n_s: int, theta_c: float, N0: float, P0: float) -> np.ndarray:
    """The Newton start on pad k: every hinge at the contact's theta_c / n_s, N0, P0."""
    return np.concatenate([np.full(k + (k < n_s), theta_c / n_s), [N0, P0]])


def pad_solves(pads, n_s: int, solve):
    """(k, corner, solve(k, corner)) for the (pad, corner) pairs in turn; a pad's far end only if
    its face's solve put the next pad into the object (else the corner cannot be the contact)."""
    next_in = False
    for k, corner in pads:
        if corner and not next_in:
            continue
        solved = solve(k, corner)
        next_in = solved is not None and k < n_s and solved[1][k + 1] < -grasp_fem.PENETRATION
        yield k, corner, solved


def pad_order(first: int, n_s: int) -> list[tuple[int, bool]]:
    """(pad, corner) from pad ``first`` on: each pad's face, then its far end (but the tip's)."""
    return [(k, corner) for k in range(first, n_s + 1) for corner in (False, True)[:1 + (k < n_s)]]


def nearest_pad(k: int, gaps) -> int:
    """The pad but k (gaps[k] = inf) nearest the object, or inside it the most: the one that
    touches it where the one-pad state of pad k ends; pad k+1 only if it does more than
    share pad k's far end (a corner contact: both at gap 0)."""
    gaps = np.array(gaps, float)
    if k + 1 < len(gaps) and abs(gaps[k + 1]) <= grasp_fem.PENETRATION:
        gaps[k + 1] = np.inf
    return int(np.argmin(gaps))


#: how far above a pad's end [MPa] ``_snap_below()`` looks for the state the finger snaps to
SNAP_PROBE = 1e-6


def _snap_below(k: int, corner: bool, z0, j: int, design: HandDesign, diameter_mm: float, depth: float,
                mass_kg: float, value: float, reservoir: bool, P_top: float) -> Hold | None:
    """The state just below a snap of the grasp past the pump pressure ``value``: where pad j
    touches the object while pad k (its far end if ``corner``) holds it, grasp_state's finger
    moves to another state at once (its bend jumps), and the pump pressure with it, from below
    ``value`` to above it. No equilibrium has that pump pressure: the state before the snap is
    the answer (its pump pressure a little below ``value``), as the slow path's root finder,
    which closes on the jump, finds too. None if there is no such snap."""
    end = hold_on_pad(k, design, diameter_mm, depth, mass_kg, "gap", j, reservoir, z0, corner=corner)
    if end is None or not end.P_pump < value or not end.P_cavity <= P_top \
            or not is_state(end, design, diameter_mm, mass_kg):
        return None
    try:
        above = grasp_fem.grasp_state(design, diameter_mm, end.P_cavity + SNAP_PROBE, mass_kg)
    except InputError:
        return None
    P_pump = float(pump_pressure(above.P, above.theta, design, reservoir))
    # a snap: the bend jumps (a continuous change of pad moves it by ~1e-6 rad over SNAP_PROBE)
    return end if P_pump > value and abs(above.theta - end.theta) > 1e2 * SNAP_PROBE else None
