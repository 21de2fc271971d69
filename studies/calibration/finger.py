"""Calibrating the reduced finger model ``"fem"``: the finger FEM over a design space.

A *design space* (:mod:`softhand.studies.calibration.space`, a TOML file such as
``studies/finger_space.toml``) names the designs.

Each design is one case of the batch runner (:mod:`softhand.studies.batch.runner`, kind
``finger_bend``: resumable, a local pool or Dask); :func:`bend_case` runs the free-bending
FEM of :mod:`softhand.studies.bending` on the default (layered) mesh at the pressures, and on
until ``theta_target_deg`` in steps of at most ``p_step_mpa`` while P <= ``p_max_mpa``.
The finished cases become the nondimensional rows of
``reduced/calibrated/data/finger_fem.csv`` (see :mod:`softhand.reduced.calibrated.finger_fem`); :mod:`softhand.studies.calibration.finger_table`
writes it and checks a table against held-out designs.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from softhand.reduced.vocabulary.design import HandDesign
from softhand.studies.batch.studyfile import Study
from softhand.studies.calibration.space import PATH_KEYS, VARIABLES, DesignSpace, finger_design

@dataclass(frozen=True)
class SpaceStudy(Study):
    """A design space as a study of the batch runner: one ``finger_bend`` case per design."""

    case_list: tuple[tuple[dict, HandDesign], ...] = ()  #: (params, design) of every case

    def cases(self) -> list[tuple[dict, HandDesign]]:
        return list(self.case_list)


def as_study(space: DesignSpace) -> SpaceStudy:
    """The runner's study of a design space (results/<name>/, resumable)."""
    return SpaceStudy(name=space.name, kind="finger_bend", design=space.base,
                      axes=tuple((key, ()) for key in VARIABLES), params=space_params(space),
                      description="finger FEM over a design space",
                      case_list=tuple(design_cases(space) + mesh_pair_cases(space)))


def space_params(space: DesignSpace) -> dict:
    """The case parameters every design of the space shares (load path and mesh)."""
    params = {"pressures_mpa": list(space.pressures_mpa), "theta_target_deg": space.theta_target_deg,
              "p_max_mpa": space.p_max_mpa, "p_step_mpa": space.p_step_mpa}
    if space.mesh_size_mm is not None:
        params["mesh_size_mm"] = space.mesh_size_mm
    if space.axial_size_mm is not None:
        params["axial_size_mm"] = space.axial_size_mm
    return params


def case_options(params: dict):
    """The finger FEM's mesh of one case: the default, a uniform gmsh mesh (``mesh_size_mm``) or
    the layered mesh with longer slices (``axial_size_mm``)."""
    from softhand.fem.hand.finger_options import mesh_options

    return mesh_options(params.get("mesh_size_mm"), params.get("axial_size_mm"))


def check_memory(space: DesignSpace, src: str) -> None:
    """Refuse a space whose mesh (``mesh_size_mm`` or ``axial_size_mm``) is too large for this
    machine's memory on one of its designs, when it is read, not as failed cases."""
    if space.mesh_size_mm is None and space.axial_size_mm is None:
        return
    from softhand.studies.batch.registry import finger_mesh_fits

    params = space_params(space)
    for design in space.designs():
        finger_mesh_fits(params, design, src)


#: the space's longer slices (``axial_size_mm``) are used only where they put at least this many
#: slices across the untied gap between two rings; other designs run on the default mesh (one
#: 5 mm slice across a 5 mm gap bends 26 % less than the default mesh's two, where three slices
#: and more agree with the default mesh's six to 1.6 %: docs/finger.md)
MIN_GAP_SLICES = 3


def resolves_gap(design: HandDesign, axial_size: float) -> bool:
    """Whether slices of ``axial_size`` [mm] put MIN_GAP_SLICES across the design's untied gap."""
    gap = min(design.link_lengths) - design.tie_width
    return math.ceil(gap / axial_size - 1e-9) >= MIN_GAP_SLICES


def design_cases(space: DesignSpace) -> list[tuple[dict, HandDesign]]:
    """(params, design) of each design, with its own load-path keys; on the default mesh where
    the space's longer slices would not resolve the design's gap (see :data:`MIN_GAP_SLICES`)."""
    shared = space_params(space)
    cases = []
    for p, d in zip(space.points, space.designs()):
        params = {**shared, **{k: p[k] for k in PATH_KEYS if k in p}}
        if "axial_size_mm" in params and not resolves_gap(d, params["axial_size_mm"]):
            del params["axial_size_mm"]
        cases.append((params, d))
    return cases


