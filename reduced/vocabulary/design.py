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
and ``mu_sr_MPa`` (reservoir sheet). A part may have another strain energy
(:mod:`softhand.reduced.materials.rubber`; in a design file a ``[finger.material]`` table,
:mod:`softhand.reduced.vocabulary.design_files`): ``mu_sf_MPa`` / ``mu_sr_MPa`` are then its
initial shear modulus, and setting them (``softhand fit --params mu_sf_MPa``, a study sweep)
scales every modulus of the material, keeping the shape of W.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from dataclasses import dataclass
from pathlib import Path

from softhand import reduced as reduced_layer

from softhand.reduced.materials import rubber, rubber_base
from softhand.reduced.vocabulary.design_rules import (BOUNDS, CONSISTENCY, check_hinges, check_layout, check_model,
                                                       in_bounds, is_number)
from softhand.reduced.vocabulary.errors import InputError

__all__ = ["RESERVOIR_MODELS", "FINGER_MODELS", "PAPER_DESIGN_FILE", "HandDesign", "PUBLIC_KEYS",
           "KEY_OF", "MODULUS_OF", "PARTS", "BOUNDS", "CONSISTENCY", "FIELD_OF", "from_public", "hinges_for",
           "field_changes"]

#: Reservoir models the reduced layer knows; extended when a new one is added.
RESERVOIR_MODELS = ("ellipse", "fem")
#: Finger models the reduced layer knows: the paper's eqs. (2), (5), (10), or FEM-calibrated.
FINGER_MODELS = ("paper", "fem")

#: the paper TOML among the study files, beside the reduced layer (the repository, or the installed package)
PAPER_DESIGN_FILE = Path(reduced_layer.__file__).resolve().parent.parent / "studies" / "designs" / "paper.toml"


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
    finger_material: rubber_base.Rubber | None = None
    #: reservoir sheet's strain energy (its shape; scaled to mu_sr); None: Neo-Hookean
    reservoir_material: rubber_base.Rubber | None = None
    finger_model: str = "paper"  #: reduced finger model (W_f, Q), one of FINGER_MODELS
    #: width of the ring by which each link holds the tube, centred on the link [mm];
    #: not in the paper. The finger FEM ties these rings; finger_model "fem" is calibrated on it
    tie_width: float = 10.0
    #: calibration table of finger_model "fem" (a CSV file); "" = the one in the package
    finger_table: str = ""
    #: the fast hold's blocked-hinge table made for this design (a CSV file of ``python -m
    #: softhand.studies.calibration.hinges --design``); "" = the paper's design's, carried over
    hinge_table: str = ""
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
        """Raise :class:`~softhand.reduced.vocabulary.errors.InputError` naming the first bad field (bounds: :data:`~softhand.reduced.vocabulary.design_rules.BOUNDS`)."""
        for name, key in KEY_OF.items():
            if key in BOUNDS:
                in_bounds(key, _to_public(name, getattr(self, name)))
        check_hinges(self)
        check_layout(self)
        for check in CONSISTENCY:
            check(self)
        check_model("reservoir_model", self.reservoir_model, RESERVOIR_MODELS)
        check_model("finger_model", self.finger_model, FINGER_MODELS)

    # ------------------------------------------------------------------ derived
    @property
    def finger_rubber(self) -> rubber_base.Rubber:
        """The finger tube's strain energy, with initial shear modulus mu_sf."""
        return _scaled(self.finger_material, self.mu_sf)

    @property
    def reservoir_rubber(self) -> rubber_base.Rubber:
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
        """A copy with some fields changed, validated: by field name in internal units
        (``a=3.5``, ``theta0`` in rad) or by the design file's key (``a_mm=3.5``,
        ``theta0_deg=20``), with the file's rules (a new ``l0_mm`` scales the hinges); a name
        that is both (``n``, ``finger_model``) is the field."""
        public = {k: changes.pop(k) for k in list(changes) if k in FIELD_OF and k not in KEY_OF}
        design = dataclasses.replace(self, **changes)
        return dataclasses.replace(design, **field_changes(public, design, source="replace")) if public else design

    # ------------------------------------------------------------------ I/O
    def to_dict(self) -> dict:
        """Public (unit-suffixed) keys -> values, as in a design TOML file; a part with a
        material table adds ``{"finger": {"material": {"model": ..., parameters}}}``."""
        out = {key: _to_public(name, getattr(self, name)) for name, key in KEY_OF.items()
               if not (name in _OMITTED_AT_DEFAULT and getattr(self, name) == _default(name))}
        for part in PARTS:
            if getattr(self, f"{part}_material") is not None:
                material = getattr(self, f"{part}_rubber")
                out[part] = {"material": {"model": material.model, **material.parameters()}}
        return out

    def to_toml(self) -> str:
        """The design as a TOML document that :func:`~softhand.reduced.vocabulary.design_files.load_design` reads back."""
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
KEY_OF = {
    "theta0": "theta0_deg", "l0": "l0_mm", "a": "a_mm", "b": "b_mm", "d": "d_mm",
    "R": "R_mm", "t": "t_mm", "V0": "V0_mm3", "n": "n", "n_s": "n_s",
    "mu_sf": "mu_sf_MPa", "mu_sr": "mu_sr_MPa", "hinge_s": "hinge_s_mm",
    "base_offset": "base_offset_mm", "g": "g_N_per_kg", "reservoir_model": "reservoir_model",
    "finger_model": "finger_model", "tie_width": "tie_width_mm", "finger_table": "finger_table",
    "finger_azimuths": "finger_azimuths_deg", "pad_width": "pad_width_mm", "hinge_table": "hinge_table",
}
#: the hand layout's fields: written only when set, so that every design's hash stays what it was
_OMITTED_AT_DEFAULT = ("finger_azimuths", "pad_width", "hinge_table")


