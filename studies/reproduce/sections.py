"""The sections of ``softhand reproduce``: one function per result of the paper.

Each builder ``build(ctx, outdir) -> (markdown, numbers)`` calls the owning library
function, writes its CSV/PNG/VTK files into ``outdir`` and returns the Markdown body
(links relative to ``outdir``) and its headline numbers. No printing; no CLI calls.
The FEM sections live in :mod:`softhand.studies.reproduce.fem_sections`; the paper's numbers they
compare with come from :mod:`softhand.reduced.vocabulary.paper`.
"""
from __future__ import annotations

import functools
import math
import warnings
from pathlib import Path

import numpy as np

from softhand.studies.io.files import figure, save_figure, write_csv
from softhand.reduced.vocabulary import paper
from softhand.studies.reproduce.section import Context, Section, md_table


# ---------------------------------------------------------------------- Fig. 7, reduced
def fig7_reduced(ctx: Context, outdir: Path):
    """Eq. (27) with and (28) without reservoir over 0-90 deg; the reservoir's offset."""
    from softhand.studies.curve import at_angles, at_pressures, plot_curves

    d = ctx.design
    theta_deg = np.arange(0.0, 90.0 + 1e-9, 1.0)
    rows = at_angles(theta_deg, d)
    P, P0 = (np.array([r[k] for r in rows]) for k in ("P_pump_MPa", "P_cavity_MPa"))
    offset = P0 - P
    write_csv(outdir / "fig7_reduced.csv", rows, ["theta_deg", "P_pump_MPa", "P_cavity_MPa"])
    pressures = np.round(np.arange(0.0, 0.8 + 1e-9, 0.1), 10)
    by_p = at_pressures(pressures, d, strict=False)
    write_csv(outdir / "fig7_reduced_by_pressure.csv", by_p)
    P_fem, why = _pressure_fem_reservoir(np.radians(theta_deg), d)
    plot_curves(outdir / "fig7_reduced.png", [("the paper's design", d, rows)],
                title="Fig. 7 analogue: reduced model", markers=False,
                extra=[] if P_fem is None else [("eq. (27), FEM-calibrated reservoir", P_fem, theta_deg)],
                xlim=(-0.15, None))
    numbers = {"offset_mean_MPa": float(offset.mean()), "offset_min_MPa": float(offset.min()),
               "offset_max_MPa": float(offset.max()), "P_at_0deg_MPa": float(P[0]),
               "P_at_90deg_MPa": float(P[-1])}
    if P_fem is not None:
        numbers["offset_mean_fem_reservoir_MPa"] = float(np.mean(P0 - P_fem))
    text = f"""Free fingers, the paper's design; θ = 0–90° in 1° steps
([fig7_reduced.csv](fig7_reduced.csv)), and θ at the paper's pressures 0–0.8 MPa
([fig7_reduced_by_pressure.csv](fig7_reduced_by_pressure.csv)).

![Fig. 7 analogue](fig7_reduced.png)

The reservoir lowers the pressure needed for a bend by {offset.mean():.4f} MPa on average
over 0–90° (from {offset.min():.4f} to {offset.max():.4f} MPa); the paper says about
{paper.RESERVOIR_OFFSET_MPA} MPa. With the reservoir P(0) = {P[0]:.4f} MPa < 0: at zero pump
pressure the charged sheet already bends the fingers a little.
{_fem_reservoir_note(P0, P_fem, why)}

{md_table(by_p)}
"""
    return text, numbers


def _pressure_fem_reservoir(theta, design):
    """(eq. (27) with the FEM-calibrated reservoir model, None) or (None, why not)."""
    from softhand.reduced.equations import hand

    try:
        return hand.pressure(theta, design.replace(reservoir_model="fem"), reservoir=True), None
    except Exception as exc:  # an optional line of the figure: say why it is missing
        return None, f"{type(exc).__name__}: {exc}"


def _fem_reservoir_note(P0, P_fem, why) -> str:
    if P_fem is None:
        return f"(No FEM-calibrated reservoir line: {why}.)"
    offset = P0 - P_fem
    return (f"With the FEM-calibrated reservoir model (`reservoir_model = \"fem\"`) the "
            f"offset is {offset.mean():.4f} MPa on average ({offset.min():.4f} to "
            f"{offset.max():.4f} MPa).")


