"""``softhand control``: the 2-DOF angle controller (eqs. (30), (31)) on the simulated hand.

Runs angle control to theta_ref holding the object, with a push on the object (``--push-N``
at ``--push-at-s``, or a force profile from ``--disturbance FILE``), and pressure control
holding the pressure angle control had just before the push. Prints the summary of the
``--mode`` run (settling time, steady error, P and mean angle before/during the push) and
the grasping force in the three states of Table II next to the paper's numbers. The plant
and its parameters: reduced/plant.py and docs/control.md.

Disturbance file: CSV, header ``t_s,force_N``, then rows of time [s] (increasing, >= 0) and
push force [N]; ``#`` lines are comments. Between rows the force is interpolated linearly;
before the first row it is 0, after the last row it keeps the last value.
"""
from __future__ import annotations

import csv
import math
import sys
import warnings
from pathlib import Path

import numpy as np

from softhand.reduced import grasp
from softhand.reduced.control import Gains, default_gains, flexibility, ramp
from softhand.reduced.errors import InputError
from softhand.reduced.plant import HandTables, PlantParams, Push
from softhand.studies.cli.args import add_design_option, add_json_option, check_range, design_from_args, \
    print_json, print_table
from softhand.studies.io.control_files import plot_fig10, series_rows
from softhand.studies.io.files import kept_if_unwritable, write_csv, write_json

HELP = "simulate angle control (eqs. 30, 31) vs pressure control under a push (Table II, Fig. 10)"
DISTURBANCE_HEADER = ("t_s", "force_N")


def configure(parser) -> None:
    parser.add_argument("--theta-ref-deg", type=float, required=True, help="reference mean bend angle [deg]")
    parser.add_argument("--mass-kg", type=float, required=True, help="mass of the grasped object [kg]")
    parser.add_argument("--mode", choices=("angle", "pressure"), default="angle",
                        help="which run to summarise, plot and print first (both are simulated)")
    push = parser.add_mutually_exclusive_group()
    push.add_argument("--disturbance", metavar="FILE", help="push profile, CSV t_s,force_N")
    push.add_argument("--push-N", type=float, default=5.0, help="push force [N] (default 5)")
    parser.add_argument("--push-at-s", type=float, default=5.0, help="push start [s] (default 5)")
    parser.add_argument("--push-rise-s", type=float, default=0.5,
                        help="time the push takes to build up [s] (default 0.5; 0 = a step)")
    parser.add_argument("--push-azimuth-deg", type=float, default=0.0,
                        help="push direction about the vertical, from finger 1's outward direction")
    parser.add_argument("--push-elevation-deg", type=float, default=0.0,
                        help="push direction below the horizontal (90 = down, -90 = lifting)")
    parser.add_argument("--t-end-s", type=float, default=10.0, help="simulated time [s] (default 10)")
    parser.add_argument("--kp", type=float, help="proportional gain [MPa/deg] (default: from the plant)")
    parser.add_argument("--ki", type=float, help="integral gain [MPa/(deg s)] (default: from the plant)")
    parser.add_argument("--no-anti-windup", action="store_true", help="integrate through saturation")
    parser.add_argument("--diameter-mm", type=float, default=180.0,
                        help="object diameter, picks the paper's weight vector w (180 or 240)")
    parser.add_argument("--plant-mu-scale", type=float, default=1.0,
                        help="the simulated hand's mu_sf, mu_sr relative to the design's (mismatch)")
    _plant_options(parser)
    parser.add_argument("--plot", metavar="FILE.png", help="angles and pressure vs time (Fig. 10 analogue)")
    parser.add_argument("--out", metavar="DIR", help="write control_angle.csv, control_pressure.csv "
                                                     "(at the sensor rate) and summary.json")
    add_design_option(parser)
    add_json_option(parser)


