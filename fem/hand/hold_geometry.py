r"""Geometry of the whole-hand hold: the fingers' frames, their pads as rigid plates, the
object as a rigid body, and the pads' closest points to it.

Hand frame (3D, as ``softhand inspect`` draws the hand): y down along the palm axis; finger
j stands at azimuth :math:`\psi_j` about y, its bending plane spanned by its outward
direction :math:`R_y(\psi_j) e_x` and y, its plane normal :math:`R_y(\psi_j) e_z`. A point
of finger j's finger frame (:mod:`softhand.fem.hand.frame`: x along the finger, the hinge plate at
y = d) at distance :math:`\zeta` from its bending plane is at
:math:`R_y(\psi_j)\,(h(x, y), \zeta)` with h the in-plane map to the hand frame.

Pads: link k's grasping face is the rectangle of the finger frame's line y = d (+ pad
offset) between the link's ends (as the one-finger grasp's pads), ``width`` across the
finger (:math:`|\zeta| \le` width / 2). Object: a rigid body whose pose is a translation t
and a rotation vector r from its placed (reference) pose; a point X of the placed body is at
:math:`c_0 + t + R(r)(X - c_0)`, c_0 its centre of mass. Its signed distance (negative
inside) and outward normal come from the object's own geometry queries in its placed pose.

Contact point of a pad: the pad point where the object's signed distance is smallest
(:func:`pad_contacts`): started at the projection of the object's centre onto the pad,
clamped to the rectangle (exact for a sphere, and for a cylinder whose axis is normal to
the bending plane -- the one-finger grasp's circle), then improved by projected gradient
steps with backtracking on the signed distance (a convex object's signed distance is convex,
so this finds the deepest point of a box or a tilted cylinder). Where the object's point
deepest through the pad's plane (its support point along the pad's normal, closed form for
every primitive, a mesh's extreme vertex) lies over the pad, the contact is there instead: gap its height over the
plane, normal the pad's. The two agree wherever the pad is clear of the object (the pad point
nearest the object is that point's foot); they differ once a pad has sunk onto an edge or a
corner, where the deepest pad point's nearest face switches across the edge's bisecting plane
and its normal with it, while the support point's normal turns with the pad (the limit of a
rounded edge as its radius goes to 0). A mesh's support point is its extreme vertex where that is
one of its edges or corners (on ties the nearest point of the tied face or edge); on a smooth
surface's facets the deepest pad point on the mesh's smooth (cubic B-spline) distance stays
(:func:`softhand.reduced.holding.object_mesh.mesh_support`). A box (of any rotation) and a
cylinder (of any axis) meet a pad by the largest separation over directions instead
(:mod:`softhand.reduced.holding.box_contact`, :mod:`softhand.reduced.holding.cylinder_contact`),
which also gives the normal of a pad's side lying across an edge or a rim (the two edges'
common normal; the deepest pad point's face normal flips there). A pad whose plane has the
object's centre behind it cannot touch: its gap is +inf (as in :mod:`softhand.fem.contact`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from softhand.fem.constraints import PlanarChain
from softhand.fem.hand.frame import hand_frame
from softhand.reduced.holding.box_contact import box_pad_contacts
from softhand.reduced.holding.cylinder_contact import cylinder_pad_contacts
from softhand.reduced.holding.object_geometry import over_pad


def rot_y(psi: float) -> np.ndarray:
    """Rotation by psi [rad] about the hand's y axis (the palm axis, pointing down)."""
    c, s = math.cos(psi), math.sin(psi)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


@dataclass(frozen=True)
class FingerFrame:
    """Where finger j stands: the map of its finger frame into the 3D hand frame."""

    azimuth: float  #: about the palm axis, from finger 0 [rad]

    def matrix(self, design) -> np.ndarray:
        """E (3, 2): finger-frame in-plane vectors -> hand-frame 3D vectors."""
        M, _ = hand_frame(design)
        return rot_y(self.azimuth) @ np.vstack([M, np.zeros((1, 2))])

    def normal(self) -> np.ndarray:
        """Unit normal of the bending plane in the hand frame (the pads' width direction)."""
        return rot_y(self.azimuth)[:, 2]

    def origin(self, design) -> np.ndarray:
        """Hand-frame position of the finger frame's origin [mm]."""
        M, origin = hand_frame(design)
        return rot_y(self.azimuth) @ np.r_[origin - M @ [0.0, design.d], 0.0]

    def to_hand(self, design, xy, zeta=0.0) -> np.ndarray:
        """Finger-frame points xy (m, 2) at distance zeta (m,) from the plane -> hand frame (m, 3)."""
        xy = np.atleast_2d(np.asarray(xy, dtype=float))
        return self.origin(design) + xy @ self.matrix(design).T + np.multiply.outer(zeta, self.normal())


