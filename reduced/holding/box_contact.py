r"""Contact of the hold's flat pads with a box, by separating axes: the one rule by which a pad
meets a box, in the fast hold (:func:`softhand.reduced.holding.hand_layout.pad_distance`) and the
FEM hold (:func:`softhand.fem.hand.hold_geometry.pad_contacts`) alike.

A pad (a rectangle) and a box are convex polytopes. Their signed distance is the largest
separation over the separating-axis candidates (Gottschalk, Lin and Manocha 1996, OBBTree;
Ericson, *Real-Time Collision Detection*, 2005, sec. 4.4 and 5.2): the pad's normal, the box's
three face normals and the six cross products of a pad edge with a box edge. Along a unit axis u
oriented from the pad to the box (D the centres' offset),

.. math:: s(u) = |u \cdot D| - \sum_i h_i |u \cdot b_i| - \tfrac{L}{2} |u \cdot a| - \tfrac{w}{2} |u \cdot e|,

b_i, h_i the box's axes and half edges, a, L and e, w the pad's axis and length along the
link and across it. The largest s is the gap where the two touch (face on corner, corner on
face, edge across edge) and minus the penetration depth once they overlap; its axis is the
contact normal. Where the pad's side crosses an edge of the box the normal is the cross
product of the two edges, which turns smoothly with the pad -- the distance's own gradient at
the pad's deepest point does not: it flips between the edge's two faces as that point crosses
the edge's bisecting plane, and a one-point contact there has no converging Newton; and a
distance sampled along the pad and refined by a parabola misplaces a contact at the edge's kink
by a fraction of the sample spacing, onto the face, with the face's normal.

Where the two are apart with a corner nearest a corner or an edge (no candidate axis is
the distance's direction), s is less than the distance: only touching pads bear force, and
at touch the largest s is exact.

A mesh that is a rectangular box (:func:`cuboid_of`) is met as the box is.
"""
from __future__ import annotations

import numpy as np

#: relative size below which a separation or a projection counts as a tie
TIE = 1e-9


