"""``softhand fit``: calibrate design parameters to measured points (bounded least squares).

    softhand fit --data studies/data/example_bending.csv --params V0_mm3,mu_sf_MPa \\
        [--design FILE] [--model reduced] [--no-reservoir] [--bounds V0_mm3=1e4:3e4] \\
        [--shore-a 70] [--diameter-mm 180 | --weights w1,..,w5] \\
        [--json] [--plot FILE.png] [--out DESIGN.toml]

Prints the fitted values with standard errors, their correlation, RMSE and max error in
the data's units, and every identifiability warning (also on stderr). ``--out`` writes
the calibrated design as a TOML file that every verb reads with ``--design``.
"""
from __future__ import annotations

import sys

from softhand.studies.cli.args import NUMBER_LIST, add_design_option, add_json_option, design_from_args, parse_values, \
    print_json

HELP = "calibrate design parameters (V0, mu, ...) to measured bend angles or grasp forces"


def configure(parser) -> None:
    parser.add_argument("--data", required=True, metavar="FILE.csv",
                        help="measurements: columns P_pump_MPa,theta_deg[,finger] (free bending) or "
                             "P_pump_MPa,theta_deg,mass_kg,F_v_N[,diameter_mm] (grasp); '#' comments")
    parser.add_argument("--params", required=True, metavar="KEYS",
                        help="design keys to fit, comma-separated, e.g. V0_mm3,mu_sf_MPa")
    parser.add_argument("--model", default="reduced", help="model to fit (default: reduced)")
    parser.add_argument("--no-reservoir", action="store_true",
                        help="fit the hand without reservoir (eq. (28)) instead of eq. (27)")
    parser.add_argument("--bounds", default=None, metavar="KEY=LO:HI,...",
                        help="bounds of fitted keys (default: start/100..start*100)")
    parser.add_argument("--shore-a", type=float, default=None, metavar="S",
                        help="start fitted mu_sf_MPa / mu_sr_MPa from Gent's Shore A relation")
    parser.add_argument("--diameter-mm", type=float, default=None, metavar="D",
                        help="grasp data without diameter_mm column: the paper's w for D (180, 240)")
    parser.add_argument("--weights", default=None, metavar="w1,..,wn",
                        help="grasp data without diameter_mm column: the weight vector w")
    parser.add_argument("--normalise", action="store_true",
                        help="scale w to sum 1 (eq. (23); the paper's 180 mm w sums to 1.40)")
    add_design_option(parser)
    add_json_option(parser)
    parser.add_argument("--plot", default=None, metavar="FILE.png",
                        help="write data vs fitted model and the residuals")
    parser.add_argument("--out", default=None, metavar="DESIGN.toml",
                        help="write the calibrated design (readable by every verb via --design)")


def run(args) -> int:
    from softhand.reduced.fitting.csvdata import read_measurements
    from softhand.reduced.vocabulary.errors import InputError
    from softhand.reduced.fitting.fit import check_params
    from softhand.studies.fit import FitStudy, run as run_study
    from softhand.studies.io.files import write_outputs

    design = design_from_args(args)
    data = read_measurements(args.data)
    keys = check_params(args.params, len(data))
    sheet = [k for k in keys if k in RESERVOIR_KEYS]
    if args.no_reservoir and sheet:
        raise InputError("--params", args.params, f"{sheet[0]} is the reservoir's; with --no-reservoir "
                                                  "the model has no reservoir to fit it to")
    design = _start_from_shore_a(design, keys, args.shore_a)
    w = _weights(args, design, data)
    study = FitStudy(data, keys, design, model=args.model, reservoir=not args.no_reservoir,
                     weights=None if w is None else tuple(float(x) for x in w), normalise=args.normalise,
                     bounds=_parse_bounds(args.bounds), data_name=args.data)
    result = run_study(study)
    write_outputs(result, "fit", args.out, args.plot)
    if args.json:
        print_json(result.summary())
    else:
        _print_report(result.fit, data, args)
    for note in result.notes:
        print(f"softhand fit: warning: {note}", file=sys.stderr)
    return 0


#: the fitted keys that only the reservoir sheet uses (eqs. (11)-(18))
RESERVOIR_KEYS = ("V0_mm3", "mu_sr_MPa", "R_mm", "t_mm")


