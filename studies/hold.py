"""Hold studies: one hold (its files), and the hold map over two of pressure, mass, object size,
friction and pull direction.

:class:`HoldMap` runs the fast hold model (:mod:`softhand.reduced.holding.hold`) on a grid: at each point the
holding margin, the load the hand bears along the pull over the object's weight ((m g + limit)
/ m g; >= 1: held), the holding limit [N], and both pressures. The closed hand depends only on
the pressure and the object's geometry, so it is computed once per pressure and size and
reused across masses, frictions and pulls, and so are the hands closed along the object's slide
(per pull; :mod:`softhand.reduced.holding.hold_slide`): the map's cost is then mostly linear programs.
``write`` makes ``hold_map.csv`` and ``hold_map.png`` (held region shaded, margin contours, the
margin-1 line where it drops, the pump's limit drawn when pressure is an axis). Units: MPa, kg,
mm, N, deg.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from softhand.reduced.holding import hold, hold_fast
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.holding.hand_layout import place_object
from softhand.reduced.holding.objects import GraspObject

#: the map's axes: name -> (label, unit)
AXES = {"pressure": ("pump pressure", "MPa"), "mass": ("mass", "kg"), "size": ("object size", "mm"),
        "friction": ("friction coefficient", "-"), "pull": ("pull angle from straight down", "deg")}
#: most points of a map (a 50 x 50 grid)
MAX_MAP_POINTS = 2500
#: each axis's values (a mass > 0: the margin is over the weight)
AXIS_LIMITS = {"pressure": (-1.0, 5.0), "mass": (1e-3, 100.0), "size": (1e-3, 1000.0), "friction": (0.0, 10.0),
               "pull": (-180.0, 180.0)}


def scaled(obj: GraspObject, size_mm: float) -> GraspObject:
    """The object scaled so that its largest dimension is ``size_mm`` (a mesh cannot be)."""
    if obj.shape == "mesh":
        raise InputError("--map", "size", "a mesh object has one size; map another quantity")
    if obj.shape == "box":
        k = size_mm / max(obj.size_mm)
        return replace(obj, size_mm=tuple(k * v for v in obj.size_mm))
    k = size_mm / max(obj.diameter_mm, obj.length_mm)
    return replace(obj, diameter_mm=k * obj.diameter_mm, length_mm=k * obj.length_mm)


def object_size(obj: GraspObject) -> float:
    if obj.shape == "box":
        return max(obj.size_mm)
    return max(obj.diameter_mm, obj.length_mm)


def pull_from_angle(angle_deg: float) -> np.ndarray:
    """The pull turned from straight down (+y) towards finger 0 (+x) by ``angle_deg``."""
    a = math.radians(angle_deg)
    return np.array([math.sin(a), math.cos(a), 0.0])


@dataclass(frozen=True)
class HoldMap:
    design: HandDesign
    obj: GraspObject
    x: tuple                  #: (axis name, values)
    y: tuple                  #: (axis name, values)
    pressure_MPa: float = 1.0     #: pump pressure where it is not an axis
    pull: tuple = hold.DOWN       #: pull direction where "pull" is not an axis
    max_pump_MPa: float = 2.0
    finger_model: str = "fem"
    rows: list = field(default_factory=list, compare=False)

    def __post_init__(self):
        for name, values in (self.x, self.y):
            if name not in AXES:
                raise InputError("--map", name, f"must be two of {', '.join(AXES)}")
        if self.x[0] == self.y[0]:
            raise InputError("--map", self.x[0], "the two axes must differ")
        for name, values in (self.x, self.y):
            lo, hi = AXIS_LIMITS[name]
            bad = [v for v in values if not lo <= v <= hi]
            if bad:
                raise InputError(f"--map {name}", bad[0], f"must be in [{lo:g}, {hi:g}] {AXES[name][1]}")
        if "mass" not in (self.x[0], self.y[0]) and not self.obj.mass_kg > 0:
            raise InputError("--mass-kg", self.obj.mass_kg, "must be > 0 for a map (its margin is the load "
                                                            "borne over the weight)")
        count = len(self.x[1]) * len(self.y[1])
        if count > MAX_MAP_POINTS:
            raise InputError("--map", f"{len(self.x[1])} x {len(self.y[1])}",
                             f"is {count} points; at most {MAX_MAP_POINTS} (e.g. 50 x 50)")


def map_point(m: HoldMap, values: dict):
    """(object, pump pressure [MPa], pull direction) at a map point {axis: value}."""
    obj = m.obj
    if "size" in values:
        obj = scaled(obj, values["size"])
    if "mass" in values:
        obj = replace(obj, mass_kg=float(values["mass"]))
    if "friction" in values:
        obj = replace(obj, friction=float(values["friction"]))
    pull = pull_from_angle(values["pull"]) if "pull" in values else np.asarray(m.pull, float)
    return obj, values.get("pressure", m.pressure_MPa), pull


def run_map(m: HoldMap, progress=None) -> list[dict]:
    """The map's rows (module doc); ``progress(done, total)`` after each point."""
    d = hold_fast.finger_design(m.design, m.finger_model)
    cache, rows = {}, []
    (xn, xs), (yn, ys) = m.x, m.y
    total, done = len(xs) * len(ys), 0
    for yv in ys:
        for xv in xs:
            obj, P_pump, pull = map_point(m, {xn: float(xv), yn: float(yv)})
            key = (round(float(P_pump), 12), obj.shape, obj.diameter_mm, obj.length_mm, obj.size_mm)
            if key not in cache:
                placed = place_object(obj, d)
                Pc = hold.cavity_pressure(float(P_pump), placed, d)
                cache[key] = (placed, hold_fast.close_hand(Pc, placed, d), {})
            placed, closed, slides = cache[key]
            along = slides.setdefault(tuple(np.round(np.asarray(pull, float), 12)), {})  # by pull: the slide's poses
            r = hold.solve_hold(d, obj, P_cavity_MPa=closed.P_cavity, pull_direction=pull, placed=placed,
                                closed=closed, slide_hands=along)
            weight = obj.mass_kg * d.g
            raw = r.extra.get("limit_pull_N")
            margin = math.inf if weight == 0 else (0.0 if raw is None else (weight + raw) / weight)
            rows.append({xn: float(xv), yn: float(yv), "held": r.held, "holding_limit_N": r.holding_limit_N,
                         "margin": margin, "P_pump_MPa": r.P_pump_MPa, "P_cavity_MPa": r.P_cavity_MPa,
                         "contacts": len(r.contacts)})
            done += 1
            if progress is not None:
                progress(done, total)
    return rows


