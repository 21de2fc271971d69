r"""The object a hand holds: its shape, pose, mass and friction, and its geometry in the hand frame.

Shapes (each a rigid body of uniform density, its centre of mass at its centre):

* ``sphere``   -- ``diameter_mm``;
* ``cylinder`` -- ``diameter_mm``, ``length_mm``; axis along the hand frame's y (the palm's
  axis, vertical) before rotation: a bottle taken from above;
* ``box``      -- ``size_mm = [x, y, z]``, edges along the hand frame's axes before rotation;
* ``capsule``  -- ``diameter_mm``, ``length_mm`` (end to end, >= the diameter); axis along y;
* ``mesh``     -- ``file``: a closed triangle mesh (STL, OBJ, PLY; mm), read by trimesh; its
  centre is its centre of mass.

The hand frame (docs/conventions.md): origin on the palm's axis at the height of the finger
bases, y down along the palm's axis (gravity), x outward through finger 0, z = x cross y.
**Placement**: the object's centre on the palm's axis, its top ``PALM_GAP`` below the palm,
lowered until the open fingers' pads clear it by ``CLEARANCE`` (as the one-finger grasp places
its circle, :func:`softhand.reduced.equations.contact.object_depth`); then turned by ``rotation_deg = [rx, ry, rz]``
(about the hand frame's x, then y, then z, through the centre) and shifted by ``offset_mm``.
A table with only ``diameter_mm`` and ``mass_kg`` (the one-finger grasp's object) is a
**sphere**: its section by every finger's bending plane is the circle the one-finger models see.

Geometry queries are vectorised over points (..., 3) in the hand frame: :meth:`Placed.sdf`
(signed distance, negative inside) and :meth:`Placed.normal` (outward unit normal, the
distance's gradient). Primitives use their closed-form distance; a mesh, trilinear
interpolation of its distance sampled once on a grid (:mod:`softhand.reduced.holding.object_mesh`, points on its longest
edge; error ~ the grid step squared over the surface's radius of curvature). Units: mm, kg, rad.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.holding.object_mesh import MeshData, grid_sdf, mesh_features, mesh_sdf, read_mesh, self_intersection

__all__ = ["SHAPES", "KEYS", "GraspObject", "Placed", "MeshData", "check_object", "object_from_table",
           "object_from_short", "load_object", "parse_object", "read_mesh", "mesh_sdf", "self_intersection",
           "local_sdf", "local_extent", "surface", "feature_points", "place", "rotation_matrix"]

SHAPES = ("sphere", "cylinder", "box", "capsule", "mesh")
#: keys of the ``[object]`` table
KEYS = ("shape", "diameter_mm", "length_mm", "size_mm", "file", "offset_mm", "rotation_deg",
        "mass_kg", "friction")
#: which dimensions each shape needs
NEEDS = {"sphere": ("diameter_mm",), "cylinder": ("diameter_mm", "length_mm"), "box": ("size_mm",),
         "capsule": ("diameter_mm", "length_mm"), "mesh": ("file",)}
#: default placement, as the one-finger grasp's (reduced.contact.PALM_GAP, CLEARANCE) [mm]
PALM_GAP, CLEARANCE = 10.0, 2.0
#: largest object dimension [mm], mass [kg], friction coefficient
UPPER = {"diameter_mm": 1000.0, "length_mm": 2000.0, "size_mm": 1000.0, "mass_kg": 100.0, "friction": 10.0,
         "offset_mm": 1000.0, "rotation_deg": 360.0}
#: the friction coefficient when none is given
DEFAULT_FRICTION = 0.5


@dataclass(frozen=True)
class GraspObject:
    """A rigid object to hold: shape, dimensions [mm], pose from the default placement, mass, friction."""

    shape: str = "sphere"                        #: one of SHAPES
    diameter_mm: float = 0.0                     #: sphere, cylinder, capsule [mm]
    length_mm: float = 0.0                       #: cylinder, capsule (end to end) [mm]
    size_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)  #: box edges along x, y, z before rotation [mm]
    file: str = ""                               #: mesh file (absolute once read from a table)
    offset_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)  #: shift from the default placement [mm]
    rotation_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)  #: about x, then y, then z [deg]
    mass_kg: float = 0.0                         #: [kg]
    friction: float = DEFAULT_FRICTION           #: Coulomb coefficient against the pads

    def __post_init__(self):
        check_object(self)

    @property
    def rotation(self) -> np.ndarray:
        """3 x 3 rotation object frame -> hand frame (x, then y, then z, extrinsic)."""
        return rotation_matrix(self.rotation_deg)

    @property
    def axisymmetric_about_y(self) -> bool:
        """Whether the object, turned as posed, is symmetric about the palm's axis through its centre
        (every finger then sees it alike if it is centred: one finger is solved for all)."""
        upright = np.allclose(self.rotation[:, 1], [0.0, 1.0, 0.0], atol=1e-12) or \
            np.allclose(self.rotation[:, 1], [0.0, -1.0, 0.0], atol=1e-12)
        return self.shape == "sphere" or (self.shape in ("cylinder", "capsule") and upright)

    def to_dict(self) -> dict:
        """The ``[object]`` table's keys of this object (only those its shape uses)."""
        out = {"shape": self.shape}
        for key in NEEDS[self.shape]:
            value = getattr(self, key)
            out[key] = list(value) if isinstance(value, tuple) else value
        out.update(offset_mm=list(self.offset_mm), rotation_deg=list(self.rotation_deg),
                   mass_kg=self.mass_kg, friction=self.friction)
        return out

    def describe(self) -> str:
        """One line: shape and dimensions."""
        if self.shape == "sphere":
            return f"sphere {self.diameter_mm:g} mm"
        if self.shape in ("cylinder", "capsule"):
            return f"{self.shape} {self.diameter_mm:g} x {self.length_mm:g} mm"
        if self.shape == "box":
            return "box " + " x ".join(f"{v:g}" for v in self.size_mm) + " mm"
        return f"mesh {Path(self.file).name}"


