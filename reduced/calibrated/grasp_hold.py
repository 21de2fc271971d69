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
pressure, and on the later pads and their far ends in turn, see :func:`fast_hold`). Neither
path answers above the free finger's pressure at its largest bend, where ``grasp_state`` has
no state. Where a second pad touches the object, the one-pad model ends (the same equations
with that pad's gap = 0 give the end, :func:`one_pad_end`; a task's margin is measured there
if the pump limit lies beyond, :func:`at_pump`) or the state snaps to another pad (the state
below the snap answers a pump pressure inside the jump). Units: mm, N, MPa, rad.
"""
from __future__ import annotations

import itertools
from typing import NamedTuple

import numpy as np
from scipy.optimize import brentq

from softhand.reduced.equations import contact, hand, kinematics
from softhand.reduced.calibrated import grasp_fem
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.equations.reservoir import oil_volume, pressure as p_r

#: tolerance of the fast solve (Newton step, relative on the unknowns) and of the slow path's brentq [MPa]
_XTOL, _PTOL = 1e-13, 1e-13
#: where one pad stops holding the object alone, the end is bisected to this [MPa] (after 0.05 MPa)
#: before the second Newton solve for it from there (``_end_between()``)
BRACKET_RESOLUTION = 1e-3


class Hold(NamedTuple):
    """A grasp posed by F_v or by the pump pressure."""

    P_cavity: float   #: the finger's cavity pressure [MPa]
    P_pump: float     #: the pump pressure, P_cavity less the reservoir's p_r at theta [MPa]
    F_v: float        #: normal force per finger (29) [N]
    theta: float      #: the finger's bend, sum of the hinge angles [rad]
    link: int         #: the touching pad
    fast: bool        #: found by the one-solve path (False: the slow path)
    edge: str = ""    #: :func:`at_pump` only: why the grasp stops below the pump pressure asked ("": it does not)


#: :attr:`Hold.edge`: one pad no longer holds the object alone above this state (a second pad touches it)
ONE_PAD_END = "one pad no longer holds the object alone (a second pad touches it)"
#: :attr:`Hold.edge`: the cavity pressure reaches the calibrated finger's highest (the free finger's at its
#: largest bend), above which the finger model has no state
LARGEST_BEND = "the cavity pressure reaches the calibrated finger's highest (the free finger's at its largest bend)"


class NotReached(InputError):
    """The force or pump pressure asked is not reached on one pad; ``reached`` is the grasp
    where one pad stops holding the object alone (or at the calibrated finger's highest
    pressure): how far it comes."""

    def __init__(self, target: str, value: float, allowed: str, reached: Hold):
        super().__init__(target, value, allowed)
        self.reached = reached


def reservoir_pressure(theta, design: HandDesign, reservoir: bool = True):
    """p_r [MPa] at the oil the n fingers take at bend theta [rad] (0 without the reservoir)."""
    if not reservoir:
        return 0.0 * np.asarray(theta, float)
    return p_r(oil_volume(hand.check_theta(theta), design), design)


def _pump(P, theta, design: HandDesign, reservoir: bool):
    """The pump pressure [MPa] at cavity pressure P with the fingers at bend theta [rad]."""
    return hand.pump_pressure_at_bend(P, hand.check_theta(theta), design) if reservoir else P


def _residuals(Z, k: int, depth: float, radius: float, weight: float, target: str, value: float,
               design: HandDesign, reservoir: bool, corner: bool = False):
    """The module's equations at a batch of unknowns Z (B, m + 2), m = k held hinges (+ 1 for the
    distal ones) -> (residuals (B, m + 2), F_v (B,)); :func:`softhand.reduced.calibrated.grasp_fem.grasp_state`'s
    equilibrium with pad k touching (``corner``: with its far end, the hinge it shares with pad
    k+1), written for many states at once."""
    n_s, m = design.n_s, Z.shape[1] - 2
    q = np.concatenate([Z[:, :k], np.repeat(Z[:, k:k + 1], n_s - k, axis=1)], axis=1)
    N, P = Z[:, m], Z[:, m + 1]
    p = kinematics.joint_positions(q, design)                       # (B, n_s + 2, 2)
    alpha = kinematics.link_angles(q, design)                       # (B, n_s + 1)
    C = np.array([0.0, depth])
    A, AB = p[:, k], p[:, k + 1] - p[:, k]
    tau = np.ones(len(Z)) if corner else \
        np.minimum(np.maximum(np.einsum("bi,bi->b", C - A, AB) / np.einsum("bi,bi->b", AB, AB), 0.0), 1.0)
    xs = A + tau[:, None] * AB                                      # closest point of pad k
    rho = np.linalg.norm(C - xs, axis=1)
    nu = (C - xs) / rho[:, None]
    t = np.stack([-np.sin(alpha[:, k]), np.cos(alpha[:, k])], axis=1)
    dx = (xs[:, None, :] - p[:, 1:-1]) @ contact.OMEGA.T            # hinge j turns x* about x_j
    dx[:, k:] = 0.0                                                 # ... for j <= k only
    grad, Tq = -np.einsum("bji,bi->bj", dx, nu), weight * np.einsum("bji,bi->bj", dx, t)
    moments = grasp_fem.hinge_moments(q, P[:, None], design) - N[:, None] * grad - Tq
    tip = np.stack([np.cos(alpha[:, -1]), np.sin(alpha[:, -1])], axis=1)
    F_v = np.einsum("bi,bi->b", -N[:, None] * nu + weight * t, tip)
    if target == "F_v":
        cond = F_v - value
    elif target == "P_pump":
        cond = _pump(P, q.sum(axis=1), design, reservoir) - value
    elif target == "gap":  # pad ``value`` just touches the object: where one pad stops holding it alone
        cond = contact.pad_gaps(q, C, radius, design)[:, int(value)]
    else:
        raise ValueError(target)
    # hinges 1..k held; hinge k+1 (as every distal one) free: M_{k+1} = 0
    return np.column_stack([moments[:, :m], rho - radius, cond]), F_v


def _newton(fun, z0, scale, *, max_iter: int = 40):
    """Newton on fun (batched, see ``_residuals()``) from z0: one batched call per iteration
    gives the residual and its Jacobian by forward differences (steps 1e-7 scale); a step that
    does not decrease the residual is taken back and halved. The root, or None."""
    z, h = np.asarray(z0, float), 1e-7 * np.asarray(scale, float)
    best, dz = None, None
    for _ in range(max_iter):
        R = fun(np.vstack([z, z + np.diag(h)]))[0]
        if best is not None and not np.linalg.norm(R[0]) < best[1]:  # worse: back, half the step
            dz = 0.5 * dz
            z = best[0] + dz
            continue
        best = (z, np.linalg.norm(R[0]))
        try:
            dz = -np.linalg.solve(((R[1:] - R[0]) / h[:, None]).T, R[0])
        except np.linalg.LinAlgError:
            return None
        if not np.all(np.isfinite(dz)):
            return None
        if np.all(np.abs(dz) <= _XTOL * np.maximum(np.abs(z), scale)):
            return z + dz
        z = z + dz
    return None


def fast_hold(design: HandDesign, diameter_mm: float, mass_kg: float, target: str, value: float, *,
              reservoir: bool = True) -> Hold | None:
    """The grasp with F_v = value [N] (``target="F_v"``) or pump pressure value [MPa]
    (``target="P_pump"``), by one Newton solve of the module's equations from the contact; None
    if that solve fails or is not the state :func:`softhand.reduced.calibrated.grasp_fem.grasp_state` reaches (see
    module doc).

    A pump pressure well above contact often presses a later pad than the one that touched
    first (the paper's hand at 2 MPa on 180 mm: pad 3, touching with pad 2), or a pad's far end
    (the hinge it shares with the next pad: ``grasp_state``'s corner contact): each pad with
    its face, then with its far end, is tried in turn, and an answer other than the first
    pad's face is kept only if ``grasp_state`` at its pressure is the same state (one
    equilibrium, against a dozen for the slow path). The pump pressure grows with the
    cavity's, so its answer is the only one; F_v need not (it drops where the touching pad
    changes): a later pad's F_v is kept only if it is the root the slow path finds, the one
    in the first interval of its grid (``_first_on_the_grid()``)."""
    design = grasp_fem.fem_finger(design)
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
    pads = _pads(first, design.n_s)
    into = []  # the solves that put another pad into the object: a snap may lie below them
    N0 = max(float(value), 1.0) if target == "F_v" else 1.0
    solve = lambda k, corner: _solve_on_pad(k, design, diameter_mm, depth, mass_kg, target, value, reservoir,  # noqa: E731
                                            _start(k, design.n_s, theta_c, N0, P0), corner)
    P_top = _largest_pressure(design)
    for k, corner, solved in _pad_solves(pads, design.n_s, solve):
        held = None if solved is None else _held(k, solved, design, reservoir)
        if held is None and target == "P_pump" and solved is not None and solved[0][-2] >= 0.0:
            into.append((k, corner, solved))
        if held is None or not held.P_cavity <= P_top:  # grasp_state has no state there
            continue
        if (k, corner) == (first, False) or _is_state(held, design, diameter_mm, mass_kg) and \
                (target == "P_pump" or _first_on_the_grid(held, P_c, design, diameter_mm, mass_kg, value)):
            return held
    for k, corner, (z, gaps, _) in into:
        j = _nearest_pad(k, gaps)
        if _next_to(j, k, corner):  # the contact moves on to a neighbour (a pad beyond: two contacts)
            snap = _snap_below(k, corner, z, j, design, diameter_mm, depth, mass_kg, value, reservoir, P_top)
            if snap is not None:
                return snap
    return None


#: the slow path's bracket: its first step above the contact pressure [MPa]; each next one twice as long
GRID_STEP = 0.05


def _grid(P0: float, top: float):
    """The cavity pressures [MPa] the slow path steps through: P0, then P0 + GRID_STEP, each step
    twice the last, up to top (the last one)."""
    P, step = P0, GRID_STEP
    yield P
    while P < top:
        P, step = min(P + step, top), 2.0 * step
        yield P


def _first_on_the_grid(held: Hold, P_contact: float, design: HandDesign, diameter_mm: float, mass_kg: float,
                       F_v: float) -> bool:
    """Whether F_v at held (on a later pad than the first) is the root :func:`slow_hold` finds:
    F_v below the asked one at every point of its grid (``_grid()`` from the contact
    pressure) below held's pressure, so that held lies in the grid's first interval where F_v
    reaches it. A few states at pressures of one pad, against the slow path's bracket and brentq."""
    for P in _grid(P_contact + 1e-9, held.P_cavity):
        if P >= held.P_cavity:
            break
        try:
            if grasp_fem.grasp_state(design, diameter_mm, P, mass_kg).F_v >= F_v:
                return False
        except InputError:
            return False
    return True


