"""Case functions of the batch runner's kinds that have no module of their own.

Each has the kind signature ``fn(case_params: dict, design, outdir) -> dict of numbers``
(see :mod:`softhand.studies.batch.studyfile`) and calls the owning library; imports stay inside the
functions so a worker only imports what its kind needs.
"""
from __future__ import annotations

import math
from pathlib import Path

from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError


def curve(params: dict, design: HandDesign, outdir: Path) -> dict:
    """One point of the free-finger curve: eq. (27) with and (28) without reservoir.

    ``theta_deg`` -> P_pump_MPa, P_cavity_MPa (= the pump pressure without reservoir), V_mm3, p_reservoir_MPa (+ h_mm, lambda_r: ellipse model);
    ``pressure_mpa`` -> theta_deg, theta_no_reservoir_deg (the inverse).
    """
    from softhand.studies.curve import at_angles, at_pressures

    if ("theta_deg" in params) == ("pressure_mpa" in params):
        raise InputError("curve", sorted(params), "give exactly one of theta_deg, pressure_mpa")
    if "theta_deg" in params:
        row = at_angles(params["theta_deg"], design)[0]
        return {k: v for k, v in row.items() if k != "theta_deg"}
    row = at_pressures(params["pressure_mpa"], design)[0]
    return {k: row[k] for k in ("theta_deg", "theta_no_reservoir_deg")}


def grasp(params: dict, design: HandDesign, outdir: Path) -> dict:
    """Eqs. (24), (25), (29) at one state (:func:`softhand.studies.grasp.state`): F_x, F_y, F_v for (P, theta, m) and w.

    ``weights`` (n_s numbers) or ``diameter_mm`` (the paper's presets, 180 or 240).
    """
    from softhand.reduced.equations.grasp import check_weights, weights_for_diameter
    from softhand.studies.grasp import state

    if "weights" in params:
        w = check_weights(params["weights"], design)
    else:
        w = weights_for_diameter(params.get("diameter_mm", 180.0), design)
    s = state(params["pressure_mpa"], params["theta_deg"], params.get("mass_kg", 0.0), w, design)
    return {k: s[k] for k in ("F_x_N", "F_y_N", "F_v_N", "F_v_kgf", "w")}


def control(params: dict, design: HandDesign, outdir: Path) -> dict:
    """The flexibility experiment (Table II) at one setting (:mod:`softhand.studies.control`)."""
    from softhand.studies.control import ControlStudy, run

    result = run(ControlStudy(design=design, theta_ref=math.radians(params.get("theta_ref_deg", 50.0)),
                              mass_kg=params.get("mass_kg", 2.0), diameter_mm=params.get("diameter_mm", 180.0),
                              push_n=params.get("push_n", 5.0), push_at_s=params.get("push_at_s", 5.0),
                              t_end_s=params.get("t_end_s", 10.0)))
    s = result.flex.angle_summary
    out = {"settling_time_s": s.settling_time, "P_before_MPa": s.P_before,
           "P_during_MPa": s.P_during, "theta_during_deg": math.degrees(s.theta_during)}
    out |= {f"F_v_{r['state']}_kgf": r["F_v_estimated_kgf"] for r in result.rows}
    return out


def reservoir(params: dict, design: HandDesign, outdir: Path) -> dict:
    """The reservoir sheet by FEM against the ellipse model over the fingers' stroke.

    ``mesh_size_mm`` sets the elements along the radius and through the thickness;
    ``theta_max_deg`` the largest finger bend of the operating range (default 90).
    """
    from softhand.studies.reservoir import ReservoirStudy, run

    mesh = {}
    if "mesh_size_mm" in params:
        h = params["mesh_size_mm"]
        mesh = {"n_radial": max(4, math.ceil(design.R / h)), "n_thick": max(1, math.ceil(design.t / h))}
    result = run(ReservoirStudy(design=design, theta_max=math.radians(params.get("theta_max_deg", 90.0)),
                                **mesh))
    v, at_v0 = result.verdict, result.rows[1]
    out = {f"{key}_rel_error_max": max(abs(v[key]["min"]), abs(v[key]["max"]))
           for key in ("apex_height", "mean_stretch", "strain_energy", "pressure")}
    out |= {"p_V0_MPa": at_v0["p_MPa"], "p_ellipse_V0_MPa": at_v0["p_ellipse_MPa"],
            "stroke_dp_fem_MPa": v["stroke_dp_fem_MPa"],
            "stroke_dp_ellipse_MPa": v["stroke_dp_ellipse_MPa"], "max_gap_mm": v["max_gap_mm"]}
    result.write_vtk(outdir)
    fem = result.fem
    return {**out, "mesh": {**(mesh or {"n_radial": result.study.n_radial,
                                        "n_thick": result.study.n_thick}), "dofs": fem.ndofs},
            "solver": {"newton_iterations": fem.newton_iterations, "wall_time_s": fem.wall_time}}


def weights(params: dict, design: HandDesign, outdir: Path) -> dict:
    """One grasp by FEM (:func:`softhand.studies.weights.run_case`): w, theta, F_v by FEM and eq. (25)."""
    from softhand.studies.weights import WeightsCase, run_case

    case = WeightsCase(design=design, **{k: float(v) for k, v in params.items()})
    return run_case(case, out=outdir).batch_record()  # the VTK series; the runner writes result.json
