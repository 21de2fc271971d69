"""Hinge weight vectors w from the grasp FEM, over object diameters; F_v against eq. (25).

* :func:`weights` -- one grasp case (diameter, mass, cavity pressure, mesh) through the FEM
  (:mod:`softhand.fem.hand.grasp`), cached on disk by its inputs: w, theta, hinge angles, contact forces,
  F_v from the FEM and from eq. (25) with this w at the same P, theta, m.
  :func:`run_case` wraps it in a :class:`CaseResult` that summarises and writes itself.
* :func:`run` (:class:`WeightsStudy`) -- w(D) over diameters, and w at an unseen diameter
  by interpolation checked against the FEM there (:class:`WeightsResult`: summary, plot, write).
* The Fig. 8 analogue (F_v against theta at several pressures) is :mod:`softhand.studies.fig8`.

The cache is :mod:`softhand.studies.weights_cache`; a state's reported numbers (eq. (25)'s
F_v beside the FEM's) are in :mod:`softhand.studies.weights_rows`.

``softhand weights``, ``softhand grasp --diameter-mm``, the batch kind ``weights`` and the
``weights_fem`` section of ``softhand reproduce`` only choose the inputs.

Pressures: P is the finger's cavity pressure. Eq. (25) is evaluated without the reservoir
term at P, which equals eq. (25) with the reservoir at the pump pressure P - p_r(V(theta))
(docs/conventions.md), so no reservoir model enters the comparison.
"""
from __future__ import annotations

import hashlib
import json
import math
import sys
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np

from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.io.files import jsonable, write_json
from softhand.studies.weights_cache import CACHE_FORMAT, cache_dir, read_entry, write_entry
from softhand.studies.weights_rows import rubber_stretches, state_row

#: the default element size of the grasp FEM [mm] (docs/grasp.md: w's mesh sensitivity)
MESH_SIZE = 6.0


@dataclass(frozen=True)
class WeightsCase:
    """One grasp: the inputs that determine w (and the cache key)."""

    design: HandDesign = field(default_factory=HandDesign)
    diameter_mm: float = 180.0
    mass_kg: float = 0.0
    pressure_mpa: float = 0.8      #: cavity pressure of the first state
    dP_mpa: float = 0.05           #: pressure step to the second state
    mesh_size_mm: float = MESH_SIZE
    depth_mm: float | None = None  #: object centre below the palm; None: fem.hand.grasp.default_depth

    def key(self) -> str:
        """Hash of the inputs, the cache format and the package version."""
        values = {k: v for k, v in asdict(self).items() if k != "design"}
        blob = json.dumps({"design": self.design.to_dict(), **values, "format": CACHE_FORMAT,
                           "version": _package_version()}, sort_keys=True, default=jsonable)
        return hashlib.sha256(blob.encode()).hexdigest()[:20]


def _package_version() -> str:
    from softhand.reduced.vocabulary.versions import package_version

    return package_version()


def failed_record(case: WeightsCase, states) -> dict:
    """result.json's fields of a grasp FEM that stopped: the case and the states it reached
    (the last one's contact may not have converged: its penetration says by how much)."""
    rows = [{"P_cavity_MPa": s.P, "theta_deg": math.degrees(s.theta), "hinge_deg": np.degrees(s.q).tolist(),
             "contact_force_N": s.N.tolist(), "F_v_fem_N": s.F_v,
             "max_penetration_mm": float(np.max(-s.gap[s.N > 0], initial=0.0))} for s in states]
    return {"diameter_mm": case.diameter_mm, "mass_kg": case.mass_kg, "P_cavity_MPa": case.pressure_mpa,
            "dP_MPa": case.dP_mpa, "mesh_size_mm": case.mesh_size_mm,
            "last_converged_P_cavity_MPa": rows[-1]["P_cavity_MPa"] if rows else 0.0, "states": rows,
            "design": case.design.to_dict()}


def finger_options(mesh_size_mm: float):
    """The grasp FEM's finger mesh: graded (element size mesh_size_mm, half that at the ring
    edges), not refined; pinned here so that it does not follow the free-bending default."""
    from softhand.fem.hand.finger import FingerOptions

    return FingerOptions(mesher="gmsh", mesh_size=mesh_size_mm, edge_ratio=0.5, edge_reach=3.0, mesh_refine=0)


