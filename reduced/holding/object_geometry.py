"""The object's geometry: its distance, extent, surface and edges in its own frame, and the
object placed in the hand frame (:class:`softhand.reduced.holding.object_geometry.Placed`).

Geometry queries are vectorised over points (..., 3) in the hand frame: :meth:`Placed.sdf`
(signed distance, negative inside) and :meth:`Placed.normal` (outward unit normal, the
distance's gradient). Primitives use their closed-form distance; a mesh, the cubic B-spline
of its distance sampled once on a grid (:mod:`softhand.reduced.holding.object_mesh`, points on
its longest edge) and its exact vertices at its edges and corners. Units: mm, rad.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from softhand.reduced.holding.object_mesh import grid_sdf, mesh_support, read_mesh
from softhand.reduced.holding.objects import GraspObject


def local_sdf(obj: GraspObject, p) -> np.ndarray:
    """Signed distance [mm] (negative inside) at points p (..., 3) in the object's own frame
    (centre at the origin, before rotation)."""
    p = np.asarray(p, float)
    if obj.shape == "sphere":
        return np.linalg.norm(p, axis=-1) - 0.5 * obj.diameter_mm
    if obj.shape == "box":
        q = np.abs(p) - 0.5 * np.asarray(obj.size_mm)
        return np.linalg.norm(np.maximum(q, 0.0), axis=-1) + np.minimum(np.max(q, axis=-1), 0.0)
    if obj.shape == "cylinder":
        d = np.stack([np.hypot(p[..., 0], p[..., 2]) - 0.5 * obj.diameter_mm,
                      np.abs(p[..., 1]) - 0.5 * obj.length_mm], axis=-1)
        return np.minimum(np.max(d, axis=-1), 0.0) + np.linalg.norm(np.maximum(d, 0.0), axis=-1)
    if obj.shape == "capsule":
        h = 0.5 * (obj.length_mm - obj.diameter_mm)
        axis = np.zeros_like(p)
        axis[..., 1] = np.clip(p[..., 1], -h, h)
        return np.linalg.norm(p - axis, axis=-1) - 0.5 * obj.diameter_mm
    mesh = read_mesh(obj.file)
    return grid_sdf(mesh, p)


#: depth differences below this [mm] are ties in :func:`support_point`
TIE_MM = 1e-7


def support_point(shape: str, size, u, ref) -> np.ndarray | None:
    """The object's point deepest along -u (the argmin of X . u over the body), rows (m, 3), in
    its own frame (centre at the origin, a cylinder's or capsule's axis along y; ``size`` as
    :func:`dimensions`); where that set is an edge or a face (u normal to it), its point nearest
    ``ref`` (m, 3). None for a mesh (:func:`~softhand.reduced.holding.object_mesh.mesh_support`, which
    :meth:`Placed.support` calls). A flat pad facing along u touches the object
    there when that point lies over the pad: an edge or corner against the pad's face."""
    u, ref = np.atleast_2d(np.asarray(u, float)), np.atleast_2d(np.asarray(ref, float))
    # a component of u is taken as 0 where moving across the whole object along it changes the
    # depth by less than TIE_MM: a tie (a direction's round-off must not pick a far corner)
    tiny = TIE_MM * np.linalg.norm(u, axis=1) / (float(np.max(size)) if len(size) else 1.0)
    if shape == "sphere":
        return -0.5 * size[0] * u / np.linalg.norm(u, axis=1)[:, None]
    if shape == "box":
        h = 0.5 * np.asarray(size, float)
        return np.where(np.abs(u) > tiny[:, None], -h * np.sign(u), np.clip(ref, -h, h))
    if shape not in ("cylinder", "capsule"):
        return None
    r = 0.5 * size[0]
    h = 0.5 * size[1] - (r if shape == "capsule" else 0.0)
    end = np.where(np.abs(u[:, 1]) > tiny, -h * np.sign(u[:, 1]), np.clip(ref[:, 1], -h, h))
    if shape == "capsule":  # the end sphere's centre on the axis, then the sphere's support
        return end[:, None] * np.array([0.0, 1.0, 0.0]) - r * u / np.linalg.norm(u, axis=1)[:, None]
    ur, rr = u * [1.0, 0.0, 1.0], ref * [1.0, 0.0, 1.0]
    nu, nr = np.linalg.norm(ur, axis=1)[:, None], np.linalg.norm(rr, axis=1)[:, None]
    radial = np.where(nu > tiny[:, None], -r * ur / np.where(nu > 0, nu, 1.0),
                      rr * np.minimum(1.0, r / np.where(nr > 0, nr, 1.0)))
    return radial + end[:, None] * np.array([0.0, 1.0, 0.0])


