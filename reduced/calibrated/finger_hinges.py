r"""The calibrated finger's hinges: the moment M_j = dE/d theta_hat_j that holds each hinge of the
finger at hinge angles theta_hat and cavity pressure P, and the energy E(theta_hat; P) it is the
gradient of; the finger of the FEM-informed grasp (:mod:`softhand.reduced.calibrated.grasp_fem`) and of
the fast hold (:mod:`softhand.reduced.holding.hold_finger`).

Each hinge j carries its own energy E_j(theta_hat_j; P) in the
blocked-hinge table (the hinges uncoupled, E = sum E_j). At fixed hinge angles dE/dP = -V, the oil
inside, so the moment holding hinge j, M_j = dE/d theta_hat_j, changes with P by
dM_j/dP = -A_j, A_j = dV/d theta_hat_j the oil the hinge draws per radian *at fixed P*.
With A_j a function of the hinge's bend theta_j = n_s theta_hat_j and the pressure, and
M_j = 0 on the free curve P_free(theta) of the calibrated finger (``finger_model = "fem"``,
:mod:`softhand.reduced.calibrated.finger_fem`; it bends its equal hinges equally),

.. math:: M_j = -\int_{P_{free}(\theta_j)}^{P} A_j(\theta_j, p)\,dp, \qquad
          E_j = \int_0^{\hat\theta_j} M_j .

A_j is measured by the finger FEM with its hinges locked by springs at free bends and the
pressure raised (:mod:`softhand.reduced.calibrated.hinge_table`,
``reduced/calibrated/data/grasp_hinges.csv``, written by ``python -m
softhand.studies.calibration.hinges``): about 1.8 a^2 pi d for a straight hinge and 1.2 a^2 pi d
for a bent one at its free pressure, growing with the pressure above it (a locked tube
swells), against dQ/dtheta = 1.86 a^2 pi d of the free finger, which includes the tube's
swelling with P along the free curve. The table is the paper's design (Table I); another
design's is that table carried to its geometry by ratios measured on a coarse grid over the
design space (:mod:`softhand.reduced.calibrated.hinge_space`), or a table of its own
(``hinge_table``, made by the same study with ``--design``). Without this, the free
finger's W_f and Q split equally over the hinges, the contact force of a finger held by
the object low on it comes out 50 % too large.

**Coupled through the tube (the fast hold's hinges).** The table's hinges
were locked at one bend; the finger FEM's are coupled (:mod:`softhand.reduced.calibrated.hinge_coupling`):
its free finger shares the bend unequally, q_f(P), and its condensed stiffness S(P) there is
below the table's and couples neighbours. :func:`coupled_moments` and :func:`coupled_energy` are
the table's (M_sep, E_sep) corrected to second order about that free state,

.. math:: M(\hat\theta) = M_{sep}(\hat\theta) - M_{sep}(q_f) + C\,(\hat\theta - q_f), \qquad
          C = S - \mathrm{diag}\,\partial M_{sep,j}/\partial\hat\theta_j\,(q_f),

.. math:: E(\hat\theta) = E_{sep}(\hat\theta) - M_{sep}(q_f)\cdot\hat\theta
          + \tfrac12 (\hat\theta - q_f)^T C\,(\hat\theta - q_f),

so M = 0 and dM/d theta_hat = S at the FEM's free state, and the table's nonlinearity away from it.
On the paper's design, blocked by hinge loads in 16 patterns (the finger FEM, held out: the
correction reads only the free states), the moments of the held hinges at 1.5 MPa are within
1.6 % rms of the FEM's, worst 5.0 % (the table alone: 8.1 %, 17 %); at 0.9 MPa within 1.6 % rms,
worst 2.7 %, where no hinge is held within 1 deg of straight (the table alone: 8.0 %, 14 %), and up
to 56 % off where one is (a straight hinge between bent ones is far softer than the table, locked
all straight, says; 66 % for the table alone). The fast hold
(:mod:`softhand.reduced.holding.hold_finger`) takes these; the one-finger grasp of
:mod:`softhand.reduced.calibrated.grasp_fem` and the design tasks' F_v keep the table's separable
hinges (their solvers reduce the distal hinges to one free angle), so a hold's pad force and the
grasp's differ by what the coupling gives (1-3 % on the paper's 180 mm sphere). The oil the hinges
draw (:func:`volume_rate`) is the table's.

**Held far below the free bends.** Beyond second order the coupled moments miss what the finger
FEM needs where a held hinge has a neighbour bent more than itself, or is the base hinge held near
straight (a grasp's: the base hinge of a finger on the paper's 180 mm sphere sits at a fifth of its
free bend); :mod:`softhand.reduced.calibrated.hinge_blocked` adds the gradient of an energy fitted to
the finger FEM held by grasp-like loads over the hinge grid's designs (``blocked=False``: without it).
P is the cavity pressure. Units: mm, N, MPa, rad.
"""
from __future__ import annotations