def _plant_options(parser) -> None:
    d = PlantParams()
    parser.add_argument("--tau-f-s", type=float, default=d.tau_f, help=f"finger lag [s] (default {d.tau_f})")
    parser.add_argument("--tau-m-s", type=float, default=d.tau_m, help=f"pump motor lag [s] (default {d.tau_m})")
    parser.add_argument("--q-max-mm3-s", type=float, default=d.q_max,
                        help=f"pump flow limit [mm^3/s] (default {d.q_max:g})")
    parser.add_argument("--p-max-mpa", type=float, default=d.P_max, help=f"pump pressure limit [MPa] (default {d.P_max})")
    parser.add_argument("--sample-hz", type=float, default=d.sample_hz,
                        help=f"sensor/controller rate [Hz] (default {d.sample_hz:g})")
    parser.add_argument("--noise-deg", type=float, default=0.0, help="angle sensor noise, std [deg]")
    parser.add_argument("--noise-mpa", type=float, default=0.0, help="pressure sensor noise, std [MPa]")
    parser.add_argument("--seed", type=int, default=0, help="of the sensor noise")


def read_disturbance(path: str | Path):
    """The push profile of a ``t_s,force_N`` CSV file as a function of t [s]; InputError on bad files."""
    path = Path(path)
    from softhand.reduced.design import read_input_file

    data = read_input_file(path, "--disturbance", "a CSV file t_s,force_N")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise InputError("--disturbance", str(path), "is not a text (CSV) file") from None
    rows = [(number, cells) for number, cells in enumerate(csv.reader(text.splitlines()), start=1)
            if cells and "".join(cells).strip() and not cells[0].lstrip().startswith("#")]
    if not rows or tuple(c.strip() for c in rows[0][1]) != DISTURBANCE_HEADER:
        raise InputError("--disturbance", str(path), f"must start with the header {','.join(DISTURBANCE_HEADER)}")
    if len(rows) < 2:
        raise InputError("--disturbance", str(path), "has no data rows")
    values = np.array([_row(path, number, cells) for number, cells in rows[1:]])
    t, force = values[:, 0], values[:, 1]
    if np.any(t < 0) or np.any(np.diff(t) <= 0):
        bad = int(np.flatnonzero(np.concatenate([[t[0] < 0], np.diff(t) <= 0]))[0])
        raise InputError(f"--disturbance {path.name}: line {rows[bad + 1][0]}", float(t[bad]),
                         "times must be >= 0 and strictly increasing")
    return lambda x: np.interp(x, t, force, left=0.0, right=force[-1])


def _row(path: Path, number: int, cells: list[str]) -> tuple[float, float]:
    where = f"--disturbance {path.name}: line {number}"
    if len(cells) != 2:
        raise InputError(where, ",".join(cells), "must be two numbers: t_s,force_N")
    try:
        t, force = float(cells[0]), float(cells[1])
    except ValueError:
        raise InputError(where, ",".join(cells), "must be two numbers: t_s,force_N") from None
    if not (math.isfinite(t) and math.isfinite(force)):
        raise InputError(where, ",".join(cells), "must be finite numbers")
    lo, hi = LIMITS["--push-N"]
    if not (t <= 600 and lo <= force <= hi):
        raise InputError(where, ",".join(cells), f"t_s must be at most 600 s and force_N in [{lo:g}, {hi:g}]")
    return t, force