def default_layout(n: int) -> tuple[FingerFrame, ...]:
    """The paper's hand: n identical fingers evenly spaced about the palm axis (2 pi j / n)."""
    return tuple(FingerFrame(2.0 * math.pi * j / n) for j in range(n))


@dataclass(frozen=True)
class PadSet:
    """The pads of one finger: link k's rectangle between ends[k] and ends[k + 1] on y = y."""

    chain: PlanarChain
    ends: tuple[float, ...]  #: n_s + 2 arc positions: base, hinges, tip [mm]
    y: float                 #: the pads' line in the finger frame [mm]
    width: float             #: across the finger [mm]
    design: object = None    #: the HandDesign (for the finger frame's placement)

    @property
    def n_links(self) -> int:
        return len(self.ends) - 1


class Pose:
    """A rigid body's pose: translation t [mm] and rotation vector r [rad] from its placed pose."""

    def __init__(self, centre, p=None):
        self.c0 = np.asarray(centre, dtype=float)
        p = np.zeros(6) if p is None else np.asarray(p, dtype=float)
        self.t, self.r = p[:3], p[3:]
        self.R = Rotation.from_rotvec(self.r).as_matrix()

    @property
    def centre(self) -> np.ndarray:
        return self.c0 + self.t

    def to_body(self, x) -> np.ndarray:
        """Hand-frame points (m, 3) -> the placed body's frame."""
        return self.c0 + (np.asarray(x) - self.centre) @ self.R

    def to_hand(self, X) -> np.ndarray:
        """Placed-body points (m, 3) -> the hand frame now."""
        return self.centre + (np.asarray(X) - self.c0) @ self.R.T


def signed_distance(body, pose: Pose, x):
    """(d (m,), outward normal (m, 3)) of hand-frame points x at the body's current pose."""
    d, n = body.signed_distance(pose.to_body(x))
    return d, np.asarray(n) @ pose.R.T


@dataclass
class PadContacts:
    """The closest points of all pads (of the solved fingers) to the object."""

    g: np.ndarray      #: (m,) gap [mm], +inf facing away
    normal: np.ndarray  #: (m, 3) the object's outward normal there
    x: np.ndarray      #: (m, 3) the pad point, hand frame [mm]
    X: np.ndarray      #: (m, 2) its finger-frame reference position on its link [mm]
    zeta: np.ndarray   #: (m,) its distance from the bending plane [mm]


def pad_points(frames, padsets, qs, X, zeta) -> np.ndarray:
    """(m, 3) hand-frame positions of pad material points: finger-frame references X (m, 2) at
    distances zeta (m,) from the bending planes, one per link of every finger in turn."""
    xp, i = [], 0
    for frame, pads, q in zip(frames, padsets, qs):
        m = pads.n_links
        xy = pads.chain.point_map(q, np.arange(m), X[i:i + m], order=0)[0]
        xp.append(frame.to_hand(pads.design, xy, zeta[i:i + m]))
        i += m
    return np.concatenate(xp)


def pad_corners(pads: PadSet, q):
    """Start A and end B (n_links, 2) of every pad line, finger frame, current, and their references."""
    links = np.arange(pads.n_links)
    ends = np.asarray(pads.ends, dtype=float)
    A0 = np.c_[ends[:-1], np.full(pads.n_links, pads.y)]
    B0 = np.c_[ends[1:], np.full(pads.n_links, pads.y)]
    A = pads.chain.point_map(q, links, A0, order=0)[0]
    B = pads.chain.point_map(q, links, B0, order=0)[0]
    return A, B, A0, B0