def _start_from_shore_a(design, keys, shore_a):
    """The fitted moduli's start from a Shore A hardness (Gent's relation), named --shore-a."""
    if shore_a is None:
        return design
    from softhand.reduced.vocabulary.design_files import design_from_dict
    from softhand.reduced.vocabulary.errors import InputError
    from softhand.reduced.materials.materials_data import shear_modulus_from_shore_a

    try:
        mu = shear_modulus_from_shore_a(shore_a)
    except InputError as exc:
        raise exc.renamed("--shore-a") from None
    start = {k: mu for k in ("mu_sf_MPa", "mu_sr_MPa") if k in keys}
    if not start:
        raise InputError("--shore-a", shore_a, "only sets the start of a fitted mu_sf_MPa "
                         "or mu_sr_MPa; name one in --params")
    try:
        return design_from_dict(start, design)
    except InputError as exc:  # the modulus is outside the design's bounds
        raise InputError("--shore-a", shore_a, f"gives {exc.field} = {mu:.4g} MPa (Gent's "
                         f"relation): {exc.allowed}") from None


def _weights(args, design, data):
    """w from --diameter-mm or --weights, each only where the data need it."""
    from softhand.reduced.vocabulary.errors import InputError

    given = [(o, v) for o, v in (("--diameter-mm", args.diameter_mm), ("--weights", args.weights),
                                 ("--normalise", args.normalise or None)) if v is not None]
    if data.kind == "bending" and given:
        raise InputError(given[0][0], given[0][1], f"only for grasp data; {args.data} holds "
                                                   "bending angles")
    if data.kind != "bending" and data.diameter is not None and given[:1] and given[0][0] != "--normalise":
        raise InputError(given[0][0], given[0][1], f"{args.data} has a diameter_mm column, which "
                                                   "picks w; drop the option")
    if args.weights is not None and args.diameter_mm is not None:
        raise InputError("--weights", args.weights, "give --weights or --diameter-mm, not both")
    if args.diameter_mm is not None:
        from softhand.reduced.equations.grasp import weights_for_diameter

        try:
            return weights_for_diameter(args.diameter_mm, design)
        except InputError as exc:
            raise exc.renamed("--diameter-mm") from None
    if args.weights is not None:
        return parse_values(args.weights, "--weights", forms=NUMBER_LIST, more=None)
    return None


def _parse_bounds(text):
    """'K=lo:hi,K2=lo:hi' -> {K: (lo, hi)}."""
    if text is None:
        return None
    import math

    from softhand.reduced.vocabulary.design import BOUNDS
    from softhand.reduced.vocabulary.errors import InputError
    from softhand.reduced.vocabulary.inputfiles import plain_float

    bounds = {}
    for item in text.split(","):
        key, _, rng = item.partition("=")
        try:
            lo, hi = (plain_float(x) for x in rng.split(":"))
        except ValueError:
            raise InputError("--bounds", item, "must be KEY=LOW:HIGH, e.g. V0_mm3=1e4:3e4") from None
        limits = BOUNDS.get(key.strip(), (-math.inf, math.inf))
        if not (math.isfinite(lo) and math.isfinite(hi) and limits[0] <= lo and hi <= limits[1]):
            raise InputError(f"--bounds {key.strip()}", rng, f"must be finite and within the design "
                             f"bounds [{limits[0]:g}, {limits[1]:g}]")
        if key.strip() in bounds:
            raise InputError("--bounds", text, f"{key.strip()} is bounded twice")
        bounds[key.strip()] = (lo, hi)
    return bounds


def _print_report(result, data, args) -> None:
    from softhand.studies.cli.args import print_table

    kind = "free-bending" if data.kind == "bending" else "grasp"
    print(f"{data.source}: {len(data)} {kind} points; model {args.model} "
          f"({'without' if args.no_reservoir else 'with'} reservoir); fitted {data.quantity}")
    rows = [{"parameter": k, "start": f"{p0:.6g}", "fitted": f"{v:.6g}",
             "std_error": f"{se:.2g}", "rel_error": f"{100 * se / abs(v):.2g} %" if v else "-"}
            for k, p0, v, se in zip(result.params, result.initial, result.values, result.stderr)]
    print_table(rows)
    if len(result.params) > 1:
        print("correlation:")
        print_table([{"": k, **{k2: c for k2, c in zip(result.params, row)}}
                     for k, row in zip(result.params, result.correlation)], digits=3)
    u = data.unit
    print(f"RMSE {result.rmse:.4g} {u} (at the start {result.initial_rmse:.4g} {u}), "
          f"max |error| {result.max_error:.4g} {u}, residual scatter {result.sigma:.4g} {u} "
          f"on {result.dof} degrees of freedom")
    by_finger = result.rmse_by_finger()
    if by_finger:
        print("RMSE by finger: " + ", ".join(f"{f}: {e:.3g} {u}" for f, e in by_finger.items()))
    print(f"condition number of the scaled Jacobian: {result.condition:.3g}; "
          f"{result.nfev} model evaluations")
    for w in result.warnings:
        print(f"WARNING: {w}")
    if args.out:
        print(f"calibrated design: {args.out}")
    if args.plot:
        print(f"plot: {args.plot}")
