"""The checked values of a design task file (:func:`softhand.studies.design.task.task_from_dict` reads
them): each number within its range, the free keys' bounds (kept by the design rules, clipped to
the finger table's calibrated box) and the base design.
"""
from __future__ import annotations

import math
from pathlib import Path

from softhand.reduced.vocabulary.design import BOUNDS, PAPER_DESIGN_FILE, PUBLIC_KEYS, HandDesign
from softhand.reduced.vocabulary.design_files import design_from_dict, load_design
from softhand.reduced.vocabulary.errors import InputError

#: design keys the optimiser may vary; "l0_mm" scales the hinge positions with the tube
FREE_KEYS = ("a_mm", "b_mm", "d_mm", "l0_mm", "R_mm", "t_mm", "V0_mm3", "tie_width_mm")
#: the free keys that change the finger (a design's own hinge table no longer fits)
FINGER_KEYS = ("a_mm", "b_mm", "d_mm", "l0_mm", "tie_width_mm")
#: the design space the packaged finger table was calibrated on (its [space] box)
CALIBRATED_SPACE = PAPER_DESIGN_FILE.parents[1] / "finger_space.toml"
#: highest value of each number of a task (the lowest: > 0, or >= 0 where zero makes sense)
UPPER = {"diameter_mm": 500.0, "mass_kg": 20.0, "max_pressure_MPa": 5.0, "force_factor": 100.0,
         "margin_N": 1000.0, "opening_mm": 1000.0, "rubber_stretch": 10.0, "min_wall_mm": 50.0,
         "mesh_size_mm": 12.0, "edge_ratio": 1.0, "dP_MPa": 0.5}
#: lowest value of the FEM proof's mesh and step (a finer one is refused, not run for hours), of the
#: force factor (below 1 the fingers would not carry the object's weight) and of the pump limit
#: (10 kPa: far below the contact pressure of any finger in the calibrated space, ~0.1-0.5 MPa)
LOWER = {"mesh_size_mm": 0.5, "edge_ratio": 0.05, "dP_MPa": 0.001, "force_factor": 1.0,
         "max_pressure_MPa": 0.01}
#: least non-zero mass [kg] and margin [N]: 0 is a massless object or no margin (the fingers
#: press with m g / n, or just touch), a positive value below it asks for a force the grasp
#: model does not resolve (a root at 1e-300 N ran for minutes)
LEAST_NONZERO = {"mass_kg": 1e-3, "margin_N": 1e-3}
UPPER.update({"margin": 100.0, "pull_N": 1e5})
LOWER.update({"margin": 1.0})


def base_design(value, folder: Path) -> HandDesign:
    """A task's ``base_design``: the paper's (None), else the design file looked up as given,
    next to the task file (``folder``) and in the package."""
    if value is None:
        return load_design(None)
    if not isinstance(value, str):
        raise InputError("base_design", value, "must be a file name (string)")
    for candidate in (Path(value), folder / value, PAPER_DESIGN_FILE.parents[2] / value):
        if candidate.is_file():
            return load_design(candidate)
    raise InputError("base_design", value, "no such design file (looked as given, next to the "
                                           "task file and in the package)")


def checked_number(table: dict, section: str, key: str, *, required: bool = False, default=None,
                   positive: bool = True, above: float | None = None):
    """``table[key]`` of the task's ``[section]`` as a float, checked against its range (> 0, or
    >= 0 where not ``positive``, > ``above``; at most UPPER, at least LOWER, 0 or at least
    LEAST_NONZERO): ``default`` when absent, InputError when ``required``."""
    if key not in table:
        if required:
            raise InputError(f"{section}.{key}", None, "is required")
        return default
    value = table[key]
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    limit, upper = above if above is not None else 0.0, UPPER[key]
    if not ok or (value <= limit if positive or above is not None else value < 0) or value > upper \
            or value < LOWER.get(key, -math.inf) or 0 < value < LEAST_NONZERO.get(key, 0.0):
        what = f"> {limit:g}" if positive or above is not None else ">= 0"
        what = f">= {LOWER[key]:g}" if key in LOWER else what
        what = f"0 or a number >= {LEAST_NONZERO[key]:g}" if key in LEAST_NONZERO else f"a number {what}"
        raise InputError(f"{section}.{key}", value, f"must be {what} and <= {upper:g}")
    return float(value)


def free_bounds(table: dict, base: HandDesign) -> tuple[tuple[str, float, float], ...]:
    """The ``[free]`` table as ((public key, lower, upper), ...): free keys only, bounds within
    the design's BOUNDS."""
    if not table:
        raise InputError("free", table, f"must name at least one design key with [lower, upper] "
                                        f"bounds; allowed: {', '.join(FREE_KEYS)}")
    out = []
    for key, bounds in table.items():
        if key not in FREE_KEYS or key not in PUBLIC_KEYS:
            allowed = [k for k in FREE_KEYS if k in PUBLIC_KEYS]
            raise InputError(f"free.{key}", bounds, f"not a free design key; allowed: {', '.join(allowed)}")
        if not (isinstance(bounds, list) and len(bounds) == 2
                and all(isinstance(b, (int, float)) and not isinstance(b, bool) and math.isfinite(b)
                        for b in bounds) and 0 < bounds[0] < bounds[1]):
            raise InputError(f"free.{key}", bounds, "must be [lower, upper] with 0 < lower < upper")
        lo, hi = BOUNDS[key]
        if bounds[0] < lo or bounds[1] > hi:
            raise InputError(f"free.{key}", bounds, f"must lie within [{lo:g}, {hi:g}]")
        out.append((key, float(bounds[0]), float(bounds[1])))
    return tuple(out)


#: free keys whose smaller values the design rules favour (a + b < d, t < R, ties shorter than
#: the links); the others' larger values (V0 is in no rule)
_RULES_FAVOUR_LOW = ("a_mm", "b_mm", "t_mm", "tie_width_mm")


def check_free_bounds_keep_the_rules(free, base: HandDesign) -> None:
    """InputError if no design within the free bounds passes the design rules: each rule is
    monotone in each key, so the box's most favourable corner decides (before any search)."""
    corner = {key: lo if key in _RULES_FAVOUR_LOW else hi for key, lo, hi in free}
    try:
        design_from_dict(corner, base, source="free")
    except InputError as exc:
        raise InputError("free", {key: [lo, hi] for key, lo, hi in free},
                         f"no design within these bounds keeps the design rules; at their most "
                         f"favourable corner, {exc}") from None


def calibrated_bounds(free, base: HandDesign):
    """(free bounds clipped to the packaged finger table's box, the bounds that were clipped)."""
    if base.finger_model != "fem" or base.finger_table:
        return free, ()
    from softhand.studies.calibration.space import load_space

    box = load_space(CALIBRATED_SPACE).box
    out, clipped = [], []
    for key, lo, hi in free:
        if key not in box:
            out.append((key, lo, hi))
            continue
        c_lo, c_hi = max(lo, box[key][0]), min(hi, box[key][1])
        if not c_lo < c_hi:
            raise InputError(f"free.{key}", [lo, hi], f'must overlap [{box[key][0]:g}, {box[key][1]:g}], '
                             'the calibrated space of finger_model "fem"')
        out.append((key, c_lo, c_hi))
        if (c_lo, c_hi) != (lo, hi):
            clipped.append((key, lo, hi))
    return tuple(out), tuple(clipped)