def _next_to(j: int, k: int, corner: bool) -> bool:
    """Whether pad j is next to the contact of pad k (its far end, the hinge with pad k+1, if
    ``corner``): touching it may move the contact there; a pad beyond makes two contacts."""
    return k - 1 <= j <= k + 1 + corner


def _start(k: int, n_s: int, theta_c: float, N0: float, P0: float) -> np.ndarray:
    """The Newton start on pad k: every hinge at the contact's theta_c / n_s, N0, P0."""
    return np.concatenate([np.full(k + (k < n_s), theta_c / n_s), [N0, P0]])


def _pad_solves(pads, n_s: int, solve):
    """(k, corner, solve(k, corner)) for the (pad, corner) pairs in turn; a pad's far end only if
    its face's solve put the next pad into the object (else the corner cannot be the contact)."""
    next_in = False
    for k, corner in pads:
        if corner and not next_in:
            continue
        solved = solve(k, corner)
        next_in = solved is not None and k < n_s and solved[1][k + 1] < -grasp_fem.PENETRATION
        yield k, corner, solved


def _pads(first: int, n_s: int) -> list[tuple[int, bool]]:
    """(pad, corner) from pad ``first`` on: each pad's face, then its far end (but the tip's)."""
    return [(k, corner) for k in range(first, n_s + 1) for corner in (False, True)[:1 + (k < n_s)]]


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
    end = _hold_on_pad(k, design, diameter_mm, depth, mass_kg, "gap", j, reservoir, z0, corner=corner)
    if end is None or not end.P_pump < value or not end.P_cavity <= P_top \
            or not _is_state(end, design, diameter_mm, mass_kg):
        return None
    try:
        above = grasp_fem.grasp_state(design, diameter_mm, end.P_cavity + SNAP_PROBE, mass_kg)
    except InputError:
        return None
    P_pump = float(_pump(above.P, above.theta, design, reservoir))
    # a snap: the bend jumps (a continuous change of pad moves it by ~1e-6 rad over SNAP_PROBE)
    return end if P_pump > value and abs(above.theta - end.theta) > 1e2 * SNAP_PROBE else None


