"""The FEM sections of ``softhand reproduce`` (see :mod:`studies.reproduce_sections`).

Each calls the owning study module's library function with the section's mesh size:
CI-sized with ``--quick``, the module's default otherwise.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from studies.output import save_figure, write_csv
from studies.reproduce import Context, Section
from studies.reproduce_sections import figure, md_table


# ---------------------------------------------------------------------- FEM verification
def verify(ctx: Context, outdir: Path):
    """The FEM core against closed forms (``softhand verify``), case by case."""
    from studies.verify import REGISTRY, run_case

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


# ---------------------------------------------------------------------- reservoir vs ellipse
def reservoir_fem(ctx: Context, outdir: Path):
    """The reservoir sheet by FEM against the paper's half-ellipse model (11)-(18)."""
    from studies.reservoir import COLUMNS, ReservoirStudy, run

    mesh = {"n_radial": 16, "n_thick": 1} if ctx.quick else {}
    with progress_bar("  inflating the sheet", "mm³") as bar:
        result = run(ReservoirStudy(design=ctx.design, **mesh),
                     progress=lambda v: bar.update(v - bar.n))
    write_csv(outdir / "reservoir.csv", result.rows, COLUMNS)
    v = result.verdict
    verdict = [{"quantity": name, "min": v[key]["min"], "max": v[key]["max"], "at_V0": v[key]["at_V0"]}
               for name, key in (("apex height", "apex_height"), ("mean stretch", "mean_stretch"),
                                 ("strain energy", "strain_energy"), ("pressure dW/dV", "pressure"))]
    verdict.append({"quantity": "pressure change over the stroke", "min": v["stroke_dp"],
                    "max": v["stroke_dp"], "at_V0": v["stroke_dp"]})
    write_csv(outdir / "reservoir_verdict.csv", verdict)
    _reservoir_plot(result, ctx.design, outdir / "reservoir.png")
    vtk = write_sheet_vtk(result, outdir)
    fem = result.fem
    numbers = {f"{row['quantity'].replace(' ', '_').replace('/', '_')}_max_rel_error":
               max(abs(row["min"]), abs(row["max"])) for row in verdict}
    numbers |= {"stroke_dp_fem_MPa": v["stroke_dp_fem_MPa"],
                "stroke_dp_ellipse_MPa": v["stroke_dp_ellipse_MPa"], "max_gap_mm": v["max_gap_mm"],
                "dofs": fem.ndofs, "newton_iterations": fem.newton_iterations}
    text = f"""The clamped NBR sheet (R = {ctx.design.R} mm, t = {ctx.design.t} mm), axisymmetric
FEM under volume control, against the half-ellipse model at the same oil volume
([reservoir.csv](reservoir.csv); {fem.ndofs} DOFs, {fem.newton_iterations} Newton iterations,
{fem.wall_time:.1f} s). Operating range: V = {v['V_range_mm3'][0]:.0f}–{v['V_range_mm3'][1]:.0f} mm³
(fingers 0–90°).

{md_table(result.rows, COLUMNS)}

Relative error of the ellipse model, (ellipse − FEM)/FEM, over the operating range
([reservoir_verdict.csv](reservoir_verdict.csv)):

{md_table(verdict)}

The pressure change over the stroke — what the reservoir takes off the pump pressure —
is {v['stroke_dp_fem_MPa']:.4f} MPa by FEM and {v['stroke_dp_ellipse_MPa']:.4f} MPa by the
ellipse model; the largest gap between the profiles is {v['max_gap_mm']:.2f} mm.

![reservoir](reservoir.png)

VTK of the deformed sheet (ParaView, `softhand inspect`): {", ".join(f"[{n}]({n})" for n in vtk)}.
"""
    return text, numbers


def _reservoir_plot(result, design, path: Path) -> None:
    from reduced import reservoir as ellipse

    fig, (ax1, ax2) = figure(2)
    r = np.linspace(0.0, design.R, 101)
    for state, color in zip(result.states, ("C0", "C1", "C2", "C3")):
        h = float(ellipse.height(state.volume, design))
        ax1.plot(r, state.profile_at(r), color=color, label=f"FEM, V = {state.volume:.0f} mm³")
        ax1.plot(r, h * np.sqrt(1 - (r / design.R) ** 2), ":", color=color)
    ax1.set(xlabel="r [mm]", ylabel="z [mm]", title="profiles: FEM (solid), half-ellipse (dotted)")
    V = np.asarray(result.fem.path_volume)
    ax2.plot(V, result.fem.path_pressure, label="FEM")
    keep = V > 0
    ax2.plot(V[keep], ellipse.ellipse_pressure(V[keep], design), ":", label="ellipse model")
    ax2.set(xlabel="V [mm³]", ylabel="p [MPa]", title="reservoir pressure p(V)")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    save_figure(fig, path)


def write_sheet_vtk(result, outdir: Path) -> list[str]:
    """The deformed sheet per volume (r-z section and revolved to 3D) as .vtu files."""
    from fem.reservoir import sheet_vtk
    from meshes.convert import write_vtu

    solid, names = result.fem.model.build()[0], []
    for state in result.states:
        for suffix, (points, cells, data) in zip(("", "_3d"), sheet_vtk(solid, state)):
            name = f"sheet_V{state.volume:.0f}{suffix}.vtu"
            write_vtu(outdir / name, points, cells, point_data=data)
            names.append(name)
    return names


def progress_bar(desc: str, unit: str):
    """A nested tqdm bar (stderr, removed when done) for a long FEM path."""
    from tqdm import tqdm

    return tqdm(desc=desc, unit=unit, leave=False, position=1, file=sys.stderr)


SECTIONS: list[Section] = [
    Section("reservoir_fem", "Reservoir: FEM against the ellipse model",
            ("studies.reservoir:run", "fem.reservoir:sheet_vtk", "meshes.convert:write_vtu"),
            reservoir_fem),
    Section("verify", "FEM verification against closed forms",
            ("studies.verify:run_case", "studies.verify:REGISTRY"), verify, in_quick=False),
]
