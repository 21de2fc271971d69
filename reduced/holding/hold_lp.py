r"""The holding limit of a closed hand as a linear program (limit analysis of the grasp).

The fingers have closed on the object at the cavity pressure P (frictionless, the object held
in place: :mod:`softhand.reduced.holding.hold_fast`), each touching pad c at x_c with the object's outward normal
n_c. Then the object is let go and pulled along d. Unknowns: each pad's normal force N_c >= 0
and its friction force F_c (in the tangent plane), and the pull lam beyond the weight W = m g:

.. math::
   \sum_c (-N_c n_c + F_c) + W e_y + \lambda d = 0, \qquad
   \sum_c (x_c - x_G) \times (-N_c n_c + F_c) = 0 \qquad \text{(the object's six equations)}

   |F_c| \le \mu N_c \qquad \text{(Coulomb)}

   -\sum_{c \in i} (N_c n_c - F_c)\cdot \partial x_c/\partial\hat\theta_j \le -M_j(\hat\theta^*, P)
   \qquad \text{(finger i, hinge j)}

   N_c / N^*_c = N_{c'} / N^*_{c'} \qquad \text{(pads c, c' of one finger that pressed when it closed)}

The last line is each finger's hinge equilibrium read as a capacity: the force of the object on
the finger's pads may push hinge j open with at most the moment the pressure holds it with at
the grasp state, -M_j >= 0 (:func:`softhand.reduced.holding.hold_finger.hinge_moments`; in the closed state it is
met with equality by the closing forces). The fingers stay at their grasp configuration (small
displacements: the object and the pads are rigid, the compliance is the hinges'), so the
holding limit is the largest lam for which some set of contact forces satisfies all of the
above: a statically admissible state, the lower bound of limit analysis. The last line keeps the
share of each finger's pads in their closing ratio: a finger pressing with two pads (a box's top
edge and its face, a ball in the crease between two links) is statically indeterminate, and
limit analysis would let it squeeze the object between them as hard as its hinges' moments allow,
as if the hinges gave way at those moments; they are elastic and stiffen as they open, so the
share between the pads is the stiffness's, which the closing found (measured: a 160 mm cube held
by a top edge and a fingertip, 39.9 N of holding limit with the squeeze against the FEM's 28.5 N,
24.7 N without it). It is solved by HiGHS
(:func:`scipy.optimize.linprog`). The Coulomb cone is replaced by the inscribed polygon of
:data:`GENERATORS` directions, one along the tangential part of the load's direction (so a pull
along the pad is bounded exactly by mu N): elsewhere the friction the polygon allows is at most
1 - cos(pi / GENERATORS) = 1.9 % below the cone's.

The state reported under the object's own weight (lam = 0) is the admissible one whose normal
forces are closest (sum of ``|N_c - N*_c|``) to the closing forces N*_c, the friction shared as evenly
as it can be (the largest ``|F_c|`` / (mu N*_c) least). Units: N, mm.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.optimize import linprog

#: directions of the polygon that replaces each friction cone
GENERATORS = 16
#: a friction force within this fraction of mu N is on the cone ("slip")
SLIP_TOL = 1e-6
#: the largest pull sought [N]; a hold beyond it is reported as this (the LP is then unbounded)
MAX_PULL = 1e6


class ContactSet(NamedTuple):
    """The touching pads after closing and the fingers' hinge capacities."""

    finger: np.ndarray       #: (C,) finger of each contact
    link: np.ndarray         #: (C,) pad of each contact
    point: np.ndarray        #: (C, 3) contact point [mm]
    normal: np.ndarray       #: (C, 3) the object's outward unit normal there
    closing_N: np.ndarray    #: (C,) normal force at the end of closing [N]
    J: np.ndarray            #: (H, C, 3) d x_c / d theta_hat of each capacity row's hinge [mm/rad]
    capacity: np.ndarray     #: (H,) -M_j >= 0, the opening moment each hinge holds [N mm]


