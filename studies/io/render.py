"""Render a VTK result (a ``.vtm`` scene, a ``.vtu``, or one step of a ``.pvd``) with pyvista.

This module and :mod:`.scene_read` (reading the files) are the only ones that import pyvista
(and this one imageio, for animations).
Rendering is off-screen by default (no display needed). The picture shows the *body* (the
finger's ``tube``, the reservoir's ``sheet``, or a plain file's mesh) deformed by its
``displacement_mm`` (true scale) and coloured by a field, with a colour bar labelled with
the field's unit; its undeformed shape as a faint ghost; the links and hinges of a finger;
the object of a grasp; the contact forces as arrows ending at the pads, labelled in N.
The title gives the file, the step and the pressure (and bend angle or volume).

A field is named as in the file (``von_mises_MPa``, ``J``, ...; ``describe()`` lists
them); a vector or tensor field is shown by its magnitude, or by one component with
``NAME[i]`` (e.g. ``principal_stretches[0]``, the largest stretch). Point data are
preferred to cell data of the same name.
"""
from __future__ import annotations

import importlib.util
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyvista as pv

from softhand.meshes.atomic import atomic_path
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.io.files import kept_if_unwritable
from softhand.studies.io.manifest import check_single
from softhand.studies.io.scene_read import field_names, field_values, load_scene
from softhand.studies.io.render_style import (VIEWS, body_name, camera, clim_of, colour_label, default_field,
                                   default_png, finger_turns, has_display, title_of)

ANIMATIONS = (".gif", ".mp4")


@dataclass(frozen=True)
class FieldSummary:
    file: str      #: the file rendered
    step: int      #: index of the step in a .pvd (0 otherwise)
    n_steps: int   #: steps in the file (1 for a .vtu/.vtm)
    field: str     #: field shown (with [i] for a component)
    location: str  #: "point" or "cell"
    minimum: float
    maximum: float
    peak_at: tuple[float, float, float]  #: reference position of the maximum [mm]
    png: str | None  #: picture (or animation) written, or None (interactive only)


def describe(path: str | Path, step: int | None = None) -> list[dict]:
    """Every array of every block: block, name, location (point/cell/field), components."""
    scene, _, _ = load_scene(path, step)
    rows = []
    for name, block in zip(scene.keys(), scene):
        for location in ("point", "cell", "field"):
            for key, value in getattr(block, f"{location}_data").items():
                value = np.asarray(value)
                rows.append({"block": name, "field": key, "location": location,
                             "components": 1 if value.ndim == 1 else int(value.shape[1])})
    return rows


def inspect(path: str | Path, *, field: str | None = None, step: int | None = None,
            out: str | Path | None = None, view: str | None = None, hand: bool = True,
            interactive: bool = False) -> FieldSummary:
    """Render ``path`` coloured by ``field``; write ``out`` (PNG) unless only interactive."""
    _check_view(view)
    scene, index, n_steps = load_scene(path, step)
    body = scene[body_name(scene.keys())]
    field = field or default_field(field_names(body))
    values, location = _checked_values(body, field)
    centres = body.points if location == "point" else body.cell_centers().points
    peak = np.asarray(centres[int(np.nanargmax(values))], dtype=float)
    if interactive and not has_display():
        raise InputError("--interactive", True, "needs a display (DISPLAY is not set); "
                                                "omit it to render off-screen")
    png = None if interactive and out is None else Path(out or default_png(path, index, field))
    if out is None and png is not None:  # the default name: never over a file of the user's
        check_single(png, "--out (not given: the default name)")
    plotter = _plotter(interactive=interactive)
    _draw(plotter, scene, field, title=title_of(path, scene, index, n_steps), view=view, hand=hand)
    written = None
    if png is not None:
        with kept_if_unwritable(png, "inspect"):  # a full disk: the field's range is still printed
            with atomic_path(png) as tmp:
                plotter.screenshot(str(tmp))
            written = str(png)
            if out is None:  # (a name given is recorded by the command line, as every --out FILE)
                from softhand.studies.io.outputs import record_single

                record_single(png, "inspect")
    if interactive:
        plotter.show()
    plotter.close()
    return FieldSummary(str(path), index, n_steps, field, location, float(np.nanmin(values)),
                        float(np.nanmax(values)), tuple(peak.tolist()), written)


#: most steps an animation draws (the FEM verbs write at most 200 pressures or volumes)
MAX_FRAMES = 1000


def animate(path: str | Path, out: str | Path, *, field: str | None = None,
            view: str | None = None, hand: bool = True, fps: float = 4.0) -> FieldSummary:
    """Render every step of a ``.pvd`` with one camera and colour range into a GIF or MP4."""
    import imageio.v2 as imageio

    _check_view(view)
    out = Path(out)
    if out.suffix not in ANIMATIONS:
        raise InputError("--animate", str(out), f"must end in {' or '.join(ANIMATIONS)}")
    if Path(path).suffix != ".pvd":
        raise InputError("file", str(path), "must be a .pvd series to animate")
    if out.suffix == ".mp4" and importlib.util.find_spec("imageio_ffmpeg") is None:
        raise InputError("--animate", str(out), "MP4 needs imageio-ffmpeg (pip install imageio-ffmpeg); "
                                                "or write a .gif")
    steps = load_scene(path)[2]
    if steps > MAX_FRAMES:
        raise InputError("file", str(path), f"has {steps} steps; --animate draws at most {MAX_FRAMES} "
                                            "(a result of this toolkit has at most a few hundred)")
    scenes = [load_scene(path, k) for k in range(steps)]
    bodies = [s[body_name(s.keys())] for s, _, _ in scenes]
    field = field or default_field(field_names(bodies[-1]))
    ranges = np.array([[np.nanmin(v), np.nanmax(v)] for v in (_checked_values(b, field)[0] for b in bodies)])
    clim = (float(ranges[:, 0].min()), float(ranges[:, 1].max()))
    plotter = _plotter(window_size=(800, 600))
    frames = []
    for scene, index, n in scenes[::-1]:  # the last (largest) state first: it sets the camera
        plotter.clear()
        _draw(plotter, scene, field, title=title_of(path, scene, index, n), view=view, clim=clim,
              keep_camera=bool(frames), hand=hand)
        frames.append(plotter.screenshot(return_img=True))
    plotter.close()
    frames = frames[::-1]
    written = None
    with kept_if_unwritable(out, "inspect"):
        with atomic_path(out) as tmp:
            if out.suffix == ".gif":
                imageio.mimsave(tmp, frames, format="GIF", duration=1000.0 / fps, loop=0)
            else:
                imageio.mimsave(tmp, frames, fps=fps)
        written = str(out)
    return FieldSummary(str(path), len(scenes) - 1, len(scenes), field, "point", clim[0], clim[1],
                        (np.nan,) * 3, written)