def _is_state(held: Hold, design: HandDesign, diameter_mm: float, mass_kg: float) -> bool:
    """Whether ``grasp_state`` at held's cavity pressure is held's state (pad, bend)."""
    state = grasp_fem.grasp_state(design, diameter_mm, held.P_cavity, mass_kg)
    return state.link == held.link and abs(state.theta - held.theta) <= 1e-9 * max(1.0, abs(held.theta))


def _hold_on_pad(k: int, design: HandDesign, diameter_mm: float, depth: float, mass_kg: float, target: str,
                 value: float, reservoir: bool, z0, corner: bool = False) -> Hold | None:
    """:func:`fast_hold`'s Newton solve with pad k touching (``corner``: with its far end), from
    z0 = (held hinges, distal hinges, N, cavity pressure); None if it fails or its state is not
    acceptable (N < 0, another pad in the object -- but pad ``value`` for ``target="gap"`` --,
    a residual left)."""
    solved = _solve_on_pad(k, design, diameter_mm, depth, mass_kg, target, value, reservoir, z0, corner)
    if solved is None:
        return None
    if target == "gap":
        solved[1][int(value)] = np.inf
    return _held(k, solved, design, reservoir)


def _held(k: int, solved, design: HandDesign, reservoir: bool) -> Hold | None:
    """The Hold of ``_solve_on_pad()``'s solution with pad k touching, None if it is not
    acceptable (N < 0, another pad in the object)."""
    z, gaps, F_v = solved
    if z[-2] < 0.0 or np.min(gaps) < -grasp_fem.PENETRATION:
        return None
    q = _hinges(z, k, design.n_s)
    theta, P = float(np.sum(q)), float(z[-1])
    return Hold(P, float(_pump(P, theta, design, reservoir)), F_v, theta, k, True)


