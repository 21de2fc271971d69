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
its circle, :func:`reduced.contact.object_depth`); then turned by ``rotation_deg = [rx, ry, rz]``
(about the hand frame's x, then y, then z, through the centre) and shifted by ``offset_mm``.
A table with only ``diameter_mm`` and ``mass_kg`` (the one-finger grasp's object) is a
**sphere**: its section by every finger's bending plane is the circle the one-finger models see.

Geometry queries are vectorised over points (..., 3) in the hand frame: :meth:`Placed.sdf`
(signed distance, negative inside) and :meth:`Placed.normal` (outward unit normal, the
distance's gradient). Primitives use their closed-form distance; a mesh, trilinear
interpolation of its distance sampled once on a grid (:data:`MESH_GRID` points on its longest
edge; error ~ the grid step squared over the surface's radius of curvature). Units: mm, kg, rad.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from .errors import InputError

SHAPES = ("sphere", "cylinder", "box", "capsule", "mesh")
#: keys of the ``[object]`` table
KEYS = ("shape", "diameter_mm", "length_mm", "size_mm", "file", "offset_mm", "rotation_deg",
        "mass_kg", "friction")
#: which dimensions each shape needs
NEEDS = {"sphere": ("diameter_mm",), "cylinder": ("diameter_mm", "length_mm"), "box": ("size_mm",),
         "capsule": ("diameter_mm", "length_mm"), "mesh": ("file",)}
#: mesh files read (trimesh's loaders)
MESH_SUFFIXES = (".stl", ".obj", ".ply")
#: default placement, as the one-finger grasp's (reduced.contact.PALM_GAP, CLEARANCE) [mm]
PALM_GAP, CLEARANCE = 10.0, 2.0
#: largest object dimension [mm], mass [kg], friction coefficient
UPPER = {"diameter_mm": 1000.0, "length_mm": 2000.0, "size_mm": 1000.0, "mass_kg": 100.0, "friction": 10.0,
         "offset_mm": 1000.0, "rotation_deg": 360.0}
#: grid points along a mesh's longest bounding-box edge for its distance field
MESH_GRID = 40
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
    from .inputfiles import read_toml

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


# ---------------------------------------------------------------------------------- meshes
@dataclass(frozen=True)
class MeshData:
    """A closed triangle mesh read and checked, its distance sampled on a grid (object frame:
    origin at its centre of mass)."""

    vertices: np.ndarray   #: (nv, 3) [mm], centred at the centre of mass
    faces: np.ndarray      #: (nf, 3) vertex indices, outward winding
    grid: tuple            #: (x, y, z) grid axes [mm]
    distance: np.ndarray   #: signed distance at the grid points, negative inside [mm]


@lru_cache(maxsize=8)
def read_mesh(path: str, field: str = "object.file") -> MeshData:
    """Read STL/OBJ/PLY with trimesh; InputError for a missing, open or self-intersecting mesh."""
    p = Path(path)
    if p.suffix.lower() not in MESH_SUFFIXES:
        raise InputError(field, path, f"must be a mesh file ending in {', '.join(MESH_SUFFIXES)}")
    if not p.is_file():
        raise InputError(field, path, "no such file")
    import trimesh  # only a mesh object needs it

    try:
        mesh = trimesh.load_mesh(str(p), process=True)
    except Exception as exc:  # noqa: BLE001 -- any reader failure is bad input
        raise InputError(field, path, f"is not a readable triangle mesh ({type(exc).__name__})") from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) < 4:
        raise InputError(field, path, "is not a single triangle mesh of at least 4 triangles")
    if not mesh.is_watertight:
        raise InputError(field, path, "is not closed (open edges or edges shared by more than two "
                                      "triangles); the object must be a closed surface")
    if not mesh.is_winding_consistent:
        raise InputError(field, path, "has inconsistently oriented triangles")
    if mesh.volume < 0:
        mesh.invert()
    if not mesh.volume > 0:
        raise InputError(field, path, "encloses no volume")
    pair = self_intersection(mesh.vertices, mesh.faces)
    if pair is not None:
        raise InputError(field, path, f"intersects itself (triangles {pair[0]} and {pair[1]})")
    vertices = np.asarray(mesh.vertices - mesh.center_mass, float)
    faces = np.asarray(mesh.faces, int)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    step = float(np.max(hi - lo)) / (MESH_GRID - 1)
    axes = tuple(np.arange(lo[i] - 3 * step, hi[i] + 3.5 * step, step) for i in range(3))
    points = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    distance = mesh_sdf(vertices, faces, points).reshape(tuple(len(a) for a in axes))
    return MeshData(vertices, faces, axes, distance)


#: triangles whose centroids are nearest a point, among which its closest triangle is sought
MESH_CANDIDATES = 24


def mesh_sdf(vertices, faces, points, *, block: int = 8192) -> np.ndarray:
    """Signed distance [mm] (negative inside) of points (m, 3) to a closed triangle mesh: exact
    point-triangle distances to the :data:`MESH_CANDIDATES` triangles of nearest centroid (a
    k-d tree), the sign from the closest triangle's face normal (among equally close ones, the
    one most aligned with the point's offset: the right side at edges and corners)."""
    from scipy.spatial import cKDTree

    V, F, P = np.asarray(vertices, float), np.asarray(faces, int), np.asarray(points, float)
    T = V[F]
    n = np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    k = min(MESH_CANDIDATES, len(F))
    tree = cKDTree(T.mean(axis=1))
    out = np.empty(len(P))
    for start in range(0, len(P), block):
        p = P[start:start + block]
        _, idx = tree.query(p, k=k)
        idx = idx.reshape(len(p), k)
        c = closest_on_triangles(p[:, None, :], T[idx])                 # (b, k, 3)
        off = p[:, None, :] - c
        dist = np.linalg.norm(off, axis=-1)
        best = dist.min(axis=1, keepdims=True)
        cos = np.einsum("bki,bki->bk", off, n[idx]) / np.maximum(dist, 1e-300)
        tie = dist <= best * (1 + 1e-9) + 1e-12
        j = np.argmax(np.where(tie, np.abs(cos), -1.0), axis=1)
        sign = np.sign(cos[np.arange(len(p)), j])
        out[start:start + block] = np.where(sign < 0, -1.0, 1.0) * best[:, 0]
    return out


def closest_on_triangles(p, T) -> np.ndarray:
    """The point of each triangle T (..., 3, 3) closest to p (..., 3) (Ericson's regions, vectorised)."""
    a, b, c = T[..., 0, :], T[..., 1, :], T[..., 2, :]
    ab, ac, ap = b - a, c - a, p - a
    dot = lambda u, v: np.einsum("...i,...i", u, v)  # noqa: E731
    d1, d2 = dot(ab, ap), dot(ac, ap)
    bp, cp = p - b, p - c
    d3, d4, d5, d6 = dot(ab, bp), dot(ac, bp), dot(ab, cp), dot(ac, cp)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    safe = lambda x: np.where(np.abs(x) > 1e-300, x, 1e-300)  # noqa: E731
    denom = safe(va + vb + vc)
    v, w = vb / denom, vc / denom
    out = a + v[..., None] * ab + w[..., None] * ac                          # inside the face
    e_bc = (d4 - d3) / safe((d4 - d3) + (d5 - d6))
    out = np.where(((va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0))[..., None], b + e_bc[..., None] * (c - b), out)
    e_ac = d2 / safe(d2 - d6)
    out = np.where(((vb <= 0) & (d2 >= 0) & (d6 <= 0))[..., None], a + e_ac[..., None] * ac, out)
    e_ab = d1 / safe(d1 - d3)
    out = np.where(((vc <= 0) & (d1 >= 0) & (d3 <= 0))[..., None], a + e_ab[..., None] * ab, out)
    out = np.where(((d6 >= 0) & (d5 <= d6))[..., None], c, out)
    out = np.where(((d3 >= 0) & (d4 <= d3))[..., None], b, out)
    out = np.where(((d1 <= 0) & (d2 <= 0))[..., None], a, out)
    return out


def self_intersection(vertices, faces):
    """A pair of triangles (i, j) that cross each other (sharing no vertex), or None: every edge
    tested (Moller-Trumbore) against the triangles whose centroid lies within reach of its
    midpoint (a k-d tree; reach = half the longest edge + the largest centroid-to-corner distance)."""
    from scipy.spatial import cKDTree

    V, F = np.asarray(vertices, float), np.asarray(faces, int)
    T = V[F]
    centroid = T.mean(axis=1)
    edges = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    owner = np.tile(np.arange(len(F)), 3)
    mid = 0.5 * (V[edges[:, 0]] + V[edges[:, 1]])
    reach = 0.5 * np.max(np.linalg.norm(V[edges[:, 1]] - V[edges[:, 0]], axis=1)) \
        + np.max(np.linalg.norm(T - centroid[:, None], axis=-1))
    near = cKDTree(centroid).query_ball_point(mid, reach)
    counts = np.fromiter((len(n) for n in near), int, len(near))
    ei = np.repeat(np.arange(len(edges)), counts)
    ti = np.fromiter((t for n in near for t in n), int, int(counts.sum()))
    shares = np.any(edges[ei][:, :, None] == F[ti][:, None, :], axis=(1, 2))
    ei, ti = ei[~shares], ti[~shares]
    O, D = V[edges[ei, 0]], V[edges[ei, 1]] - V[edges[ei, 0]]
    A, E1, E2 = T[ti, 0], T[ti, 1] - T[ti, 0], T[ti, 2] - T[ti, 0]
    h = np.cross(D, E2)
    det = np.einsum("ij,ij->i", E1, h)
    ok = np.abs(det) > 1e-12 * np.linalg.norm(E1, axis=1) * np.linalg.norm(E2, axis=1) * np.linalg.norm(D, axis=1)
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = O - A
    u = np.einsum("ij,ij->i", s, h) * inv
    q = np.cross(s, E1)
    v = np.einsum("ij,ij->i", D, q) * inv
    t = np.einsum("ij,ij->i", E2, q) * inv
    eps = 1e-9
    hit = ok & (u > eps) & (v > eps) & (u + v < 1 - eps) & (t > eps) & (t < 1 - eps)
    if np.any(hit):
        k = int(np.flatnonzero(hit)[0])
        return int(owner[ei[k]]), int(ti[k])
    return None


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
    return _trilinear(mesh, p)


def _trilinear(mesh: MeshData, p) -> np.ndarray:
    """The mesh's grid distance at p (..., 3), trilinear; outside the grid, plus the distance to it."""
    axes = mesh.grid
    lo = np.array([a[0] for a in axes])
    hi = np.array([a[-1] for a in axes])
    step = np.array([a[1] - a[0] for a in axes])
    inside = np.clip(p, lo, hi)
    outside = np.linalg.norm(p - inside, axis=-1)
    x = (inside - lo) / step
    shape = np.array(mesh.distance.shape)
    i = np.minimum(np.floor(x).astype(int), shape - 2)
    f = x - i
    D = mesh.distance
    out = np.zeros(p.shape[:-1])
    for corner in np.ndindex(2, 2, 2):  # the cell's eight corners
        c = np.asarray(corner)
        w = np.prod(np.where(c, f, 1.0 - f), axis=-1)
        out += w * D[i[..., 0] + c[0], i[..., 1] + c[1], i[..., 2] + c[2]]
    return out + outside


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