def _check_view(view) -> None:
    if view is not None and view not in VIEWS:
        raise InputError("--view", view, f"allowed: {', '.join(VIEWS)}")


def _checked_values(body, field):
    if field is None:
        names = field_names(body)
        raise InputError("field", None, f"no default field; allowed: {', '.join(names)}" if names
                         else "the file has no point or cell fields to colour by")
    values, location = field_values(body, field)
    if not np.any(np.isfinite(values)):
        raise InputError("field", field, "has no finite values in this file")
    return values, location


def _plotter(*, interactive=False, window_size=(1200, 900)) -> pv.Plotter:
    with pv.vtk_verbosity("off"):
        plotter = pv.Plotter(off_screen=not interactive, window_size=window_size)
    plotter.set_background("white")
    return plotter


def _draw(plotter, scene, field, *, title, view, clim=None, keep_camera=False, hand=True) -> None:
    """Add the scene's actors: ghost, coloured body, links, hinges, object, force arrows;
    with ``hand`` the hand's other fingers (copies turned about the hand's axis y)."""
    names = scene.keys()
    body_key = body_name(names)
    body = scene[body_key]
    values, location = field_values(body, field)
    shown = _deformed(body)
    shown.clear_data()
    getattr(shown, f"{location}_data")["field"] = values
    plotter.add_mesh(_surface(body), color="grey", opacity=0.12)
    parts = [(_surface(shown), {"scalars": "field", "cmap": "viridis", "clim": clim or clim_of(values)})]
    for name, block in zip(names, scene):
        if name.startswith("link_"):
            parts.append((block.extract_surface(algorithm="dataset_surface"), {"color": "#b0b4bb"}))
        elif name.startswith("hinge_"):
            parts.append((block.extract_surface(algorithm="dataset_surface"), {"color": "#4a4f57"}))
        elif name == "object":
            plotter.add_mesh(block, color="#e0a060", opacity=0.3, smooth_shading=True)
        elif name == "contact_forces":
            _draw_forces(plotter, block)
    n = int(np.asarray(body.field_data["n_fingers"]).ravel()[0]) if "n_fingers" in body.field_data and hand else 1
    turns = finger_turns(n, view if body_key == "tube" else "iso")
    actors = [plotter.add_mesh(mesh.rotate_y(turn, point=(0.0, 0.0, 0.0), inplace=False)
                               if turn else mesh, show_scalar_bar=False, **style)
              for turn in turns for mesh, style in parts]
    plotter.add_scalar_bar(colour_label(field), mapper=actors[0].mapper, vertical=True, position_x=0.8, position_y=0.12,
                           width=0.05, height=0.7, color="black", fmt="%.3g", title_font_size=14,
                           label_font_size=13)
    plotter.add_text(title, font_size=10, color="black")
    if not keep_camera:
        camera(plotter, view, sheet=body_key != "tube", zoom=1.0 if body_key == "tube" and len(turns) == 1 else 1.3)


def _draw_forces(plotter, forces) -> None:
    """Arrows of the force of the object on each touching pad, tip at the pad, length
    proportional to the force (the largest 40 mm), labelled in N."""
    f = np.asarray(forces.point_data["force_N"], dtype=float)
    size = np.linalg.norm(f, axis=1)
    touching = size > 1e-6 * max(size.max(), 1e-300)
    if not touching.any():
        return
    scale = 40.0 / size.max()
    tails = forces.points[touching] - scale * f[touching]
    arrows = pv.PolyData(tails)
    arrows["vectors"] = scale * f[touching]
    glyphs = arrows.glyph(orient="vectors", scale="vectors", factor=1.0,
                          geom=pv.Arrow(tip_length=0.25, tip_radius=0.12, shaft_radius=0.04))
    plotter.add_mesh(glyphs, color="#d62728", name="forces")
    plotter.add_point_labels(tails, [f"{s:.3g} N" for s in size[touching]], font_size=14,
                             text_color="#d62728", shape=None, show_points=False,
                             always_visible=True, name="force_labels")


def _deformed(mesh):
    shown = mesh.copy()
    for name in ("displacement_mm", "displacement"):
        if name in mesh.point_data:
            shown.points = mesh.points + np.asarray(mesh.point_data[name], dtype=float)
            break
    return shown


def _surface(mesh):
    """The outer surface (quadratic cells tessellated), for fast, smooth drawing."""
    return mesh.extract_surface(nonlinear_subdivision=2, algorithm="dataset_surface") if isinstance(mesh, pv.UnstructuredGrid) else mesh


__all__ = ["FieldSummary", "VIEWS", "animate", "describe", "field_names", "field_values",
           "inspect", "load_scene"]