def _solve_on_pad(k: int, design: HandDesign, diameter_mm: float, depth: float, mass_kg: float, target: str,
                  value: float, reservoir: bool, z0, corner: bool = False):
    """The Newton solve of ``_hold_on_pad()``, unchecked: (z, the gaps of the pads but k (and
    k+1 for a corner), F_v), or None if it fails or leaves a residual."""
    radius, weight = 0.5 * float(diameter_mm), float(mass_kg) * design.g / design.n
    m = len(z0) - 2
    fun = lambda Z: _residuals(Z, k, depth, radius, weight, target, value, design, reservoir, corner)  # noqa: E731
    try:
        z = _newton(fun, z0, np.concatenate([np.full(m, 0.01), [1.0, 0.1]]))
    except InputError:  # an iterate beyond the models' range (e.g. more oil than the reservoir holds)
        return None
    if z is None:
        return None
    res, F_v = fun(z[None])
    if np.max(np.abs(res)) > 1e-8:
        return None
    gaps = contact.pad_gaps(_hinges(z, k, design.n_s), (0.0, depth), radius, design)
    gaps[k:k + 1 + corner] = np.inf
    return z, gaps, float(F_v[0])


def _hinges(z, k: int, n_s: int) -> np.ndarray:
    """The hinge angles (n_s,) of the unknowns z: k held, the distal ones at z[k]."""
    return np.concatenate([z[:k], np.full(n_s - k, z[k] if k < n_s else 0.0)])


def _largest_pressure(design: HandDesign) -> float:
    """The largest cavity pressure [MPa] either path answers at: the free finger's at (nearly)
    its largest bend, where :func:`softhand.reduced.calibrated.grasp_fem.grasp_state` stops."""
    return float(hand.finger_pressure(0.999 * hand.THETA_RANGE[1], design))


