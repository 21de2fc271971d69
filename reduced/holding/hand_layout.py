r"""The hand as it is built: where each finger stands, its pads in 3D, and where the object sits.

Hand frame (docs/conventions.md): origin on the palm's axis at the height of the finger bases;
**y** down along the palm's axis (gravity); finger 0 bends in the x-y plane with **x** outward;
**z** = x cross y. Finger i stands at azimuth phi_i about the palm's axis (the design's
``finger_azimuths_deg``; default n fingers evenly spaced from 0, the paper's four at 0, 90, 180,
270 deg as ``softhand inspect`` draws them): its outward direction is finger 0's turned about
+y by phi_i, e_out = (cos phi, 0, -sin phi), its bending plane spanned by e_out and y, its plane
normal e_n = e_out x e_y. A point (x, y) of the finger's plane (:mod:`softhand.reduced.equations.kinematics`: base
at (base_offset, 0), base link mounted theta0 = 20 deg outward) is x e_out + y e_y in the hand frame.

Each link k's **pad** is the rigid plate between its joints (the hinge plate side, facing the
palm's axis): a rectangle with centre c, unit vectors ``along`` (the link, base to tip) and
``across`` (= e_n), half sizes (link length / 2, pad width / 2), and ``normal`` = the inward
normal -(cos alpha_k e_out + sin alpha_k e_y) towards the object. Pad width: the design's
``pad_width_mm``, default the tube's outer diameter 2 (a + b).

:func:`place_object` puts an object at its default placement (its centre on the palm's axis,
its top ``PALM_GAP`` below the palm, lowered until the open fingers clear it by ``CLEARANCE``),
then its pose; it refuses an object the open fingers do not clear or that reaches the palm.
:func:`pad_distance` gives each pad's gap to the object, its closest point and the object's
normal there (vectorised over fingers and pads). Units: mm, rad.
"""
from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np
from scipy.optimize import brentq

from softhand.reduced.equations import contact, kinematics
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.holding.box_contact import box_pad_contacts
from softhand.reduced.holding.cylinder_contact import cylinder_distance, cylinder_pad_contacts
from softhand.reduced.holding.object_geometry import Placed, over_pad, place
from softhand.reduced.holding.objects import CLEARANCE, PALM_GAP, GraspObject

#: points sampled along and across a pad for a non-spherical object (then refined by parabolas)
PAD_SAMPLES = (17, 3)


def azimuths(design: HandDesign) -> np.ndarray:
    """Each finger's azimuth phi_i about the palm's axis (n,) [rad]."""
    if design.finger_azimuths:
        return np.asarray(design.finger_azimuths, float)
    return 2.0 * np.pi * np.arange(design.n) / design.n


def pad_width(design: HandDesign) -> float:
    """Pad width across the finger [mm]: the design's, or the tube's outer diameter."""
    return design.pad_width if design.pad_width > 0 else 2.0 * (design.a + design.b)


class FingerFrames(NamedTuple):
    """Each finger's plane in the hand frame: unit vectors (n, 3)."""

    e_out: np.ndarray     #: outward, in the plane
    e_down: np.ndarray    #: along y (gravity), in the plane
    e_normal: np.ndarray  #: normal to the bending plane (the hinges' axes)


def finger_frames(design: HandDesign) -> FingerFrames:
    """The fingers' planes (:class:`FingerFrames`) for the design's layout."""
    return _frames(tuple(azimuths(design)))


@lru_cache(maxsize=64)
def _frames(phi: tuple) -> FingerFrames:
    phi = np.asarray(phi, float)
    e_out = np.stack([np.cos(phi), np.zeros_like(phi), -np.sin(phi)], axis=-1)
    e_down = np.tile([0.0, 1.0, 0.0], (len(phi), 1))
    return FingerFrames(e_out, e_down, np.cross(e_out, e_down))


def to_hand(points_2d, frames: FingerFrames) -> np.ndarray:
    """Finger-plane points (nf, ..., 2) [mm] -> hand frame (nf, ..., 3)."""
    p = np.asarray(points_2d, float)
    shape = (len(frames.e_out),) + (1,) * (p.ndim - 2) + (3,)
    return p[..., :1] * frames.e_out.reshape(shape) + p[..., 1:2] * frames.e_down.reshape(shape)


