r"""The fast hold model: the whole hand closes on any object, then its holding limit along a pull.

**Closing** (the object held in place, frictionless, as the FEM's path closes the hand before
the object is let go): every finger i, in its own plane, takes the hinge angles that make its
energy least with no pad inside the object,

.. math:: \min_{\hat\theta} E(\hat\theta; P) \quad \text{s.t.} \quad g_k(\hat\theta) \ge 0
          \ (k = 1..n_s),

E = sum_j int M_j the hinges' energy at cavity pressure P (:func:`hinge_moments`), g_k the gap
of pad k to the object (:func:`softhand.reduced.holding.hand_layout.pad_distance`). Its optimality conditions
are the hinge equilibrium with the pads' contact forces, M_j = sum_k N_k dg_k/d theta_hat_j,
N_k >= 0, N_k g_k = 0: exactly the one-finger grasp's equations (:mod:`softhand.reduced.calibrated.grasp_fem`,
whose frictionless circle in the bending plane is the special case, a test) for any number of
touching pads. Solved by SLSQP from the pose where the finger, closing with equal hinges, first
touches; then the active pads' equations by Newton (scipy's hybrid method) to 1e-10.

**Holding**: the touching pads, their normals and closing forces, and each finger's hinge
capacities (-M_j at the closed state) go to the limit analysis of :mod:`softhand.reduced.holding.hold_lp`.

Finger models: ``"fem"`` (default), the calibrated finger of :mod:`softhand.reduced.calibrated.grasp_fem` (hinge by
hinge, from the finger FEM); ``"paper"``, the paper's finger (W_f, Q of eqs. (2), (10)) with its
energy shared equally by the hinges, M_j = -dQ/dtheta (P - P_free(n_s theta_hat_j)).
Where every finger sees the object alike (:func:`softhand.reduced.holding.hand_layout.symmetric`: a centred sphere,
an upright cylinder, a square box under four fingers), one finger is solved and its state turned to the others. Units: mm, N, MPa, rad.
"""
from __future__ import annotations

import math
from dataclasses import replace
from typing import NamedTuple

import numpy as np
from scipy.optimize import brentq, minimize, nnls, root

from softhand.reduced.calibrated import grasp_fem
from softhand.reduced.equations import finger, hand, reservoir
from softhand.reduced.holding import hand_layout
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.holding.object_geometry import Placed

#: the finger models of the fast hold
FINGER_MODELS = ("fem", "paper")
#: a pad within this gap [mm] of the object counts as touching
TOUCH = 1e-6
#: Gauss points of E's quadrature along each hinge
_GX, _GW = np.polynomial.legendre.leggauss(16)
_GX, _GW = 0.5 * (_GX + 1.0), 0.5 * _GW
#: a gap of a pad facing away, given to the optimiser in place of +inf [mm]
_FAR = 1e3
#: uniform-hinge bends scanned for the first touch
_SCAN = 33


def finger_design(design: HandDesign, finger_model: str = "fem") -> HandDesign:
    """The design with the finger model of the hold (``"fem"``: calibrated; ``"paper"``)."""
    if finger_model not in FINGER_MODELS:
        raise InputError("finger_model", finger_model, f"must be one of {', '.join(FINGER_MODELS)}")
    if finger_model == "fem":
        return grasp_fem.fem_finger(design)
    return design if design.finger_model == "paper" else replace(design, finger_model="paper")


def hinge_moments(q, P, design: HandDesign) -> np.ndarray:
    """M_j = dE/d theta_hat_j [N mm/rad] (..., n_s) at hinge angles q (..., n_s) [rad], cavity
    pressure P [MPa], for the design's finger model (module doc)."""
    if design.finger_model == "fem":
        return grasp_fem.hinge_moments(q, P, design)
    theta = design.n_s * np.asarray(q, float)
    return -finger.volume_rate(theta, design) * (P - hand.finger_pressure(theta, design))


def hinge_energy(q, P, design: HandDesign) -> float:
    """E = sum_j int_0^q_j M_j [N mm] (16-point Gauss along each hinge; M_j depends on q_j alone)."""
    q = np.asarray(q, float)
    M = hinge_moments(_GX[:, None] * q[None, :], P, design)
    return float(np.sum(_GW[:, None] * M * q[None, :]))