def write_map(m: HoldMap, rows: list[dict], out) -> list:
    """``hold_map.csv`` and ``hold_map.png`` in folder ``out``; the paths."""
    from pathlib import Path

    from softhand.studies.io.files import figure, save_figure, write_csv

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    paths = [write_csv(out / "hold_map.csv", rows)]
    (xn, xs), (yn, ys) = m.x, m.y
    Z = np.array([r["margin"] for r in rows], float).reshape(len(ys), len(xs))
    Z = np.where(np.isfinite(Z), Z, np.nan)
    fig, axes = figure()
    ax = axes[0]
    X, Y = np.meshgrid(np.asarray(xs, float), np.asarray(ys, float))
    if len(xs) > 1 and len(ys) > 1:
        top = np.nanmax(Z) if np.any(np.isfinite(Z)) else 1.0
        ax.contourf(X, Y, np.nan_to_num(Z, nan=1e9), levels=[1.0, 1e10], colors=["#cfe8cf"])
        levels = [v for v in (1.0, 1.5, 2.0, 3.0, 5.0) if v <= max(top, 1.0)]
        cs = ax.contour(X, Y, Z, levels=levels, colors="k", linewidths=[2.0] + [0.8] * (len(levels) - 1))
        ax.clabel(cs, fmt=lambda v: f"{v:g}x")
    ax.scatter(X[Z >= 1.0], Y[Z >= 1.0], s=4, c="#2a7a2a", label="held")
    ax.scatter(X[~(Z >= 1.0)], Y[~(Z >= 1.0)], s=4, c="#b03030", label="not held")
    for name, draw in ((xn, ax.axvline), (yn, ax.axhline)):
        if name == "pressure":
            draw(m.max_pump_MPa, color="#1f4fb4", ls="--", label=f"pump limit {m.max_pump_MPa:g} MPa")
    ax.set_xlabel(f"{AXES[xn][0]} [{AXES[xn][1]}]")
    ax.set_ylabel(f"{AXES[yn][0]} [{AXES[yn][1]}]")
    pose = "".join(f", {word} {', '.join(f'{v:g}' for v in values)} {unit}" for word, values, unit in
                   (("turned", m.obj.rotation_deg, "deg about x, y, z"), ("moved", m.obj.offset_mm, "mm"))
                   if any(values))
    ax.set_title(f"hold map: {m.obj.describe()}{pose}\ncontours: load borne / weight", fontsize=10)
    ax.legend(loc="best", fontsize=7)
    paths.append(save_figure(fig, out / "hold_map.png"))
    return paths