def rotation_matrix(rotation_deg) -> np.ndarray:
    """R = Rz Ry Rx [-] from angles [deg] about the hand frame's x, y, z (applied in that order)."""
    rx, ry, rz = np.radians(np.asarray(rotation_deg, float))
    cx, sx, cy, sy, cz, sz = math.cos(rx), math.sin(rx), math.cos(ry), math.sin(ry), math.cos(rz), math.sin(rz)
    Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


# ---------------------------------------------------------------------------------- checks
def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def check_object(obj: GraspObject, source: str = "object") -> None:
    """InputError naming the first bad field of ``obj`` (before any computation)."""
    if obj.shape not in SHAPES:
        raise InputError(f"{source}.shape", obj.shape, f"must be one of {', '.join(SHAPES)}")
    for key in NEEDS[obj.shape]:
        value = getattr(obj, key)
        if key == "file":
            if not isinstance(value, str) or not value:
                raise InputError(f"{source}.file", value, "must name a mesh file (STL, OBJ or PLY)")
            continue
        values = value if isinstance(value, tuple) else (value,)
        if not all(_is_number(v) and 0.0 < v <= UPPER[key] for v in values):
            raise InputError(f"{source}.{key}", list(values) if isinstance(value, tuple) else value,
                             f"must be {'three numbers' if key == 'size_mm' else 'a number'} > 0 and "
                             f"<= {UPPER[key]:g} mm")
    if obj.shape == "capsule" and obj.length_mm < obj.diameter_mm:
        raise InputError(f"{source}.length_mm", obj.length_mm,
                         f"must be >= the diameter_mm = {obj.diameter_mm:g} (a capsule's length is end to end)")
    for key in ("offset_mm", "rotation_deg"):
        value = getattr(obj, key)
        if len(value) != 3 or not all(_is_number(v) and abs(v) <= UPPER[key] for v in value):
            raise InputError(f"{source}.{key}", list(value), f"must be three numbers within +-{UPPER[key]:g}")
    if not (_is_number(obj.mass_kg) and 0.0 <= obj.mass_kg <= UPPER["mass_kg"]):
        raise InputError(f"{source}.mass_kg", obj.mass_kg, f"must be a number >= 0 and <= {UPPER['mass_kg']:g} kg")
    if not (_is_number(obj.friction) and 0.0 <= obj.friction <= UPPER["friction"]):
        raise InputError(f"{source}.friction", obj.friction,
                         f"must be a Coulomb coefficient >= 0 and <= {UPPER['friction']:g}")


