r"""The holding limit of a closed hand as a linear program (limit analysis of the grasp).

The fingers have closed on the object at the cavity pressure P (frictionless, the object held
in place: :mod:`softhand.reduced.holding.hold_fast`), each touching pad c at x_c with the object's outward normal
n_c. Then the object is let go and pulled along d. Unknowns: each pad's normal force N_c >= 0
and its friction force F_c (in the tangent plane), and the pull lam beyond the weight W = m g:

.. math::
   \sum_c (-N_c n_c + F_c) + W e_y + \lambda d = 0, \qquad
   \sum_c (x_c - x_G) \times (-N_c n_c + F_c) = 0 \qquad \text{(the object's six equations)}

   |F_c| \le \mu N_c \qquad \text{(Coulomb)}

   M_j(\hat\theta^*, P) + K_j\,\delta\hat\theta_j = \sum_{c \in i} (N_c n_c - F_c)\cdot \partial x_c/\partial\hat\theta_j
   \qquad \text{(finger i, hinge j)}

   \sum_j \partial g_c/\partial\hat\theta_j\,\delta\hat\theta_j = 0 \qquad \text{(pad c stays on the object; } \ge 0
   \text{ for a pad that touched without force)}

The last two lines are each finger's hinge equilibrium, elastic: the force of the object on the
finger's pads bends its hinges by :math:`\delta\hat\theta` from the grasp state, each hinge
answering with its stiffness :math:`K_j = \partial M_j/\partial\hat\theta_j` at the grasp
(:func:`softhand.reduced.holding.hold_finger.hinge_stiffness`; at :math:`\delta\hat\theta = 0` the
closing forces meet it exactly), while the pads that press stay on the object, held where the
slide has brought it (small displacements: the object and the pads are rigid, the compliance is
the hinges'; the object's large motion along the pull is :mod:`softhand.reduced.holding.hold_slide`'s).
A finger's normal forces change with the friction on its pads as its hinges' compliance gives:
a tip pad whose friction loads every hinge sheds or gains N by the compliance-weighted mean of
the hinges' loads, a finger pressing with two pads shares them by its stiffness. The finger FEM
does the same: the 180 mm sphere of 2 kg at 0.9 MPa, pulled in steps of 0.25 N, raises its pads'
N by 0.024 N per newton of friction while they stick (12.538 -> 12.570 N); this model 0.0226.
(Until 2026-12-06 each hinge was a capacity, the opening moment the pressure held at the grasp,
and a finger's pads kept their closing ratio: the weakest hinge then bounded a tip pad's N, and
the fast limit was 10-31 % below the FEM's on every tip contact and wedge; docs/grasp.md.)
The holding limit is the largest lam for which some set of contact forces satisfies all of the
above. It is solved by HiGHS
(:func:`scipy.optimize.linprog`). The Coulomb cone is replaced by the inscribed polygon of
:data:`GENERATORS` directions, one along the tangential part of the load's direction (so a pull
along the pad is bounded exactly by mu N): elsewhere the friction the polygon allows is at most
1 - cos(pi / GENERATORS) = 1.9 % below the cone's.

The state reported under the object's own weight (lam = 0) is the admissible one whose normal
forces are closest (sum of ``|N_c - N*_c|``) to the closing forces N*_c, the friction shared as evenly
as it can be (the largest ``|F_c|`` / (mu N*_c) least), the object free to move a little (its small
translation and rotation enter the pads' gap rates): the elastic fingers fix each pad's N for a
given friction, and a frictionless ball caged below its equator rests only once it has risen
until their push balances its weight. Units: N, mm.
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
    """The touching pads after closing and the fingers' hinges at the grasp."""

    finger: np.ndarray       #: (C,) finger of each contact
    link: np.ndarray         #: (C,) pad of each contact
    point: np.ndarray        #: (C, 3) contact point [mm]
    normal: np.ndarray       #: (C, 3) the object's outward unit normal there
    closing_N: np.ndarray    #: (C,) normal force at the end of closing [N]
    J: np.ndarray            #: (H, C, 3) d x_c / d theta_hat_j of every finger's hinge j [mm/rad] (0: not on c's finger)
    moment: np.ndarray       #: (H,) M_j at the grasp [N mm/rad] (negative: the pressure holds the hinge shut)
    stiffness: np.ndarray    #: (H,) K_j = dM_j / d theta_hat_j at the grasp [N mm/rad]


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


