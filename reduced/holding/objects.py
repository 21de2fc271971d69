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

Here the object as given (checked, and read from a table, a short form or a TOML file); its
geometry and the object placed in the hand frame: :mod:`softhand.reduced.holding.object_geometry`.
Units: mm, kg, rad.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.holding.object_mesh import read_mesh

__all__ = ["SHAPES", "KEYS", "GraspObject", "check_object", "object_from_table", "object_from_short",
           "load_object", "parse_object", "rotation_matrix"]

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
#: the smallest dimension of a primitive [mm] (an object is given in mm: a smaller one is a unit slip)
SMALLEST_MM = 1.0
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
        if not all(_is_number(v) and SMALLEST_MM <= v <= UPPER[key] for v in values):
            raise InputError(f"{source}.{key}", list(values) if isinstance(value, tuple) else value,
                             f"must be {'three numbers' if key == 'size_mm' else 'a number'} >= {SMALLEST_MM:g} and "
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
    other = sorted(k for k in data if k != "object")
    if other:  # e.g. a design task's [hold]: not silently ignored
        raise InputError(field, str(path), f"holds {', '.join(other)} besides [object]; an object file holds "
                                           "the [object] table alone (a hold's margin and pull are options)")
    return object_from_table(data["object"], source=f"{path.name}: object", base_dir=path.parent)


def parse_object(text: str, *, field: str = "--object") -> GraspObject:
    """A short form (:func:`object_from_short`) or a TOML file's ``[object]`` table."""
    if _SHORT.fullmatch(text.strip()) or (":" in text and not Path(text).exists()
                                          and text.split(":")[0] in SHORT_FORMS):
        return object_from_short(text, field=field)
    return load_object(text, field=field)