import math
from dataclasses import replace
from functools import lru_cache

import numpy as np

from softhand.reduced.calibrated import hinge_blocked, hinge_coupling, hinge_space, hinge_table
from softhand.reduced.equations import hand
from softhand.reduced.vocabulary.design import HandDesign

#: step [rad] of the central difference of the table's per-hinge stiffness at the free state
_DQ = 1e-6


def fem_finger(design: HandDesign) -> HandDesign:
    """The design with the calibrated finger (``finger_model = "fem"``; its table kept)."""
    return design if design.finger_model == "fem" else replace(design, finger_model="fem")


def volume_rate(theta, P, design: HandDesign) -> np.ndarray:
    """A_j [mm^3/rad] (..., n_s): oil hinge j draws per radian at fixed pressure, at hinge bends theta
    = n_s theta_hat (..., n_s) [rad] and cavity pressure P [MPa] (:mod:`softhand.reduced.calibrated.hinge_table`)."""
    return hinge_table.volume_rate(hinge_data(design), theta, P) * design.a ** 2 * math.pi * design.d


def hinge_moments(q, P, design: HandDesign) -> np.ndarray:
    """The table's M_j (M_sep,j of the module doc) = -int_{P_free(theta_j)}^P A_j(theta_j, p) dp [N mm/rad] (..., n_s) at hinge
    angles q (..., n_s) [rad] and cavity pressure P [MPa], theta_j = n_s q_j; P_free of finger_model "fem"."""
    design = fem_finger(design)
    theta = design.n_s * np.asarray(q, float)
    M = hinge_table.moment(hinge_data(design), theta, P, hand.finger_pressure(theta, design), hinge_space.reverse_scale(design))
    return M * design.a ** 2 * math.pi * design.d


def coupled_moments(q, P, design: HandDesign, *, blocked: bool = True) -> np.ndarray:
    """M_j [N mm/rad] (..., n_s) of the hinges coupled through the tube (module doc) at hinge angles q
    (..., n_s) [rad] and cavity pressure P [MPa] (broadcast against q[..., :1]); ``blocked``: with the
    correction for hinges held far below their free bends (:mod:`~softhand.reduced.calibrated.hinge_blocked`)."""
    design = fem_finger(design)
    q = np.asarray(q, float)
    M = hinge_moments(q, P, design)
    if np.ndim(P) == 0:
        q_f, M_f, C = coupling(design, float(P))
        M = M + (q - q_f) @ C.T - M_f
        return M + hinge_blocked.moments(q, q_f, float(P), design) if blocked else M
    Pq = np.broadcast_to(P, q.shape)[..., 0]
    for p in np.unique(Pq):  # a few pressures at most
        q_f, M_f, C = coupling(design, float(p))
        at = Pq == p
        M[at] += (q[at] - q_f) @ C.T - M_f
        if blocked:
            M[at] += hinge_blocked.moments(q[at], q_f, float(p), design)
    return M


def coupled_stiffness(q, P: float, design: HandDesign) -> np.ndarray:
    """dM_j/d theta_hat_j [N mm/rad] (..., n_s) of :func:`coupled_moments`, the diagonal: the table's
    (each M_sep,j depends on q_j alone: one central difference of every hinge at once) plus C's and the
    held hinges' correction's (:func:`softhand.reduced.calibrated.hinge_blocked.stiffness`)."""
    design = fem_finger(design)
    q_f, _, C = coupling(design, float(P))
    return (_table_stiffness(np.asarray(q, float), P, design) + np.diagonal(C)
            + hinge_blocked.stiffness(q, q_f, float(P), design))


def coupled_free_angles(P: float, design: HandDesign) -> np.ndarray:
    """The coupled finger's free hinge angles q_f (n_s,) [rad] at cavity pressure P [MPa]: every
    coupled M_j = 0 (the calibrated finger's bend, shared among the hinges as the finger FEM's)."""
    return coupling(fem_finger(design), float(P))[0].copy()


@lru_cache(maxsize=256)
def coupling(design: HandDesign, P: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q_f (n_s,) [rad], M_sep(q_f) (n_s,) [N mm/rad], C (n_s, n_s) [N mm/rad]) at cavity pressure P
    [MPa] (module doc); the design has the calibrated finger. C is linear in P between the coupling
    table's pressures (exact there), so the moments are smooth in P to round-off."""
    q_f, _ = hinge_coupling.free_state(design, P)
    p, C = _corrections(design)
    i0, i1, w = hinge_space._lerp(float(P), p)
    return q_f, hinge_moments(q_f, P, design), (1 - w) * C[i0] + w * C[i1]


