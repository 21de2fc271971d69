"""``softhand reservoir``: FEM inflation of the reservoir sheet vs the paper's ellipse model.

Per volume: FEM pressure, apex height, strain energy; the ellipse model's (13)–(18) at the
same volume; the mean stretches and the largest gap between the profiles. Then the pressure
maximum (if the path passes one) and the verdict over the operating range (V0 - stroke .. V0).
``--plot``: profiles, p(V) of both models, and the hand's P(theta) with both reservoir
models. ``--out DIR``: result.json (rows, verdict, wet-surface profiles z(r) and mid-surface
stretches per volume, the whole p(V), W(V) path), rows.csv, VTK of the deformed sheet per
volume (r–z and revolved to 3D); see :class:`softhand.studies.reservoir.ReservoirStudyResult`. ``--write-calibration FILE.csv``: the table of ``reduced/calibrated/reservoir_fem.py``.
"""
from __future__ import annotations

from pathlib import Path

from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.cli.args import MAX_FEM_POINTS, MOST_FEM_POINTS, add_design_option, add_json_option, \
    add_max_cases_option, add_progress_option, design_from_args, max_cases, parse_values, print_json, print_table
from softhand.studies.io.values import check_distinct
from softhand.studies.io.files import write_outputs
from softhand.studies.io.outputs import replaced_outputs

HELP = "inflate the reservoir sheet (FEM) and measure the ellipse assumption (eqs. 11-18)"


def configure(parser) -> None:
    parser.add_argument("--volume-mm3", metavar="LIST",
                        help="oil volumes [mm^3]: start:stop:step or a,b,c "
                             "(default: V0 - stroke at 90 deg, V0, V0 + 2000)")
    parser.add_argument("--plot", metavar="FILE.png", help="profiles, p(V) and P(theta), both models")
    parser.add_argument("--out", metavar="DIR", help="write result.json, rows.csv and VTK here")
    parser.add_argument("--n-radial", type=int, default=40, help="Q2 elements along the radius")
    parser.add_argument("--n-thick", type=int, default=2, help="Q2 elements through the thickness")
    parser.add_argument("--write-calibration", metavar="FILE.csv",
                        help="write the FEM calibration table of the 'fem' reservoir model")
    add_max_cases_option(parser, MAX_FEM_POINTS, MOST_FEM_POINTS)
    add_design_option(parser)
    add_json_option(parser)
    add_progress_option(parser)


def _study(args):
    from softhand.studies.reservoir import ReservoirStudy

    limit = max_cases(args, MAX_FEM_POINTS, MOST_FEM_POINTS)
    design = design_from_args(args)
    for name, hi in (("n_radial", 400), ("n_thick", 20)):
        if not 1 <= getattr(args, name) <= hi:
            raise InputError(f"--{name.replace('_', '-')}", getattr(args, name),
                             f"must be a whole number in [1, {hi}]")
    volumes = ()
    if args.volume_mm3 is not None:
        volumes = tuple(parse_values(args.volume_mm3, "--volume-mm3", limit))
        check_distinct(volumes, args.volume_mm3, "--volume-mm3")
        low, high = 1e-4 * design.V0, 100 * design.V0  # below 1e-4 V0 the sheet barely moves
        if min(volumes) < low or max(volumes) > high:
            raise InputError("--volume-mm3", args.volume_mm3,
                             f"volumes must be in [{low:.4g}, {high:.4g}] mm^3 (1e-4 V0 .. 100 V0)")
        from softhand.reduced.equations.reservoir import check_holds

        check_holds(max(volumes), design, "--volume-mm3")
    return ReservoirStudy(design=design, volumes_mm3=volumes, n_radial=args.n_radial,
                          n_thick=args.n_thick)


#: what a reservoir run writes into --out (its manifest: an earlier run's are replaced whole)
OUTPUT_NAMES = ("result.json", "rows.csv", "sheet.pvd", "sheet", "sheet_V*_rz.vtu")