def mesh_pair_cases(space: DesignSpace) -> list[tuple[dict, HandDesign]]:
    """The [mesh_pair] design on the space's mesh and on the default mesh (none if absent)."""
    if space.mesh_pair is None:
        return []
    point, pressures = space.mesh_pair
    design = finger_design(point, space.base)
    path = {"pressures_mpa": list(pressures), "theta_target_deg": space.theta_target_deg,
            "p_max_mpa": pressures[-1], "p_step_mpa": space.p_step_mpa}
    coarse = {k: v for k, v in space_params(space).items() if k in ("mesh_size_mm", "axial_size_mm")}
    return [({**path, **coarse}, design), (path, design)]


# ---------------------------------------------------------------------- one case
def load_path(theta_08: float, space: dict) -> list[float]:
    """Pressures [MPa] after the listed ones: on to theta_target (linear estimate from the
    bend ``theta_08`` [rad] reached at the last listed pressure), in steps <= p_step_mpa."""
    last = space["pressures_mpa"][-1]
    target = math.radians(space["theta_target_deg"])
    if theta_08 >= target or last >= space["p_max_mpa"]:
        return []
    P_end = min(space["p_max_mpa"], last * target / max(theta_08, 1e-6))
    n = math.ceil((P_end - last) / space["p_step_mpa"] - 1e-9)
    return [round(last + (P_end - last) * k / n, 4) for k in range(1, n + 1)]


def cavity_pressures(numbers: dict) -> list:
    """The cavity pressures [MPa] of a ``finger_bend`` case's numbers (``P_cavity_MPa``; cases
    finished before the pressures were named ``P_MPa``, the same cavity pressure)."""
    return numbers["P_cavity_MPa"] if "P_cavity_MPa" in numbers else numbers["P_MPa"]


def bend_case(params: dict, design: HandDesign, outdir: Path) -> dict:
    """Kind ``finger_bend``: the free-bending FEM of one design on the default mesh.

    params: ``pressures_mpa`` (list), ``theta_target_deg``, ``p_max_mpa``, ``p_step_mpa``;
    ``mesh_size_mm`` (optional): a uniform gmsh mesh of that size instead of the default mesh;
    ``axial_size_mm`` (optional): the default (layered) mesh with slices of at most that length.
    Returns P_cavity_MPa, theta_deg, dQ_mm3 (whole finger) and rubber_stretch
    (:mod:`softhand.fem.rubber_stretch`) per converged pressure, and ``rubber_stretch_a_rho``:
    per converged pressure, per a/rho of the table's
    :data:`~softhand.reduced.calibrated.finger_fem_table.A_RHO`, the stretch averaged over a ball
    of radius a / (a/rho) (what a finger of that size, these groups, would report).
    """
    from softhand.fem.hand.finger import FingerModel, solve_pressures
    from softhand.reduced.calibrated.finger_fem_table import A_RHO

    model = FingerModel(design, case_options(params))
    states, stats = solve_pressures(model, params["pressures_mpa"])
    more = load_path(states[-1].theta, params)
    its, facs, wall = stats.newton_iterations, stats.factorizations, stats.wall_seconds
    linear = [stats.solver]  # each sweep's solver: its precision, and why it fell back if it did
    if more:  # restart at the last pressure (its state is converged: ~1 iteration) for the history
        extra, s2 = solve_pressures(model, [states[-1].P, *more], y0=states[-1].y)
        states = states + extra[1:]
        its, facs, wall = its + s2.newton_iterations, facs + s2.factorizations, wall + s2.wall_seconds
        linear.append(s2.solver)
    return {"P_cavity_MPa": [s.P for s in states], "theta_deg": [math.degrees(s.theta) for s in states],
            "dQ_mm3": [s.dQ for s in states],
            "rubber_stretch": [s.rubber_stretch for s in states],
            "rubber_stretch_a_rho": model.rubber_stretches([s.y for s in states],
                                                           [design.a / x for x in A_RHO]).tolist(),
            "mesh": {"mesher": model.options.mesher, "dofs": model.ndofs,
                     "elements": model.mesh.nelements},
            "solver": {"newton_iterations": its, "factorizations": facs, "wall_time_s": wall,
                       "linear_solvers": linear}}
