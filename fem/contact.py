r"""Frictionless contact between the rigid links of a planar chain and a rigid analytic object.

The object is seen in the chain's plane as a circle (centre :math:`C`, radius :math:`R`):
a cylinder whose axis is normal to the bending plane, or a sphere centred in that plane --
against flat rigid pads the two give the same contact. Link :math:`k` grasps with its
*pad*, the segment of its reference line :math:`y = y_p` between its two ends
:math:`s_k, s_{k+1}`, facing :math:`+y` (the finger frame of :mod:`softhand.fem.hand.finger`: the hinge
plate side). A link touches the object with the point of its pad closest to :math:`C`:

.. math:: x^* = x(X^*, q),\quad X^* = \arg\min_{X \in \text{pad}} |C - x(X, q)|,\qquad
          g = |C - x^*| - R ,

:math:`\nu = (C - x^*)/\rho`, :math:`\rho = |C - x^*|`. Whether :math:`X^*` is inside the
pad ("face") or at an end ("corner"), the gradient is :math:`\partial g/\partial q =
-\nu\cdot J` with :math:`J = \partial x/\partial q` at the fixed material point (the
distance is stationary along the pad). The Hessians differ:

* corner: :math:`\partial^2 g = -\nu\cdot H + J^T (I - \nu\nu^T) J / \rho`;
* face: with :math:`n = \nu` the pad normal and :math:`m_j = 1` when hinge :math:`j` turns
  the link, :math:`a_j = (\Omega n)\cdot J_j`:
  :math:`\partial^2 g = -n\cdot H - \rho\, m m^T - m a^T - a m^T`.

A pad whose line has the centre behind it (:math:`n \cdot (C - x^*) \le 0`) cannot touch
the object: its gap is :math:`+\infty`.

Normal force (augmented Lagrangian; multipliers :math:`\lambda_k = 0` is the plain
penalty method): :math:`N_k = \langle \lambda_k - \epsilon g_k \rangle`, the potential
:math:`\Pi = \sum_k \langle\lambda_k - \epsilon g_k\rangle^2 / (2\epsilon)`, generalised
force :math:`Q = -\partial\Pi/\partial q = \sum_k N_k\, \partial g_k/\partial q`. Uzawa
updates :math:`\lambda \leftarrow N` drive :math:`g \to 0` on the active pads.

The grasped object's weight share (eq. (24)) acts on the pads tangentially, along the
link towards the tip, :math:`T_k = W s_k\, t_k`, split over the pads by shares
:math:`s_k` (the normal-force shares, held fixed during a Newton solve and updated with
the multipliers). A force along the pad line has the same moment wherever on the line it
acts, so its generalised force is :math:`J^T T_k` at :math:`X^*`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softhand.fem.constraints import OMEGA, PlanarChain, rotation


@dataclass(frozen=True)
class Circle:
    """The object's section in the chain's plane (finger frame)."""

    centre: tuple[float, float]  #: centre C [mm]
    radius: float                #: radius R [mm]


@dataclass(frozen=True)
class Pads:
    """The grasping faces of the links of ``chain``: link k holds the segment
    (ends[k], y) - (ends[k+1], y) of its reference configuration, facing +y."""

    chain: PlanarChain
    ends: tuple[float, ...]  #: n_s + 2 arc positions: base, hinges, tip [mm]
    y: float                 #: the pads' line in the reference configuration [mm]

    @property
    def n_links(self) -> int:
        return len(self.ends) - 1


@dataclass(frozen=True)
class Gaps:
    """Gap of every pad to the object and its derivatives in the hinge angles q."""

    g: np.ndarray        #: (n_links,) gap [mm]; +inf where the pad faces away
    grad: np.ndarray     #: (n_links, n_s) dg/dq [mm/rad]
    hess: np.ndarray     #: (n_links, n_s, n_s) d2g/dq2 [mm/rad^2]
    X: np.ndarray        #: (n_links, 2) reference position of the closest pad point [mm]
    x: np.ndarray        #: (n_links, 2) its current position [mm]
    nu: np.ndarray       #: (n_links, 2) unit vector from it towards the centre
    J: np.ndarray        #: (n_links, 2, n_s) dx/dq at the closest material point
    H: np.ndarray        #: (n_links, 2, n_s, n_s) d2x/dq2 there
    tangent: np.ndarray  #: (n_links, 2) current pad direction t_k (towards the tip)


def gaps(pads: Pads, circle: Circle, q) -> Gaps:
    """Gaps g_k(q) [mm] of all pads to the circle, with gradient and Hessian in q."""
    chain, links = pads.chain, np.arange(pads.n_links)
    q = np.asarray(q, dtype=float)
    ends = np.asarray(pads.ends, dtype=float)
    A = np.c_[ends[:-1], np.full(pads.n_links, pads.y)]
    B = np.c_[ends[1:], np.full(pads.n_links, pads.y)]
    xa = chain.point_map(q, links, A)[0]
    xb = chain.point_map(q, links, B)[0]
    C = np.asarray(circle.centre, dtype=float)
    tau = np.einsum("ki,ki->k", C - xa, xb - xa) / np.einsum("ki,ki->k", xb - xa, xb - xa)
    face = (tau > 0.0) & (tau < 1.0)
    X = A + np.clip(tau, 0.0, 1.0)[:, None] * (B - A)
    x, J, H = chain.point_map(q, links, X)
    rho = np.linalg.norm(C - x, axis=1)
    nu = (C - x) / rho[:, None]
    phi = chain.link_angles(q)
    normal = np.einsum("ijk,j->ki", rotation(phi), [0.0, 1.0])
    g = np.where(np.einsum("ki,ki->k", normal, C - x) > 0.0, rho - circle.radius, np.inf)
    grad = -np.einsum("ki,kij->kj", nu, J)
    hess = np.where(face[:, None, None], _face_hessian(nu, rho, J, H, links),
                    _corner_hessian(nu, rho, J, H))
    tangent = np.einsum("ijk,j->ki", rotation(phi), [1.0, 0.0])
    return Gaps(g, grad, hess, X, x, nu, J, H, tangent)


def _corner_hessian(nu, rho, J, H):
    """d2|C - x|/dq2 at a fixed material point (a pad end)."""
    P = np.eye(2)[None] - np.einsum("ki,kj->kij", nu, nu)
    return (-np.einsum("ki,kijl->kjl", nu, H)
            + np.einsum("kaj,kab,kbl->kjl", J, P, J) / rho[:, None, None])


def _face_hessian(nu, rho, J, H, links):
    """d2/dq2 of n.(C - x) for the pad line of normal n = nu through the contact point."""
    n_s = J.shape[-1]
    m = (np.arange(n_s)[None, :] < links[:, None]).astype(float)   # hinge j turns link k
    a = np.einsum("ab,kb,kaj->kj", OMEGA, nu, J)                    # (Omega n) . J_j
    return (-np.einsum("ki,kijl->kjl", nu, H) - rho[:, None, None] * np.einsum("kj,kl->kjl", m, m)
            - np.einsum("kj,kl->kjl", m, a) - np.einsum("kj,kl->kjl", a, m))


@dataclass(frozen=True)
class ContactLoad:
    """Normal forces and generalised forces of the contact (and the weight share) at q."""

    N: np.ndarray       #: (n_links,) normal force of the object on each pad [N], >= 0
    Q: np.ndarray       #: (n_s,) generalised force on the hinge angles [N mm]
    dQ: np.ndarray      #: (n_s, n_s) dQ/dq [N mm/rad]
    forces: np.ndarray  #: (n_links, 2) force of the object on each pad (normal + weight) [N]
    points: np.ndarray  #: (n_links, 2) where it acts (the closest pad points) [mm]


def normal_forces(g, penalty: float, multipliers) -> np.ndarray:
    """N_k = <lambda_k - penalty g_k> [N] (augmented Lagrangian; lambda = 0: penalty)."""
    with np.errstate(invalid="ignore"):
        return np.where(np.isfinite(g), np.maximum(np.asarray(multipliers) - penalty * g, 0.0), 0.0)


def contact_load(gp: Gaps, penalty: float, multipliers, *, weight: float = 0.0,
                 shares=None) -> ContactLoad:
    """Generalised forces of the normal contact and of the weight share ``weight`` [N]
    split over the pads by ``shares`` (n_links, summing to 1), with their q-derivative."""
    N = normal_forces(gp.g, penalty, multipliers)
    active = N > 0.0
    Q = np.einsum("k,kj->j", N, gp.grad)
    dQ = (np.einsum("k,kjl->jl", N[active], gp.hess[active])
          - penalty * np.einsum("kj,kl->jl", gp.grad[active], gp.grad[active]))
    forces = -N[:, None] * gp.nu
    if weight:
        T = weight * np.asarray(shares, dtype=float)
        n_s = gp.J.shape[-1]
        m = (np.arange(n_s)[None, :] < np.arange(len(T))[:, None]).astype(float)
        Ot = gp.tangent @ OMEGA.T                                        # Omega t
        Q = Q + np.einsum("k,ki,kij->j", T, gp.tangent, gp.J)
        dQ = dQ + (np.einsum("k,ki,kijl->jl", T, gp.tangent, gp.H)
                   + np.einsum("k,ki,kij,kl->jl", T, Ot, gp.J, m))
        forces = forces + T[:, None] * gp.tangent
    return ContactLoad(N, Q, dQ, forces, gp.x)