class FingerGeometry(NamedTuple):
    """One finger's pads against the object at hinge angles q."""

    gap: np.ndarray      #: (n_s+1,) [mm]
    point: np.ndarray    #: (n_s+1, 3)
    normal: np.ndarray   #: (n_s+1, 3) the object's outward normal
    dx: np.ndarray       #: (n_s+1, n_s, 3) d point_k / d theta_hat_j [mm/rad]
    dg: np.ndarray       #: (n_s+1, n_s) d gap_k / d theta_hat_j [mm/rad]


def finger_geometry(q, i: int, placed: Placed, design: HandDesign) -> FingerGeometry:
    """Finger i's pads at hinge angles q (n_s,) or a batch (B, n_s): gaps, closest points,
    normals and their rates (a batch adds the leading axis B to every array)."""
    q = np.asarray(q, float)
    Q = q.reshape(-1, design.n_s)
    p = hand_layout.pads(Q, design, fingers=[i] * len(Q))
    pd = hand_layout.pad_distance(placed, p)
    frames = hand_layout.finger_frames(design)
    e_out, e_down = frames.e_out[i], frames.e_down[i]
    x, hinges = pd.point, p.joints[:, 1:-1]                            # (B, k, 3), (B, n_s, 3)
    r = x[:, :, None, :] - hinges[:, None, :, :]                       # (B, k, j, 3)
    rx, ry = r @ e_out, r @ e_down
    dx = -ry[..., None] * e_out + rx[..., None] * e_down               # rotation about hinge j
    turns = np.arange(1, design.n_s + 1)[None, :] <= np.arange(design.n_s + 1)[:, None]
    dx = np.where(turns[None, ..., None], dx, 0.0)
    dg = np.einsum("bkji,bki->bkj", dx, pd.normal)
    out = FingerGeometry(pd.gap, x, pd.normal, dx, dg)
    return FingerGeometry(*(v[0] for v in out)) if q.ndim == 1 else out


class FingerState(NamedTuple):
    """A finger closed on the object at P."""

    q: np.ndarray         #: (n_s,) hinge angles [rad]
    N: np.ndarray         #: (n_s+1,) closing normal force on each pad [N] (0: not touching)
    geometry: FingerGeometry
    moments: np.ndarray   #: (n_s,) M_j at q [N mm/rad]
    residual: float       #: hinge equilibrium residual, max ``|M - dg^T N|`` / max ``|M|`` [-]


def close_finger(i: int, P: float, placed: Placed, design: HandDesign) -> FingerState:
    """Finger i closing at cavity pressure P [MPa] on the object held in place (module doc)."""
    n_s = design.n_s
    theta_free = float(hand.bend_angle(P, design, reservoir=False))
    q_free = np.full(n_s, theta_free / n_s)
    if theta_free <= 0.0:
        return _free(i, q_free, P, placed, design)
    first = first_touch(i, theta_free, placed, design)
    if first is None:
        return _free(i, q_free, P, placed, design)
    found = _active_set(i, first, P, placed, design)
    if found is None:  # Newton from the first touch missed: follow the pressure up from the touch
        P_touch = float(hand.finger_pressure(float(np.sum(first)), design))
        found = (first, None, None)
        for P_k in np.linspace(P_touch, P, 6)[1:]:
            found = _active_set(i, found[0], P_k, placed, design, found[1], found[2])
            if found is None:
                break
    if found is not None:
        return _state_of(i, found[0], found[2], P, placed, design)
    return _by_slsqp(i, first, P, placed, design)


def _kkt(i, P, placed, design, active, n_s):
    """The equations of finger i with pads ``active`` touching, batched: z (B, n_s + m) -> (B, n_s + m)."""
    def fun(Z):
        q, N = Z[:, :n_s], Z[:, n_s:]
        g = finger_geometry(q, i, placed, design)
        M = hinge_moments(q, P, design)
        return np.concatenate([M - np.einsum("bkj,bk->bj", g.dg[:, active], N), g.gap[:, active]], axis=1)
    return fun