class Pads(NamedTuple):
    """The links' pads of every finger, (nf, n_s + 1, ...) arrays in the hand frame."""

    centre: np.ndarray   #: (nf, n_s+1, 3) [mm]
    along: np.ndarray    #: (nf, n_s+1, 3) unit, base to tip of the link
    across: np.ndarray   #: (nf, n_s+1, 3) unit, the finger's plane normal
    normal: np.ndarray   #: (nf, n_s+1, 3) unit, inward (towards the object)
    half: np.ndarray     #: (n_s+1, 2) half length, half width [mm]
    joints: np.ndarray   #: (nf, n_s+2, 3) base, hinges, tip [mm]


def pads(q, design: HandDesign, fingers=None) -> Pads:
    """Every finger's pads at hinge angles q (nf, n_s) [rad] (:class:`Pads`); ``fingers``: only
    those (indices; q then has one row per finger named)."""
    q = np.asarray(q, float)
    frames = finger_frames(design)
    if fingers is not None:
        frames = FingerFrames(*(f[np.asarray(fingers)] for f in frames))
    alpha = kinematics.link_angles(q, design)                           # (nf, n_s+1)
    joints = to_hand(kinematics.positions_at(alpha, design), frames)    # (nf, n_s+2, 3)
    along_2d = np.stack([-np.sin(alpha), np.cos(alpha)], axis=-1)
    normal_2d = -np.stack([np.cos(alpha), np.sin(alpha)], axis=-1)
    across = np.repeat(frames.e_normal[:, None, :], q.shape[-1] + 1, axis=1)
    half = np.stack([0.5 * np.asarray(design.link_lengths), np.full(design.n_s + 1, 0.5 * pad_width(design))], -1)
    return Pads(0.5 * (joints[:, :-1] + joints[:, 1:]), to_hand(along_2d, frames), across,
                to_hand(normal_2d, frames), half, joints)


class PadDistance(NamedTuple):
    """Each pad's distance to the object, (nf, n_s + 1, ...) arrays."""

    gap: np.ndarray      #: (nf, n_s+1) [mm]; +inf where the pad faces away from the object
    point: np.ndarray    #: (nf, n_s+1, 3) the pad's point closest to the object [mm]
    normal: np.ndarray   #: (nf, n_s+1, 3) the object's outward normal there (the pad pushes along -normal)


def pad_distance(placed: Placed, p: Pads) -> PadDistance:
    """Gap of every pad to the object: exact for a sphere (the pad rectangle's point nearest the
    centre); for a box (or a mesh that is one) by separating axes (:mod:`softhand.reduced.holding.box_contact`, as the FEM
    hold: a pad's side across a box edge has the two edges' cross product as normal); otherwise the least distance on a :data:`PAD_SAMPLES` grid of the pad refined by a
    parabola through the least sample and its neighbours, along then across (exact for a flat
    face; error O(h^3) on a curved one, h = 1/16 of the link). Then, by the FEM hold's own rule
    (:func:`softhand.reduced.holding.object_geometry.over_pad`), where the object's point deepest
    through the pad's plane (:meth:`~softhand.reduced.holding.object_geometry.Placed.support`,
    closed form, a mesh's extreme vertex) lies over the pad, the contact is there: gap its height
    above the pad, normal the pad's (an edge or corner against the pad's face; on a line of ties,
    the point nearest the pad's point nearest the centre)."""
    d = placed.centre - p.centre  # the pad's point nearest the centre: a sphere's contact, else ties' start
    s = np.minimum(np.maximum(np.einsum("fki,fki->fk", d, p.along), -p.half[:, 0]), p.half[:, 0])
    w = np.minimum(np.maximum(np.einsum("fki,fki->fk", d, p.across), -p.half[:, 1]), p.half[:, 1])
    ref = p.centre + s[..., None] * p.along + w[..., None] * p.across
    if placed.obj.shape == "cylinder" or placed.box() is not None:
        return _convex_distance(placed, p, ref)
    if placed.obj.shape == "sphere":
        x = ref
        gap = placed.sdf(x)
    else:
        x, gap = _sampled_closest(placed, p)
    n = placed.normal(x)
    facing = np.einsum("fki,fki->fk", n, p.normal) < 0.0
    gap = np.where(facing, gap, np.inf)
    S = placed.support(p.normal.reshape(-1, 3), ref.reshape(-1, 3))
    # the object's point deepest through the pad's plane, where it is over the pad
    over, s, w, h = over_pad(S.reshape(x.shape), p.centre, p.along, p.across, p.normal, p.half[:, 0], p.half[:, 1])
    x = np.where(over[..., None], p.centre + s[..., None] * p.along + w[..., None] * p.across, x)
    n = np.where(over[..., None], -p.normal, n)
    towards = np.einsum("fki,fki->fk", placed.centre - x, p.normal) > 0.0
    gap = np.where(over, np.where(towards, h, np.inf), gap)
    return PadDistance(gap, x, n)