def _system(cs: ContactSet, centre, weight_N: float, pull, mu: float, gens: np.ndarray, moving: bool = False):
    """Equality (A_eq, b_eq) and inequality (A_ub, b_ub) of the LP in z = (N (C), beta (C G), dq, m, lam),
    and the count of (dq, m): dq the bends of the hinges some pad loads (the other hinges stay as they
    closed), m the object's small translation and rotation where it is ``moving`` (else none)."""
    C, G = len(cs.finger), gens.shape[1]
    loaded = np.flatnonzero(np.any(cs.J != 0.0, axis=(1, 2)))     # hinges some pad can turn
    Q, M = len(loaded), (6 if moving else 0)
    r = cs.point - np.asarray(centre, float)
    # force on the object per unit of each unknown: N -> -n, beta -> t, dq, m -> 0, lam -> d
    f_N = -cs.normal                                           # (C, 3)
    f_b = gens.reshape(C * G, 3)                               # (C G, 3)
    cols_f = np.vstack([f_N, f_b, np.zeros((Q + M, 3)), np.asarray(pull, float)[None]])   # (nz, 3)
    arms = np.vstack([r, np.repeat(r, G, axis=0), np.zeros((Q + M + 1, 3))])
    A_eq = np.vstack([cols_f.T, np.cross(arms, cols_f).T])     # (6, nz)
    b_eq = np.concatenate([[0.0, -weight_N, 0.0], np.zeros(3)])
    nz = A_eq.shape[1]
    cone = np.zeros((C, nz))
    cone[np.arange(C), np.arange(C)] = -mu
    cone[np.repeat(np.arange(C), G), C + np.arange(C * G)] = 1.0
    # hinge j: K_j dq_j - (N n - beta t) . J = -M_j  (the force on the finger is N n - beta t)
    J = cs.J[loaded]                                           # (Q, C, 3)
    dg = np.einsum("ci,hci->hc", cs.normal, J)                 # (Q, C) gap rates
    hinge = np.zeros((Q, nz))
    hinge[:, :C] = -dg
    hinge[:, C:C + C * G] = np.einsum("cgi,hci->hcg", gens, J).reshape(Q, C * G)
    hinge[np.arange(Q), C + C * G + np.arange(Q)] = cs.stiffness[loaded]
    # pads that pressed stay on the object (gap rate 0); those that touched without force may leave it.
    # gap rate: dg . dq - n . (dx + dw x r) = dg . dq - n . dx - (r x n) . dw
    stay = np.zeros((C, nz))
    stay[:, C + C * G:C + C * G + Q] = dg.T
    if moving:
        stay[:, C + C * G + Q:C + C * G + Q + 3] = -cs.normal
        stay[:, C + C * G + Q + 3:C + C * G + Q + 6] = -np.cross(r, cs.normal)
    pressed = cs.closing_N > 0.0
    A_eq = np.vstack([A_eq, hinge, stay[pressed]])
    b_eq = np.concatenate([b_eq, -cs.moment[loaded], np.zeros(int(pressed.sum()))])
    A_ub = np.vstack([cone, -stay[~pressed]])
    b_ub = np.zeros(len(A_ub))
    return A_eq, b_eq, A_ub, b_ub, Q + M


def _bounds(C: int, G: int, free: int, lam: tuple, extra: int = 0) -> np.ndarray:
    """(nz + extra, 2): N, beta >= 0, dq and m free, lam within ``lam``, ``extra`` more >= 0."""
    b = np.zeros((C + C * G + free + 1 + extra, 2))
    b[:, 1] = np.inf
    b[C + C * G:C + C * G + free, 0] = -np.inf
    b[C + C * G + free] = lam
    return b


def _state(z, cs: ContactSet, gens, mu, A_eq, b_eq, size: float) -> LimitState:
    C, G = len(cs.finger), gens.shape[1]
    N, beta = z[:C], z[C:C + C * G].reshape(C, G)
    F = np.einsum("cg,cgi->ci", beta, gens)
    R = A_eq @ z - b_eq
    residual = float(max(np.max(np.abs(R[:3])), np.max(np.abs(R[3:6])) / size)) if len(R) else 0.0
    slip = beta.sum(axis=1) >= mu * N * (1.0 - SLIP_TOL) - 1e-12
    return LimitState(float(z[-1]), N, F, slip & (N > 0), residual)


def holding_limit(cs: ContactSet, centre, weight_N: float, pull, mu: float, *,
                  size_mm: float = 100.0, moment=None) -> LimitState | None:
    """The largest pull lam [N] along the unit vector ``pull`` beyond the weight ``weight_N`` (along
    +y) that an admissible state bears (module doc), and that state; None if none exists even
    with the pull turned into a push of the weight's size (the object is not held at all).
    ``size_mm`` scales the moment residual; ``moment``: a moment [N mm] (3,) applied to the object
    besides (:mod:`softhand.reduced.holding.hold_turn` differentiates the limit by it)."""
    if not len(cs.finger):
        return None
    load = np.asarray(pull, float)
    gens = tangent_generators(cs.normal, load)
    A_eq, b_eq, A_ub, b_ub, Q = _system(cs, centre, weight_N, load, mu, gens)
    if moment is not None:
        b_eq[3:6] -= np.asarray(moment, float)
    c = np.zeros(A_eq.shape[1])
    c[-1] = -1.0
    bounds = _bounds(len(cs.finger), gens.shape[1], Q, (-weight_N - 1.0, MAX_PULL))
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
    A_eq, b_eq, A_ub, b_ub, Q = _system(cs, centre, weight_N, load, mu, gens, moving=True)
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
    bounds = _bounds(C, G, Q, (pull_N, pull_N), extra=C + 1)
    sol = linprog(c, A_ub=A_ub2, b_ub=b_ub2, A_eq=A_eq2, b_eq=b_eq, bounds=bounds, method="highs")
    if sol.status != 0:
        return None
    return _state(sol.x[:nz], cs, gens, mu, A_eq, b_eq, size_mm)


def _pick(C: int, nz: int) -> np.ndarray:
    out = np.zeros((C, nz))
    out[np.arange(C), np.arange(C)] = 1.0
    return out
