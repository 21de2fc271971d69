"""Render a VTK state (``.vtu``, or one step of a ``.pvd``) with pyvista.

This is the one module of the project that imports pyvista. Rendering is off-screen by
default (no display needed); the picture shows the mesh deformed by its ``displacement``
(true scale) coloured by a field, with a scalar bar and a title.

A field is named as in the file (``von_mises``, ``J``, ...); a vector or tensor field is
shown by its magnitude, or by one component with ``NAME[i]`` (e.g.
``principal_stretches[0]``, the largest stretch). Point data are preferred to cell data
of the same name.
"""
from __future__ import annotations

import contextlib
import logging
import os
import re
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyvista as pv

from meshes.atomic import atomic_path
from reduced.errors import InputError

SUFFIXES = (".vtu", ".pvd", ".vtk")
DEFAULT_FIELDS = ("von_mises", "displacement")


@dataclass(frozen=True)
class FieldSummary:
    file: str      #: the file rendered
    step: int      #: index of the step in a .pvd (0 for a .vtu)
    n_steps: int   #: steps in the file (1 for a .vtu)
    field: str     #: field shown (with [i] for a component)
    location: str  #: "point" or "cell"
    minimum: float
    maximum: float
    peak_at: tuple[float, float, float]  #: reference position of the maximum [mm]
    png: str | None  #: picture written, or None (interactive only)


def load_state(path: str | Path, step: int | None = None) -> tuple[pv.DataSet, int, int]:
    """(mesh, step index, number of steps) of a ``.vtu``/``.vtk`` or a step of a ``.pvd``."""
    path = Path(path)
    if path.suffix not in SUFFIXES or not path.is_file():
        raise InputError("file", str(path), f"must be an existing {'/'.join(SUFFIXES)} file")
    _sniff(path)
    with pv.vtk_verbosity("off"), _quiet_logging():
        try:
            reader = pv.get_reader(str(path))
            times = list(reader.time_values) if path.suffix == ".pvd" else [0.0]
        except Exception as exc:  # VTK reports bad files through many exception types
            raise InputError("file", str(path), f"must be a readable VTK file: {_first_line(exc)}") from None
        index = _step_index(step, len(times))
        try:
            if path.suffix == ".pvd":
                reader.set_active_time_point(index)
            mesh = reader.read()
        except Exception as exc:
            raise InputError("file", str(path), f"must be a readable VTK file: {_first_line(exc)}") from None
    if isinstance(mesh, pv.MultiBlock):
        mesh = mesh.combine() if mesh.n_blocks else pv.UnstructuredGrid()
    if mesh.n_points == 0:
        raise InputError("file", str(path), "must be a VTK file with a mesh (found no points)")
    return mesh, index, len(times)


def field_values(mesh: pv.DataSet, name: str) -> tuple[np.ndarray, str]:
    """(scalar values, "point"|"cell") of field ``name`` or ``name[i]`` on ``mesh``."""
    match = re.fullmatch(r"(.+?)(?:\[(\d+)\])?", name)
    base, component = match.group(1), match.group(2)
    for location, data in (("point", mesh.point_data), ("cell", mesh.cell_data)):
        if base in data:
            values = np.asarray(data[base], dtype=float)
            break
    else:
        raise InputError("field", name, f"allowed: {', '.join(field_names(mesh))}")
    if values.ndim == 1:
        if component not in (None, "0"):
            raise InputError("field", name, f"{base} is a scalar; use it without [i]")
        return values, location
    if component is None:
        return np.linalg.norm(values, axis=1), location
    if int(component) >= values.shape[1]:
        raise InputError("field", name, f"{base} has components [0]..[{values.shape[1] - 1}]")
    return values[:, int(component)], location


def field_names(mesh: pv.DataSet) -> list[str]:
    """The names of the point and cell arrays, each once."""
    return list(dict.fromkeys([*mesh.point_data.keys(), *mesh.cell_data.keys()]))