def _newton(fun, z0, scale, *, tol: float = 1e-11, max_iter: int = 30):
    """Newton on a batched fun (one call per iteration: the point and its forward-difference
    neighbours), steps halved while the residual grows; the root or None."""
    z, h = np.asarray(z0, float), 1e-7 * np.asarray(scale, float)
    best = None
    for _ in range(max_iter):
        R = fun(np.vstack([z, z + np.diag(h)]))
        norm = float(np.linalg.norm(R[0]))
        if not np.isfinite(norm):
            return None
        if best is not None and norm >= best[1]:
            dz = 0.5 * dz  # noqa: F821 -- set below on the first pass
            z = best[0] + dz
            continue
        best = (z, norm)
        try:
            dz = -np.linalg.solve(((R[1:] - R[0]) / h[:, None]).T, R[0])
        except np.linalg.LinAlgError:
            return None
        if np.all(np.abs(dz) <= tol * np.maximum(np.abs(z), scale)):
            return z + dz
        z = z + dz
    return None


def _active_set(i, q0, P, placed, design, active=None, N=None):
    """Finger i's contact equations with a growing / shrinking set of touching pads, from q0 and
    the pads ``active`` (default: the one nearest the object at q0) with forces N: (q, active, N)
    or None if it does not settle."""
    n_s = design.n_s
    if not active:
        g0 = finger_geometry(q0, i, placed, design)
        active = [int(np.argmin(np.where(np.isfinite(g0.gap[1:]), g0.gap[1:], np.inf))) + 1]
    q, N = q0, dict(N or {})
    for _ in range(2 * n_s + 2):
        fun = _kkt(i, P, placed, design, active, n_s)
        M0 = hinge_moments(q, P, design)
        z0 = np.concatenate([q, [max(N.get(k, 1.0), 1e-3) for k in active]])
        scale = np.concatenate([np.full(n_s, 0.1), np.full(len(active), max(float(np.max(np.abs(M0))) / 50.0, 1e-3))])
        z = _newton(fun, z0, scale)
        if z is None:
            return None
        q, N = z[:n_s], dict(zip(active, z[n_s:]))
        geo = finger_geometry(q, i, placed, design)
        negative = [k for k in active if N[k] < 0.0]
        if negative:
            active = [k for k in active if k not in negative[:1]]
            if not active:
                return None
            continue
        gaps = np.where(np.isfinite(geo.gap), geo.gap, np.inf)
        gaps[0] = np.inf
        gaps[active] = np.inf
        k = int(np.argmin(gaps))
        if gaps[k] >= -TOUCH:
            return q, active, N
        same = [a for a in active if np.linalg.norm(geo.point[a] - geo.point[k]) < 1e-6]
        if same:  # two pads meeting at their hinge touch at one point: one constraint, the new pad's
            active = sorted([a for a in active if a not in same] + [k])
            continue
        active = sorted(active + [k])
    return None


def _state_of(i, q, N_of, P, placed, design) -> FingerState:
    geo = finger_geometry(q, i, placed, design)
    M = hinge_moments(q, P, design)
    N = np.zeros(design.n_s + 1)
    for k, v in N_of.items():
        N[k] = v
    res = float(np.max(np.abs(M - geo.dg.T @ N)) / max(np.max(np.abs(M)), 1e-12))
    return FingerState(q, N, geo, M, res)


def _by_slsqp(i, first, P, placed, design) -> FingerState:
    """The constrained energy minimum by SLSQP, then the touching pads' equations polished."""
    n_s = design.n_s
    fun = lambda q: hinge_energy(q, P, design)  # noqa: E731
    jac = lambda q: hinge_moments(q, P, design)  # noqa: E731

    def cons(q):
        g = finger_geometry(q, i, placed, design).gap[1:]
        return np.where(np.isfinite(g), g, _FAR)

    def cons_jac(q):
        geo = finger_geometry(q, i, placed, design)
        return np.where(np.isfinite(geo.gap[1:, None]), geo.dg[1:], 0.0)

    sol = minimize(fun, first, jac=jac, method="SLSQP",
                   constraints=[{"type": "ineq", "fun": cons, "jac": cons_jac}],
                   bounds=[(-0.5 * math.pi / n_s, math.pi / n_s)] * n_s,
                   options={"ftol": 1e-10, "maxiter": 60})
    return _polish(i, sol.x, P, placed, design)


def _free(i, q, P, placed, design) -> FingerState:
    geo = finger_geometry(q, i, placed, design)
    M = hinge_moments(q, P, design)
    return FingerState(q, np.zeros(design.n_s + 1), geo, M, float(np.max(np.abs(M))))