def _convex_distance(placed: Placed, p: Pads, ref) -> PadDistance:
    """A box's (or a box mesh's) or a cylinder's gaps by the largest separation over directions, the FEM hold's rule
    (:mod:`softhand.reduced.holding.box_contact`, :mod:`softhand.reduced.holding.cylinder_contact`)."""
    shape = p.centre.shape
    half = np.broadcast_to(p.half, shape[:-1] + (2,)).reshape(-1, 2)
    flat = lambda v: np.reshape(v, (-1, 3))  # noqa: E731
    pads = (flat(p.centre), flat(p.along), half[:, 0], flat(p.across), half[:, 1], flat(p.normal), flat(ref))
    obj = placed.obj
    box = placed.box()
    if box is not None:
        gap, n, x = box_pad_contacts(*box, *pads)
    else:
        k, r, h = placed.R[:, 1], 0.5 * obj.diameter_mm, 0.5 * obj.length_mm  # a cylinder's axis: its own y
        # the circles' maxima to 1e-7 rad (the FEM's central differences need them to round-off)
        gap, n, x = cylinder_pad_contacts(placed.centre, k, r, h, *pads,
                                          lambda q: cylinder_distance(q - placed.centre, k, r, h), steps=30)
    x, n = x.reshape(shape), n.reshape(shape)
    towards = np.einsum("...i,...i->...", placed.centre - x, p.normal) > 0.0
    return PadDistance(np.where(towards, gap.reshape(shape[:-1]), np.inf), x, n)


def _sampled_closest(placed: Placed, p: Pads):
    na, nc = PAD_SAMPLES
    u = np.linspace(-1.0, 1.0, na)
    v = np.linspace(-1.0, 1.0, nc)
    S = u[None, :, None] * p.half[:, 0, None, None]                     # (k, na, 1)
    W = v[None, None, :] * p.half[:, 1, None, None]                     # (k, 1, nc)
    pts = p.centre[:, :, None, None, :] + S[None, ..., None] * p.along[:, :, None, None, :] \
        + W[None, ..., None] * p.across[:, :, None, None, :]            # (nf, k, na, nc, 3)
    f = placed.sdf(pts)
    flat = f.reshape(f.shape[:2] + (-1,)).argmin(axis=-1)
    ia, ic = np.unravel_index(flat, (na, nc))
    s = u[ia] * p.half[:, 0]
    w = v[ic] * p.half[:, 1]
    ha, hc = 2.0 * p.half[:, 0] / (na - 1), 2.0 * p.half[:, 1] / (nc - 1)
    for step, lo_hi, axis in ((ha, p.half[:, 0], "a"), (hc, p.half[:, 1], "c")):
        at = lambda s_, w_: placed.sdf(p.centre + s_[..., None] * p.along + w_[..., None] * p.across)  # noqa: E731
        t = s if axis == "a" else w
        f0 = at(s, w)
        fm = at(s - step, w) if axis == "a" else at(s, w - step)
        fp = at(s + step, w) if axis == "a" else at(s, w + step)
        curv = fp + fm - 2.0 * f0
        shift = np.where(curv > 1e-12, -0.5 * step * (fp - fm) / np.where(curv > 1e-12, curv, 1.0), 0.0)
        t = np.clip(t + np.clip(shift, -step, step), -lo_hi, lo_hi)
        if axis == "a":
            s = t
        else:
            w = t
    x = p.centre + s[..., None] * p.along + w[..., None] * p.across
    return x, placed.sdf(x)