def _check_inputs(args) -> None:
    checks = [("--theta-ref-deg", args.theta_ref_deg, -30 < args.theta_ref_deg < 120, "in (-30, 120) deg"),
              ("--mass-kg", args.mass_kg, args.mass_kg >= 0, ">= 0"),
              ("--t-end-s", args.t_end_s, 2.0 <= args.t_end_s <= 600, "in [2, 600] s"),
              ("--push-at-s", args.push_at_s, 1.0 <= args.push_at_s < args.t_end_s, "in [1 s, t_end)"),
              ("--push-rise-s", args.push_rise_s, args.push_rise_s >= 0, ">= 0"),
              ("--plant-mu-scale", args.plant_mu_scale, args.plant_mu_scale > 0, "> 0"),
              ("--noise-deg", args.noise_deg, args.noise_deg >= 0, ">= 0"),
              ("--noise-mpa", args.noise_mpa, args.noise_mpa >= 0, ">= 0")]
    for name, value, ok, allowed in checks:
        if not (ok and math.isfinite(value)):
            raise InputError(name, value, f"must be {allowed}")
    for option, (lo, hi) in LIMITS.items():
        value = getattr(args, option[2:].replace("-", "_"))
        if value is not None:
            check_range(option, value, lo, hi)
    if args.diameter_mm not in grasp.PAPER_WEIGHTS:
        raise InputError("--diameter-mm", args.diameter_mm,
                         f"must be one of {', '.join(f'{D:g}' for D in grasp.PAPER_WEIGHTS)}")


#: option -> (lowest, highest) allowed, beyond the checks above
LIMITS = {"--push-N": (-1000.0, 1000.0), "--push-rise-s": (0.0, 600.0),
          "--push-azimuth-deg": (-360.0, 360.0), "--push-elevation-deg": (-90.0, 90.0),
          "--kp": (0.0, 100.0), "--ki": (0.0, 1000.0), "--plant-mu-scale": (0.01, 100.0),
          "--tau-f-s": (1e-3, 100.0), "--tau-m-s": (1e-3, 100.0), "--q-max-mm3-s": (1.0, 1e7),
          "--p-max-mpa": (0.01, 10.0), "--sample-hz": (1.0, 1000.0), "--noise-deg": (0.0, 30.0),
          "--noise-mpa": (0.0, 1.0), "--seed": (0, 2**32 - 1), "--mass-kg": (0.0, 100.0)}


def _setup(args):
    """(design, plant design, plant params, w, push, force profile, gains) from the arguments."""
    design = design_from_args(args)
    plant_design = design.replace(mu_sf=args.plant_mu_scale * design.mu_sf,
                                  mu_sr=args.plant_mu_scale * design.mu_sr)
    plant = PlantParams(tau_f=args.tau_f_s, tau_m=args.tau_m_s, q_max=args.q_max_mm3_s,
                        P_max=args.p_max_mpa, sample_hz=args.sample_hz,
                        noise_theta=math.radians(args.noise_deg), noise_P=args.noise_mpa, seed=args.seed)
    with warnings.catch_warnings():  # the paper's 180 mm w sums to 1.40; reported in the output
        warnings.simplefilter("ignore", grasp.WeightSumWarning)
        w = grasp.weights_for_diameter(args.diameter_mm, design)
    push = Push(math.radians(args.push_azimuth_deg), math.radians(args.push_elevation_deg))
    force = read_disturbance(args.disturbance) if args.disturbance else \
        ramp(args.push_N, args.push_at_s, args.push_rise_s)
    gains = default_gains(HandTables(design, w), plant)
    if args.kp is not None or args.ki is not None:
        per_rad = 180.0 / math.pi  # MPa/deg -> MPa/rad
        gains = Gains(kp=gains.kp if args.kp is None else args.kp * per_rad,
                      ki=gains.ki if args.ki is None else args.ki * per_rad)
    gains = Gains(gains.kp, gains.ki, anti_windup=not args.no_anti_windup)
    return design, plant_design, plant, w, push, force, gains


def _summary_dict(s) -> dict:
    """The summary in edge units; nan (not applicable, e.g. no push) becomes None (JSON null)."""
    deg = math.degrees
    return {key: None if isinstance(value, float) and math.isnan(value) else value for key, value in {"mode": s.mode, "settling_time_s": s.settling_time, "theta_error_deg": deg(s.theta_error),
            "P_error_MPa": s.P_error, "P_before_MPa": s.P_before, "theta_before_deg": deg(s.theta_before),
            "P_during_MPa": s.P_during, "theta_during_deg": deg(s.theta_during),
            "fingers_during_deg": [deg(x) for x in s.fingers_during],
            "push_start_s": s.push_start, "push_end_s": s.push_end}.items()}