def first_touch(i: int, theta_free: float, placed: Placed, design: HandDesign):
    """Uniform hinge angles (n_s,) at which finger i closing with equal hinges first touches the
    object below its free bend, or None."""
    n_s = design.n_s
    th = np.linspace(0.0, theta_free, _SCAN)
    q = np.repeat(th[:, None] / n_s, n_s, axis=1)
    gaps = hand_layout.pad_distance(placed, hand_layout.pads(q, design, fingers=[i] * _SCAN)).gap
    if np.min(gaps[0]) < 0.0:
        raise InputError("object", placed.obj.describe(), f"overlaps finger {i}'s open pads")
    if np.min(gaps[0, 0]) <= 0.0 or np.any(gaps[:, 0] < 0.0):
        raise InputError("object", placed.obj.describe(), f"touches finger {i}'s base link, which cannot press")
    g = np.min(gaps[:, 1:], axis=1)
    closed = np.flatnonzero(g <= 0.0)
    if not closed.size:
        return None
    k = closed[0]

    def gmin(t):
        qq = np.full((1, n_s), t / n_s)
        return float(np.min(hand_layout.pad_distance(placed, hand_layout.pads(qq, design, fingers=[i])).gap[0, 1:]))

    t = brentq(gmin, th[k - 1], th[k], xtol=1e-12)
    return np.full(n_s, t / n_s)


def _polish(i, q, P, placed, design) -> FingerState:
    """The active pads' equations M = dg_A^T N_A, g_A = 0 by Newton from the optimiser's answer."""
    geo = finger_geometry(q, i, placed, design)
    M = hinge_moments(q, P, design)
    active = np.flatnonzero(geo.gap[1:] < 1e-4) + 1
    if not active.size:
        return _free(i, q, P, placed, design)
    N_A, _ = nnls(geo.dg[active].T, M)
    n_s = design.n_s

    def residual(z):
        qq, NA = z[:n_s], z[n_s:]
        g = finger_geometry(qq, i, placed, design)
        return np.concatenate([hinge_moments(qq, P, design) - g.dg[active].T @ NA, g.gap[active]])

    sol = root(residual, np.concatenate([q, N_A]), method="hybr", options={"xtol": 1e-12})
    z = sol.x if sol.success else np.concatenate([q, N_A])
    q, N_A = z[:n_s], z[n_s:]
    geo = finger_geometry(q, i, placed, design)
    M = hinge_moments(q, P, design)
    N = np.zeros(n_s + 1)
    N[active] = N_A
    res = float(np.max(np.abs(M - geo.dg.T @ N)) / max(np.max(np.abs(M)), 1e-12))
    return FingerState(q, N, geo, M, res)


class Closed(NamedTuple):
    """The hand closed on the object at P."""

    P_cavity: float
    P_pump: float
    fingers: tuple          #: FingerState per finger
    symmetric: bool         #: one finger solved, turned to the others


def close_hand(P_cavity: float, placed: Placed, design: HandDesign, *, reservoir_on: bool = True) -> Closed:
    """Every finger closed on the object at cavity pressure P [MPa] (``design`` with its finger
    model, :func:`finger_design`); the pump pressure is P less the reservoir's at the oil taken."""
    sym = hand_layout.symmetric(placed, design)
    if sym:
        one = close_finger(0, P_cavity, placed, design)
        states = tuple(_turned(one, i, placed, design) for i in range(design.n))
    else:
        states = tuple(close_finger(i, P_cavity, placed, design) for i in range(design.n))
    return Closed(P_cavity, pump_pressure(P_cavity, [s.q.sum() for s in states], design, reservoir_on),
                  states, sym)


def _turned(state: FingerState, i: int, placed: Placed, design: HandDesign) -> FingerState:
    if i == 0:
        return state
    return FingerState(state.q, state.N, finger_geometry(state.q, i, placed, design), state.moments, state.residual)


def pump_pressure(P_cavity: float, thetas, design: HandDesign, reservoir_on: bool = True) -> float:
    """P_pump = P_cavity - p_r(V0 - sum_i (Q(theta_i) - Q(0))) [MPa] (the fingers' bends theta_i [rad])."""
    if not reservoir_on:
        return float(P_cavity)
    taken = float(np.sum(finger.oil_taken(np.asarray(thetas, float), design)))
    return float(P_cavity - reservoir.pressure(design.V0 - taken, design))