def box_pad_contacts(centre, axes, half, pc, a, hl, e, hw, facing, ref):
    """Contacts of m pads with one box: pad centres pc (m, 3), unit axes a (along, half length hl
    (m,)) and e (across, half width hw (m,)), unit normals ``facing`` towards the box; the box's
    centre (3,), axes (3, 3) as columns and half edges (3,), hand frame now; ``ref`` (m, 3) a
    pad point that breaks ties (the pad point nearest the box's centre). Returns (gap (m,) [mm],
    the box's outward normal (m, 3), the pad's contact point (m, 3))."""
    B = np.asarray(axes, float).T                                   # (3 box axes, 3)
    U = np.concatenate([facing[:, None, :], np.broadcast_to(B, (len(pc), 3, 3)),
                        np.cross(a[:, None, :], B[None]), np.cross(e[:, None, :], B[None])], axis=1)
    size = np.linalg.norm(U, axis=2)
    valid = size > 1e-9
    U = U / np.where(valid, size, 1.0)[..., None]
    D = np.asarray(centre, float) - pc
    along = np.einsum("mki,mi->mk", U, D)
    radius = (np.abs(np.einsum("mki,ji->mkj", U, B)) @ np.asarray(half, float)
              + hl[:, None] * np.abs(np.einsum("mki,mi->mk", U, a))
              + hw[:, None] * np.abs(np.einsum("mki,mi->mk", U, e)))
    sep = np.where(valid, np.abs(along) - radius, -np.inf)
    scale = TIE * (1.0 + float(np.max(half)))
    k = np.argmax(sep >= sep.max(axis=1, keepdims=True) - scale, axis=1)  # the first of the ties
    rows = np.arange(len(pc))
    u = U[rows, k] * np.where(along[rows, k] < 0.0, -1.0, 1.0)[:, None]  # pad -> box
    ub, ua, ue = u @ B.T, np.einsum("mi,mi->m", u, a), np.einsum("mi,mi->m", u, e)
    r_ref = ref - pc
    s_ref = np.clip(np.einsum("mi,mi->m", r_ref, a), -hl, hl)
    w_ref = np.clip(np.einsum("mi,mi->m", r_ref, e), -hw, hw)
    # the box's corner deepest along -u (ties: its point nearest ref) and the pad's deepest along u
    local = np.clip((ref - centre) @ B.T, -half, half)
    corner = np.where(np.abs(ub) > TIE, -np.sign(ub) * half, local)
    s_pad = np.where(np.abs(ua) > TIE, np.sign(ua) * hl, s_ref)
    w_pad = np.where(np.abs(ue) > TIE, np.sign(ue) * hw, w_ref)
    # pad face against the box's corner: the corner's foot on the pad
    y = centre + corner @ B
    foot = y - pc
    s, w = np.clip(np.einsum("mi,mi->m", foot, a), -hl, hl), np.clip(np.einsum("mi,mi->m", foot, e), -hw, hw)
    # pad corner against a box face: the pad's deepest point
    face = (k >= 1) & (k <= 3)
    s, w = np.where(face, s_pad, s), np.where(face, w_pad, w)
    # a pad edge across a box edge: the closest points of the two lines
    cross = k >= 4
    i = np.where(cross, (k - 4) % 3, 0)
    d_box = B[i]
    side = k <= 6                                   # along the pad's side, else across its end
    d_pad = np.where(side[:, None], a, e)
    p0 = pc + np.where(side, 0.0, s_pad)[:, None] * a + np.where(side, w_pad, 0.0)[:, None] * e
    c12 = np.einsum("mi,mi->m", d_pad, d_box)
    r = p0 - y                                      # y is on the box edge's line
    t = (c12 * np.einsum("mi,mi->m", d_box, r) - np.einsum("mi,mi->m", d_pad, r)) / np.maximum(1.0 - c12 ** 2, 1e-12)
    s = np.where(cross & side, np.clip(t, -hl, hl), np.where(cross, s_pad, s))
    w = np.where(cross & ~side, np.clip(t, -hw, hw), np.where(cross, w_pad, w))
    return sep[rows, k], -u, pc + s[:, None] * a + w[:, None] * e


#: a mesh is a box when its volume and its oriented bounding box's agree to this (relative)
CUBOID_TOL = 1e-6


def cuboid_of(vertices, faces):
    """(half edges (3,), axes (3, 3) as columns, centre (3,)) of the mesh if it is a rectangular box --
    its volume that of its smallest oriented bounding box (trimesh), to :data:`CUBOID_TOL` -- else None.
    A box read from a file then meets the pads as the box primitive does, by separating axes, in
    both hold models (its distance grid rounds the edges over a grid step)."""
    import trimesh

    mesh = trimesh.Trimesh(vertices, faces, process=False)
    to_origin, extents = trimesh.bounds.oriented_bounds(mesh)
    if not abs(float(np.prod(extents)) - float(mesh.volume)) <= CUBOID_TOL * float(mesh.volume):
        return None
    A = np.asarray(to_origin, float)[:3, :3].T                 # the box's axes in the object frame, to ~1e-8
    # to round-off: each axis the area-weighted mean of its faces' normals, then the nearest rotation
    n = mesh.face_normals * mesh.area_faces[:, None]
    along = n @ A                                               # (nf, 3)
    side = np.abs(mesh.face_normals @ A).argmax(axis=1)
    M = np.stack([(np.sign(along[side == i, i])[:, None] * n[side == i]).sum(axis=0) for i in range(3)], axis=1)
    U, _, Vt = np.linalg.svd(M)
    A = U @ Vt * [1.0, 1.0, np.sign(np.linalg.det(U @ Vt))]  # a rotation (a box is its own mirror image)
    x = np.asarray(vertices, float) @ A
    lo, hi = x.min(axis=0), x.max(axis=0)
    return 0.5 * (hi - lo), A, A @ (0.5 * (hi + lo))