def object_from_table(table, *, source: str = "object", base_dir: str | Path = ".") -> GraspObject:
    """A :class:`GraspObject` from an ``[object]`` table (keys :data:`KEYS`); ``file`` is resolved
    next to the TOML file (``base_dir``) and the mesh read and checked now."""
    if not isinstance(table, dict):
        raise InputError(source, table, "must be a table ([object])")
    for key in table:
        if key not in KEYS:
            raise InputError(f"{source}.{key}", table[key], f"unknown key; allowed: {', '.join(KEYS)}")
    shape = table.get("shape")
    if shape is None:
        if set(table) - {"diameter_mm", "mass_kg", "friction", "offset_mm", "rotation_deg"}:
            raise InputError(f"{source}.shape", None, f"is required with these keys; one of {', '.join(SHAPES)}")
        shape = "sphere"  # today's object: diameter and mass
    if shape not in SHAPES:
        raise InputError(f"{source}.shape", shape, f"must be one of {', '.join(SHAPES)}")
    for key in table:
        if key in ("diameter_mm", "length_mm", "size_mm", "file") and key not in NEEDS[shape]:
            raise InputError(f"{source}.{key}", table[key], f"is not a dimension of a {shape}; "
                             f"a {shape} takes {', '.join(NEEDS[shape])}")
    for key in NEEDS[shape]:
        if key not in table:
            raise InputError(f"{source}.{key}", None, f"is required for a {shape}")
    values = {"shape": shape}
    for key in ("diameter_mm", "length_mm", "mass_kg", "friction"):
        if key in table:
            if not _is_number(table[key]):
                raise InputError(f"{source}.{key}", table[key], "must be a number")
            values[key] = float(table[key])
    for key in ("size_mm", "offset_mm", "rotation_deg"):
        if key in table:
            value = table[key]
            if not (isinstance(value, list) and len(value) == 3 and all(_is_number(v) for v in value)):
                raise InputError(f"{source}.{key}", value, "must be a list of three numbers [x, y, z]")
            values[key] = tuple(float(v) for v in value)
    if shape == "mesh":
        file = table["file"]
        if not isinstance(file, str) or not file:
            raise InputError(f"{source}.file", file, "must name a mesh file (STL, OBJ or PLY)")
        path = Path(file) if Path(file).is_absolute() else Path(base_dir) / file
        values["file"] = str(Path(path).resolve())
        read_mesh(values["file"], f"{source}.file")  # bad meshes are refused here
    try:
        return GraspObject(**values)
    except InputError as exc:
        raise exc.renamed(exc.field.replace("object", source, 1)) from None


_SHORT = re.compile(r"(sphere|cylinder|box|capsule):([0-9.eE+-]+(?:x[0-9.eE+-]+)*)")
#: short forms: shape -> (keys the numbers fill)
SHORT_FORMS = {"sphere": "sphere:D", "cylinder": "cylinder:DxL", "box": "box:XxYxZ", "capsule": "capsule:DxL"}