def over_pad(S, centre, along, across, normal, half_along, half_across):
    """Where the object's support points S (..., 3) against flat pads lie over them: the pads are
    rectangles (centres, unit axes along and across, unit normals towards the object, half sizes;
    all broadcast to S's leading shape). Returns (over, s, w, height): whether S is over its pad,
    its coordinates along and across from the centre, and its height along the normal (the
    pad's gap to the object there). The one rule by which a pad meets an edge or corner, in the
    fast hold and the FEM hold alike."""
    rel = np.asarray(S, float) - centre
    s, w = np.einsum("...i,...i->...", rel, along), np.einsum("...i,...i->...", rel, across)
    over = (np.abs(s) <= half_along) & (np.abs(w) <= half_across)
    return over, s, w, np.einsum("...i,...i->...", rel, normal)


def dimensions(obj: GraspObject) -> tuple:
    """A primitive's sizes as :func:`support_point` takes them: sphere (D,), cylinder and capsule
    (D, length), box (x, y, z edges) [mm]; () for a mesh."""
    return {"sphere": (obj.diameter_mm,), "box": tuple(obj.size_mm or ()),
            "cylinder": (obj.diameter_mm, obj.length_mm),
            "capsule": (obj.diameter_mm, obj.length_mm)}.get(obj.shape, ())


def size_radius(obj: GraspObject) -> float:
    """The object's radius as the holds measure a slide by it [mm]: half the diameter of a sphere
    or cylinder, else half the diagonal of its bounding box (a box's, a capsule's, a mesh's)."""
    if obj.shape in ("sphere", "cylinder"):
        return 0.5 * obj.diameter_mm
    lo, hi = local_extent(obj)
    return 0.5 * float(np.linalg.norm(hi - lo))


def local_extent(obj: GraspObject) -> tuple[np.ndarray, np.ndarray]:
    """(lowest, highest) corner (3,) of the object's bounding box in its own frame [mm]."""
    if obj.shape == "sphere":
        r = np.full(3, 0.5 * obj.diameter_mm)
    elif obj.shape == "box":
        r = 0.5 * np.asarray(obj.size_mm)
    elif obj.shape in ("cylinder", "capsule"):
        r = np.array([0.5 * obj.diameter_mm, 0.5 * obj.length_mm, 0.5 * obj.diameter_mm])
    else:
        v = read_mesh(obj.file).vertices
        return v.min(axis=0), v.max(axis=0)
    return -r, r