def run(args) -> int:
    _check_inputs(args)
    design, plant_design, plant, w, push, force, gains = _setup(args)
    theta_ref = math.radians(args.theta_ref_deg)
    result = flexibility(design, theta_ref, args.mass_kg, w, force, push=push, gains=gains, plant=plant,
                         plant_design=plant_design, t_end=args.t_end_s)
    chosen, other = (result.angle_summary, result.pressure_summary) if args.mode == "angle" \
        else (result.pressure_summary, result.angle_summary)
    report = {"mode": args.mode, "summary": _summary_dict(chosen), "other_mode": _summary_dict(other),
              "table2": result.rows,
              "gains": {"kp_MPa_per_deg": math.radians(gains.kp), "ki_MPa_per_deg_s": math.radians(gains.ki),
                        "anti_windup": gains.anti_windup},
              "plant": {k: getattr(plant, k) for k in PlantParams.__dataclass_fields__},
              "push": {"azimuth_deg": args.push_azimuth_deg, "elevation_deg": args.push_elevation_deg,
                       "source": args.disturbance or f"{args.push_N:g} N at {args.push_at_s:g} s, "
                                                      f"rise {args.push_rise_s:g} s"},
              "w": [float(x) for x in w], "design": design.to_dict()}
    if args.out:
        out = Path(args.out)
        with kept_if_unwritable(out, "control"):
            write_csv(out / "control_angle.csv", series_rows(result.angle, plant.steps_per_sample))
            write_csv(out / "control_pressure.csv", series_rows(result.pressure, plant.steps_per_sample))
            write_json(out / "summary.json", report)
    if args.plot:
        with kept_if_unwritable(args.plot, "control"):
            plot_fig10(args.plot, result, args.mode, args.theta_ref_deg)
    if result.angle_summary.P_before >= plant.P_max - 1e-3:
        print(f"softhand control: warning: angle control saturates the pump at P_max = {plant.P_max:g} MPa "
              f"before the push; theta_ref is not reached", file=sys.stderr)
    if args.json:
        print_json(report)
    else:
        _print_text(report)
    return 0


def _print_text(report: dict) -> None:
    """The summary of both runs side by side, then Table II."""
    s = report["summary"]
    print(f"{s['mode']} control; push: {report['push']['source']} "
          f"(azimuth {report['push']['azimuth_deg']:g} deg, elevation {report['push']['elevation_deg']:g} deg)")
    g = report["gains"]
    print(f"gains: kp = {g['kp_MPa_per_deg']:.4g} MPa/deg, ki = {g['ki_MPa_per_deg_s']:.4g} MPa/(deg s), "
          f"anti-windup {'on' if g['anti_windup'] else 'off'}")
    rows = [{"": name, "angle control": report[key if report["mode"] == "angle" else other][name],
             "pressure control": report[other if report["mode"] == "angle" else key][name]}
            for name in ("settling_time_s", "theta_error_deg", "P_error_MPa", "P_before_MPa",
                         "theta_before_deg", "P_during_MPa", "theta_during_deg", "fingers_during_deg")
            for key, other in [("summary", "other_mode")]]
    print_table(rows)
    if report["table2"]:
        print("\nTable II: F_v estimated as the paper does, eqs. (25), (29) from the mean P and theta")
        print_table([{"state": r["state"], "P_MPa": r["P_MPa"], "theta_deg": r["theta_deg"],
                      "F_v_kgf": r["F_v_estimated_kgf"], "F_v_actual_N": r["F_v_actual_mean_N"],
                      "paper_P_MPa": r["paper_P_MPa"], "paper_theta_deg": r["paper_theta_deg"],
                      "paper_F_v_kgf": r["paper_F_v_kgf"]} for r in report["table2"]])
    sys.stdout.flush()