# ---------------------------------------------------------------------- Table II, reduced
def table2_reduced(ctx: Context, outdir: Path):
    """F_v by eqs. (24), (25), (29) at the three (P, θ) of Table II, m = 2 kg, 180 mm w."""
    from softhand.reduced.equations.grasp import KGF, WeightSumWarning, check_weights, grasp_forces

    d = ctx.design
    w_paper = np.asarray(paper.WEIGHTS[180.0])
    w_unit = check_weights(w_paper, d, normalise=True)
    rows = []
    for state, (P, theta_deg, F_paper) in paper.TABLE_II.items():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", WeightSumWarning)  # stated in the text below
            F = grasp_forces(P, math.radians(theta_deg), 2.0, w_paper, d).F_v / KGF
        F_unit = grasp_forces(P, math.radians(theta_deg), 2.0, w_unit, d).F_v / KGF
        rows.append({"state": state, "P_pump_MPa": P, "theta_deg": theta_deg, "F_v_paper_kgf": F_paper,
                     "F_v_kgf": float(F), "F_v_w_normalised_kgf": float(F_unit)})
    write_csv(outdir / "table2_reduced.csv", rows)
    numbers = {f"F_v_{r['state']}_kgf": r["F_v_kgf"] for r in rows}
    numbers |= {f"F_v_{r['state']}_w_normalised_kgf": r["F_v_w_normalised_kgf"] for r in rows}
    text = f"""The grasping force the reduced model gives for the three (P, θ) states of
Table II, m = 2 kg, with the paper's 180 mm weight vector w = {tuple(w_paper.tolist())} exactly as
printed (Σw = {w_paper.sum():.2f}, violating eq. (23)) and normalised to Σw = 1
([table2_reduced.csv](table2_reduced.csv)).

{md_table(rows)}

The paper's flexibility claim is that the push under angle control (c) leaves a lower
force than the push under pressure control (b). With these (P, θ) the model gives
F_v(c) = {rows[2]['F_v_kgf']:.3f} and F_v(b) = {rows[1]['F_v_kgf']:.3f} kgf (w as printed):
{_ordering_verdict(rows[1]['F_v_kgf'], rows[2]['F_v_kgf'])}
A negative F_v means eq. (25) finds the finger pulled toward the object rather than
pressing on it at that (P, θ).
"""
    return text, numbers


def _ordering_verdict(F_b: float, F_c: float) -> str:
    """Whether F_v(c) < F_v(b) is a statement about grasping forces at all."""
    if F_b <= 0 and F_c <= 0:
        return ("neither state presses on the object (both F_v <= 0), so the comparison "
                "says nothing about flexibility.")
    return f"the ordering {'holds' if F_c < F_b else 'does not hold'}."


# ---------------------------------------------------------------------- Fig. 8, reduced
def fig8_reduced(ctx: Context, outdir: Path):
    """F_v(θ) by eq. (25), (29) at the paper's pressures for 2 kg/180 mm and 6 kg/240 mm."""
    from softhand.reduced.equations.grasp import KGF, WeightSumWarning, angle_at, grasp_forces

    d = ctx.design
    theta_deg = np.arange(0.0, 90.0 + 1e-9, 1.0)
    fig, axes = figure(2)
    rows, numbers = [], {}
    for ax, (D, mass, pressures, *_) in zip(axes, paper.FIG8):
        w = np.asarray(paper.WEIGHTS[D])
        for P in pressures:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", WeightSumWarning)
                F_v = grasp_forces(P, np.radians(theta_deg), mass, w, d).F_v / KGF
                theta_free = float(np.degrees(angle_at(P, mass, w, d)))
            ax.plot(theta_deg, F_v, label=f"{P} MPa")
            rows += [{"diameter_mm": D, "mass_kg": mass, "P_pump_MPa": P, "theta_deg": t, "F_v_kgf": f}
                     for t, f in zip(theta_deg, F_v)]
            numbers[f"theta_F0_{D:.0f}mm_{P}MPa_deg"] = theta_free
        ax.axhline(0.0, color="k", lw=0.6)
        ax.set(xlabel="bend angle θ [deg]", ylabel="F_v [kgf]",
               title=f"{mass:g} kg, {D:g} mm, paper's w")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    save_figure(fig, outdir / "fig8_reduced.png")
    write_csv(outdir / "fig8_reduced.csv", rows)
    free = [{"diameter_mm": D, "mass_kg": m, "P_pump_MPa": P,
             "theta_at_F_v_0_deg": numbers[f"theta_F0_{D:.0f}mm_{P}MPa_deg"]}
            for D, m, ps, *_ in paper.FIG8 for P in ps]
    text = f"""Eq. (25) solved for F_x, with F_y = mg/n (24) and F_v by (29), against θ at the
paper's grasp pressures, with the paper's w vectors as printed
([fig8_reduced.csv](fig8_reduced.csv)). The paper compares such lines with measured
points (errors {' and '.join(f'{g.error_kgf:g}' for g in paper.FIG8)} kgf); the
measurements are not public, so only the model side is reproduced here. The angle at
which F_v falls to 0 (the finger just stops pressing) at each pressure:

![Fig. 8 analogue](fig8_reduced.png)

{md_table(free)}
"""
    return text, numbers


