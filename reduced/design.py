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
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

from .errors import InputError

#: Reservoir models the reduced layer knows; extended when a new one is added.
RESERVOIR_MODELS = ("ellipse", "fem")

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

    def __post_init__(self):
        object.__setattr__(self, "hinge_s", tuple(float(s) for s in self.hinge_s))
        self.validate()

    # ------------------------------------------------------------------ validation
    def validate(self) -> None:
        """Raise :class:`InputError` naming the first bad field."""
        for name in ("l0", "a", "b", "d", "R", "t", "V0", "mu_sf", "mu_sr", "g"):
            _positive(_KEY_OF[name], getattr(self, name))
        if not 0.0 <= self.theta0 < math.pi / 2:
            raise InputError("theta0_deg", math.degrees(self.theta0), "must be in [0, 90) degrees")
        for name in ("n", "n_s"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise InputError(name, value, "must be a whole number >= 1")
        if len(self.hinge_s) != self.n_s:
            raise InputError("hinge_s_mm", list(self.hinge_s),
                             f"must have n_s = {self.n_s} values")
        s = (0.0, *self.hinge_s, self.l0)
        if any(s1 <= s0 for s0, s1 in zip(s, s[1:])):
            raise InputError("hinge_s_mm", list(self.hinge_s),
                             f"must increase strictly within (0, l0 = {self.l0}) mm")
        if not math.isfinite(self.base_offset):
            raise InputError("base_offset_mm", self.base_offset, "must be a finite number")
        if self.reservoir_model not in RESERVOIR_MODELS:
            raise InputError("reservoir_model", self.reservoir_model,
                             f"must be one of {', '.join(RESERVOIR_MODELS)}")

    def check_volume(self, theta_max: float) -> None:
        """Raise if V0 cannot supply the oil the fingers take at bend ``theta_max`` [rad] (eq. (15))."""
        needed = self.n * math.pi * self.a**2 * self.d * theta_max
        if needed >= self.V0:
            raise InputError("V0_mm3", self.V0,
                             f"must exceed the {needed:.0f} mm^3 the fingers take at "
                             f"{math.degrees(theta_max):.1f} deg")

    # ------------------------------------------------------------------ derived
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
        """Public (unit-suffixed) keys -> values, as in a design TOML file."""
        return {key: _to_public(name, getattr(self, name)) for name, key in _KEY_OF.items()}

    def to_toml(self) -> str:
        """The design as a TOML document that :func:`load_design` reads back."""
        lines = ["# softhand hand design; units in the key names"]
        for key, value in self.to_dict().items():
            lines.append(f"{key} = {json.dumps(value)}")
        return "\n".join(lines) + "\n"

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
}
_FIELD_OF = {key: name for name, key in _KEY_OF.items()}
PUBLIC_KEYS = tuple(_KEY_OF.values())


def _positive(key: str, value) -> None:
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not value > 0 \
            or not math.isfinite(value):
        raise InputError(key, value, "must be a positive number")


def _to_public(name: str, value):
    if name == "theta0":
        return math.degrees(value)
    if name == "hinge_s":
        return list(value)
    return value


def _from_public(key: str, value):
    """Convert one public (TOML) value to the internal field value, checking its type."""
    name = _FIELD_OF[key]
    default = HandDesign.__dataclass_fields__[name].default
    if name == "hinge_s":
        if not isinstance(value, list) or not all(_is_number(v) for v in value):
            raise InputError(key, value, "must be a list of numbers [mm]")
        return tuple(float(v) for v in value)
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


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def design_from_dict(values: dict, base: HandDesign | None = None, *, source: str = "design") -> HandDesign:
    """A design from public keys (as in TOML), over ``base`` (default: the paper's)."""
    base = base if base is not None else HandDesign()
    changes = {}
    for key, value in values.items():
        if key not in _FIELD_OF:
            raise InputError(f"{source}: {key}", value,
                             f"unknown key; allowed: {', '.join(PUBLIC_KEYS)}")
        changes[_FIELD_OF[key]] = _from_public(key, value)
    return dataclasses.replace(base, **changes)


def load_design(path: str | Path | None = None) -> HandDesign:
    """Read a design TOML file (keys as in ``studies/designs/paper.toml``); None: the paper's."""
    path = Path(path) if path is not None else PAPER_DESIGN_FILE
    try:
        with open(path, "rb") as f:
            values = tomllib.load(f)
    except FileNotFoundError:
        raise InputError("--design", str(path), "no such file; give a design TOML file") from None
    except IsADirectoryError:
        raise InputError("--design", str(path), "is a directory; give a design TOML file") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError("--design", str(path), f"is not valid TOML ({exc})") from None
    return design_from_dict(values, source=path.name)
