"""The whole-hand FEM's holding limits kept as the fast hold model's reference.

``studies/data/hold_fem_limits.json`` holds 61 holds the whole-hand FEM ran (``softhand hold
--model fem``, default finger mesh, the limit resolved to 0.5 % of the pull): the design, the
object, its mass and friction, the pressure, the pull and the FEM's holding limit (0: not held;
then the share of the weight it bore). A case re-run with the FEM's pull drawn by displacement
(``--pull-control displacement``: the limit the first maximum of the pull along the slide) keeps
that limit, and the one its pull stepped as a force reached as ``fem_limit_stepped_N``; the rest
keep the stepped limit until they are re-run (``benchmarks/hold_pull_control.py``).

Spheres, upright, tilted and lying cylinders, cubes (one turned 45°) and a flat box, capsules,
balls that wedge as they slide, a sideways pull, two balls read from STL files (built here by the
recipe the file names), boxes and cubes turned about the palm's axis, cylinders at other angles,
on the paper's design and four others; 44 held (one with 5 % of its weight to spare, one with
0.7 %: none with its pull stepped), 17 not; most of them were run after the fast model had been
built, to test it. No fast-model number was fitted to them: they are what the fast model is
measured against (docs/grasp.md) and what ``tests/studies/test_hold_reference.py``
holds it to. Each FEM run takes minutes; :func:`compare` runs the fast model on all of them in seconds:

    python benchmarks/hold_fast_vs_fem.py --reference

Units: N, mm, MPa, kg.
"""
from __future__ import annotations

import json
import tempfile
from dataclasses import replace
from importlib import resources
from pathlib import Path
from typing import NamedTuple

import numpy as np

from softhand.reduced.holding import hold_fast
from softhand.reduced.holding.hand_layout import place_object
from softhand.reduced.holding.hold import DOWN, cavity_pressure, solve_hold
from softhand.reduced.holding.objects import object_from_table
from softhand.reduced.vocabulary.design import HandDesign


class Row(NamedTuple):
    """One reference hold: the FEM's limit and the fast model's on the same case."""

    name: str
    P_cavity_MPa: float
    weight_N: float
    fem_limit_N: float    #: 0: not held, or held with no pull to spare
    fem_margin: float     #: the FEM's load borne over the weight, less 1 (not held: the share it bore, less 1)
    fast_held: bool
    fast_limit_N: float

    @property
    def fem_held(self) -> bool:
        return self.fem_margin >= 0.0

    @property
    def error(self) -> float:
        """fast / FEM - 1 of the holding limit (nan unless both hold and the FEM's limit is above 0)."""
        if not (self.fem_held and self.fast_held and self.fem_limit_N > 0.0):
            return float("nan")
        return self.fast_limit_N / self.fem_limit_N - 1.0

    @property
    def load_error(self) -> float:
        """fast / FEM - 1 of the load borne along the pull, weight + holding limit (what a margin of
        "hold k times the weight" asks for; nan unless both hold)."""
        if not (self.fem_held and self.fast_held):
            return float("nan")
        return (self.weight_N + self.fast_limit_N) / (self.weight_N + self.fem_limit_N) - 1.0


def load() -> dict:
    """The reference file's contents (``about``, ``designs``, ``meshes``, ``cases``)."""
    text = resources.files("softhand.studies").joinpath("data/hold_fem_limits.json").read_text(encoding="utf-8")
    return json.loads(text)


def design_of(case: dict, designs: dict) -> HandDesign:
    """The case's design: the paper's with the named design's changes."""
    changes = designs[case["design"]]
    return replace(HandDesign(), **{k: tuple(v) if isinstance(v, list) else v for k, v in changes.items()})


def build_mesh(name: str, folder: Path) -> Path:
    """The STL of the reference mesh ``name`` (the recipe in the file's ``meshes``), written into folder."""
    path = Path(folder) / f"{name}.stl"
    if name == "icosphere":
        import trimesh

        trimesh.creation.icosphere(subdivisions=4, radius=90.0).export(path)
        return path
    if name != "scanned":
        raise ValueError(f"no recipe for the reference mesh {name!r}")
    import pyvista

    ball = pyvista.Icosphere(radius=1.0, nsub=5)
    x = np.asarray(ball.points, float)
    polar, azimuth = np.arccos(np.clip(x[:, 1], -1.0, 1.0)), np.arctan2(x[:, 2], x[:, 0])
    noise = np.random.default_rng(2).standard_normal(len(x))
    ball.points = x * (90.0 + 1.5 * np.sin(3 * polar) * np.cos(2 * azimuth + 0.4) + 0.2 * noise)[:, None]
    ball.save(path)
    return path


def case_inputs(case: dict, designs: dict, folder: Path):
    """(design, object, cavity pressure [MPa]) of one reference case (meshes built into ``folder``)."""
    design = design_of(case, designs)
    table = dict(case["object"], mass_kg=case["mass_kg"], friction=case["friction"])
    if table["shape"] == "mesh":
        table["file"] = str(build_mesh(table["file"], folder))
    obj = object_from_table(table, source=case["name"])
    P = case.get("P_cavity_MPa")
    if P is None:  # a design task's optimum, given by its pump pressure
        P = cavity_pressure(case["P_pump_MPa"], place_object(obj, hold_fast.finger_design(design, "fem")), design)
    return design, obj, P


def run_case(case: dict, designs: dict, folder: Path) -> Row:
    """The fast hold model on one reference case (meshes built into ``folder``)."""
    design, obj, P = case_inputs(case, designs, folder)
    result = solve_hold(design, obj, P_cavity_MPa=P, pull_direction=case.get("pull", DOWN))
    weight = case["mass_kg"] * design.g
    limit = float(case["fem_limit_N"])
    margin = limit / weight if limit > 0.0 else float(case["fem_weight_share"]) - 1.0
    return Row(case["name"], float(P), weight, limit, margin, result.held, result.holding_limit_N)


def compare(progress=None) -> list[Row]:
    """The fast model on every reference case, in the file's order; ``progress(done, total)``."""
    data = load()
    rows = []
    with tempfile.TemporaryDirectory(prefix="softhand-reference-") as folder:
        for case in data["cases"]:
            rows.append(run_case(case, data["designs"], Path(folder)))
            if progress is not None:
                progress(len(rows), len(data["cases"]))
    return rows


def summary(rows: list[Row]) -> dict:
    """How close the fast model is: verdicts agreeing (all cases), and over the cases both hold, how
    many fast limits lie within 5 and 10 % of the FEM's, the rms and the median of the absolute error,
    and the same of the load borne (``load_*``); ``differ``: the cases whose verdicts differ, with the
    FEM's margin."""
    both = [r for r in rows if r.fem_held and r.fast_held]
    e, L = np.abs([r.error for r in both if r.fem_limit_N > 0.0]), np.abs([r.load_error for r in both])
    return {"cases": len(rows), "verdicts_agree": sum(r.fem_held == r.fast_held for r in rows),
            "differ": [(r.name, r.fem_margin) for r in rows if r.fem_held != r.fast_held],
            "both_held": len(both), "within_5_percent": int(np.sum(e <= 0.05)),
            "within_10_percent": int(np.sum(e <= 0.10)), "rms_percent": float(100 * np.sqrt(np.mean(e ** 2))),
            "median_percent": float(100 * np.median(e)),
            "load_within_5_percent": int(np.sum(L <= 0.05)), "load_within_10_percent": int(np.sum(L <= 0.10)),
            "load_median_percent": float(100 * np.median(L))}