class LimitState(NamedTuple):
    """One admissible state of the LP."""

    pull_N: float            #: lam [N]
    normal_N: np.ndarray     #: (C,)
    friction: np.ndarray     #: (C, 3) friction force on the object [N]
    slip: np.ndarray         #: (C,) bool, on the cone
    residual: float          #: the object's equilibrium residual (force [N] and moment / size) at the answer


def tangent_generators(normal, direction, count: int = GENERATORS) -> np.ndarray:
    """(C, count, 3) unit tangents around each normal, the first along ``direction``'s tangential
    part (or any tangent where it has none)."""
    n = np.asarray(normal, float)
    d = np.broadcast_to(np.asarray(direction, float), n.shape)
    t1 = d - np.einsum("ci,ci->c", d, n)[:, None] * n
    weak = np.linalg.norm(t1, axis=1) < 1e-9
    if np.any(weak):
        helper = np.where(np.abs(n[weak, 0:1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
        t1[weak] = helper - np.einsum("ci,ci->c", helper, n[weak])[:, None] * n[weak]
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = np.cross(n, t1)
    a = 2.0 * np.pi * np.arange(count) / count
    return np.cos(a)[None, :, None] * t1[:, None, :] + np.sin(a)[None, :, None] * t2[:, None, :]


def _system(cs: ContactSet, centre, weight_N: float, pull, mu: float, gens: np.ndarray):
    """Equality (A_eq, b_eq) and inequality (A_ub, b_ub) of the LP in z = (N (C), beta (C G), lam)."""
    C, G = len(cs.finger), gens.shape[1]
    r = cs.point - np.asarray(centre, float)
    # force on the object per unit of each unknown: N -> -n, beta -> t, lam -> d
    f_N = -cs.normal                                           # (C, 3)
    f_b = gens.reshape(C * G, 3)                               # (C G, 3)
    cols_f = np.vstack([f_N, f_b, np.asarray(pull, float)[None]])        # (nz, 3)
    arms = np.vstack([r, np.repeat(r, G, axis=0), np.zeros((1, 3))])
    A_eq = np.vstack([cols_f.T, np.cross(arms, cols_f).T])     # (6, nz)
    b_eq = np.concatenate([[0.0, -weight_N, 0.0], np.zeros(3)])
    cone = np.zeros((C, C + C * G + 1))
    cone[np.arange(C), np.arange(C)] = -mu
    cone[np.repeat(np.arange(C), G), C + np.arange(C * G)] = 1.0
    # hinge rows: force on the finger = N n - beta t; row: -(that) . J <= capacity
    H = len(cs.capacity)
    hinge = np.zeros((H, C + C * G + 1))
    if H:
        hinge[:, :C] = -np.einsum("ci,hci->hc", cs.normal, cs.J)
        hinge[:, C:C + C * G] = np.einsum("cgi,hci->hcg", gens, cs.J).reshape(H, C * G)
    A_ub = np.vstack([cone, hinge])
    b_ub = np.concatenate([np.zeros(C), cs.capacity])
    share = [(a, b) for f in np.unique(cs.finger)
             for a, b in _pairs(np.flatnonzero((cs.finger == f) & (cs.closing_N > 0.0)))]
    if share:  # N_a N*_b - N_b N*_a = 0: a finger's pads keep their closing ratio
        rows = np.zeros((len(share), A_eq.shape[1]))
        for r, (a, b) in enumerate(share):
            rows[r, a], rows[r, b] = cs.closing_N[b], -cs.closing_N[a]
        A_eq, b_eq = np.vstack([A_eq, rows]), np.concatenate([b_eq, np.zeros(len(share))])
    return A_eq, b_eq, A_ub, b_ub


def _pairs(index):
    return zip(index[:-1], index[1:])


def _state(z, cs: ContactSet, gens, mu, A_eq, b_eq, size: float) -> LimitState:
    C, G = len(cs.finger), gens.shape[1]
    N, beta = z[:C], z[C:C + C * G].reshape(C, G)
    F = np.einsum("cg,cgi->ci", beta, gens)
    R = A_eq @ z - b_eq
    residual = float(max(np.max(np.abs(R[:3])), np.max(np.abs(R[3:6])) / size)) if len(R) else 0.0
    slip = beta.sum(axis=1) >= mu * N * (1.0 - SLIP_TOL) - 1e-12
    return LimitState(float(z[-1]), N, F, slip & (N > 0), residual)


def holding_limit(cs: ContactSet, centre, weight_N: float, pull, mu: float, *,
                  size_mm: float = 100.0) -> LimitState | None:
    """The largest pull lam [N] along the unit vector ``pull`` beyond the weight ``weight_N`` (along
    +y) that an admissible state bears (module doc), and that state; None if none exists even
    with the pull turned into a push of the weight's size (the object is not held at all).
    ``size_mm`` scales the moment residual."""
    if not len(cs.finger):
        return None
    load = np.asarray(pull, float)
    gens = tangent_generators(cs.normal, load)
    A_eq, b_eq, A_ub, b_ub = _system(cs, centre, weight_N, load, mu, gens)
    nz = A_eq.shape[1]
    c = np.zeros(nz)
    c[-1] = -1.0
    bounds = [(0, None)] * (nz - 1) + [(-weight_N - 1.0, MAX_PULL)]
    sol = linprog(c, A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=b_eq, bounds=bounds, method="highs")
    if sol.status != 0:
        return None
    return _state(sol.x, cs, gens, mu, A_eq, b_eq, size_mm)


def weight_state(cs: ContactSet, centre, weight_N: float, mu: float, *, pull_N: float = 0.0, pull=(0, 1, 0),
                 size_mm: float = 100.0) -> LimitState | None:
    """The admissible state at pull ``pull_N`` (default 0: the object's own weight) whose normal
    forces are closest to the closing forces (L1); None if there is none (not held)."""
    if not len(cs.finger):
        return None
    load = np.asarray(pull, float)
    direction = np.asarray([0.0, 1.0, 0.0]) * weight_N + pull_N * load
    gens = tangent_generators(cs.normal, direction if np.linalg.norm(direction) > 0 else load)
    A_eq, b_eq, A_ub, b_ub = _system(cs, centre, weight_N, load, mu, gens)
    C, nz = len(cs.finger), A_eq.shape[1]
    G = gens.shape[1]
    # z' = (z, s (C), u): s_c >= |N_c - N*_c|, u >= each pad's friction over mu N*_c; minimise
    # sum s + a little u (friction shared evenly, none where none is needed)
    share = np.zeros((C, nz + C + 1))
    share[np.repeat(np.arange(C), G), C + np.arange(C * G)] = 1.0
    share[:, -1] = -mu * np.maximum(cs.closing_N, 1e-9 * max(float(np.max(cs.closing_N)), 1.0))
    A_ub2 = np.vstack([np.hstack([A_ub, np.zeros((len(A_ub), C + 1))]),
                       np.hstack([_pick(C, nz), -np.eye(C), np.zeros((C, 1))]),
                       np.hstack([-_pick(C, nz), -np.eye(C), np.zeros((C, 1))]), share])
    b_ub2 = np.concatenate([b_ub, cs.closing_N, -cs.closing_N, np.zeros(C)])
    A_eq2 = np.hstack([A_eq, np.zeros((len(A_eq), C + 1))])
    c = np.concatenate([np.zeros(nz), np.ones(C), [1e-3 * max(float(np.sum(cs.closing_N)), 1e-9)]])
    bounds = [(0, None)] * (nz - 1) + [(pull_N, pull_N)] + [(0, None)] * (C + 1)
    sol = linprog(c, A_ub=A_ub2, b_ub=b_ub2, A_eq=A_eq2, b_eq=b_eq, bounds=bounds, method="highs")
    if sol.status != 0:
        return None
    return _state(sol.x[:nz], cs, gens, mu, A_eq, b_eq, size_mm)


def _pick(C: int, nz: int) -> np.ndarray:
    out = np.zeros((C, nz))
    out[np.arange(C), np.arange(C)] = 1.0
    return out
