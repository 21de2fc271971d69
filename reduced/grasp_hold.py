r"""The FEM-informed grasp (:mod:`reduced.grasp_fem`) posed for a design: the pump pressure that
holds the object with a given F_v, and F_v at a given pump pressure, each by one solve.

:func:`reduced.grasp_fem.grasp_state` finds the finger's equilibrium at one cavity pressure P.
A design question fixes something else -- F_v (the pressure that holds the object) or the
pump's pressure (the force it gives) -- and a root finder on P around ``grasp_state`` costs a
dozen equilibria. Here P is one more unknown of the same equilibrium: with pad k touching
(hinges 1..k held, the distal hinges at one angle q_d, bent as the free finger's), the unknowns
z = (q_1..q_k, q_d, N, P) solve

.. math:: M_j(q, P) - N\,\partial_j g_k - T_j = 0 \ (j \le k), \quad M_{k+1}(q, P) = 0,
          \quad g_k(q) = 0, \quad c(q, N, P) = 0,

(M_{k+1} = 0 is P_free(n_s q_d) = P: the distal hinges as the free finger's), the first three exactly :func:`reduced.grasp_fem.grasp_state`'s equations, and the last the
design's condition: F_v(q, N) = F_req, or P - p_r(theta) = P_pump, the pump pressure being the
cavity's less the reservoir's pressure at the oil the fingers have taken at the bend theta =
sum q (as ``softhand grasp --model fem`` and eq. (27)). The answer is accepted if it is the
state ``grasp_state`` reaches at that P (N >= 0, no other pad penetrating the object);
otherwise, or if the solve fails, the same numbers come from a bracketing root finder on
``grasp_state`` (the slow path, :func:`slow_hold`). The solve is Newton's method with one
batched evaluation of the equations per iteration (the state and its finite-difference
neighbours at once), 5-6 iterations from the contact state (the pump pressure given: at that
pressure, and on the later pads in turn, see :func:`fast_hold`). Neither path answers above
the free finger's pressure at its largest bend, where ``grasp_state`` has no state. Units:
mm, N, MPa, rad.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.optimize import brentq

from . import contact, grasp_fem, hand, kinematics
from .design import HandDesign
from .errors import InputError

#: tolerance of the fast solve (Newton step, relative on the unknowns) and of the slow path's brentq [MPa]
_XTOL, _PTOL = 1e-13, 1e-13
#: the slow path's bracket: the least pressure step [MPa] towards where one pad stops holding
#: the object alone (a heavy object: the condition is not met before; without it, 60 halvings)
BRACKET_RESOLUTION = 1e-3


class Hold(NamedTuple):
    """A grasp posed by F_v or by the pump pressure."""

    P_cavity: float   #: the finger's cavity pressure [MPa]
    P_pump: float     #: the pump pressure, P_cavity less the reservoir's p_r at theta [MPa]
    F_v: float        #: normal force per finger (29) [N]
    theta: float      #: the finger's bend, sum of the hinge angles [rad]
    link: int         #: the touching pad
    fast: bool        #: found by the one-solve path (False: the slow path)


def reservoir_pressure(theta, design: HandDesign, reservoir: bool = True):
    """p_r [MPa] at the oil the n fingers take at bend theta [rad] (0 without the reservoir)."""
    if not reservoir:
        return 0.0 * np.asarray(theta, float)
    return hand._reservoir_pressure(hand.check_theta(theta), design)


def _residuals(Z, k: int, depth: float, radius: float, weight: float, target: str, value: float,
               design: HandDesign, reservoir: bool):
    """The module's equations at a batch of unknowns Z (B, m + 2), m = k held hinges (+ 1 for the
    distal ones) -> (residuals (B, m + 2), F_v (B,)); :func:`reduced.grasp_fem.grasp_state`'s
    equilibrium with pad k touching, written for many states at once."""
    n_s, m = design.n_s, Z.shape[1] - 2
    q = np.concatenate([Z[:, :k], np.repeat(Z[:, k:k + 1], n_s - k, axis=1)], axis=1)
    N, P = Z[:, m], Z[:, m + 1]
    p = kinematics.joint_positions(q, design)                       # (B, n_s + 2, 2)
    alpha = kinematics.link_angles(q, design)                       # (B, n_s + 1)
    C = np.array([0.0, depth])
    A, AB = p[:, k], p[:, k + 1] - p[:, k]
    tau = np.clip(np.einsum("bi,bi->b", C - A, AB) / np.einsum("bi,bi->b", AB, AB), 0.0, 1.0)
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
        cond = P - reservoir_pressure(q.sum(axis=1), design, reservoir) - value
    else:
        raise ValueError(target)
    # hinges 1..k held; hinge k+1 (as every distal one) free: M_{k+1} = 0
    return np.column_stack([moments[:, :m], rho - radius, cond]), F_v


def _newton(fun, z0, scale, *, max_iter: int = 40):
    """Newton on fun (batched, see :func:`_residuals`) from z0: one batched call per iteration
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
    if that solve fails or is not the state :func:`reduced.grasp_fem.grasp_state` reaches (see
    module doc).

    A pump pressure well above contact often presses a later pad than the one that touched
    first (the paper's hand at 2 MPa on 180 mm: pad 3, touching with pad 2): the later pads are
    tried in turn, and such an answer is kept only if ``grasp_state`` at its pressure is the
    same state (one equilibrium, against a dozen for the slow path). The pump pressure grows
    with the cavity's, so its answer is the only one; F_v need not (it drops where the
    touching pad changes), so for F_v only the first pad is tried: a later pad's answer
    could be a second root."""
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
    for k in range(first, first + 1 if target == "F_v" else design.n_s + 1):
        held = _hold_on_pad(k, design, diameter_mm, depth, mass_kg, target, value, reservoir, theta_c, P0)
        if held is None or not held.P_cavity <= _largest_pressure(design):  # grasp_state has no state there
            continue
        if k == first:
            return held
        state = grasp_fem.grasp_state(design, diameter_mm, held.P_cavity, mass_kg)
        if state.link == k and abs(state.theta - held.theta) <= 1e-9 * max(1.0, abs(held.theta)):
            return held
    return None


def _hold_on_pad(k: int, design: HandDesign, diameter_mm: float, depth: float, mass_kg: float, target: str,
                 value: float, reservoir: bool, theta_c: float, P0: float) -> Hold | None:
    """:func:`fast_hold`'s Newton solve with pad k touching, from hinges at theta_c / n_s and
    cavity pressure P0; None if it fails or its state is not acceptable (N < 0, another pad in
    the object, a residual left)."""
    radius, weight = 0.5 * float(diameter_mm), float(mass_kg) * design.g / design.n
    n_s = design.n_s
    m = k + (k < n_s)  # the held hinges, and one unknown for the distal ones if there are any
    fun = lambda Z: _residuals(Z, k, depth, radius, weight, target, value, design, reservoir)  # noqa: E731
    z0 = np.concatenate([np.full(m, theta_c / n_s), [max(float(value), 1.0) if target == "F_v" else 1.0, P0]])
    try:
        z = _newton(fun, z0, np.concatenate([np.full(m, 0.01), [1.0, 0.1]]))
    except InputError:  # an iterate beyond the models' range (e.g. more oil than the reservoir holds)
        return None
    if z is None:
        return None
    res, F_v = fun(z[None])
    q = np.concatenate([z[:k], np.full(n_s - k, z[k])])
    gaps = contact.pad_gaps(q, (0.0, depth), radius, design)
    gaps[k] = np.inf
    if z[m] < 0.0 or np.min(gaps) < -grasp_fem._PENETRATION or np.max(np.abs(res)) > 1e-8:
        return None
    theta, P = float(np.sum(q)), float(z[m + 1])
    return Hold(P, float(P - reservoir_pressure(theta, design, reservoir)), float(F_v[0]), theta, k, True)


def _largest_pressure(design: HandDesign) -> float:
    """The largest cavity pressure [MPa] either path answers at: the free finger's at (nearly)
    its largest bend, where :func:`reduced.grasp_fem.grasp_state` stops."""
    return float(hand.finger_pressure(0.999 * hand.THETA_RANGE[1], design))


def _condition(target: str, value: float, design: HandDesign, reservoir: bool):
    """c(q, P, F_v) of the module docstring: F_v - value [N], or P - p_r - value [MPa]."""
    if target == "F_v":
        return lambda q, P, F_v: F_v - value
    if target == "P_pump":
        return lambda q, P, F_v: P - float(reservoir_pressure(float(np.sum(q)), design, reservoir)) - value
    raise ValueError(target)


def slow_hold(design: HandDesign, diameter_mm: float, mass_kg: float, target: str, value: float, *,
              reservoir: bool = True) -> Hold:
    """The same grasp as :func:`fast_hold`, by brentq on the cavity pressure around
    :func:`reduced.grasp_fem.grasp_state` (from the contact pressure up to the free finger's
    pressure at its largest bend)."""
    design = grasp_fem.fem_finger(design)
    P_max = _largest_pressure(design)
    depth = contact.object_depth(diameter_mm, design)
    theta_c, _ = contact.contact_angle(diameter_mm, design, depth=depth)
    state = lambda P: grasp_fem.grasp_state(design, diameter_mm, P, mass_kg)  # noqa: E731
    cond = _condition(target, value, design, reservoir)

    def f(P):
        s = state(P)
        return cond(s.q, P, s.F_v)

    lo = float(hand.finger_pressure(theta_c, design)) + 1e-9
    if target == "P_pump" and value > lo:
        # the reservoir's pressure is not negative, so the cavity pressure of the answer is at
        # least the pump's: the bracket starts there (no root below it); and if one pad no longer
        # holds the object alone there, it does not at the answer either (a pump limit beyond
        # where a second pad touches: one equilibrium instead of a bracket halving to that edge)
        try:
            lo, f_lo = float(value), f(float(value))
        except InputError:
            raise InputError(target, value, f"not reached by the finger on one pad: a second pad "
                                            f"touches below the cavity pressure {value:.4g} MPa, "
                                            "the least the pump pressure needs") from None
    else:
        f_lo = f(lo)
    step, grow = 0.05, 2.0
    hi, f_hi = lo, f_lo
    for _ in range(60):  # the first sign change above the contact pressure: steps 0.05, 0.1, ... MPa
        hi = min(lo + step, P_max)
        try:
            f_hi = f(hi)
        except InputError:  # e.g. several pads on the object: closer, down to BRACKET_RESOLUTION
            hi, f_hi, step, grow = lo, f_lo, 0.5 * step, 1.0
            if step < BRACKET_RESOLUTION:
                break
            continue
        if f_lo * f_hi <= 0.0:
            break
        if hi == P_max:
            break
        lo, f_lo, step = hi, f_hi, grow * step
    if not f_lo * f_hi <= 0.0:
        raise InputError(target, value, f"not reached by the finger on one pad between its contact "
                                        f"pressure and {hi:.4g} MPa")
    P = brentq(f, lo, hi, xtol=_PTOL, rtol=4 * np.finfo(float).eps)
    s = state(P)
    return Hold(float(P), float(P - reservoir_pressure(s.theta, design, reservoir)), s.F_v, s.theta,
                s.link, False)


def hold(design: HandDesign, diameter_mm: float, mass_kg: float, target: str, value: float, *,
         reservoir: bool = True) -> Hold:
    """The grasp with F_v = value [N] (``target="F_v"``) or at the pump pressure value [MPa]
    (``target="P_pump"``): :func:`fast_hold`, else :func:`slow_hold`."""
    fast = fast_hold(design, diameter_mm, mass_kg, target, value, reservoir=reservoir)
    return fast if fast is not None else slow_hold(design, diameter_mm, mass_kg, target, value,
                                                   reservoir=reservoir)
