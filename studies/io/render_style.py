"""What ``softhand inspect`` shows by default: the body, its field, the labels, the camera,
the colour range, the default file name.

Pure functions of names and numbers (no pyvista here; :mod:`softhand.studies.io.render` draws).
"""
from __future__ import annotations

import os
import re
import sys
from pathlib import Path

import numpy as np

from softhand.reduced.vocabulary.errors import InputError

#: blocks that are the deformable body, in order of preference
BODIES = ("tube", "sheet")
#: the default field of a body: the first present (older files: names without units)
#: (rubber_stretch: the converged measure the design limits judge; von Mises peaks at the
#: bonded corners and paints one red spot)
DEFAULT_FIELDS = ("rubber_stretch", "von_mises_MPa", "displacement_mm", "von_mises", "displacement", "height")
#: --view: side = normal to the bending plane (finger) / to a meridian plane (sheet)
VIEWS = ("side", "iso", "top", "front")
UNITS = {"MPa": "MPa", "mm": "mm", "N": "N", "mm3": "mm^3", "deg": "deg"}  # VTK's font: ASCII
DIMENSIONLESS = ("principal_stretches", "J", "fiber_stretch", "hoop_stretch", "rubber_stretch")


def body_name(names) -> str:
    """The block drawn deformed and coloured: the tube, the sheet, else the first block."""
    names = list(names)
    return next((b for b in BODIES if b in names), names[0])


def default_field(names) -> str | None:
    """The first of :data:`DEFAULT_FIELDS` that the body holds (None if none)."""
    return next((f for f in DEFAULT_FIELDS if f in names), None)


def colour_label(field: str) -> str:
    """Colour-bar title with the unit: ``von_mises_MPa`` -> ``von Mises stress [MPa]``."""
    match = re.fullmatch(r"(.+?)(?:\[(\d+)\])?", field)
    base, component = match.group(1), match.group(2)
    unit_match = re.fullmatch(r"(.+)_(MPa|mm3|mm|N|deg)", base)
    name, unit = (unit_match.group(1), UNITS[unit_match.group(2)]) if unit_match else \
        (base, "-" if base in DIMENSIONLESS else None)
    words = {"von_mises": "von Mises stress", "cauchy_stress": "Cauchy stress",
             "rubber_stretch": "rubber stretch (ball average)"}.get(name, name.replace("_", " "))
    if component is not None and name == "principal_stretches":
        words = f"principal stretch {int(component) + 1}" + (" (largest)" if component == "0" else "")
    elif component is not None:
        words += f" [{component}]"
    elif name in ("displacement", "cauchy_stress", "force"):
        words = f"{words} magnitude"
    return words if unit is None else f"{words} [{unit}]"


#: field-data pressure -> its name in a picture's title (``pressure_MPa``: files written before
#: the pressures were named, a finger's cavity pressure or the reservoir sheet's)
PRESSURES = {"P_pump_MPa": "P_pump", "P_cavity_MPa": "P_cavity", "p_reservoir_MPa": "p_reservoir",
             "pressure_MPa": "P"}


def title_of(path, scene, index: int, n_steps: int) -> str:
    """File, step and the state's numbers (pressure, bend angle, volume) from field data."""
    fd = next((b.field_data for b in scene if len(b.field_data)), {})
    value = lambda k: float(np.asarray(fd[k]).ravel()[0])  # noqa: E731
    parts = [Path(path).name, f"step {index}/{n_steps - 1}"]
    for key, name in PRESSURES.items():  # each pressure by its name: pump, cavity, reservoir
        if key in fd:
            parts.append(f"{name} = {value(key):.4g} MPa")
    if "theta_deg" in fd:
        parts.append(f"theta = {value('theta_deg'):.1f} deg")
    if "volume_mm3" in fd:
        parts.append(f"V = {value('volume_mm3'):.0f} mm^3")
    if "F_v_N" in fd:
        parts.append(f"F_v = {value('F_v_N'):.3g} N")
    return "   ".join(parts)


def finger_turns(n: int, view: str | None) -> list[float]:
    """The turns about the hand's axis [deg] of the fingers drawn of an n-finger hand: all of
    them, except in the side view, which looks along the bending plane's normal: there only
    the fingers in that plane (the modelled one, and the one opposite it when n is even) --
    any other would be seen edge-on across the object, drawn through it."""
    turns = [360.0 * k / n for k in range(n)]
    return [a for a in turns if a in (0.0, 180.0)] if view in (None, "side") else turns


def camera(plotter, view: str | None, *, sheet: bool, zoom: float = 1.0) -> None:
    """Point the camera: finger scenes are in the hand frame (y down, bending plane z = 0),
    anything else (``sheet``) has z up; ``side`` (the default of a finger) looks normal to
    the bending plane, ``iso`` is the default of the rest."""
    view = view or ("iso" if sheet else "side")
    if view not in VIEWS:
        raise InputError("--view", view, f"allowed: {', '.join(VIEWS)}")
    up = (0.0, 0.0, 1.0) if sheet else (0.0, -1.0, 0.0)
    direction = {  # from the focal point towards the camera
        "side": (0.0, -1.0, 0.0) if sheet else (0.0, 0.0, -1.0),
        "iso": (1.0, -1.0, 0.8) if sheet else (0.8, -0.6, -1.0),
        "top": (0.0, 0.0, 1.0) if sheet else (0.0, -1.0, 0.0),
        "front": (1.0, 0.0, 0.0),
    }[view]
    if view == "top":
        up = (0.0, 1.0, 0.0) if sheet else (1.0, 0.0, 0.0)
    plotter.reset_camera()
    focus = np.asarray(plotter.camera.focal_point)
    distance = np.linalg.norm(np.asarray(plotter.camera.position) - focus)
    d = np.asarray(direction) / np.linalg.norm(direction)
    plotter.camera_position = [tuple(focus + distance * d), tuple(focus), up]
    plotter.reset_camera()
    plotter.camera.zoom(zoom)

def clim_of(values) -> tuple[float, float]:
    """Colour range: min to max, but to the 95th percentile when a few peaks (e.g. at the
    edges of the ties) would leave the rest of the body in one colour; the bar's top
    colour then stands for 'this or more'."""
    lo, hi, q = np.nanmin(values), np.nanmax(values), np.nanpercentile(values, 95.0)
    return float(lo), float(q if hi - lo > 2.0 * (q - lo) > 0 else hi)


def step_index(step: int | None, n: int) -> int:
    if step is None:
        return n - 1
    if not -n <= step < n:
        raise InputError("--step", step, f"must be in 0..{n - 1} (or -{n}..-1 from the end)")
    return step % n


def default_png(path, index: int, field: str) -> Path:
    path = Path(path)
    safe = re.sub(r"[^A-Za-z0-9_]+", "_", field).strip("_")
    return path.with_name(f"{path.stem}_step{index}_{safe}.png")


def has_display() -> bool:
    return sys.platform in ("win32", "darwin") or bool(os.environ.get("DISPLAY")
                                                        or os.environ.get("WAYLAND_DISPLAY"))