def _open_gap(obj: GraspObject, depth: float, design: HandDesign) -> float:
    """The least gap of the open hand's pads (theta_hat = 0) to the object centred at depth."""
    placed = place(obj, (0.0, depth, 0.0))
    return float(np.min(pad_distance(placed, pads(np.zeros((design.n, design.n_s)), design)).gap))


def default_depth(obj: GraspObject, design: HandDesign) -> float:
    """Depth [mm] of the object's centre at its default placement (module doc); for a sphere
    exactly :func:`softhand.reduced.equations.contact.object_depth` of its diameter (the one-finger grasp's)."""
    if obj.shape == "sphere":
        try:
            return contact.object_depth(obj.diameter_mm, design)
        except InputError:
            raise InputError("object", obj.describe(), "does not fit between the open fingers") from None
    top = place(obj, (0.0, 0.0, 0.0)).top()         # the centre's height above the object's top
    depth = PALM_GAP - top
    fun = lambda y: _open_gap(obj, y, design) - CLEARANCE  # noqa: E731
    if fun(depth) >= 0.0:
        return depth
    extent = float(np.ptp(place(obj, (0, 0, 0)).surface(resolution=16)[0], axis=0).max())
    hi = depth + extent + 2.0 * design.l0
    if fun(hi) < 0.0:
        raise InputError("object", obj.describe(), "does not fit between the open fingers")
    return float(brentq(fun, depth, hi, xtol=1e-9))


def place_object(obj: GraspObject, design: HandDesign) -> Placed:
    """The object at its default placement, then its pose (rotation_deg, offset_mm); InputError if
    it reaches above the palm or overlaps the open fingers."""
    depth = default_depth(obj, design)
    tip = float(kinematics.tip_position(np.zeros(design.n_s), design)[1])
    if place(obj, (0.0, depth, 0.0)).top() >= tip:
        raise InputError("object", obj.describe(), f"does not fit between the open fingers (lowered until "
                         f"they clear it, its top is below their tips, {tip:.4g} mm under the palm)")
    placed = place(obj, np.array([0.0, depth, 0.0]) + np.asarray(obj.offset_mm))
    if placed.top() < 0.0:
        raise InputError("object.offset_mm", list(obj.offset_mm),
                         f"puts the object inside the palm (its top {-placed.top():.4g} mm above it)")
    if any(obj.offset_mm) or any(obj.rotation_deg):
        gap = float(np.min(pad_distance(placed, pads(np.zeros((design.n, design.n_s)), design)).gap))
        if gap < 0.0:
            raise InputError("object.offset_mm", list(obj.offset_mm),
                             f"puts the object into the open fingers (overlap {-gap:.4g} mm)")
    return placed


def symmetric(placed: Placed, design: HandDesign) -> bool:
    """Whether every finger sees the object alike (one finger solved for all): its distance field
    is unchanged, to 1e-9 of its size, by turning it about the palm's axis onto each finger
    (at 600 points around it). True for a centred sphere, upright cylinder or capsule, and a
    box or mesh with the layout's symmetry (a square box under four fingers at 90 deg)."""
    if placed.obj.shape == "sphere" and placed.centre[0] == 0.0 and placed.centre[2] == 0.0:
        return True
    pts, _ = placed.surface(resolution=16)
    size = float(np.max(np.ptp(pts, axis=0)))
    k = np.arange(200) + 0.5
    u = np.stack([np.cos(np.pi * (1 + 5 ** 0.5) * k) * np.sqrt(1 - (1 - 2 * k / 200) ** 2),
                  1 - 2 * k / 200, np.sin(np.pi * (1 + 5 ** 0.5) * k) * np.sqrt(1 - (1 - 2 * k / 200) ** 2)], -1)
    probe = np.concatenate([r * size * u for r in (0.3, 0.55, 0.8)]) + np.array([0.0, placed.centre[1], 0.0])
    base = placed.sdf(probe)
    for phi in azimuths(design)[1:]:
        c, s_ = np.cos(phi), np.sin(phi)
        turned = probe @ np.array([[c, 0.0, -s_], [0.0, 1.0, 0.0], [s_, 0.0, c]])  # p -> R_y(-phi) p
        if np.max(np.abs(placed.sdf(turned) - base)) > 1e-9 * size:
            return False
    return True
