"""One finger closing on the object held in place (:mod:`softhand.reduced.holding.hold_fast`):
where it first touches, closing with equal hinges; then the least energy with no pad inside
the object, by Newton on a growing or shrinking set of touching pads, else by SLSQP and the
touching pads' equations polished. Units: mm, N, MPa, rad.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from scipy.optimize import brentq, minimize, nnls, root

from softhand.reduced.equations import hand
from softhand.reduced.holding import hand_layout
from softhand.reduced.holding.hold_finger import TOUCH, FingerGeometry, finger_geometry, free_angles, hinge_energy, hinge_moments
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.holding.object_geometry import Placed

#: a gap of a pad facing away, given to the optimiser in place of +inf [mm]
_FAR = 1e3
#: uniform-hinge bends scanned for the first touch
_SCAN = 33


class FingerState(NamedTuple):
    """A finger closed on the object at P."""

    q: np.ndarray         #: (n_s,) hinge angles [rad]
    N: np.ndarray         #: (n_s+1,) closing normal force on each pad [N] (0: not touching)
    geometry: FingerGeometry
    moments: np.ndarray   #: (n_s,) M_j at q [N mm/rad]
    residual: float       #: hinge equilibrium residual, max ``|M - dg^T N|`` / max ``|M|`` [-]


def close_finger(i: int, P: float, placed: Placed, design: HandDesign, near: FingerState | None = None) -> FingerState:
    """Finger i closing at cavity pressure P [MPa] on the object held in place (module doc of
    :mod:`softhand.reduced.holding.hold_fast`); ``near``: the finger closed on the object at a pose
    nearby, whose hinge angles and touching pads start the contact equations (the object sliding)."""
    touching = [] if near is None else [int(k) for k in np.flatnonzero(near.N > 0.0)]
    if touching:
        found = _active_set(i, near.q, P, placed, design, touching, {k: float(near.N[k]) for k in touching})
        if found is not None:
            return _state_of(i, found[0], found[2], P, placed, design, found[3])
    q_free = free_angles(P, design)
    if float(np.sum(q_free)) <= 0.0:
        return _free(i, q_free, P, placed, design)
    first = first_touch(i, q_free, placed, design)
    if first is None:
        return _free(i, q_free, P, placed, design)
    found = _active_set(i, first, P, placed, design)
    if found is None:  # Newton from the first touch missed: follow the pressure up from the touch
        P_touch = float(hand.finger_pressure(float(np.sum(first)), design))
        found = (first, None, None, None)
        for P_k in np.linspace(P_touch, P, 6)[1:]:
            found = _active_set(i, found[0], P_k, placed, design, found[1], found[2])
            if found is None:
                break
    if found is not None:
        return _state_of(i, found[0], found[2], P, placed, design, found[3])
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
    best, dz = None, np.zeros_like(z)
    for _ in range(max_iter):
        R = fun(np.vstack([z, z + np.diag(h)]))
        norm = float(np.linalg.norm(R[0]))
        if not np.isfinite(norm):
            return None
        if best is not None and norm >= best[1]:
            dz = 0.5 * dz  # the last step halved (best is set, so dz is that step)
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
    the pads ``active`` (default: the one nearest the object at q0) with forces N: (q, active, N,
    the finger's geometry at q) or None if it does not settle."""
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
            return q, active, N, geo
        same = [a for a in active if np.linalg.norm(geo.point[a] - geo.point[k]) < 1e-6]
        if same:  # two pads meeting at their hinge touch at one point: one constraint, the new pad's
            active = sorted([a for a in active if a not in same] + [k])
            continue
        active = sorted(active + [k])
    return None


def _state_of(i, q, N_of, P, placed, design, geo: FingerGeometry | None = None) -> FingerState:
    geo = finger_geometry(q, i, placed, design) if geo is None else geo
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


def first_touch(i: int, q_free, placed: Placed, design: HandDesign):
    """Hinge angles (n_s,) at which finger i, closing from straight towards its free hinge angles
    ``q_free`` (all in proportion), first touches the object, or None."""
    q_free = np.asarray(q_free, float)
    th = np.linspace(0.0, 1.0, _SCAN)
    q = th[:, None] * q_free[None, :]
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
        qq = (t * q_free)[None, :]
        return float(np.min(hand_layout.pad_distance(placed, hand_layout.pads(qq, design, fingers=[i])).gap[0, 1:]))

    return brentq(gmin, th[k - 1], th[k], xtol=1e-12) * q_free


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