def compute(case: WeightsCase, out=None, progress=None) -> dict:
    """Run the grasp FEM for one case (no cache): the flat result; with ``out`` (a folder)
    also the two states' fields as the VTK scene series ``grasp.pvd`` (hand, object, contact
    forces); ``progress`` is called with each of the two states as it converges."""
    from softhand.fem.hand.finger import FingerModel
    from softhand.fem.hand.grasp import GraspModel, grasp_weights
    from softhand.fem.newton import NotConverged

    finger = FingerModel(case.design, finger_options(case.mesh_size_mm))
    model = GraspModel(finger, case.diameter_mm, mass=case.mass_kg, depth=case.depth_mm)
    try:
        r = grasp_weights(model, case.pressure_mpa, case.dP_mpa, on_state=progress)
    except NotConverged as err:
        err.case = case  # which grasp stopped (the verb saves err.states)
        raise
    if out is not None:
        write_vtk(out, model, (r.state, r.state_dP))
    return {"diameter_mm": case.diameter_mm, "mass_kg": case.mass_kg, "depth_mm": model.depth,
            "dP_MPa": case.dP_mpa, "w": r.w.tolist(), "w_sum": float(r.w.sum()),
            **state_row(r.state, r.w, case.mass_kg, case.design), **rubber_stretches(finger, r.state),
            "mesh_size_mm": case.mesh_size_mm, "ndofs": r.ndofs, "wall_seconds": r.wall_seconds}


def write_vtk(out, model, states) -> None:
    """The contact states as the scene series grasp.pvd (see :mod:`softhand.fem.hand.scene`)."""
    from softhand.fem.io import SceneSeries
    from softhand.fem.hand.scene import grasp_scene

    series = SceneSeries(Path(out) / "grasp.pvd")
    for s in states:
        series.write(s.P, *grasp_scene(model, s))


def weights(case: WeightsCase, *, cache: bool = True, out=None, progress=None) -> dict:
    """:func:`compute`, through the JSON cache keyed by :meth:`WeightsCase.key` (``cached`` says
    which); ``out``: a folder for the VTK series grasp.pvd (always computes). The result is
    returned, not written: the caller decides where it goes.

    A cache entry is used only if it is valid (:func:`softhand.studies.weights_cache.read_entry`); an invalid one is
    recomputed and replaced, with a warning. A cache that cannot be written is a warning.
    """
    path = cache_dir() / f"{case.key()}.json"
    if out is None and cache:
        entry = read_entry(path, case.key())
        if entry is not None:
            return _untouched_said(case, {**entry, "cached": True})
    more = {} if progress is None else {"progress": progress}  # each converged state (a bar)
    result = compute(case, **more) if out is None else compute(case, out, **more)
    if cache:
        write_entry(path, case.key(), result)
    return _untouched_said(case, {**result, "cached": False})


def _untouched_said(case: WeightsCase, result: dict) -> dict:
    """A warning where the finger does not touch the object at the case's pressure (no contact
    force): its w is then the free finger's bend, not the grasp's."""
    forces = result.get("contact_force_N")
    if forces is not None and not any(f > 0.0 for f in forces):
        print(f"softhand: warning: the finger does not touch the {case.diameter_mm:g} mm object at "
              f"{case.pressure_mpa:g} MPa (theta {result['theta_deg']:.3g} deg, no contact force): its w "
              f"is the free finger's bend, not a grasp's{_reduced_contact(case, result.get('depth_mm'))}",
              file=sys.stderr)
    return result


def _reduced_contact(case: WeightsCase, depth: float | None) -> str:
    """Where the reduced model's free finger touches the object, as a hint (or nothing)."""
    from softhand.reduced.equations import contact, hand
    from softhand.reduced.vocabulary.errors import InputError

    try:
        theta, _ = contact.contact_angle(case.diameter_mm, case.design, depth=depth)
        P = float(hand.finger_pressure(theta, case.design))
    except (InputError, ValueError):
        return ""
    return (f"; the reduced model's finger touches it at theta {math.degrees(theta):.3g} deg "
            f"(cavity pressure {P:.3g} MPa)")


