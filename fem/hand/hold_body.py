r"""The rigid object of a hold as the FEM sees it: signed distance and outward normal in its
placed pose, its centre of mass, mass, friction and surface triangles.

:class:`Body` wraps the analytic primitives here (sphere, cylinder of any axis, box); any
object with the same methods (``signed_distance(points) -> (d, normals)``, ``centre``,
``mass_kg``, ``friction``, ``surface() -> (points, triangles)``) can be held; one that also has
``support(directions, references) -> points`` (or None) meets pads with its edges and corners
through the pads' own normal (:func:`softhand.fem.hand.hold_geometry.pad_contacts`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from softhand.reduced.holding.cylinder_contact import cylinder_distance, cylinder_frame
from softhand.reduced.holding.object_geometry import support_point
from softhand.reduced.vocabulary.errors import InputError

SHAPES = ("sphere", "cylinder", "box")


@dataclass(frozen=True)
class Body:
    """A placed rigid primitive (hand frame, mm, kg)."""

    shape: str                      #: "sphere", "cylinder" or "box"
    centre: tuple                   #: centre (= centre of mass) in its placed pose [mm]
    size: tuple                     #: sphere (D,), cylinder (D, length), box (x, y, z edges) [mm]
    axis: tuple = (0.0, 0.0, 1.0)   #: cylinder axis (unit, hand frame)
    mass_kg: float = 0.0
    friction: float = 0.0           #: Coulomb coefficient against the pads
    frame: tuple | None = None      #: a box's rotation, its frame -> hand frame (3 x 3 rows); None: none

    def __post_init__(self):
        if self.shape not in SHAPES:
            raise InputError("shape", self.shape, f"must be one of {', '.join(SHAPES)}")
        if not all(s > 0 for s in self.size):
            raise InputError("size_mm", self.size, "must be positive")
        if not self.friction >= 0:
            raise InputError("friction", self.friction, "must be >= 0")
        if not self.mass_kg >= 0:
            raise InputError("mass_kg", self.mass_kg, "must be >= 0")
        a = np.asarray(self.axis, dtype=float)
        object.__setattr__(self, "axis", tuple(a / np.linalg.norm(a)))

    @property
    def frame_matrix(self) -> np.ndarray:
        """A box's rotation (3, 3): its own frame -> hand frame (its edges' directions as columns)."""
        return np.eye(3) if self.frame is None else np.asarray(self.frame, dtype=float)

    @property
    def radius(self) -> float:
        """Half the diameter (sphere, cylinder) or the half diagonal of the box [mm]."""
        if self.shape == "box":
            return 0.5 * float(np.linalg.norm(self.size))
        return 0.5 * self.size[0]

    def signed_distance(self, x):
        """(d (m,), n (m, 3)): signed distance [mm] (negative inside) and outward unit normal."""
        r = np.atleast_2d(np.asarray(x, dtype=float)) - np.asarray(self.centre)
        if self.shape == "sphere":
            rho = np.linalg.norm(r, axis=1)
            return rho - 0.5 * self.size[0], r / np.where(rho > 0, rho, 1.0)[:, None]
        if self.shape == "cylinder":
            return cylinder_distance(r, np.asarray(self.axis), 0.5 * self.size[0], 0.5 * self.size[1])
        F = self.frame_matrix
        d, n = _box(r @ F, 0.5 * np.asarray(self.size, dtype=float))
        return d, n @ F.T

    def support(self, u, ref):
        """The body's points deepest along -u (m, 3), those nearest ref where that is an edge or
        a face (:func:`softhand.reduced.holding.object_geometry.support_point`), placed pose."""
        c = np.asarray(self.centre)
        F = cylinder_frame(np.asarray(self.axis)) if self.shape == "cylinder" else self.frame_matrix
        local = support_point(self.shape, self.size, np.asarray(u) @ F, (np.asarray(ref) - c) @ F)
        return c + local @ F.T

    def surface(self, n: int = 48):
        """(points (m, 3), triangles (k, 3)) of the surface in its placed pose."""
        if self.shape == "sphere":
            return _sphere_surface(np.asarray(self.centre), 0.5 * self.size[0], n)
        if self.shape == "cylinder":
            return _cylinder_surface(np.asarray(self.centre), np.asarray(self.axis),
                                     0.5 * self.size[0], self.size[1], n)
        return _box_surface(np.asarray(self.centre), 0.5 * np.asarray(self.size, dtype=float), self.frame_matrix)


def _box(r, h):
    q = np.abs(r) - h
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
    inside = np.minimum(q.max(axis=1), 0.0)
    d = outside + inside
    n_out = np.sign(r) * np.maximum(q, 0.0) / np.where(outside > 0, outside, 1.0)[:, None]
    face = np.argmax(q, axis=1)
    n_in = np.zeros_like(r)
    n_in[np.arange(len(r)), face] = np.sign(r[np.arange(len(r)), face])
    return d, np.where((outside > 0)[:, None], n_out, n_in)


def _sphere_surface(c, R, n):
    t = np.linspace(0.0, math.pi, n // 2 + 1)
    p = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    T, Pp = np.meshgrid(t, p, indexing="ij")
    pts = np.stack([np.sin(T) * np.cos(Pp), np.cos(T), np.sin(T) * np.sin(Pp)], -1).reshape(-1, 3)
    return c + R * pts, _grid_triangles(len(t), n)


def _cylinder_surface(c, e, R, length, n):
    u = cylinder_frame(e)[:, 0]
    v = np.cross(e, u)
    p = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    ring = R * (np.cos(p)[:, None] * u + np.sin(p)[:, None] * v)
    rows = [c - 0.5 * length * e + 0 * ring, c - 0.5 * length * e + ring,
            c + 0.5 * length * e + ring, c + 0.5 * length * e + 0 * ring]
    return np.concatenate(rows), _grid_triangles(4, n)


def _box_surface(c, h, F):
    corners = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], dtype=float)
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = [[a, b, c_] for a, b, c_, d in faces] + [[a, c_, d] for a, b, c_, d in faces]
    return c + (corners * h) @ F.T, np.array(tris)


def _grid_triangles(rows: int, n: int) -> np.ndarray:
    """Triangles of a (rows x n) grid periodic in its second index."""
    i, j = np.meshgrid(np.arange(rows - 1), np.arange(n), indexing="ij")
    a, b = i * n + j, i * n + (j + 1) % n
    c, d = a + n, b + n
    return np.concatenate([np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)])


@dataclass(frozen=True)
class PlacedBody:
    """Any placed object of :mod:`softhand.reduced.holding.objects` (capsule, mesh) through its own
    distance queries (its normal by central differences)."""

    placed: object
    mass_kg: float
    friction: float
    radius: float

    @property
    def centre(self):
        return tuple(self.placed.centre)

    def signed_distance(self, x):
        x = np.atleast_2d(np.asarray(x, dtype=float))
        return self.placed.sdf(x), self.placed.normal(x)

    def support(self, u, ref):
        """As :meth:`Body.support` (a mesh: its extreme vertex where that is an edge or corner, else NaN)."""
        return self.placed.support(u, ref)

    def surface(self, n: int = 48):
        return self.placed.surface(resolution=n // 2)


def body_of(obj, design):
    """The FEM's body for a :class:`softhand.reduced.holding.objects.GraspObject` at its placement (checked:
    InputError if it overlaps the open fingers or the palm): analytic for a sphere, a cylinder
    and a box (and a mesh that is a box), else the object's own distance queries."""
    from softhand.reduced.holding.hand_layout import place_object
    from softhand.reduced.holding.object_geometry import size_radius

    placed = place_object(obj, design)
    centre = tuple(float(c) for c in placed.centre)
    common = dict(mass_kg=float(obj.mass_kg), friction=float(obj.friction))
    if obj.shape == "sphere":
        return Body("sphere", centre, (obj.diameter_mm,), **common)
    if obj.shape == "cylinder":
        return Body("cylinder", centre, (obj.diameter_mm, obj.length_mm),
                    axis=tuple(placed.R @ [0.0, 1.0, 0.0]), **common)
    if obj.shape == "box":
        frame = tuple(map(tuple, placed.R)) if any(obj.rotation_deg) else None
        return Body("box", centre, tuple(obj.size_mm), frame=frame, **common)
    box = placed.box()  # a mesh that is a box meets the pads as the box does
    if box is not None:
        return Body("box", tuple(float(c) for c in box[0]), tuple(float(2.0 * h) for h in box[2]),
                    frame=tuple(tuple(float(v) for v in row) for row in box[1]),
                    **common)
    return PlacedBody(placed, radius=size_radius(obj), **common)
