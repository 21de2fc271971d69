"""One finger in the fast hold (:mod:`softhand.reduced.holding.hold_fast`): its hinge moments
and energy for the hold's finger models, and its pads against the object (gaps, closest
points, normals and their rates in the hinge angles). Units: mm, N, MPa, rad.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from softhand.reduced.calibrated import finger_hinges
from softhand.reduced.equations import finger, hand
from softhand.reduced.holding import hand_layout
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.holding.object_geometry import Placed

#: a pad within this gap [mm] of the object counts as touching
TOUCH = 1e-6
#: Gauss points of E's quadrature along each hinge
_GX, _GW = np.polynomial.legendre.leggauss(16)
_GX, _GW = 0.5 * (_GX + 1.0), 0.5 * _GW


def hinge_moments(q, P, design: HandDesign) -> np.ndarray:
    """M_j = dE/d theta_hat_j [N mm/rad] (..., n_s) at hinge angles q (..., n_s) [rad], cavity
    pressure P [MPa], for the design's finger model: the calibrated finger's hinges coupled through
    the tube (:func:`softhand.reduced.calibrated.finger_hinges.coupled_moments`), or the paper's
    finger shared equally by its hinges."""
    if design.finger_model == "fem":
        return finger_hinges.coupled_moments(q, P, design)
    theta = design.n_s * np.asarray(q, float)
    return -finger.volume_rate(theta, design) * (P - hand.finger_pressure(theta, design))


#: step [rad] of the central difference of :func:`hinge_stiffness`
_DQ = 1e-6


def hinge_stiffness(q, P, design: HandDesign) -> np.ndarray:
    """K_j = dM_j/d theta_hat_j [N mm/rad] (..., n_s) at hinge angles q, cavity pressure P [MPa] (the
    diagonal of the hinges' stiffness; the paper's finger's M_j depends on q_j alone: one central
    difference of every hinge at once)."""
    if design.finger_model == "fem":
        return finger_hinges.coupled_stiffness(q, P, design)
    q = np.asarray(q, float)
    M = hinge_moments(np.stack([q + _DQ, q - _DQ]), P, design)
    return (M[0] - M[1]) / (2.0 * _DQ)


def hinge_energy(q, P, design: HandDesign) -> float:
    """E [N mm] at hinge angles q (n_s,): the coupled hinges'
    (:func:`softhand.reduced.calibrated.finger_hinges.coupled_energy`), or sum_j int_0^q_j M_j of
    the paper's finger (16-point Gauss along each hinge; M_j depends on q_j alone)."""
    if design.finger_model == "fem":
        return finger_hinges.coupled_energy(q, P, design)
    q = np.asarray(q, float)
    M = hinge_moments(_GX[:, None] * q[None, :], P, design)
    return float(np.sum(_GW[:, None] * M * q[None, :]))


def free_angles(P: float, design: HandDesign) -> np.ndarray:
    """The free finger's hinge angles (n_s,) [rad] at cavity pressure P [MPa]: the calibrated finger's
    bend shared among its hinges as the finger FEM's (every coupled M_j = 0), the paper's equally."""
    if design.finger_model == "fem":
        return finger_hinges.coupled_free_angles(P, design)
    return np.full(design.n_s, float(hand.bend_angle(P, design, reservoir=False)) / design.n_s)


class FingerGeometry(NamedTuple):
    """One finger's pads against the object at hinge angles q."""

    gap: np.ndarray      #: (n_s+1,) [mm]
    point: np.ndarray    #: (n_s+1, 3)
    normal: np.ndarray   #: (n_s+1, 3) the object's outward normal
    dx: np.ndarray       #: (n_s+1, n_s, 3) d point_k / d theta_hat_j [mm/rad]
    dg: np.ndarray       #: (n_s+1, n_s) d gap_k / d theta_hat_j [mm/rad]


def finger_geometry(q, i, placed: Placed, design: HandDesign) -> FingerGeometry:
    """Finger i's pads at hinge angles q (n_s,) or a batch (B, n_s): gaps, closest points,
    normals and their rates (a batch adds the leading axis B to every array; ``i`` may then name
    a finger per row)."""
    q = np.asarray(q, float)
    Q = q.reshape(-1, design.n_s)
    fingers = np.broadcast_to(np.asarray(i, int), len(Q))
    p = hand_layout.pads(Q, design, fingers=fingers)
    pd = hand_layout.pad_distance(placed, p)
    frames = hand_layout.finger_frames(design)
    e_out, e_down = frames.e_out[fingers], frames.e_down[fingers]      # (B, 3)
    x, hinges = pd.point, p.joints[:, 1:-1]                            # (B, k, 3), (B, n_s, 3)
    r = x[:, :, None, :] - hinges[:, None, :, :]                       # (B, k, j, 3)
    rx, ry = np.einsum("bkji,bi->bkj", r, e_out), np.einsum("bkji,bi->bkj", r, e_down)
    dx = -ry[..., None] * e_out[:, None, None] + rx[..., None] * e_down[:, None, None]  # rotation about hinge j
    turns = np.arange(1, design.n_s + 1)[None, :] <= np.arange(design.n_s + 1)[:, None]
    dx = np.where(turns[None, ..., None], dx, 0.0)
    dg = np.einsum("bkji,bki->bkj", dx, pd.normal)
    out = FingerGeometry(pd.gap, x, pd.normal, dx, dg)
    return FingerGeometry(*(v[0] for v in out)) if q.ndim == 1 else out
