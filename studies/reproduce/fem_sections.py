"""The FEM sections of ``softhand reproduce`` (see :mod:`softhand.studies.reproduce.sections`).

Each runs the owning study with the section's mesh size (CI-sized with ``--quick``, the
study's default otherwise) and lets the study's result write, plot and summarise itself;
the section adds only its Markdown text and headline numbers.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from softhand.reduced.vocabulary import paper
from softhand.studies.io.files import figure, save_figure, write_csv
from softhand.studies.reproduce.section import Context, Section, md_table


# ---------------------------------------------------------------------- FEM verification
def verify(ctx: Context, outdir: Path):
    """The FEM core against closed forms (``softhand verify``), case by case."""
    from softhand.studies.verification.registry import REGISTRY, run_case

    rows, errors = [], []
    for name in REGISTRY:
        try:
            checks, seconds = run_case(name, quick=ctx.quick)
        except Exception as exc:  # one broken case must not hide the others
            errors.append(f"- `{name}`: {type(exc).__name__}: {exc}")
            continue
        rows += [{**c.row(), "wall_time_s": seconds} for c in checks]
    if rows:
        write_csv(outdir / "verify.csv", rows)
    passed = sum(bool(r["passed"]) for r in rows)
    numbers = {"checks": len(rows), "passed": passed, "cases_failing_to_run": len(errors),
               "max_rel_error": max((r["rel_error"] for r in rows), default=math.nan)}
    table = md_table(rows, ["case", "quantity", "exact", "fem", "rel_error", "tolerance",
                            "passed"]) if rows else "*no check ran*"
    text = f"""The FEM core against closed forms ({'CI-sized' if ctx.quick else 'default'} meshes):
{passed} of {len(rows)} checks pass ([verify.csv](verify.csv)).

{table}
"""
    if errors:
        text += "\nCases that did not run:\n\n" + "\n".join(errors) + "\n"
    return text, numbers


# ---------------------------------------------------------------------- Fig. 7 with FEM points
def fig7_fem(ctx: Context, outdir: Path):
    """Free bending by finger FEM against eq. (28), and the whole hand (finger FEM + reservoir-
    sheet FEM) against eq. (27)."""
    from softhand.fem.hand.finger import FingerOptions
    from softhand.studies.bending import BendingStudy, run, vtk_writer

    step = 0.2 if ctx.quick else 0.1
    pressures = tuple(np.round(np.arange(0.0, 0.8 + 1e-9, step), 10))
    options = FingerOptions(mesher="gmsh", mesh_size=6.0, edge_ratio=1.0, mesh_refine=0) if ctx.quick else FingerOptions()
    folder = outdir / "bend"  # the files of `softhand bend --hand --out bend`
    with progress_bar("  bending the finger", "pressure", ctx.progress) as bar:
        result = run(BendingStudy(ctx.design, pressures, options, hand=True),
                     on_state=vtk_writer(folder / "finger.pvd", then=lambda model, state: bar.update(1)))
    result.write(folder)
    result.plot(outdir / "fig7_fem.png", title="Fig. 7 with FEM points")
    rows = [{**r, **h} for r, h in zip(result.rows, result.hand.rows)]
    numbers = {"theta_fem_at_max_P_deg": rows[-1]["theta_deg"],
               "theta_eq28_at_max_P_deg": rows[-1]["theta_reduced_deg"],
               "max_abs_theta_difference_deg": float(np.max(np.abs(
                   [r["theta_deg"] - r["theta_reduced_deg"] for r in rows]))),
               "max_abs_hand_pressure_difference_MPa": result.hand.max_abs_difference_MPa(),
               "reservoir_offset_fem_MPa": result.hand.offset_fem_MPa,
               "max_radial_stretch": float(max(r["radial_stretch_max"] for r in rows)),
               "dofs": result.ndofs, "newton_iterations": result.stats.newton_iterations,
               "fem_wall_time_s": result.stats.wall_seconds}
    columns = ["P_cavity_MPa", "theta_deg", "theta_reduced_deg", "dQ_mm3", "dQ_reduced_mm3",
               "radial_stretch_max", "p_reservoir_fem_MPa", "P_pump_fem_MPa", "P_pump_eq27_MPa"]
    text = f"""The finger FEM (half model, rigid links on hinges, {result.ndofs} unknowns,
{'CI mesh 6 mm' if ctx.quick else 'default mesh'}) at {len(rows)} pressures, against eq. (28)
at the same pressure; the whole hand P = p_finger − p_r(V0 − n ΔQ_FEM) with the
reservoir-sheet FEM ({result.hand.reservoir_ndofs} DOFs), against eq. (27) at the FEM angle
([bend/table.csv](bend/table.csv), [bend/hand.csv](bend/hand.csv), VTK series
[bend/finger.pvd](bend/finger.pvd)). Largest |θ_FEM − θ_eq.(28)| =
{numbers['max_abs_theta_difference_deg']:.2f}°; largest |P_hand,FEM − P_eq.(27)| =
{numbers['max_abs_hand_pressure_difference_MPa']:.4f} MPa; reservoir offset p_r(V0) by FEM
{result.hand.offset_fem_MPa:.4f} MPa (paper: about {paper.RESERVOIR_OFFSET_MPA} MPa); largest
radial stretch {numbers['max_radial_stretch']:.4f} (the model assumes 1).