def _condition(target: str, value: float, design: HandDesign, reservoir: bool):
    """c(theta, P, F_v) of the module docstring: F_v - value [N], or P - p_r(theta) - value [MPa]."""
    if target == "F_v":
        return lambda theta, P, F_v: F_v - value
    if target == "P_pump":
        return lambda theta, P, F_v: float(_pump(P, theta, design, reservoir)) - value
    raise ValueError(target)


def slow_hold(design: HandDesign, diameter_mm: float, mass_kg: float, target: str, value: float, *,
              reservoir: bool = True) -> Hold:
    """The same grasp as :func:`fast_hold`, by brentq on the cavity pressure around
    :func:`softhand.reduced.calibrated.grasp_fem.grasp_state` (from the contact pressure up to the free finger's
    pressure at its largest bend). Where one pad stops holding the object alone before the
    condition is met, the end is solved for (:func:`one_pad_end`'s way) and the refusal
    names it: its cavity and pump pressures and F_v."""
    design = grasp_fem.fem_finger(design)
    P_max = _largest_pressure(design)
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
    for hi in itertools.islice(_grid(lo, P_max), 1, None):  # the first sign change above lo
        try:
            s_hi = state(hi)
        except InputError:  # one pad no longer holds the object alone below hi: up to its end
            end = _end_between(state, s_lo, hi, design, diameter_mm, mass_kg, reservoir)
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
                         _hold_of(s_lo, design, reservoir, LARGEST_BEND))
    P = brentq(f, lo, hi, xtol=_PTOL, rtol=4 * np.finfo(float).eps)
    s = state(P)
    c = cond(s.theta, P, s.F_v)
    if abs(c) > 1e-8 * max(1.0, abs(value)) and (c > 0.0) == (target == "P_pump"):
        # a snap, not a root (the state, and the condition, jump): the state below it for the
        # pump pressure (the last one the pump reaches, as fast_hold's), above it for F_v (the
        # first that presses with F_v); brentq's P may lie on either side of the jump
        step = _PTOL if target == "F_v" else -_PTOL
        for _ in range(20):
            s = state(P + step)
            if (cond(s.theta, s.P, s.F_v) > 0.0) != (target == "P_pump"):
                P = P + step
                break
            step *= 2.0
        else:
            s = state(P)
    return Hold(float(P), float(_pump(P, s.theta, design, reservoir)), s.F_v, s.theta,
                s.link, False)


def hold(design: HandDesign, diameter_mm: float, mass_kg: float, target: str, value: float, *,
         reservoir: bool = True) -> Hold:
    """The grasp with F_v = value [N] (``target="F_v"``) or at the pump pressure value [MPa]
    (``target="P_pump"``): :func:`fast_hold`, else :func:`slow_hold`."""
    fast = fast_hold(design, diameter_mm, mass_kg, target, value, reservoir=reservoir)
    return fast if fast is not None else slow_hold(design, diameter_mm, mass_kg, target, value,
                                                   reservoir=reservoir)


