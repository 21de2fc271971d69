"""``softhand weights``: hinge weight vectors w from the grasp FEM (eqs. (21)-(25)).

One diameter: w (n_s values, sum 1), theta, hinge angles, contact forces, F_v from the FEM
and from eq. (25) with this w at the same P, theta, m. Results are cached by input
(``~/.cache/softhand/weights``), so a repeated call is instant.
Several diameters (``--diameter-mm 120:300:30``): the w(D) table, ``--check-mm D`` compares
the interpolated w with the FEM there, ``--plot FILE.png`` draws w(D).
``--fig8 P1,P2,..``: the Fig. 8 analogue for one object (F_v vs theta at those pressures,
theta varied by the object's depth), ``--plot`` draws it.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.vocabulary.paper import FIG8
from softhand.studies.cli.args import MOST_FEM_POINTS, add_design_option, add_json_option, \
    add_max_cases_option, add_progress_option, design_from_args, max_cases, parse_values, print_json, print_table
from softhand.studies.io.values import check_distinct
from softhand.studies.design.task_values import UPPER
from softhand.studies.io.files import kept_if_unwritable
from softhand.studies.io.outputs import replaced_outputs

HELP = "hinge weight vectors w for an object diameter from the grasp FEM; F_v vs eq. (25)"

COLUMNS = ["diameter_mm", "w", "theta_deg", "F_v_fem_N", "F_v_reduced_N", "contact_force_N"]


def configure(parser) -> None:
    from softhand.studies.weights import MESH_SIZE

    parser.add_argument("--diameter-mm", required=True, metavar="D",
                        help="object diameter(s) [mm]: one number, a,b,c or start:stop:step")
    parser.add_argument("--mass-kg", default="0", metavar="M", help="object mass [kg] (default 0)")
    parser.add_argument("--pressure-mpa", default="0.8", metavar="P",
                        help="finger cavity pressure [MPa] (default 0.8)")
    parser.add_argument("--dp-mpa", default="0.05", metavar="DP",
                        help="pressure step between the two contact states [MPa] (default 0.05)")
    parser.add_argument("--mesh-size-mm", default=str(MESH_SIZE), metavar="H",
                        help=f"finger element size [mm] (default {MESH_SIZE:g})")
    parser.add_argument("--depth-mm", metavar="Y",
                        help="object centre below the palm [mm] (default: docs/grasp.md placement)")
    parser.add_argument("--check-mm", metavar="D", help="several diameters: an unseen one to check "
                                                        "the interpolated w against the FEM")
    parser.add_argument("--fig8", metavar="P1,P2,..", help="Fig. 8 analogue at these pressures [MPa]")
    parser.add_argument("--plot", metavar="FILE.png", help="draw w(D) or the Fig. 8 analogue")
    parser.add_argument("--out", metavar="DIR", help="one diameter: write result.json and the VTK "
                                                     "series grasp.pvd of both contact states (recomputes)")
    parser.add_argument("--no-cache", action="store_true", help="recompute, do not read or write the cache")
    add_max_cases_option(parser, MAX_DIAMETERS, MOST_FEM_POINTS)
    add_design_option(parser)
    add_json_option(parser)
    add_progress_option(parser)


#: option -> (lowest, highest) allowed, in the option's unit; the cavity pressure up to the pump
#: limit design tasks allow, so that a design's grasp can be checked at its pump's limit
LIMITS = {"--diameter-mm": (60.0, 500.0), "--mass-kg": (0.0, 20.0),
          "--pressure-mpa": (0.01, UPPER["max_pressure_MPa"]),
          "--dp-mpa": (0.001, 0.5), "--mesh-size-mm": (2.0, 12.0), "--depth-mm": (-1000.0, 1000.0),
          "--check-mm": (60.0, 500.0), "--fig8": (0.01, 3.0)}
#: most diameters of one sweep and pressures of one --fig8 (one grasp FEM each)
MAX_DIAMETERS, MAX_FIG8 = 50, 20


def _values(text, field: str, max_count: int = 1):
    lo, hi = LIMITS[field]
    allowed = f"{'a number' if max_count == 1 else 'numbers'} in [{lo:g}, {hi:g}]"
    values = parse_values(str(text), field, max_count, allowed if max_count == 1 else None)
    if values.min() < lo or values.max() > hi:
        raise InputError(field, text, f"must be {allowed}")
    return values


def _scalar(text, field: str) -> float:
    return float(_values(text, field)[0])


def case_from_args(args):
    from softhand.studies.weights import WeightsCase

    return WeightsCase(design=design_from_args(args), diameter_mm=180.0,
                       mass_kg=_scalar(args.mass_kg, "--mass-kg"),
                       pressure_mpa=_scalar(args.pressure_mpa, "--pressure-mpa"),
                       dP_mpa=_scalar(args.dp_mpa, "--dp-mpa"),
                       mesh_size_mm=_scalar(args.mesh_size_mm, "--mesh-size-mm"),
                       depth_mm=None if args.depth_mm is None else _scalar(args.depth_mm, "--depth-mm"))


def run(args) -> int:
    from softhand.fem.newton import NotConverged

    try:
        return _run(args)
    except NotConverged as exc:  # the FEM's own failure: one line, exit 1
        if getattr(exc, "states", None) and getattr(exc, "case", None) is not None:
            return _failed(exc, Path(args.out or FAILED_OUT))
        print(f"softhand weights: error: the grasp FEM did not converge: {str(exc)[:300]}",
              file=sys.stderr)
        return 1


#: where a failed grasp FEM without --out leaves the states it reached
FAILED_OUT = "results/weights"


def _failed(exc, out: Path) -> int:
    """The grasp FEM stopped: the states it reached (result.json + grasp.pvd) and one error
    line naming the cavity pressure reached; exit code 1."""
    from softhand.studies.io.failure import save_last_converged
    from softhand.studies.weights import failed_record, write_vtk

    record = failed_record(exc.case, exc.states)
    return save_last_converged(
        out, "weights", "grasp FEM", str(exc).split(";")[0], f"P_cavity = {record['last_converged_P_cavity_MPa']:.4g} MPa",
        record, write_files=lambda folder: write_vtk(folder, exc.model, exc.states), files="grasp.pvd",
        names=OUTPUT_NAMES)


def _run(args) -> int:
    from dataclasses import replace

    case = case_from_args(args)
    diameters = _values(args.diameter_mm, "--diameter-mm", max_cases(args, MAX_DIAMETERS, MOST_FEM_POINTS))
    check = None if args.check_mm is None else _scalar(args.check_mm, "--check-mm")
    if check is not None and (diameters.size == 1 or args.fig8 is not None):
        raise InputError("--check-mm", args.check_mm, "applies to several diameters "
                         "(--diameter-mm a,b,.. or start:stop:step), not to one or to --fig8")
    if args.out is not None and (diameters.size > 1 or args.fig8 is not None):
        raise InputError("--out", args.out, "applies to one diameter, not to a sweep or --fig8")
    if args.out is not None:  # a file or folder of the user's (or another verb's) there: before the FEM
        from softhand.studies.io.outputs import check_owned

        check_owned(args.out, OUTPUT_NAMES, "--out", "weights")
    if args.fig8 is not None and diameters.size > 1:
        raise InputError("--fig8", args.fig8, "is for one object: give one --diameter-mm")
    if args.plot is not None and diameters.size == 1 and args.fig8 is None:
        raise InputError("--plot", args.plot, "draws w(D) of several diameters or the Fig. 8 analogue "
                         "(--fig8); one diameter's grasp is in --out's VTK (softhand inspect)")
    check_distinct(diameters, args.diameter_mm, "--diameter-mm")
    if case.depth_mm is not None:  # an object placed into the open finger: before any FEM or message
        from softhand.fem.hand.grasp import check_placement

        for D in diameters:
            try:
                check_placement(case.design, float(D), case.depth_mm)
            except InputError as exc:
                raise InputError("--depth-mm", args.depth_mm, exc.allowed) from None
    if check is not None and not diameters.min() <= check <= diameters.max():
        raise InputError("--check-mm", args.check_mm, f"must lie within the diameters "
                         f"[{diameters.min():g}, {diameters.max():g}] mm")
    if check is not None and np.isclose(diameters, check, rtol=0.0, atol=1e-9).any():
        raise InputError("--check-mm", args.check_mm, "is one of the swept diameters; the check "
                         "is of w interpolated at a diameter between them")
    if args.fig8 is not None:
        pressures = _values(args.fig8, "--fig8", max_cases(args, MAX_FIG8, MOST_FEM_POINTS))
        check_distinct(pressures, args.fig8, "--fig8")
        return _fig8(args, replace(case, diameter_mm=float(diameters[0])), pressures)
    if diameters.size == 1:
        result = _one(replace(case, diameter_mm=float(diameters[0])), args)
        print_json(result) if args.json else _print_one(result)
        return 0
    return _sweep(args, case, diameters)


def _one(case, args) -> dict:
    """One diameter's grasp FEM, with a bar of its two contact states (P, P + dP) on stderr."""
    from tqdm import tqdm

    from softhand.studies.weights import run_case

    # staged, renamed into place when complete: the earlier run's result stays whole until then
    with replaced_outputs(args.out, OUTPUT_NAMES, verb="weights") as stage, \
            tqdm(total=2, desc="grasp FEM", unit="state", file=sys.stderr, leave=False,
                 disable=args.no_progress) as bar:  # the series is written as the states converge
        result = run_case(case, cache=not args.no_cache, out=stage, progress=lambda state: bar.update())
        if args.out:
            with kept_if_unwritable(Path(args.out) / "result.json", "weights"):
                result.write(stage)
    return result.summary()


