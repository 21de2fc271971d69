"""``softhand control``: the 2-DOF angle controller (eqs. (30), (31)) on the simulated hand.

Runs angle control to theta_ref holding the object, with a push on the object (``--push-N``
at ``--push-at-s``, or a force profile from ``--disturbance FILE``), and pressure control
holding the pressure angle control had just before the push. Prints the summary of the
``--mode`` run (settling time, steady error, P and mean angle before/during the push) and
the grasping force in the three states of Table II next to the paper's numbers. The plant
and its parameters: reduced/dynamics/plant.py and docs/control.md. The study itself is
:mod:`softhand.studies.control`; the disturbance file's format: :mod:`softhand.studies.io.control_files`.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

from softhand.reduced.equations import grasp
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.dynamics.plant import PlantParams, Push
from softhand.studies.cli.args import add_design_option, add_json_option, check_range, design_from_args, \
    print_json, print_table
from softhand.studies.io.control_files import PUSH_LIMITS_N
from softhand.studies.io.files import kept_if_unwritable

HELP = "simulate angle control (eqs. 30, 31) vs pressure control under a push (Table II, Fig. 10)"


def configure(parser) -> None:
    parser.add_argument("--theta-ref-deg", type=float, required=True, help="reference mean bend angle [deg]")
    parser.add_argument("--mass-kg", type=float, required=True, help="mass of the grasped object [kg]")
    parser.add_argument("--mode", choices=("angle", "pressure"), default="angle",
                        help="which run to summarise, plot and print first (both are simulated)")
    push = parser.add_mutually_exclusive_group()
    push.add_argument("--disturbance", metavar="FILE", help="push profile, CSV t_s,force_N")
    push.add_argument("--push-N", type=float, default=5.0, help="push force [N] (default 5)")
    parser.add_argument("--push-at-s", type=float, default=None,
                        help=f"push start [s] (default {PUSH_AT_S:g}; not with --disturbance)")
    parser.add_argument("--push-rise-s", type=float, default=None,
                        help=f"time the push takes to build up [s] (default {PUSH_RISE_S:g}; 0 = a "
                             "step; not with --disturbance)")
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


#: the ramp push's start and rise time [s] when not given
PUSH_AT_S, PUSH_RISE_S = 5.0, 0.5


def _check_inputs(args) -> None:
    """Every option in range; the ramp's options only without --disturbance (then filled in)."""
    if args.disturbance is not None:
        for option, value in (("--push-at-s", args.push_at_s), ("--push-rise-s", args.push_rise_s)):
            if value is not None:
                raise InputError(option, value, "not with --disturbance, whose file gives the push")
    args.push_at_s = PUSH_AT_S if args.push_at_s is None else args.push_at_s
    args.push_rise_s = PUSH_RISE_S if args.push_rise_s is None else args.push_rise_s
    checks = [("--theta-ref-deg", args.theta_ref_deg, -30 < args.theta_ref_deg < 120, "in (-30, 120) deg"),
              ("--mass-kg", args.mass_kg, args.mass_kg >= 0, ">= 0"),
              ("--t-end-s", args.t_end_s, 2.0 <= args.t_end_s <= 600, "in [2, 600] s"),
              ("--push-at-s", args.push_at_s, args.disturbance is not None
               or 1.0 <= args.push_at_s < args.t_end_s, "in [1 s, --t-end-s)"),
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
    if args.kp == 0 and args.ki == 0:
        raise InputError("--kp", args.kp, "and --ki are both 0: angle control would not act; give "
                                          "one of them > 0 (or neither, for the plant's gains)")
    if args.disturbance is None and args.push_at_s + args.push_rise_s >= args.t_end_s:
        raise InputError("--push-at-s + --push-rise-s", f"{args.push_at_s:g} + {args.push_rise_s:g} s",
                         f"must bring the push to its full force before --t-end-s = {args.t_end_s:g} s")
    if args.diameter_mm not in grasp.PAPER_WEIGHTS:
        raise InputError("--diameter-mm", args.diameter_mm,
                         f"must be one of {', '.join(f'{D:g}' for D in grasp.PAPER_WEIGHTS)}")


#: option -> (lowest, highest) allowed, beyond the checks above
LIMITS = {"--push-N": PUSH_LIMITS_N, "--push-rise-s": (0.0, 600.0),
          "--push-azimuth-deg": (-360.0, 360.0), "--push-elevation-deg": (-90.0, 90.0),
          "--kp": (0.0, 100.0), "--ki": (0.0, 1000.0), "--plant-mu-scale": (0.01, 100.0),
          "--tau-f-s": (1e-3, 100.0), "--tau-m-s": (1e-3, 100.0), "--q-max-mm3-s": (1.0, 1e7),
          "--p-max-mpa": (0.01, 10.0), "--sample-hz": (1.0, 1000.0), "--noise-deg": (0.0, 30.0),
          "--noise-mpa": (0.0, 1.0), "--seed": (0, 2**32 - 1), "--mass-kg": (0.0, 100.0)}


def study_from_args(args):
    """The :class:`softhand.studies.control.ControlStudy` the arguments ask for (checked)."""
    from softhand.studies.control import ControlStudy

    _check_inputs(args)
    design = design_from_args(args)
    plant = PlantParams(tau_f=args.tau_f_s, tau_m=args.tau_m_s, q_max=args.q_max_mm3_s,
                        P_max=args.p_max_mpa, sample_hz=args.sample_hz,
                        noise_theta=math.radians(args.noise_deg), noise_P=args.noise_mpa, seed=args.seed)
    per_rad = 180.0 / math.pi  # MPa/deg -> MPa/rad
    return ControlStudy(
        design=design, theta_ref=math.radians(args.theta_ref_deg), mass_kg=args.mass_kg,
        diameter_mm=args.diameter_mm, push_n=args.push_N, push_at_s=args.push_at_s,
        push_rise_s=args.push_rise_s, disturbance=args.disturbance,
        push=Push(math.radians(args.push_azimuth_deg), math.radians(args.push_elevation_deg)),
        kp=None if args.kp is None else args.kp * per_rad, ki=None if args.ki is None else args.ki * per_rad,
        anti_windup=not args.no_anti_windup, plant=plant, plant_mu_scale=args.plant_mu_scale,
        t_end_s=args.t_end_s)


def run(args) -> int:
    from softhand.studies.control import FILES, run as run_study
    from softhand.studies.io.outputs import check_output_tree, check_owned, replaced_outputs

    study = study_from_args(args)
    if args.out:
        check_output_tree(args.out, "--out", files=FILES)
        check_owned(args.out, FILES, "--out", "control")
    result = run_study(study)
    with replaced_outputs(args.out, FILES, verb="control") as stage:  # renamed into place when whole
        if stage is not None:
            with kept_if_unwritable(Path(args.out), "control"):
                result.write(stage, args.mode)
    if args.plot:
        with kept_if_unwritable(args.plot, "control"):
            result.plot(args.plot, args.mode)
    P_max = study.plant.P_max
    if result.flex.angle_summary.P_before >= P_max - 1e-3:
        print(f"softhand control: warning: angle control saturates the pump at P_max = {P_max:g} MPa "
              f"before the push; theta_ref is not reached", file=sys.stderr)
    report = result.summary(args.mode)
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
        paper = ("paper_P_pump_MPa", "paper_theta_deg", "paper_F_v_kgf")  # the paper's hand only
        print_table([{"state": r["state"], "P_pump_MPa": r["P_pump_MPa"], "theta_deg": r["theta_deg"],
                      "F_v_kgf": r["F_v_estimated_kgf"], "F_v_actual_N": r["F_v_actual_mean_N"],
                      **{k: r[k] for k in paper if k in r}} for r in report["table2"]])
    sys.stdout.flush()
