"""What values a :class:`softhand.reduced.vocabulary.design.HandDesign` may take: one table of bounds per public
key, the checks between fields, and the model-name check (each raises one
:class:`softhand.reduced.vocabulary.errors.InputError` naming the field)."""
from __future__ import annotations

import math

from softhand.reduced.vocabulary.errors import InputError

__all__ = ["BOUNDS", "CONSISTENCY", "check_hinges", "check_layout", "check_model", "in_bounds", "is_number"]


#: public key -> (lowest, highest) allowed value, both included, in the key's unit. Every
#: number of a design is checked against this one table (the hinge positions hinge_s_mm lie
#: strictly inside (0, l0_mm));
#: a new numeric design key adds one line here. The limits are physical: a rubber tube of
#: a hand-sized soft finger, a rubber reservoir sheet, Earth-like gravity.
BOUNDS: dict[str, tuple[float, float]] = {
    "theta0_deg": (0.0, 89.0),        # base link inclination
    "l0_mm": (10.0, 1000.0),          # finger tube length
    "a_mm": (0.1, 50.0),              # tube inner radius
    "b_mm": (0.1, 50.0),              # tube wall thickness
    "d_mm": (0.2, 200.0),             # tube axis to hinge plate (also > a + b)
    "R_mm": (1.0, 500.0),             # reservoir sheet radius
    "t_mm": (0.01, 50.0),             # reservoir sheet thickness (also < R)
    "V0_mm3": (1.0, 1.0e8),           # initial oil volume
    "n": (1, 12),                     # fingers
    "n_s": (1, 20),                   # hinges per finger
    "mu_sf_MPa": (1.0e-3, 100.0),     # rubber shear modulus, finger tube
    "mu_sr_MPa": (1.0e-3, 100.0),     # rubber shear modulus, reservoir sheet
    "base_offset_mm": (-1000.0, 1000.0),
    "g_N_per_kg": (0.01, 100.0),
    "tie_width_mm": (0.1, 1000.0),    # the links' tied rings (also shorter than every link)
}


def in_bounds(key: str, value) -> None:
    lo, hi = BOUNDS[key]
    if not is_number(value) or not math.isfinite(value) or not lo <= value <= hi:
        raise InputError(key, value, f"must be a number in [{lo:g}, {hi:g}]")


def _tube_fits(design: "HandDesign") -> None:
    if not design.a + design.b < design.d:
        raise InputError("d_mm", design.d, f"must exceed the tube's outer radius a_mm + b_mm = "
                         f"{design.a + design.b:g} (the tube lies between its axis and the hinge plate)")


def _sheet_thinner_than_radius(design: "HandDesign") -> None:
    if not design.t < design.R:
        raise InputError("t_mm", design.t, f"must be smaller than the sheet radius R_mm = {design.R:g}")


def _ties_fit_links(design: "HandDesign") -> None:
    shortest = min(design.link_lengths)
    if design.tie_width >= shortest:
        raise InputError("tie_width_mm", design.tie_width,
                         f"must be shorter than every link (shortest {shortest:g} mm)")


#: checks between fields, run after the bounds; each raises InputError naming one field
CONSISTENCY = (_tube_fits, _sheet_thinner_than_radius, _ties_fit_links)


def check_hinges(design: "HandDesign") -> None:
    """The counts n and n_s whole numbers, and n_s hinge positions, finite and strictly
    increasing within (0, l0)."""
    for name in ("n", "n_s"):
        value = getattr(design, name)
        if isinstance(value, bool) or not isinstance(value, int):
            raise InputError(name, value, "must be a whole number")
    if len(design.hinge_s) != design.n_s:
        raise InputError("hinge_s_mm", list(design.hinge_s),
                         f"must have n_s = {design.n_s} values")
    s = (0.0, *design.hinge_s, design.l0)
    if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in s) \
            or any(not s1 > s0 for s0, s1 in zip(s, s[1:])):  # nan compares false both ways
        raise InputError("hinge_s_mm", list(design.hinge_s),
                         f"must be finite and increase strictly within (0, l0 = {design.l0:g}) mm")


def check_layout(design: "HandDesign") -> None:
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


def check_model(field: str, name: str, models) -> None:
    """A model name the registry knows (every model takes any rubber the project fits)."""
    if name not in models:
        raise InputError(field, name, f"must be one of {', '.join(models)}")


def is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)