def _default(name: str):
    return HandDesign.__dataclass_fields__[name].default


#: every key a design file may hold (the TOML names, with their units)
PUBLIC_KEYS = tuple(KEY_OF.values())
#: parts that may carry a ``[<part>.material]`` table, and the modulus key it sets
PARTS = ("finger", "reservoir")
MODULUS_OF = {"finger": "mu_sf", "reservoir": "mu_sr"}


def _scaled(material, mu0: float) -> rubber_base.Rubber:
    if material is None:
        return rubber.NeoHookean(mu0)
    return material if material.mu0 == mu0 else material.scaled(mu0 / material.mu0)


def _is_neo_hookean(material) -> bool:
    return material is None or isinstance(material, rubber.NeoHookean)


def _to_public(name: str, value):
    if name == "theta0":
        return math.degrees(value)
    if name == "hinge_s":
        return list(value)
    if name == "finger_azimuths":
        return [math.degrees(v) for v in value]
    return value


#: public TOML key -> dataclass field
FIELD_OF = {key: name for name, key in KEY_OF.items()}


def from_public(key: str, value):
    """Convert one public (TOML) value to the internal field value, checking its type."""
    name = FIELD_OF[key]
    default = HandDesign.__dataclass_fields__[name].default
    if name == "hinge_s":
        if not isinstance(value, list) or not all(is_number(v) for v in value):
            raise InputError(key, value, "must be a list of numbers [mm]")
        return tuple(float(v) for v in value)
    if name == "finger_azimuths":
        if not isinstance(value, list) or not all(is_number(v) for v in value):
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
    if not is_number(value):
        raise InputError(key, value, "must be a number")
    return math.radians(value) if name == "theta0" else float(value)


def hinges_for(base: HandDesign, l0: float, n_s: int) -> tuple[float, ...]:
    """Hinge positions [mm] for a tube of length l0 with n_s hinges: the base's scaled with l0
    (equal links stay equal), or equal links when the number of hinges changes."""
    if n_s == base.n_s:
        return tuple(s * l0 / base.l0 for s in base.hinge_s)
    return tuple(l0 * k / (n_s + 1) for k in range(1, n_s + 1))


def field_changes(values: dict, base: HandDesign, *, source: str = "design") -> dict:
    """The field changes that public keys (as in TOML, units in the names; no material tables)
    make to ``base``, each checked for its type: without ``hinge_s_mm``, a new ``l0_mm`` scales
    the base's hinge positions with it and a new ``n_s`` spaces the hinges equally."""
    changes = {}
    for key, value in values.items():
        if key not in FIELD_OF:
            raise InputError(f"{source}: {key}", value,
                             f"unknown key; allowed: {', '.join(PUBLIC_KEYS)}, "
                             "[finger.material], [reservoir.material]")
        changes[FIELD_OF[key]] = from_public(key, value)
    if "hinge_s" not in changes and ("l0" in changes or "n_s" in changes):
        changes["hinge_s"] = hinges_for(base, changes.get("l0", base.l0), changes.get("n_s", base.n_s))
    return changes