{md_table(rows, columns)}

![Fig. 7 with FEM points](fig7_fem.png)
"""
    return text, numbers


# ---------------------------------------------------------------------- reservoir vs ellipse
def reservoir_fem(ctx: Context, outdir: Path):
    """The reservoir sheet by FEM against the paper's half-ellipse model (11)-(18)."""
    from softhand.studies.reservoir import COLUMNS, ReservoirStudy, run

    mesh = {"n_radial": 16, "n_thick": 1} if ctx.quick else {}
    with progress_bar("  inflating the sheet", " mm³", ctx.progress) as bar:  # whole mm³ of oil
        result = run(ReservoirStudy(design=ctx.design, **mesh),
                     progress=lambda v: bar.update(round(v) - bar.n))
    folder = outdir / "reservoir"  # the files of `softhand reservoir --out reservoir`
    files = result.write(folder)
    result.plot(outdir / "reservoir.png")
    v = result.verdict
    verdict = [{"quantity": name, "min": v[key]["min"], "max": v[key]["max"], "at_V0": v[key]["at_V0"]}
               for name, key in (("apex height", "apex_height"), ("mean stretch", "mean_stretch"),
                                 ("strain energy", "strain_energy"), ("pressure dW/dV", "pressure"))]
    verdict.append({"quantity": "pressure change over the stroke", "min": v["stroke_dp"],
                    "max": v["stroke_dp"], "at_V0": v["stroke_dp"]})
    write_csv(outdir / "reservoir_verdict.csv", verdict)
    fem = result.fem
    numbers = {f"{row['quantity'].replace(' ', '_').replace('/', '_')}_max_rel_error":
               max(abs(row["min"]), abs(row["max"])) for row in verdict}
    numbers |= {"stroke_dp_fem_MPa": v["stroke_dp_fem_MPa"],
                "stroke_dp_ellipse_MPa": v["stroke_dp_ellipse_MPa"], "max_gap_mm": v["max_gap_mm"],
                "dofs": fem.ndofs, "newton_iterations": fem.newton_iterations}
    vtk = [name for name in files if name.endswith((".pvd", ".vtu"))]
    text = f"""The clamped NBR sheet (R = {ctx.design.R} mm, t = {ctx.design.t} mm), axisymmetric
FEM under volume control, against the half-ellipse model at the same oil volume
([reservoir/rows.csv](reservoir/rows.csv), [reservoir/result.json](reservoir/result.json);
{fem.ndofs} DOFs, {fem.newton_iterations} Newton iterations, {fem.wall_time:.1f} s).
Operating range: V = {v['V_range_mm3'][0]:.0f}–{v['V_range_mm3'][1]:.0f} mm³ (fingers 0–90°).

{md_table(result.rows, COLUMNS)}

Relative error of the ellipse model, (ellipse − FEM)/FEM, over the operating range
([reservoir_verdict.csv](reservoir_verdict.csv)):

{md_table(verdict)}

The pressure change over the stroke — what the reservoir takes off the pump pressure —
is {v['stroke_dp_fem_MPa']:.4f} MPa by FEM and {v['stroke_dp_ellipse_MPa']:.4f} MPa by the
ellipse model; the largest gap between the profiles is {v['max_gap_mm']:.2f} mm.

![reservoir](reservoir.png)

VTK of the deformed sheet (ParaView, `softhand inspect`): {", ".join(f"[{n}](reservoir/{n})" for n in vtk)}.
"""
    return text, numbers