# ---------------------------------------------------------------------- Table II and Fig. 10, controller
@functools.lru_cache(maxsize=4)
def _flexibility(ctx: Context):
    """Angle control to 50 deg holding 2 kg, a 5 N push at 5 s; then pressure control (Table II).
    Both sections take the one simulation of a context."""
    from softhand.studies.control import ControlStudy, run

    return run(ControlStudy(design=ctx.design))


def table2_control(ctx: Context, outdir: Path):
    """Table II by simulation: the three states of the flexibility experiment."""
    result = _flexibility(ctx)
    study = result.study
    columns = ["state", "P_pump_MPa", "theta_deg", "F_v_estimated_kgf", "F_v_actual_mean_N",
               "paper_P_pump_MPa", "paper_theta_deg", "paper_F_v_kgf"]
    columns = [c for c in columns if c in result.rows[0]]  # the paper's columns: its own hand only
    write_csv(outdir / "table2_control.csv", result.rows)
    F = {r["state"]: r["F_v_estimated_kgf"] for r in result.rows}
    numbers = {f"F_v_{k}_kgf": v for k, v in F.items()}
    numbers["P_a_MPa"] = result.rows[0]["P_pump_MPa"]
    verdict = "holds" if F["c_push_angle_control"] < F["b_push_pressure_control"] else "does not hold"
    text = f"""The simulated hand (reduced-model statics, pump and finger lags; the paper's
design and 180 mm w) holds a 2 kg object under angle control at θ_ref = 50° (eqs. (30),
(31)); a {study.push_n:g} N horizontal push ramps up from {study.push_at_s:g} s in {study.push_rise_s:g} s. Pressure control then holds
the pressure angle control had before the push. Each state's F_v is estimated as the
paper does, by eq. (25) from the window-mean P and θ; the plant's actual mean pad force is
next to it ([table2_control.csv](table2_control.csv)).

{md_table(result.rows, columns)}

The paper's flexibility result — the push under angle control (c) leaves a lower force
than under pressure control (b) — {verdict} in this simulation:
F_v(c) = {F['c_push_angle_control']:.3f} kgf, F_v(b) = {F['b_push_pressure_control']:.3f} kgf
(paper: {paper.TABLE_II['c_push_angle_control'][2]} and {paper.TABLE_II['b_push_pressure_control'][2]} kgf).
"""
    return text, numbers


def fig10_control(ctx: Context, outdir: Path):
    """Fig. 10 analogue: finger angles and pressure against time, angle vs pressure control."""
    result = _flexibility(ctx)
    study = result.study
    result.plot(outdir / "fig10_control.png", "angle")
    write_csv(outdir / "fig10_control.csv", result.series("angle"))  # at the sensor rate, 100 Hz
    s = result.flex.angle_summary
    numbers = {"settling_time_s": s.settling_time, "theta_error_deg": math.degrees(s.theta_error),
               "P_before_MPa": s.P_before, "P_during_MPa": s.P_during,
               "theta_before_deg": math.degrees(s.theta_before),
               "theta_during_deg": math.degrees(s.theta_during)}
    text = f"""Angle control to θ_ref = 50° with a 2 kg object; a {study.push_n:g} N push from
{study.push_at_s:g} s ([fig10_control.csv](fig10_control.csv), angle control, 100 Hz).
Settling time {s.settling_time:.2f} s (±1°), steady error {math.degrees(s.theta_error):.3f}°;
pressure {s.P_before:.3f} MPa before and {s.P_during:.3f} MPa during the push; mean angle
{math.degrees(s.theta_before):.2f}° before and {math.degrees(s.theta_during):.2f}° during it.
In the paper the pressure drops under the push ({paper.TABLE_II['b_push_pressure_control'][0]} → {paper.TABLE_II['c_push_angle_control'][0]} MPa).

![Fig. 10 analogue](fig10_control.png)
"""
    return text, numbers


REDUCED_SECTIONS: list[Section] = [
    Section("fig7_reduced", "Fig. 7: pressure and bend angle, reduced model",
            ("softhand.reduced.equations.hand:pressure",), fig7_reduced),
    Section("table2_reduced", "Table II: grasping force, reduced model",
            ("softhand.reduced.equations.grasp:grasp_forces", "softhand.reduced.vocabulary.paper:TABLE_II"), table2_reduced),
    Section("fig8_reduced", "Fig. 8 analogue: grasping force against bend angle",
            ("softhand.reduced.equations.grasp:angle_at",), fig8_reduced),
    Section("table2_control", "Table II: angle control vs pressure control, simulated",
            ("softhand.studies.control:run", "softhand.studies.control:ControlStudy"), table2_control),
    Section("fig10_control", "Fig. 10 analogue: angle control under a push",
            ("softhand.studies.control:run", "softhand.studies.control:ControlStudy"), fig10_control),
]