@lru_cache(maxsize=16)
def _corrections(design: HandDesign) -> tuple[np.ndarray, np.ndarray]:
    """(the coupling table's pressures the design's calibrated finger reaches (K,), C = S - diag dM_sep/d
    theta_hat at q_f (K, n_s, n_s)) [N mm/rad]; C is constant beyond the last."""
    p = hinge_coupling.design_data(design)[0]
    p = p[p < hand.pressure_span(design, reservoir=False)[1]]
    C = []
    for pk in p:
        q_f, S = condensed_stiffness(design, float(pk))
        C.append(S - np.diag(_table_stiffness(q_f, pk, design)))
    return p, np.array(C)


def condensed_stiffness(design: HandDesign, P: float) -> tuple[np.ndarray, np.ndarray]:
    """(q_f (n_s,) [rad], S (n_s, n_s) [N mm/rad]): the free hinge angles and the condensed stiffness of the
    design's finger FEM at cavity pressure P [MPa] (:mod:`softhand.reduced.calibrated.hinge_coupling`). The
    coupling grid is of the paper's rubber; for another rubber (or a design's own blocked-hinge table)
    S of the geometry in the paper's rubber is scaled by the table's diagonal stiffness at the two
    free states, mean_j K_j / K_j(paper's rubber): S over the table's stiffness is the tube's geometry.
    Measured on the tutorial's fitted Yeoh rubber (tests/data/hinge_coupling_heldout.json): S within
    1.6 % of its own finger FEM's (scaled as its moments bent backwards are, 10-14 % high)."""
    design = fem_finger(design)
    q_f, S = hinge_coupling.free_state(design, P)
    twin = hinge_space.paper_rubber(design)
    if twin != design:
        q_t, _ = hinge_coupling.free_state(twin, P)
        S = S * float(np.mean(_table_stiffness(q_f, P, design) / _table_stiffness(q_t, P, twin)))
    return q_f, S


def _table_stiffness(q, P: float, design: HandDesign) -> np.ndarray:
    """dM_sep,j/d theta_hat_j (n_s,) at hinge angles q (n_s,) (one central difference of every hinge at once)."""
    M = hinge_moments(np.stack([q + _DQ, q - _DQ]), P, design)
    return (M[0] - M[1]) / (2.0 * _DQ)


def coupled_energy(q, P: float, design: HandDesign) -> float:
    """E [N mm] of the hinges coupled through the tube at hinge angles q (n_s,) [rad]: the table's
    :func:`hinge_energy` - M_sep(q_f) . q + (q - q_f) C (q - q_f) / 2 (module doc) + the held hinges'
    correction's (:func:`softhand.reduced.calibrated.hinge_blocked.energy`)."""
    design = fem_finger(design)
    q_f, M_f, C = coupling(design, float(P))
    dq = np.asarray(q, float) - q_f
    return (hinge_energy(q, P, design) + float(-M_f @ q + 0.5 * dq @ C @ dq)
            + float(hinge_blocked.energy(q, q_f, float(P), design)))


def hinge_data(design: HandDesign) -> hinge_table.HingeTable:
    """The blocked-hinge table the design's fast hold uses (its own ``hinge_table``, else the
    paper's design's carried to its geometry); InputError if it cannot be read or does not fit."""
    return hinge_space.design_table(fem_finger(design))


#: Gauss-Legendre rule on [0, 1] for E, per piece between the table's nodes
_GX, _GW = np.polynomial.legendre.leggauss(12)
_GX, _GW = 0.5 * (_GX + 1.0), 0.5 * _GW


def hinge_energy(q, P: float, design: HandDesign) -> float:
    """E = sum_j int_0^q_j M_j [N mm] of the table's moments at hinge angles q (n_s,) [rad] (12-point
    Gauss on every piece between the table's bends and the free bends of its pressures: M is smooth there)."""
    nodes = _energy_cuts(fem_finger(design))
    total = 0.0
    for j, qj in enumerate(np.asarray(q, float)):  # n_s hinges
        inside = np.sort(nodes[(nodes > min(qj, 0.0)) & (nodes < max(qj, 0.0))])
        cuts = np.r_[0.0, inside if qj >= 0 else inside[::-1], qj]  # from 0 to q_j
        x = cuts[:-1, None] + np.diff(cuts)[:, None] * _GX
        Q = np.zeros(x.shape + (design.n_s,))
        Q[..., j] = x
        M = hinge_moments(Q, P, design)[..., j]
        total += float(np.sum(M * _GW * np.diff(cuts)[:, None]))
    return total


@lru_cache(maxsize=16)
def _energy_cuts(design: HandDesign) -> np.ndarray:
    """Hinge angles theta_hat where M_j's second derivative may jump: the table's bends, and the
    free bends at its pressures (where P_free(theta) crosses a kink of A_j in p)."""
    t = hinge_data(design)
    lo, hi = hand.pressure_span(design, reservoir=False)
    p = t.p[(t.p > lo) & (t.p < hi)]
    free = np.asarray(hand.bend_angle(p, design, reservoir=False), float) if len(p) else np.zeros(0)
    return np.unique(np.r_[t.theta, free]) / design.n_s