# ---------------------------------------------------------------------- w and Fig. 8 by grasp FEM
def weights_fem(ctx: Context, outdir: Path):
    """w for the 180 mm / 2 kg and 240 mm / 6 kg objects by grasp FEM, against the paper's."""
    from softhand.studies.weights import WeightsCase, run_case

    rows, numbers = [], {}
    for D, mass, _, P, _ in paper.FIG8:
        r = run_case(WeightsCase(design=ctx.design, diameter_mm=D, mass_kg=mass, pressure_mpa=P),
                     out=outdir / f"D{D:.0f}").summary()
        w_paper = np.asarray(paper.WEIGHTS[D])
        rows.append({"diameter_mm": D, "mass_kg": mass, "P_cavity_MPa": r["P_cavity_MPa"],
                     "theta_deg": r["theta_deg"], "w_fem": r["w"],
                     "w_paper_normalised": (w_paper / w_paper.sum()).tolist(),
                     "F_v_fem_N": r["F_v_fem_N"], "F_v_reduced_N": r["F_v_reduced_N"],
                     "ndofs": r["ndofs"]})
        numbers |= {f"w{i + 1}_{D:.0f}mm": v for i, v in enumerate(r["w"])}
        numbers[f"max_abs_w_difference_{D:.0f}mm"] = float(np.max(np.abs(
            np.asarray(r["w"]) - w_paper / w_paper.sum())))
    write_csv(outdir / "weights.csv", rows)
    text = f"""Hinge weight vectors w = Δθ̂/Δθ between two converged contact states (P, P + ΔP),
normalised to Σw = 1, for the paper's two objects at a pressure inside the paper's grasp range ([weights.csv](weights.csv); VTK series
[D180/grasp.pvd](D180/grasp.pvd), [D240/grasp.pvd](D240/grasp.pvd)). The paper's vectors
are shown normalised (its 180 mm vector sums to 1.40 as printed).

{md_table(rows, ["diameter_mm", "mass_kg", "P_cavity_MPa", "theta_deg", "w_fem", "w_paper_normalised",
                 "F_v_fem_N", "F_v_reduced_N", "ndofs"], digits=3)}
"""
    return text, numbers


def fig8_fem(ctx: Context, outdir: Path):
    """Fig. 8 analogue with FEM points: F_v by grasp FEM and by eq. (25) at the same (P, θ)."""
    from softhand.studies.fig8 import Fig8Study, run
    from softhand.studies.weights import WeightsCase

    fig, axes = figure(2)
    summary, numbers = [], {}
    for ax, (D, mass, pressures, _, paper_error) in zip(axes, paper.FIG8):
        chosen = (pressures[0], pressures[-1]) if ctx.quick else pressures
        offsets = (0.0,) if ctx.quick else (0.0, 10.0, 20.0)
        case = WeightsCase(design=ctx.design, diameter_mm=D, mass_kg=mass)
        result = run(Fig8Study(case, chosen, offsets))
        result.write(outdir)
        errors = result.errors()
        summary.append({"diameter_mm": D, "mass_kg": mass, "points": len(result.rows), **errors,
                        "paper_error_vs_measurement_kgf": paper_error})
        numbers |= {f"{k}_{D:.0f}mm": v for k, v in errors.items() if v is not None}
        result.draw(ax)
        ax.set_title(f"{mass:g} kg, {D:g} mm")
    save_figure(fig, outdir / "fig8_fem.png")
    text = f"""Grasp FEM at the paper's grasp pressures ({'two pressures, one object depth' if ctx.quick
else 'four pressures, three object depths'}); each point is a converged contact state, and
eq. (25) → (29) is evaluated at the same (P, θ) with that state's FEM w and with the
paper's w (CSV per object). Errors of eq. (25) against the FEM, next to the paper's
errors against its measurements:

{md_table(summary)}

![Fig. 8 with FEM points](fig8_fem.png)
"""
    return text, numbers


def progress_bar(desc: str, unit: str, show: bool = True):
    """A nested tqdm bar (stderr, removed when done) for a long FEM path; ``show`` False: none."""
    from tqdm import tqdm

    return tqdm(desc=desc, unit=unit, leave=False, position=1, file=sys.stderr, disable=not show)


SECTIONS: list[Section] = [
    Section("fig7_fem", "Fig. 7 with finger-FEM points, and the whole hand",
            ("softhand.studies.bending:run", "softhand.studies.bending:BendingStudy",
             "softhand.studies.bending:vtk_writer", "softhand.studies.compare:whole_hand"), fig7_fem, cost=8.0),
    Section("reservoir_fem", "Reservoir: FEM against the ellipse model",
            ("softhand.studies.reservoir:run", "softhand.studies.io.reservoir_files:write_sheet_vtk"),
            reservoir_fem, cost=1.0),
    Section("weights_fem", "w for the 180 mm and 240 mm objects by grasp FEM",
            ("softhand.studies.weights:run_case", "softhand.studies.weights:WeightsCase"), weights_fem, cost=25.0),
    Section("fig8_fem", "Fig. 8 analogue with grasp-FEM points",
            ("softhand.studies.fig8:run", "softhand.studies.fig8:Fig8Study"), fig8_fem, cost=21.0),
    Section("verify", "FEM verification against closed forms",
            ("softhand.studies.verification.registry:run_case", "softhand.studies.verification.registry:REGISTRY"), verify, in_quick=False,
            cost=60.0),
]