@dataclass(frozen=True)
class CaseResult:
    """One grasp case: its flat numbers (:func:`weights`) and the files computing it wrote."""

    case: WeightsCase
    record: dict               #: :func:`compute`'s result, with ``cached``
    files: tuple = ()          #: written into the ``out`` folder while computing (grasp.pvd)

    def summary(self) -> dict:
        """The flat numbers (``softhand weights --json`` for one diameter; result.json)."""
        return self.record

    def write(self, out) -> list[str]:
        """result.json into the folder ``out``; the names there (with the VTK series)."""
        write_json(Path(out) / "result.json", self.record)
        return ["result.json", *self.files]

    def batch_record(self) -> dict:
        """The numbers a batch case keeps: w, theta, F_v, the mesh and the solver's cost."""
        r = self.record
        keep = ("w", "w_sum", "theta_deg", "hinge_deg", "F_v_fem_N", "F_v_reduced_N", "contact_force_N")
        return {**{k: r[k] for k in keep if r.get(k) is not None},
                "mesh": {"mesh_size_mm": r["mesh_size_mm"], "dofs": r["ndofs"]},
                "solver": {"newton_iterations": r["newton_iterations"], "factorizations": r["factorizations"],
                           "wall_time_s": r["wall_seconds"]}}


def run_case(case: WeightsCase, *, cache: bool = True, out=None, progress=None) -> CaseResult:
    """:func:`weights` as a :class:`CaseResult`; ``out``: a folder for grasp.pvd (computes);
    ``progress``: called with each converged grasp state."""
    return CaseResult(case, weights(case, cache=cache, out=out, progress=progress),
                      () if out is None else ("grasp.pvd",))


def interpolate(diameters, ws, diameter: float) -> np.ndarray:
    """w at ``diameter`` [mm], piecewise linear in D between tabulated (diameters, ws (m, n_s));
    a convex combination of vectors summing to 1 sums to 1."""
    D = np.asarray(diameters, dtype=float)
    if not D.min() <= diameter <= D.max():
        raise InputError("diameter_mm", diameter, f"must be within the table [{D.min():g}, {D.max():g}]")
    ws = np.asarray(ws, dtype=float)
    return np.array([np.interp(diameter, D, ws[:, i]) for i in range(ws.shape[1])])


@dataclass(frozen=True)
class WeightsStudy:
    """w(D) over diameters at one pressure and mass, and its interpolation check."""

    case: WeightsCase = field(default_factory=WeightsCase)   #: everything but the diameter
    diameters_mm: tuple[float, ...] = (120.0, 150.0, 180.0, 210.0, 240.0, 270.0, 300.0)
    check_mm: float | None = 165.0  #: an unseen diameter: interpolated w vs the FEM there


@dataclass(frozen=True)
class WeightsResult:
    rows: list        #: one :func:`weights` result per diameter
    check: dict | None  #: diameter, w_interpolated, w_fem, max_abs_difference

    def summary(self) -> dict:
        """The w(D) table and the interpolation check (``softhand weights --json``)."""
        return {"rows": self.rows, "check": self.check}

    def write(self, out) -> list[str]:
        """result.json (:meth:`summary`) and table.csv (the rows) into the folder ``out``."""
        from softhand.studies.io.files import write_csv

        write_json(Path(out) / "result.json", self.summary())
        write_csv(Path(out) / "table.csv", self.rows)
        return ["result.json", "table.csv"]

    def plot(self, path) -> None:
        """w_i against D (:func:`softhand.studies.io.weights_plot.plot_weights`)."""
        from softhand.studies.io.weights_plot import plot_weights

        plot_weights(path, self)


def run(study: WeightsStudy, *, cache: bool = True, progress=None) -> WeightsResult:
    """The FEM at every diameter (cached), then the interpolation check."""
    rows = []
    for D in study.diameters_mm:
        rows.append(weights(replace(study.case, diameter_mm=float(D)), cache=cache))
        if progress is not None:
            progress(rows[-1])
    check = None
    if study.check_mm is not None:
        fem = weights(replace(study.case, diameter_mm=float(study.check_mm)), cache=cache)
        w_int = interpolate([r["diameter_mm"] for r in rows], [r["w"] for r in rows], study.check_mm)
        check = {"diameter_mm": study.check_mm, "w_interpolated": w_int.tolist(), "w_fem": fem["w"],
                 "max_abs_difference": float(np.max(np.abs(w_int - np.array(fem["w"]))))}
    return WeightsResult(rows, check)