#: what one grasp writes into --out (its manifest: an earlier run's are replaced whole)
OUTPUT_NAMES = ("result.json", "grasp.pvd", "grasp")


def _print_one(result: dict) -> None:
    note = result.pop("F_v_reduced_note", None)
    width = max(map(len, result))
    for key, value in result.items():
        if isinstance(value, list):
            text = "[" + ", ".join(f"{v:.4g}" for v in value) + "]"
        elif isinstance(value, float):
            text = f"{value:.4g}"
        else:
            text = str(value)
        print(f"{key:<{width}}  {text}")
    if note:
        print(f"# F_v_reduced_N: {note}")


def _sweep(args, case, diameters) -> int:
    from tqdm import tqdm

    from softhand.studies.weights import WeightsStudy, run as run_study

    check = None if args.check_mm is None else _scalar(args.check_mm, "--check-mm")
    study = WeightsStudy(case=case, diameters_mm=tuple(float(D) for D in diameters), check_mm=check)
    with tqdm(total=len(diameters), desc="weights", unit="D", file=sys.stderr,
              disable=args.no_progress) as bar:
        result = run_study(study, cache=not args.no_cache, progress=lambda row: bar.update())
    if args.plot:
        with kept_if_unwritable(args.plot, "weights"):
            result.plot(args.plot)
    if args.json:
        print_json(result.summary())
    else:
        print_table(result.rows, COLUMNS, digits=3)
        if result.check:
            print_table([result.check], digits=3)
    return 0


def _fig8(args, case, pressures) -> int:
    from softhand.studies.fig8 import Fig8Study, run as run_fig8

    result = run_fig8(Fig8Study(case, tuple(float(P) for P in pressures)))
    if args.plot:
        with kept_if_unwritable(args.plot, "weights"):
            result.plot(args.plot)
    summary = result.summary()
    if args.json:
        print_json(summary)
    else:
        print_table(result.rows, ["depth_mm", "P_cavity_MPa", "theta_deg", "F_v_fem_N", "F_v_reduced_N",
                           "F_v_error_kgf", "w"], digits=3)
        for prefix, what in (("", "the FEM's w"), ("paper_w_", "the paper's w, normalised")):
            if summary[f"{prefix}rms_error_kgf"] is not None:
                print(f"F_v error, eq. (25) with {what} - FEM: rms {summary[f'{prefix}rms_error_kgf']:.3g} "
                      f"kgf, max {summary[f'{prefix}max_abs_error_kgf']:.3g} kgf "
                      f"(paper: model vs measured {' / '.join(f'{g.error_kgf:g}' for g in FIG8)} kgf)")
    return 0