def at_pump(design: HandDesign, diameter_mm: float, mass_kg: float, P_pump: float, *,
            reservoir: bool = True) -> Hold:
    """The grasp at pump pressure P_pump [MPa] (:func:`hold`) -- or, where the one-pad model
    ends at a lower pump pressure, the grasp at that end (:func:`one_pad_end`): a second pad
    touches the object, or the finger reaches its largest bend. ``Hold.edge`` then says which,
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


#: how far above the one-pad model's end [MPa] :func:`one_pad_end` checks that it has no state
END_PROBE = 1e-4


def one_pad_end(design: HandDesign, diameter_mm: float, mass_kg: float, *, reservoir: bool = True,
                beyond: float | None = None) -> Hold | None:
    """The grasp at the highest cavity pressure up to which one pad holds the object alone, from
    the contact on (``Hold.edge``: :data:`ONE_PAD_END`, or :data:`LARGEST_BEND` if that is
    where it ends); None if the finger does not touch the object.

    The end is a state where pad k holds the object and another pad j just touches it: one
    Newton solve of the module's equations with the condition gap_j = 0 (the cavity pressure
    unknown) gives it, from a state near it. ``beyond`` (a pump pressure the one-pad model does
    not reach): the start is the state of pad k (its face, then its far end) at that pump
    pressure (as :func:`fast_hold`) in which pad j is inside the object, for the pads k in
    turn; the end is kept if it is
    :func:`softhand.reduced.calibrated.grasp_fem.grasp_state`'s state at its pressure and ``grasp_state`` has none
    :data:`END_PROBE` above it (a pad change is not an end). Otherwise ``grasp_state`` is
    stepped up through the slow path's grid (``_grid()``) until it has no state and the end
    found between (``_end_between()``)."""
    design = grasp_fem.fem_finger(design)
    P_top = _largest_pressure(design)
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
        solve = lambda k, corner: _solve_on_pad(k, design, diameter_mm, depth, mass_kg, "P_pump", P_start,  # noqa: E731
                                                reservoir, _start(k, design.n_s, theta_c, 1.0, P0), corner)
        for k, corner, solved in _pad_solves(_pads(first, design.n_s), design.n_s, solve):
            if solved is None or solved[0][-2] < 0.0:
                continue
            end = _end_on_pad(k, _nearest_pad(k, solved[1]), solved[0], design, diameter_mm, depth,
                              mass_kg, reservoir, P_top, corner)
            if end is not None:
                return end
    s_lo = state(lo)
    for P in itertools.islice(_grid(lo, P_top), 1, None):
        try:
            s_lo = state(P)
        except InputError:
            return _end_between(state, s_lo, P, design, diameter_mm, mass_kg, reservoir)
    return _hold_of(s_lo, design, reservoir, LARGEST_BEND)


def _end_between(state, s_lo: grasp_fem.GraspState, hi: float, design: HandDesign, diameter_mm: float,
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
        end = _end_on_pad(k, _nearest_pad(k, gaps), z0, design, diameter_mm, s_lo.depth, mass_kg, reservoir, hi)
        if end is not None and end.P_cavity >= s_lo.P - 1e-9:
            return end
    return _hold_of(_bisect_end(state, s_lo, hi, _PTOL)[0], design, reservoir, ONE_PAD_END)


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


def _nearest_pad(k: int, gaps) -> int:
    """The pad but k (gaps[k] = inf) nearest the object, or inside it the most: the one that
    touches it where the one-pad state of pad k ends; pad k+1 only if it does more than
    share pad k's far end (a corner contact: both at gap 0)."""
    gaps = np.array(gaps, float)
    if k + 1 < len(gaps) and abs(gaps[k + 1]) <= grasp_fem.PENETRATION:
        gaps[k + 1] = np.inf
    return int(np.argmin(gaps))


def _end_on_pad(k: int, j: int, z0, design: HandDesign, diameter_mm: float, depth: float, mass_kg: float,
                reservoir: bool, P_top: float, corner: bool = False) -> Hold | None:
    """:func:`one_pad_end`'s Newton solve from z0: pad k (its far end if ``corner``) holds the
    object, pad j just touches it, at a cavity pressure up to P_top. None if it fails, or if it
    is not ``grasp_state``'s state at its pressure, or (j next to the contact: perhaps a change
    of pad) ``grasp_state`` has a state :data:`END_PROBE` above it."""
    end = _hold_on_pad(k, design, diameter_mm, depth, mass_kg, "gap", j, reservoir, z0, corner=corner)
    if end is None or not end.P_cavity <= P_top:
        return None
    if not _is_state(end, design, diameter_mm, mass_kg):
        return None
    if not _next_to(j, k, corner):  # a pad beyond the next one on the object: two contacts
        return end._replace(edge=ONE_PAD_END)
    try:
        grasp_fem.grasp_state(design, diameter_mm, end.P_cavity + END_PROBE, mass_kg)
    except InputError:
        return end._replace(edge=ONE_PAD_END)
    return None


def _hold_of(s: grasp_fem.GraspState, design: HandDesign, reservoir: bool, edge: str) -> Hold:
    """The Hold of grasp state s (found by stepping ``grasp_state``: the slow path's)."""
    return Hold(s.P, float(_pump(s.P, s.theta, design, reservoir)), s.F_v, s.theta, s.link,
                False, edge)
