"""The hand design: Table I of the paper plus what the paper leaves out.

One frozen, validated :class:`HandDesign` is the vocabulary shared by every layer.
Inside the code: mm, N, MPa, s, radians. In TOML files every key carries its unit
(``l0_mm``, ``theta0_deg``, ``V0_mm3``, ``mu_sf_MPa``); those keys are the public
parameter names (CLI ``--params``, study overrides).

Ambiguities of the paper resolved here (see ``docs/conventions.md``):

* ``a`` is the tube's inner **radius** although Table I says "internal diameter":
  eqs. (2) and (8) use it as a radius.
* ``t`` is the reservoir sheet thickness (Table I reuses ``w``, the weight vector's name).
* Hinge positions, the finger base placement and g are not in the paper; they are
  explicit parameters with documented defaults.

Rubber. The paper's rubber is Neo-Hookean with the shear moduli ``mu_sf_MPa`` (finger)
and ``mu_sr_MPa`` (reservoir sheet). A design file may give another strain energy per
part (:mod:`reduced.rubber`) as a table::

    [finger.material]
    model = "yeoh"            # neo-hookean | mooney-rivlin | yeoh | gent | ogden
    C10_MPa = 0.18
    C20_MPa = -1.4e-3
    C30_MPa = 4.0e-5

    [reservoir.material]
    model = "mooney-rivlin"
    C10_MPa = 0.5
    C01_MPa = 0.075

The parameter names are those of ``softhand material fit``. With a material table,
``mu_sf_MPa`` / ``mu_sr_MPa`` become that material's initial shear modulus (computed; a
value in the same file that disagrees is overridden, with a warning), and setting them
later (``softhand fit --params mu_sf_MPa``, a study sweep) scales every modulus of the
material, keeping the shape of W.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import os
import warnings
from dataclasses import dataclass
from pathlib import Path

from . import rubber
from .design_rules import BOUNDS, CONSISTENCY, _check_model, _in_bounds, _is_number
from .errors import InputError
from .inputfiles import MAX_FILE_BYTES, read_input_file, read_toml

__all__ = ["RESERVOIR_MODELS", "FINGER_MODELS", "PAPER_DESIGN_FILE", "HandDesign", "PUBLIC_KEYS",
           "PARTS", "BOUNDS", "CONSISTENCY", "design_from_dict", "hinges_for", "MAX_FILE_BYTES",
           "read_input_file", "read_toml", "load_design"]

#: Reservoir models the reduced layer knows; extended when a new one is added.
RESERVOIR_MODELS = ("ellipse", "fem")
#: Finger models the reduced layer knows: the paper's eqs. (2), (5), (10), or FEM-calibrated.
FINGER_MODELS = ("paper", "fem")

PAPER_DESIGN_FILE = Path(__file__).resolve().parent.parent / "studies" / "designs" / "paper.toml"


@dataclass(frozen=True)
class HandDesign:
    """A hydraulic soft hand: fingers (Table I), reservoir sheet, kinematics.

    Construct with keywords; :meth:`validate` runs in ``__post_init__``.
    """

    theta0: float = math.radians(20.0)  #: inclination of the finger's base link [rad]
    l0: float = 180.0  #: initial length of the finger tube [mm]
    a: float = 4.0  #: inner radius of the tube [mm]; Table I says 'diameter', eqs. (2), (8) use a radius
    b: float = 5.0  #: wall thickness of the tube [mm] (outer radius a + b)
    d: float = 15.0  #: distance from the tube axis to the hinge plate [mm]
    R: float = 24.0  #: radius of the reservoir sheet [mm]
    t: float = 1.0  #: thickness of the reservoir sheet [mm] (Table I: 'w')
    V0: float = 1.78e4  #: initial oil volume in the reservoir [mm^3]
    n: int = 4  #: number of fingers
    n_s: int = 5  #: number of hinge joints in a finger
    mu_sf: float = 1.15  #: initial shear modulus of the finger tube [MPa]
    mu_sr: float = 1.15  #: initial shear modulus of the reservoir sheet [MPa]
    #: hinge positions along the undeformed hinge plate, from the finger base [mm];
    #: n_s values, strictly increasing in (0, l0). Not in the paper: equal links by default.
    hinge_s: tuple[float, ...] = (30.0, 60.0, 90.0, 120.0, 150.0)
    #: horizontal distance from the hand centre to the finger base on the hinge plate [mm];
    #: not in the paper
    base_offset: float = 60.0
    g: float = 9.80665  #: gravitational acceleration [N/kg]
    reservoir_model: str = "ellipse"  #: reduced reservoir model, one of RESERVOIR_MODELS
    #: finger rubber's strain energy (its shape; scaled to mu_sf); None: Neo-Hookean
    finger_material: rubber.Rubber | None = None
    #: reservoir sheet's strain energy (its shape; scaled to mu_sr); None: Neo-Hookean
    reservoir_material: rubber.Rubber | None = None
    finger_model: str = "paper"  #: reduced finger model (W_f, Q), one of FINGER_MODELS
    #: width of the ring by which each link holds the tube, centred on the link [mm];
    #: not in the paper. The finger FEM ties these rings; finger_model "fem" is calibrated on it
    tie_width: float = 10.0
    #: calibration table of finger_model "fem" (a CSV file); "" = the one in the package
    finger_table: str = ""
    #: the hand's layout: each finger's azimuth about the palm's axis, finger 0 first [rad];
    #: () = n fingers evenly spaced from 0 (the paper's four at 0, 90, 180, 270 deg). Not in the paper
    finger_azimuths: tuple[float, ...] = ()
    #: width of each link's pad across the finger [mm]; 0 = the tube's outer diameter 2 (a + b)
    pad_width: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "hinge_s", tuple(float(s) for s in self.hinge_s))
        object.__setattr__(self, "finger_azimuths", tuple(float(s) for s in self.finger_azimuths))
        self.validate()

    # ------------------------------------------------------------------ validation
    def validate(self) -> None:
        """Raise :class:`InputError` naming the first bad field (bounds: :data:`BOUNDS`)."""
        for name, key in _KEY_OF.items():
            if key in BOUNDS:
                _in_bounds(key, _to_public(name, getattr(self, name)))
        for name in ("n", "n_s"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int):
                raise InputError(name, value, "must be a whole number")
        if len(self.hinge_s) != self.n_s:
            raise InputError("hinge_s_mm", list(self.hinge_s),
                             f"must have n_s = {self.n_s} values")
        s = (0.0, *self.hinge_s, self.l0)
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in s) \
                or any(not s1 > s0 for s0, s1 in zip(s, s[1:])):  # nan compares false both ways
            raise InputError("hinge_s_mm", list(self.hinge_s),
                             f"must be finite and increase strictly within (0, l0 = {self.l0:g}) mm")
        _check_layout(self)
        for check in CONSISTENCY:
            check(self)
        _check_model("reservoir_model", self.reservoir_model, RESERVOIR_MODELS,
                     self.reservoir_is_neo_hookean, "reservoir", "sheet", self.reservoir_material,
                     "ellipse")
        _check_model("finger_model", self.finger_model, FINGER_MODELS, self.finger_is_neo_hookean,
                     "finger", "tube", self.finger_material, "paper")

    def check_volume(self, theta_max: float) -> None:
        """Raise if V0 cannot supply the oil the fingers take at bend ``theta_max`` [rad] (eq. (15))."""
        from .finger import oil_taken  # the finger model's Q(theta) - Q(0); finger imports design

        needed = self.n * float(oil_taken(theta_max, self))
        if needed >= self.V0:
            raise InputError("V0_mm3", self.V0,
                             f"must exceed the {needed:.0f} mm^3 the fingers take at "
                             f"{math.degrees(theta_max):.1f} deg")

    # ------------------------------------------------------------------ derived
    @property
    def finger_rubber(self) -> rubber.Rubber:
        """The finger tube's strain energy, with initial shear modulus mu_sf."""
        return _scaled(self.finger_material, self.mu_sf)

    @property
    def reservoir_rubber(self) -> rubber.Rubber:
        """The reservoir sheet's strain energy, with initial shear modulus mu_sr."""
        return _scaled(self.reservoir_material, self.mu_sr)

    @property
    def finger_is_neo_hookean(self) -> bool:
        """True if the finger rubber is Neo-Hookean (the paper's eqs. (5), (9), (10))."""
        return _is_neo_hookean(self.finger_material)

    @property
    def reservoir_is_neo_hookean(self) -> bool:
        """True if the reservoir sheet is Neo-Hookean (the paper's eqs. (11), (17), (18))."""
        return _is_neo_hookean(self.reservoir_material)

    @property
    def link_lengths(self) -> tuple[float, ...]:
        """Lengths of the n_s + 1 rigid links along the hinge plate, base link first [mm]."""
        s = (0.0, *self.hinge_s, self.l0)
        return tuple(s1 - s0 for s0, s1 in zip(s, s[1:]))

    def replace(self, **changes) -> "HandDesign":
        """A copy with some fields changed (internal units), validated."""
        return dataclasses.replace(self, **changes)

    # ------------------------------------------------------------------ I/O
    def to_dict(self) -> dict:
        """Public (unit-suffixed) keys -> values, as in a design TOML file; a part with a
        material table adds ``{"finger": {"material": {"model": ..., parameters}}}``."""
        out = {key: _to_public(name, getattr(self, name)) for name, key in _KEY_OF.items()
               if not (name in _OMITTED_AT_DEFAULT and getattr(self, name) == _default(name))}
        for part in PARTS:
            if getattr(self, f"{part}_material") is not None:
                material = getattr(self, f"{part}_rubber")
                out[part] = {"material": {"model": material.model, **material.parameters()}}
        return out

    def to_toml(self) -> str:
        """The design as a TOML document that :func:`load_design` reads back."""
        lines = ["# softhand hand design; units in the key names"]
        tables = []
        for key, value in self.to_dict().items():
            if key in PARTS:
                tables += ["", f"[{key}.material]"] + [f"{k} = {json.dumps(v)}"
                                                      for k, v in value["material"].items()]
            else:
                lines.append(f"{key} = {json.dumps(value)}")
        return "\n".join(lines + tables) + "\n"

    def hash(self) -> str:
        """Short stable hash of the design's values (provenance, cache keys)."""
        text = json.dumps(self.to_dict(), sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


#: dataclass field -> public TOML key (with unit)
_KEY_OF = {
    "theta0": "theta0_deg", "l0": "l0_mm", "a": "a_mm", "b": "b_mm", "d": "d_mm",
    "R": "R_mm", "t": "t_mm", "V0": "V0_mm3", "n": "n", "n_s": "n_s",
    "mu_sf": "mu_sf_MPa", "mu_sr": "mu_sr_MPa", "hinge_s": "hinge_s_mm",
    "base_offset": "base_offset_mm", "g": "g_N_per_kg", "reservoir_model": "reservoir_model",
    "finger_model": "finger_model", "tie_width": "tie_width_mm", "finger_table": "finger_table",
    "finger_azimuths": "finger_azimuths_deg", "pad_width": "pad_width_mm",
}
#: the hand layout's fields: written only when set, so that every design's hash stays what it was
_OMITTED_AT_DEFAULT = ("finger_azimuths", "pad_width")


def _default(name: str):
    return HandDesign.__dataclass_fields__[name].default


def _check_layout(design: "HandDesign") -> None:
    """The hand layout's fields: n distinct finite azimuths (or none), a pad width >= 0."""
    az = design.finger_azimuths
    if az:
        turns = sorted(a % (2.0 * math.pi) for a in az) if all(math.isfinite(a) for a in az) else None
        if len(az) != design.n or turns is None or any(b - a < 1e-9 for a, b in zip(turns, turns[1:])) \
                or (len(turns) > 1 and turns[0] + 2.0 * math.pi - turns[-1] < 1e-9):
            raise InputError("finger_azimuths_deg", [round(math.degrees(a), 9) for a in az],
                             f"must be n = {design.n} distinct finite angles [deg] (or left out: evenly spaced)")
    if not (isinstance(design.pad_width, (int, float)) and math.isfinite(design.pad_width)
            and 0.0 <= design.pad_width <= 1000.0):
        raise InputError("pad_width_mm", design.pad_width, "must be a number in [0, 1000] mm "
                                                           "(0: the tube's outer diameter)")
_FIELD_OF = {key: name for name, key in _KEY_OF.items()}
PUBLIC_KEYS = tuple(_KEY_OF.values())
#: parts that may carry a ``[<part>.material]`` table, and the modulus key it sets
PARTS = ("finger", "reservoir")
_MODULUS_OF = {"finger": "mu_sf", "reservoir": "mu_sr"}


def _scaled(material, mu0: float) -> rubber.Rubber:
    if material is None:
        return rubber.NeoHookean(mu0)
    return material if material.mu0 == mu0 else material.scaled(mu0 / material.mu0)


def _is_neo_hookean(material) -> bool:
    return material is None or isinstance(material, rubber.NeoHookean)


def _material_changes(part: str, table, source: str, values: dict) -> dict:
    """Changes of the design fields from a ``[<part>.material]`` table."""
    if not isinstance(table, dict) or set(table) != {"material"} or not isinstance(table["material"], dict):
        raise InputError(f"{source}: {part}", table, f"must hold only a [{part}.material] table")
    params = dict(table["material"])
    model = params.pop("model", None)
    if not isinstance(model, str):
        raise InputError(f"{source}: {part}.material.model", model,
                         f"must be one of {', '.join(rubber.MODELS)}")
    material = rubber.from_parameters(model, params, source=f"{source}: {part}.material")
    name = _MODULUS_OF[part]
    given = values.get(_KEY_OF[name])
    if given is not None:  # overridden, but still a value of the file: a bad one is bad input
        try:
            _in_bounds(_KEY_OF[name], given)
        except InputError as exc:
            raise exc.renamed(f"{source}: {_KEY_OF[name]}") from None
    if _is_number(given) and not math.isclose(given, material.mu0, rel_tol=1e-9):
        warnings.warn(f"{source}: {_KEY_OF[name]} = {given} is overridden by [{part}.material], "
                      f"whose initial shear modulus is {material.mu0:.6g} MPa")
    return {f"{part}_material": material, name: material.mu0}


def _to_public(name: str, value):
    if name == "theta0":
        return math.degrees(value)
    if name == "hinge_s":
        return list(value)
    if name == "finger_azimuths":
        return [math.degrees(v) for v in value]
    return value


def _from_public(key: str, value):
    """Convert one public (TOML) value to the internal field value, checking its type."""
    name = _FIELD_OF[key]
    default = HandDesign.__dataclass_fields__[name].default
    if name == "hinge_s":
        if not isinstance(value, list) or not all(_is_number(v) for v in value):
            raise InputError(key, value, "must be a list of numbers [mm]")
        return tuple(float(v) for v in value)
    if name == "finger_azimuths":
        if not isinstance(value, list) or not all(_is_number(v) for v in value):
            raise InputError(key, value, "must be a list of numbers [deg]")
        return tuple(math.radians(float(v)) for v in value)
    if isinstance(default, str):
        if not isinstance(value, str):
            raise InputError(key, value, "must be a string")
        return value
    if isinstance(default, int) and not isinstance(default, bool):
        if not isinstance(value, int) or isinstance(value, bool):
            raise InputError(key, value, "must be a whole number")
        return value
    if not _is_number(value):
        raise InputError(key, value, "must be a number")
    return math.radians(value) if name == "theta0" else float(value)


def hinges_for(base: HandDesign, l0: float, n_s: int) -> tuple[float, ...]:
    """Hinge positions [mm] for a tube of length l0 with n_s hinges: the base's scaled with l0
    (equal links stay equal), or equal links when the number of hinges changes."""
    if n_s == base.n_s:
        return tuple(s * l0 / base.l0 for s in base.hinge_s)
    return tuple(l0 * k / (n_s + 1) for k in range(1, n_s + 1))


def design_from_dict(values: dict, base: HandDesign | None = None, *, source: str = "design") -> HandDesign:
    """A design from public keys (as in TOML), over ``base`` (default: the paper's). Without
    ``hinge_s_mm``, a new ``l0_mm`` scales the base's hinge positions with it and a new ``n_s``
    spaces the hinges equally."""
    base = base if base is not None else HandDesign()
    changes = {}
    for key, value in values.items():
        if key in PARTS:
            continue
        if key not in _FIELD_OF:
            raise InputError(f"{source}: {key}", value,
                             f"unknown key; allowed: {', '.join(PUBLIC_KEYS)}, "
                             "[finger.material], [reservoir.material]")
        changes[_FIELD_OF[key]] = _from_public(key, value)
    if "hinge_s" not in changes and ("l0" in changes or "n_s" in changes):
        changes["hinge_s"] = hinges_for(base, changes.get("l0", base.l0), changes.get("n_s", base.n_s))
    for part in PARTS:
        if part in values:
            changes.update(_material_changes(part, values[part], source, values))
    design = dataclasses.replace(base, **changes)
    if changes.get("finger_table"):
        if design.finger_model != "fem":  # the table would be unused
            raise InputError(f"{source}: finger_table", values["finger_table"], f"is the table of "
                             f"finger_model = 'fem'; this design's finger_model is {design.finger_model!r}")
        from . import finger

        try:  # read and fitted now (cached per file), not where a run first uses it
            finger.check_data(design)
        except InputError as exc:
            raise exc.renamed(f"{source}: finger_table") from None
    return design


def load_design(path: str | Path | None = None) -> HandDesign:
    """Read a design TOML file (keys as in ``studies/designs/paper.toml``); None: the paper's."""
    path = Path(path) if path is not None else PAPER_DESIGN_FILE
    values = read_toml(path, "--design", "a design TOML file")
    table = values.get("finger_table")
    if isinstance(table, str) and table and not Path(table).is_absolute():
        # relative to the file; absolute without touching the file system (a link loop or a NUL
        # in the name is the table reader's one line to say)
        values["finger_table"] = os.path.abspath(path.parent / table)
    return design_from_dict(values, source=path.name)