def pad_contacts(body, pose: Pose, frames, padsets, qs, *, iterations: int = 40) -> PadContacts:
    """Closest pad points of every pad of every finger (frames, padsets, hinge angles qs) to
    the body at pose (see the module docstring); rows finger by finger, base link first."""
    A, B, A0, B0, e_n, half = [], [], [], [], [], []
    for frame, pads, q in zip(frames, padsets, qs):
        a, b, a0, b0 = pad_corners(pads, q)
        design = pads.design
        A.append(frame.to_hand(design, a)), B.append(frame.to_hand(design, b))
        A0.append(a0), B0.append(b0)
        e_n.append(np.tile(frame.normal(), (pads.n_links, 1)))
        half.append(np.full(pads.n_links, 0.5 * pads.width))
    A, B, A0, B0, e_n, half = map(np.concatenate, (A, B, A0, B0, e_n, half))
    AB = B - A
    L2 = np.einsum("ki,ki->k", AB, AB)
    c = pose.centre
    sigma = np.clip(np.einsum("ki,ki->k", c - A, AB) / L2, 0.0, 1.0)
    zeta = np.clip(np.einsum("ki,ki->k", c - A, e_n), -half, half)
    point = lambda s, z: A + s[:, None] * AB + z[:, None] * e_n  # noqa: E731
    facing = np.cross(e_n, AB)  # the pad's normal towards the closing side (finger frame +y)
    facing /= np.linalg.norm(facing, axis=1)[:, None]
    shape = getattr(body, "shape", None)
    if shape in ("box", "cylinder"):  # the largest separation over directions (module doc)
        L = np.sqrt(L2)
        pads = (A + 0.5 * AB, AB / L[:, None], 0.5 * L, e_n, half, facing, point(sigma, zeta))
        if shape == "box":
            d, n, x = box_pad_contacts(c, pose.R @ body.frame_matrix, 0.5 * np.asarray(body.size, float), *pads)
        else:
            d, n, x = cylinder_pad_contacts(c, pose.R @ np.asarray(body.axis), 0.5 * body.size[0], 0.5 * body.size[1],
                                            *pads, lambda p: signed_distance(body, pose, p))
        sigma, zeta = np.einsum("ki,ki->k", x - A, AB) / L2, np.einsum("ki,ki->k", x - A, e_n)
        return _contacts(d, n, x, facing, c, A0, B0, sigma, zeta)
    d, n = signed_distance(body, pose, point(sigma, zeta))
    step = 0.25 * np.sqrt(L2)
    active = np.ones(len(sigma), dtype=bool)
    for _ in range(iterations):
        ds = -step * np.einsum("ki,ki->k", n, AB) / L2
        dz = -step * np.einsum("ki,ki->k", n, e_n)
        s1, z1 = np.clip(sigma + ds, 0.0, 1.0), np.clip(zeta + dz, -half, half)
        # stationary on the rectangle (a sphere's start, a clamped corner, a parallel face): done
        active &= np.hypot((s1 - sigma) * np.sqrt(L2), z1 - zeta) > 1e-12
        if not active.any():
            break
        d1, n1 = signed_distance(body, pose, point(s1, z1))
        better = active & (d1 < d - 1e-13 * (1.0 + np.abs(d)))
        sigma, zeta = np.where(better, s1, sigma), np.where(better, z1, zeta)
        d, n = np.where(better, d1, d), np.where(better[:, None], n1, n)
        step = np.where(better, step, 0.5 * step)
        active &= step > 1e-10
    x = point(sigma, zeta)
    support = getattr(body, "support", None)
    S = None if support is None else support(facing @ pose.R, pose.to_body(x))
    if S is not None:  # the object's point deepest through the pad's plane, where it is over the pad
        L = np.sqrt(L2)
        over, s_f, z_f, h = over_pad(pose.to_hand(S), A + 0.5 * AB, AB / L[:, None], e_n, facing, 0.5 * L, half)
        sigma, zeta = np.where(over, 0.5 + s_f / L, sigma), np.where(over, z_f, zeta)
        d = np.where(over, h, d)
        n = np.where(over[:, None], -facing, n)
        x = point(sigma, zeta)
    return _contacts(d, n, x, facing, c, A0, B0, sigma, zeta)


def _contacts(d, n, x, facing, c, A0, B0, sigma, zeta) -> PadContacts:
    """The pads' contacts, a pad whose plane has the object's centre c behind it facing away."""
    g = np.where(np.einsum("ki,ki->k", facing, c - x) > 0.0, d, np.inf)
    return PadContacts(g, n, x, A0 + sigma[:, None] * (B0 - A0), zeta)


def contact_rows(orbits, frames, n_links: int, cs) -> list:
    """The contact state ``cs`` as rows, every finger's pads (the images of a solved finger of ``orbits``
    rotated about the palm axis)."""
    rows, n = [], n_links
    for i, (j, images) in enumerate(orbits):
        for k in images:
            R = rot_y(frames[k].azimuth - frames[j].azimuth)
            for link in range(n):
                r = i * n + link
                N = float(cs.N[r])
                rows.append({"finger": int(k), "link": int(link), "normal_N": N,
                             "friction_N": float(np.linalg.norm(cs.T[r])),
                             "state": ("stick" if cs.stick[r] else "slip") if N > 0 else "open",
                             "gap_mm": float(cs.g[r]) if np.isfinite(cs.g[r]) else None,
                             "point_mm": (R @ cs.x[r]).tolist(),
                             "normal_force_N": (R @ (N * cs.normal[r])).tolist(),
                             "friction_force_N": (R @ cs.T[r]).tolist()})
    return rows