def run(args) -> int:
    if args.write_calibration:  # the table's own volumes and output: what it would ignore is refused
        for option, given in (("--volume-mm3", args.volume_mm3), ("--plot", args.plot), ("--out", args.out),
                              ("--json", args.json or None)):
            if given is not None:
                raise InputError(option, given, "is not used with --write-calibration (the table is "
                                                "computed over its own volumes and written to its file)")
    study = _study(args)
    if args.out:
        from softhand.studies.io.outputs import check_owned

        check_owned(args.out, OUTPUT_NAMES, "--out", "reservoir")  # a folder of the user's named sheet/: before the FEM
    if args.write_calibration:
        from softhand.studies.reservoir import write_calibration

        count = write_calibration(study, args.write_calibration)
        print(f"wrote {count} rows to {args.write_calibration}")
        return 0
    from tqdm import tqdm

    from softhand.studies.reservoir import COLUMNS, run as run_study

    from softhand.fem.volume_path import NotConverged

    try:
        with tqdm(desc="inflating", unit=" mm³", leave=False, disable=args.no_progress) as bar:  # whole mm³ of oil
            result = run_study(study, progress=lambda v: bar.update(round(v) - bar.n))
    except NotConverged as exc:
        return _failed(exc, study, Path(args.out or FAILED_OUT))
    summary = result.summary()
    with replaced_outputs(args.out, OUTPUT_NAMES, verb="reservoir") as stage:  # renamed into place when whole
        write_outputs(result, "reservoir", stage, args.plot, shown=args.out)
    if args.json:
        print_json({"rows": result.rows, **summary})
    else:
        print_table(result.rows, COLUMNS)
        pm = summary["pressure_max"]
        print("pressure maximum: " + ("none in 0..%.0f mm^3" % summary["path_max_volume_mm3"] if pm is None
                                      else f"p = {pm['p_MPa']:.4g} MPa at V = {pm['V_mm3']:.0f} mm^3"))
        v = result.verdict
        print(f"stroke {v['stroke_mm3']:.0f} mm^3: dp FEM {v['stroke_dp_fem_MPa']:.4g} MPa, "
              f"ellipse {v['stroke_dp_ellipse_MPa']:.4g} MPa ({100 * v['stroke_dp']:+.1f} %)")
        th, fem, ell = v["offset_theta_deg"], v["offset_fem_MPa"], v["offset_ellipse_MPa"]
        print(f"reservoir offset p_r over theta {th[-1]:.0f}..{th[0]:.0f} deg: FEM {fem[-1]:.4g}..{fem[0]:.4g} MPa, "
              f"ellipse {ell[-1]:.4g}..{ell[0]:.4g} MPa, ellipse - FEM "
              f"{v['offset_difference_MPa'][0]:.4g}..{v['offset_difference_MPa'][1]:.4g} MPa")
    return 0


#: where a failed inflation without --out leaves its last converged state
FAILED_OUT = "results/reservoir"


def _failed(exc, study, out: Path) -> int:
    """Newton gave up at the smallest volume step: the last converged state (result.json +
    the sheet's VTK) and one error line naming the volume and pressure reached; exit code 1."""
    from softhand.fem.hand.reservoir import sheet_state
    from softhand.studies.io.failure import save_last_converged
    from softhand.studies.io.reservoir_files import write_sheet_states

    model = study.model()
    solid = model.build()[0]
    state = sheet_state(model, solid, exc.last) if exc.last.u is not None else None
    reached = f"V = {exc.last.volume:.6g} mm^3, p = {exc.last.pressure:.6g} MPa"
    record = {"last_converged": {"V_mm3": exc.last.volume, "p_MPa": exc.last.pressure,
                                 "W_Nmm": exc.last.energy},
              "design": study.design.to_dict(), "design_hash": study.design.hash(),
              "mesh": {"n_radial": model.n_radial, "n_thick": model.n_thick}}
    return save_last_converged(
        out, "reservoir", "reservoir FEM", f"{str(exc).split(';')[0]} (Newton failed at the "
        "smallest volume step)", reached, record,
        write_files=(lambda folder: write_sheet_states(solid, [state], folder)) if state else None,
        files="sheet.pvd" if state else "", names=OUTPUT_NAMES)