def object_from_short(text: str, *, field: str = "--object", **keys) -> GraspObject:
    """``sphere:150``, ``cylinder:120x200`` (diameter x length), ``box:80x60x100``, ``capsule:60x150``
    [mm], with ``keys`` (mass_kg, friction, ...) over the defaults."""
    m = _SHORT.fullmatch(text.strip())
    allowed = f"a TOML file with an [object] table, or {', '.join(SHORT_FORMS.values())} (mm)"
    if m is None:
        raise InputError(field, text, f"must be {allowed}")
    shape, numbers = m.group(1), m.group(2).split("x")
    try:
        values = [float(v) for v in numbers]
    except ValueError:
        raise InputError(field, text, f"must be {allowed}") from None
    count = {"sphere": 1, "cylinder": 2, "box": 3, "capsule": 2}[shape]
    if len(values) != count:
        raise InputError(field, text, f"a {shape} takes {SHORT_FORMS[shape]}")
    dims = {"sphere": lambda v: {"diameter_mm": v[0]}, "box": lambda v: {"size_mm": tuple(v)},
            "cylinder": lambda v: {"diameter_mm": v[0], "length_mm": v[1]},
            "capsule": lambda v: {"diameter_mm": v[0], "length_mm": v[1]}}[shape](values)
    try:
        return GraspObject(shape=shape, **dims, **keys)
    except InputError as exc:
        raise InputError(field, text, str(exc)) from None


def load_object(path: str | Path, *, field: str = "--object") -> GraspObject:
    """The ``[object]`` table of a TOML file (a mesh's file resolved next to it)."""
    from softhand.reduced.vocabulary.inputfiles import read_toml

    path = Path(path)
    data = read_toml(path, field, "a TOML file with an [object] table")
    if "object" not in data:
        raise InputError(field, str(path), "has no [object] table")
    return object_from_table(data["object"], source=f"{path.name}: object", base_dir=path.parent)


def parse_object(text: str, *, field: str = "--object") -> GraspObject:
    """A short form (:func:`object_from_short`) or a TOML file's ``[object]`` table."""
    if _SHORT.fullmatch(text.strip()) or (":" in text and not Path(text).exists()
                                          and text.split(":")[0] in SHORT_FORMS):
        return object_from_short(text, field=field)
    return load_object(text, field=field)


# ---------------------------------------------------------------------------------- geometry
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
    pts = [[0.0, caps[0], 0.0]]
    for rad, y in rows:
        pts += [[rad * math.cos(a), y, rad * math.sin(a)] for a in phi]
    pts.append([0.0, caps[1], 0.0])
    tris, last = [], len(pts) - 1
    for j in range(n):
        k = (j + 1) % n
        tris.append((0, 1 + k, 1 + j))
        for row in range(len(rows) - 1):
            a, b = 1 + row * n, 1 + (row + 1) * n
            tris += [(a + j, a + k, b + k), (a + j, b + k, b + j)]
        base = 1 + (len(rows) - 1) * n
        tris.append((last, base + j, base + k))
    return np.asarray(pts), np.asarray(tris)


#: points along each box edge and around each cylinder rim among an object's features
FEATURE_POINTS = 65


def feature_points(obj: GraspObject) -> np.ndarray:
    """Points (m, 3) of the object's edges and corners in its own frame [mm] (a box's edges, a
    cylinder's rims, a mesh's vertices where its surface folds by more than 20 deg; none for the
    smooth sphere and capsule): where a flat pad may touch it at a point its distance is not smooth."""
    if obj.shape == "box":
        h = 0.5 * np.asarray(obj.size_mm)
        t = np.linspace(-1.0, 1.0, FEATURE_POINTS)
        out = []
        for axis in range(3):
            others = [i for i in range(3) if i != axis]
            for sa in (-1.0, 1.0):
                for sb in (-1.0, 1.0):
                    p = np.zeros((len(t), 3))
                    p[:, axis] = t * h[axis]
                    p[:, others[0]], p[:, others[1]] = sa * h[others[0]], sb * h[others[1]]
                    out.append(p)
        return np.vstack(out)
    if obj.shape == "cylinder":
        a = np.linspace(0.0, 2.0 * np.pi, 2 * FEATURE_POINTS, endpoint=False)
        r, h = 0.5 * obj.diameter_mm, 0.5 * obj.length_mm
        return np.vstack([np.stack([r * np.cos(a), np.full_like(a, y), r * np.sin(a)], -1) for y in (-h, h)])
    if obj.shape == "mesh":
        return mesh_features(obj.file)
    return np.zeros((0, 3))


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

    def features(self) -> np.ndarray:
        """:func:`feature_points` in the hand frame (m, 3) [mm]."""
        return self.centre + feature_points(self.obj) @ self.R.T

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
