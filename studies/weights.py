"""Hinge weight vectors w from the grasp FEM, over object diameters; F_v against eq. (25).

* :func:`weights` -- one grasp case (diameter, mass, cavity pressure, mesh) through the FEM
  (:mod:`softhand.fem.hand.grasp`), cached on disk by its inputs: w, theta, hinge angles, contact forces,
  F_v from the FEM and from eq. (25) with this w at the same P, theta, m.
  :func:`run_case` wraps it in a :class:`CaseResult` that summarises and writes itself.
* :func:`run` (:class:`WeightsStudy`) -- w(D) over diameters, and w at an unseen diameter
  by interpolation checked against the FEM there (:class:`WeightsResult`: summary, plot, write).
* The Fig. 8 analogue (F_v against theta at several pressures) is :mod:`softhand.studies.fig8`.

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

from softhand.reduced.equations import grasp
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.io.files import json_text, jsonable, read_bounded, write_json

#: bump when the FEM or the result's fields change, to invalidate cached results
CACHE_FORMAT = 6  # 6: the pressure named P_cavity_MPa, eq. (25)'s F_v_reduced_note; 5: entries {format, key, sha256, result}; 4: factorisations counted; 3: the finger's windings on their own degree-5 rule, mesh graded at the ring edges
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


def cache_dir():
    """``$SOFTHAND_CACHE/weights`` (default ``~/.cache/softhand/weights``), next to the meshes."""
    from softhand.meshes.cache import cache_dir as mesh_cache_dir

    return mesh_cache_dir().parent / "weights"


def reduced_F_v(P: float, theta: float, mass: float, w, design: HandDesign) -> float | None:
    """Eq. (25) -> (29) at cavity pressure P [MPa], theta [rad]: F_v [N]; None if J_x w = 0."""
    try:
        return float(grasp.grasp_forces(P, theta, mass, w, design, reservoir=False).F_v)
    except InputError:
        return None


#: eq. (25)'s F_v further than this from the FEM's, relative, is printed with why
NOTE_RTOL = 0.1


def reduced_note(F_v_red: float | None, F_v_fem: float, N, design: HandDesign) -> str | None:
    """Why eq. (25)'s F_v [N] is not to be trusted where it is further than ``NOTE_RTOL`` from
    the FEM's (N: each link's contact force [N]); None where it is close."""
    if F_v_red is None or abs(F_v_red - F_v_fem) <= NOTE_RTOL * abs(F_v_fem):
        return None
    links = [k for k, n in enumerate(N) if n > 0]
    where = f"touches link {', '.join(map(str, links))} of {design.n_s}" if links else "is not touched"
    return (f"eq. (25) charges the pressure's work to a force at the fingertip, but the object {where}: "
            f"its F_v is {F_v_red / F_v_fem:.3g} x the FEM's; use F_v_fem_N" if F_v_fem > 0 else
            f"eq. (25) charges the pressure's work to a force at the fingertip, but the object {where}; "
            "use F_v_fem_N")


def state_row(state, w, mass: float, design: HandDesign) -> dict:
    """The reported numbers of one converged contact state (forces physical, hand frame)."""
    F_v_red = reduced_F_v(state.P, state.theta, mass, w, design)
    return {"P_cavity_MPa": state.P, "theta_deg": math.degrees(state.theta),
            "hinge_deg": np.degrees(state.q).tolist(), "contact_force_N": state.N.tolist(),
            "F_x_fem_N": float(state.F[0]), "F_y_fem_N": float(state.F[1]),
            "F_v_fem_N": state.F_v, "F_v_reduced_N": F_v_red,
            "F_v_error_kgf": None if F_v_red is None else (F_v_red - state.F_v) / grasp.KGF,
            "F_v_reduced_note": reduced_note(F_v_red, state.F_v, state.N, design),
            "max_penetration_mm": float(np.max(-state.gap[state.N > 0], initial=0.0)),
            "contact_updates": state.updates, "contact_penalty_N_per_mm": state.penalty,
            "newton_iterations": state.iterations, "factorizations": state.factorizations}


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


def rubber_stretches(finger, state) -> dict:
    """The tube's converged ``rubber_stretch`` and its corner peak ``max_principal_stretch``
    (mesh-dependent) at a grasp state (:mod:`softhand.fem.rubber_stretch`)."""
    fs = finger.state(state.y, state.P)
    return {"rubber_stretch": fs.rubber_stretch, "max_principal_stretch": fs.max_principal_stretch}


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

    A cache entry is used only if it is valid (:func:`read_entry`); an invalid one is
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


#: keys and types every cached result has
_SCHEMA = {"w": list, "w_sum": float, "theta_deg": float, "F_v_fem_N": float,
           "diameter_mm": float, "mesh_size_mm": float, "ndofs": int}


def _checksum(result: dict) -> str:
    return hashlib.sha256(json.dumps(result, sort_keys=True, default=jsonable).encode()).hexdigest()


#: the largest cache entry read (one grasp's numbers: a few kB)
MAX_ENTRY_BYTES = 1 << 20


def read_entry(path: Path, key: str) -> dict | None:
    """The cached result at ``path`` if it is there and valid (format, key, schema, checksum)."""
    if not (path.exists() or path.is_symlink()):
        return None
    try:
        entry = json.loads(read_bounded(path, MAX_ENTRY_BYTES))  # a FIFO: refused, not waited on
        result = entry["result"]
        valid = (entry["format"] == CACHE_FORMAT and entry["key"] == key
                 and entry["sha256"] == _checksum(result)
                 and all(isinstance(result.get(k), t if t is not float else (int, float))
                         for k, t in _SCHEMA.items()))
    except (OSError, ValueError, KeyError, TypeError, RecursionError):  # RecursionError: nested deep
        valid = False
    if valid:
        return result
    print(f"softhand: warning: invalid cache entry {path.name}; recomputing it", file=sys.stderr)
    return None


def write_entry(path: Path, key: str, result: dict) -> None:
    """Cache ``result`` with its format, key and checksum; a failure to write is a warning."""
    result = json.loads(json_text(result))  # as it reads back
    try:
        write_json(path, {"format": CACHE_FORMAT, "key": key, "sha256": _checksum(result),
                          "result": result})
    except OSError as exc:
        print(f"softhand: warning: the result is not cached ({path.parent}: "
              f"{exc.strerror or exc})", file=sys.stderr)


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