def surface(obj: GraspObject, *, resolution: int = 32) -> tuple[np.ndarray, np.ndarray]:
    """(points (m, 3), triangles (k, 3)) of the object's surface in its own frame [mm] (a
    primitive tessellated with ``resolution`` segments around)."""
    if obj.shape == "mesh":
        m = read_mesh(obj.file)
        return m.vertices, m.faces
    if obj.shape == "box":
        h = 0.5 * np.asarray(obj.size_mm)
        pts = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float) * h
        quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
        return pts, np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
    n = int(resolution)
    phi = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    r = 0.5 * obj.diameter_mm
    if obj.shape == "sphere":
        rows = [(r * math.sin(t), -r * math.cos(t)) for t in np.linspace(0, np.pi, n // 2 + 1)[1:-1]]
        caps = (-r, r)
    elif obj.shape == "cylinder":
        h = 0.5 * obj.length_mm
        rows, caps = [(r, -h), (r, h)], (-h, h)
    else:
        h = 0.5 * (obj.length_mm - obj.diameter_mm)
        arc = np.linspace(0, 0.5 * np.pi, n // 4 + 1)[1:]
        rows = [(r * math.sin(t), -h - r * math.cos(t)) for t in arc] + \
               [(r * math.cos(t), h + r * math.sin(t)) for t in arc[::-1][1:]] + [(r, h)]
        rows = sorted(set(rows), key=lambda x: x[1])
        caps = (-h - r, h + r)
    rad, y = np.asarray(rows, float).T                                   # rings: radius, height
    ring = np.stack([rad[:, None] * np.cos(phi), np.broadcast_to(y[:, None], (len(rows), n)),
                     rad[:, None] * np.sin(phi)], axis=-1).reshape(-1, 3)
    pts = np.vstack([[0.0, caps[0], 0.0], ring, [0.0, caps[1], 0.0]])
    j = np.arange(n)[:, None]
    k, a = (j + 1) % n, 1 + n * np.arange(len(rows) - 1)[None, :]         # a: each band's lower ring
    band = np.stack([np.stack([a + j, a + k, a + n + k], -1), np.stack([a + j, a + n + k, a + n + j], -1)], axis=2)
    last, base = len(pts) - 1, 1 + (len(rows) - 1) * n
    tris = np.concatenate([np.stack([np.zeros_like(j), 1 + k, 1 + j], -1), band.reshape(n, -1, 3),
                           np.stack([np.full_like(j, last), base + j, base + k], -1)], axis=1)
    return pts, tris.reshape(-1, 3)


@dataclass(frozen=True)
class Placed:
    """An object at its pose in the hand frame: centre (3,) [mm] and rotation R (object -> hand)."""

    obj: GraspObject
    centre: np.ndarray
    R: np.ndarray

    def to_local(self, p) -> np.ndarray:
        return (np.asarray(p, float) - self.centre) @ self.R

    def sdf(self, p) -> np.ndarray:
        """Signed distance [mm] at hand-frame points p (..., 3), negative inside."""
        return local_sdf(self.obj, self.to_local(p))

    def normal(self, p, *, step: float = 1e-4) -> np.ndarray:
        """Outward unit normal (..., 3): the distance's gradient (central differences, ``step`` mm;
        closed form for a sphere)."""
        q = self.to_local(p)
        if self.obj.shape == "sphere":
            g = q
        else:
            step = max(step, 0.25 * (read_mesh(self.obj.file).grid[0][1] - read_mesh(self.obj.file).grid[0][0])) \
                if self.obj.shape == "mesh" else step
            e = np.eye(3) * step
            g = np.stack([local_sdf(self.obj, q + e[i]) - local_sdf(self.obj, q - e[i]) for i in range(3)], axis=-1)
        g = g @ self.R.T
        return g / np.maximum(np.linalg.norm(g, axis=-1, keepdims=True), 1e-300)

    def support(self, u, ref) -> np.ndarray:
        """:func:`support_point` (a mesh's :func:`~softhand.reduced.holding.object_mesh.mesh_support`)
        in the hand frame: directions u and references ref (m, 3)."""
        u, ref = np.asarray(u) @ self.R, self.to_local(ref)
        if self.obj.shape == "mesh":
            mesh = read_mesh(self.obj.file)
            tie = TIE_MM * np.linalg.norm(np.atleast_2d(u), axis=1)
            local = mesh_support(mesh, u, ref, tie)
        else:
            local = support_point(self.obj.shape, dimensions(self.obj), u, ref)
        return self.centre + local @ self.R.T

    def box(self):
        """(centre (3,), axes (3, 3) as columns, half edges (3,)) in the hand frame [mm] of a box, or of
        a mesh that is one (:func:`~softhand.reduced.holding.box_contact.cuboid_of`); None otherwise."""
        if self.obj.shape == "box":
            return self.centre, self.R, 0.5 * np.asarray(self.obj.size_mm, float)
        cuboid = read_mesh(self.obj.file).cuboid if self.obj.shape == "mesh" else None
        if cuboid is None:
            return None
        half, A, c = cuboid
        return self.centre + self.R @ c, self.R @ A, half

    def surface(self, *, resolution: int = 32) -> tuple[np.ndarray, np.ndarray]:
        """The surface as (points (m, 3) in the hand frame [mm], triangles (k, 3))."""
        pts, tris = surface(self.obj, resolution=resolution)
        return self.centre + pts @ self.R.T, tris

    def top(self) -> float:
        """The object's highest point (least y) in the hand frame [mm] (its surface's vertices)."""
        pts, _ = self.surface(resolution=64)
        return float(np.min(pts[:, 1]))


def place(obj: GraspObject, centre) -> Placed:
    """The object with its centre at ``centre`` (3,) [mm] and its own rotation."""
    return Placed(obj, np.asarray(centre, float), obj.rotation)
