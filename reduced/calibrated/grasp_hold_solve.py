"""One pad holding the object with the cavity pressure one more unknown: the equations of
:mod:`softhand.reduced.calibrated.grasp_hold` on pad k, their batched Newton solve, the
:class:`softhand.reduced.calibrated.grasp_hold_solve.Hold` they answer with, and what the fast
and the slow path share (the largest pressure either answers at, the slow path's grid of
pressures, the check that a solution is
:func:`softhand.reduced.calibrated.grasp_fem.grasp_state`'s state). Units: mm, N, MPa, rad.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from softhand.reduced.equations import contact, hand, kinematics
from softhand.reduced.calibrated import finger_hinges, grasp_fem
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.equations.reservoir import oil_volume, pressure as p_r

#: tolerance of the fast solve (Newton step, relative on the unknowns)
_XTOL = 1e-13
#: tolerance of the slow path's brentq, and of the last bisection for the one-pad grasp's end [MPa]
PTOL = 1e-13


class Hold(NamedTuple):
    """A grasp posed by F_v or by the pump pressure."""

    P_cavity: float   #: the finger's cavity pressure [MPa]
    P_pump: float     #: the pump pressure, P_cavity less the reservoir's p_r at theta [MPa]
    F_v: float        #: normal force per finger (29) [N]
    theta: float      #: the finger's bend, sum of the hinge angles [rad]
    link: int         #: the touching pad
    fast: bool        #: found by the one-solve path (False: the slow path)
    #: :func:`softhand.reduced.calibrated.grasp_hold.at_pump` only: why the grasp stops below the
    #: pump pressure asked ("": it does not)
    edge: str = ""


#: :attr:`Hold.edge`: one pad no longer holds the object alone above this state (a second pad touches it)
ONE_PAD_END = "one pad no longer holds the object alone (a second pad touches it)"
#: :attr:`Hold.edge`: the cavity pressure reaches the calibrated finger's highest (the free finger's at its
#: largest bend), above which the finger model has no state
LARGEST_BEND = "the cavity pressure reaches the calibrated finger's highest (the free finger's at its largest bend)"


def reservoir_pressure(theta, design: HandDesign, reservoir: bool = True):
    """p_r [MPa] at the oil the n fingers take at bend theta [rad] (0 without the reservoir)."""
    if not reservoir:
        return 0.0 * np.asarray(theta, float)
    return p_r(oil_volume(hand.check_theta(theta), design), design)


def pump_pressure(P, theta, design: HandDesign, reservoir: bool):
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
    moments = finger_hinges.hinge_moments(q, P[:, None], design) - N[:, None] * grad - Tq
    tip = np.stack([np.cos(alpha[:, -1]), np.sin(alpha[:, -1])], axis=1)
    F_v = np.einsum("bi,bi->b", -N[:, None] * nu + weight * t, tip)
    if target == "F_v":
        cond = F_v - value
    elif target == "P_pump":
        cond = pump_pressure(P, q.sum(axis=1), design, reservoir) - value
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


def solve_on_pad(k: int, design: HandDesign, diameter_mm: float, depth: float, mass_kg: float, target: str,
                 value: float, reservoir: bool, z0, corner: bool = False):
    """The Newton solve of :func:`hold_on_pad`, unchecked: (z, the gaps of the pads but k (and
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


def hold_of_solution(k: int, solved, design: HandDesign, reservoir: bool) -> Hold | None:
    """The Hold of :func:`solve_on_pad`'s solution with pad k touching, None if it is not
    acceptable (N < 0, another pad in the object)."""
    z, gaps, F_v = solved
    if z[-2] < 0.0 or np.min(gaps) < -grasp_fem.PENETRATION:
        return None
    q = _hinges(z, k, design.n_s)
    theta, P = float(np.sum(q)), float(z[-1])
    return Hold(P, float(pump_pressure(P, theta, design, reservoir)), F_v, theta, k, True)


def hold_on_pad(k: int, design: HandDesign, diameter_mm: float, depth: float, mass_kg: float, target: str,
                value: float, reservoir: bool, z0, corner: bool = False) -> Hold | None:
    """:func:`softhand.reduced.calibrated.grasp_hold_fast.fast_hold`'s Newton solve with pad k
    touching (``corner``: with its far end), from z0 = (held hinges, distal hinges, N, cavity
    pressure); None if it fails or its state is not acceptable (N < 0, another pad in the
    object -- but pad ``value`` for ``target="gap"`` --, a residual left)."""
    solved = solve_on_pad(k, design, diameter_mm, depth, mass_kg, target, value, reservoir, z0, corner)
    if solved is None:
        return None
    if target == "gap":
        solved[1][int(value)] = np.inf
    return hold_of_solution(k, solved, design, reservoir)


def is_state(held: Hold, design: HandDesign, diameter_mm: float, mass_kg: float) -> bool:
    """Whether ``grasp_state`` at held's cavity pressure is held's state (pad, bend)."""
    state = grasp_fem.grasp_state(design, diameter_mm, held.P_cavity, mass_kg)
    return state.link == held.link and abs(state.theta - held.theta) <= 1e-9 * max(1.0, abs(held.theta))


def hold_of_state(s: grasp_fem.GraspState, design: HandDesign, reservoir: bool, edge: str) -> Hold:
    """The Hold of grasp state s (found by stepping ``grasp_state``: the slow path's)."""
    return Hold(s.P, float(pump_pressure(s.P, s.theta, design, reservoir)), s.F_v, s.theta, s.link,
                False, edge)


def largest_pressure(design: HandDesign) -> float:
    """The largest cavity pressure [MPa] either path answers at: the free finger's at (nearly)
    its largest bend, where :func:`softhand.reduced.calibrated.grasp_fem.grasp_state` stops."""
    return float(hand.finger_pressure(0.999 * hand.THETA_RANGE[1], design))


#: the slow path's bracket: its first step above the contact pressure [MPa]; each next one twice as long
GRID_STEP = 0.05


def pressure_grid(P0: float, top: float):
    """The cavity pressures [MPa] the slow path steps through: P0, then P0 + GRID_STEP, each step
    twice the last, up to top (the last one)."""
    P, step = P0, GRID_STEP
    yield P
    while P < top:
        P, step = min(P + step, top), 2.0 * step
        yield P