def inspect(path: str | Path, *, field: str | None = None, step: int | None = None,
            out: str | Path | None = None, interactive: bool = False) -> FieldSummary:
    """Render ``path`` coloured by ``field``; write ``out`` (PNG) unless only interactive."""
    mesh, index, n_steps = load_state(path, step)
    field = field or next((f for f in DEFAULT_FIELDS if f in field_names(mesh)), None)
    if field is None:
        raise InputError("field", None, f"no default field; allowed: {', '.join(field_names(mesh))}")
    values, location = field_values(mesh, field)
    if not np.any(np.isfinite(values)):
        raise InputError("field", field, "has no finite values in this file")
    centres = mesh.points if location == "point" else mesh.cell_centers().points
    peak = np.asarray(centres[int(np.nanargmax(values))], dtype=float)
    if interactive and not _has_display():
        raise InputError("--interactive", True, "needs a display (DISPLAY is not set); "
                                                "omit it to render off-screen")
    png = None if interactive and out is None else Path(out or _default_png(path, index, field))
    title = f"{Path(path).name}  step {index}/{n_steps - 1}  {field}"
    _render(mesh, values, location, title=title, png=png, interactive=interactive)
    return FieldSummary(str(path), index, n_steps, field, location, float(np.nanmin(values)),
                        float(np.nanmax(values)), tuple(peak.tolist()), None if png is None else str(png))


def _render(mesh, values, location, *, title, png, interactive) -> None:
    shown = mesh.copy()
    shown.clear_data()
    if "displacement" in mesh.point_data:
        shown.points = mesh.points + np.asarray(mesh.point_data["displacement"], dtype=float)
    getattr(shown, f"{location}_data")["field"] = values
    with pv.vtk_verbosity("off"):
        plotter = pv.Plotter(off_screen=not interactive, window_size=(1024, 768))
        plotter.add_mesh(shown, scalars="field", cmap="viridis", show_edges=False,
                         scalar_bar_args={"title": title.rsplit("  ", 1)[-1], "width": 0.6,
                                          "position_x": 0.2, "position_y": 0.02, "fmt": "%.4g"})
        plotter.add_text(title, font_size=10)
        plotter.view_isometric()
        plotter.camera.zoom(0.8)
        if png is not None:
            with atomic_path(png) as tmp:
                plotter.screenshot(str(tmp))
        if interactive:
            plotter.show()
        plotter.close()


def _sniff(path: Path) -> None:
    """A VTK file starts with its XML header or the legacy '# vtk DataFile' line."""
    with path.open("rb") as f:
        head = f.read(256).lstrip()
    if not (head.startswith(b"<?xml") or head.startswith(b"<VTKFile")
            or head.startswith(b"# vtk DataFile")):
        raise InputError("file", str(path), "must be a VTK file (XML .vtu/.pvd or legacy .vtk)")


@contextlib.contextmanager
def _quiet_logging():
    """pyvista forwards VTK errors to the logging module; the CLI reports one line instead."""
    logging.disable(logging.CRITICAL)
    try:
        yield
    finally:
        logging.disable(logging.NOTSET)


def _first_line(exc: Exception) -> str:
    return next((line.strip() for line in str(exc).splitlines() if line.strip()),
                type(exc).__name__)


def _step_index(step: int | None, n: int) -> int:
    if step is None:
        return n - 1
    if not -n <= step < n:
        raise InputError("--step", step, f"must be in 0..{n - 1} (or -{n}..-1 from the end)")
    return step % n


def _default_png(path, index: int, field: str) -> Path:
    path = Path(path)
    safe = re.sub(r"[^A-Za-z0-9_]+", "_", field).strip("_")
    return path.with_name(f"{path.stem}_step{index}_{safe}.png")


def _has_display() -> bool:
    return sys.platform in ("win32", "darwin") or bool(os.environ.get("DISPLAY")
                                                        or os.environ.get("WAYLAND_DISPLAY"))
