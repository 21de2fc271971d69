"""``softhand hold``: does the hand hold this object, by how much, and at what pressure.

Three questions about one design (``--design``, default the paper's) and one object
(``--object FILE.toml`` with an ``[object]`` table, or ``sphere:150``, ``cylinder:120x200``,
``box:80x60x100``, ``capsule:60x150``; ``--mass-kg`` and ``--friction`` override the table's):

* ``--pressure-mpa P`` (the pump's) or ``--cavity-pressure-mpa P`` (the fingers' oil): held or
  not under the object's own weight, the holding limit along ``--pull`` (beyond the weight),
  each touching pad's forces;
* no pressure (or ``--margin`` / ``--pull-n``): the least pump pressure, and its cavity pressure,
  that holds the object with the margin asked (the weight times ``--margin`` borne in all along
  the pull, default 1; or ``--pull-n`` newtons beyond the weight), up to ``--max-pump-mpa``;
  or why no pressure within the pump's limit does;
* ``--map X=RANGE Y=RANGE`` over two of pressure, mass, size, friction, pull (the angle of the
  pull from straight down towards finger 0, deg): the held region and the holding margin, as
  ``hold_map.csv`` and ``hold_map.png`` in ``--out``; ``--check`` runs the FEM at the map's
  corners and centre.

``--model reduced`` (default) is the fast model (:mod:`softhand.reduced.holding.hold`); ``--model fem`` the
whole-hand FEM (``softhand.fem.hand.hold``), at the cavity pressure given, or at the one the fast
model finds for the pump pressure given. Both print the same ``--json`` keys.
"""
from __future__ import annotations

import sys

from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.cli.args import add_design_option, add_json_option, add_progress_option, \
    design_from_args, parse_values, print_json
from softhand.studies.cli.verbs.hold_io import (OUTPUT_NAMES, PULLS, checked_option, object_from_args,
                                                 progress_bar, pull_direction, staged, write_output)

HELP = "does the hand hold an object: held or not, holding limit, least pump pressure, hold map"
MODELS = ("reduced", "fem")


def configure(parser) -> None:
    parser.add_argument("--object", required=True, metavar="FILE.toml|SHAPE:DIMS",
                        help="the object: a TOML file with an [object] table, or sphere:D, cylinder:DxL, "
                             "box:XxYxZ, capsule:DxL [mm]")
    parser.add_argument("--model", default="reduced", choices=MODELS,
                        help="reduced: the fast hold model (default); fem: the whole-hand FEM")
    which = parser.add_mutually_exclusive_group()
    which.add_argument("--pressure-mpa", metavar="P", type=float, help="pump pressure [MPa]")
    which.add_argument("--cavity-pressure-mpa", metavar="P", type=float,
                       help="the fingers' cavity (oil) pressure [MPa] instead of the pump's")
    parser.add_argument("--mass-kg", metavar="M", type=float, help="object mass [kg] (over the table's)")
    parser.add_argument("--friction", metavar="MU", type=float, help="Coulomb coefficient pad-object (over the table's)")
    parser.add_argument("--pull", default="down", metavar="DIR",
                        help=f"pull direction x,y,z in the hand frame (y down) or one of {', '.join(PULLS)}")
    margin = parser.add_mutually_exclusive_group()
    margin.add_argument("--margin", metavar="K", type=float,
                        help="least pressure for a hold bearing K times the weight along the pull (default 1)")
    margin.add_argument("--pull-n", metavar="F", type=float,
                        help="least pressure for a hold bearing a pull of F newtons beyond the weight")
    parser.add_argument("--max-pump-mpa", metavar="P", type=float, default=2.0,
                        help="the pump's limit [MPa] (default 2.0)")
    parser.add_argument("--finger", default="fem", choices=("fem", "paper"),
                        help="the reduced model's finger: fem (calibrated, default) or paper")
    parser.add_argument("--map", nargs=2, metavar=("X=RANGE", "Y=RANGE"),
                        help="map over two of pressure, mass, size, friction, pull (RANGE start:stop:step or a,b,c)")
    parser.add_argument("--check", action="store_true", help="with --map: the FEM at the corners and centre too")
    parser.add_argument("--pull-control", choices=("force", "displacement"),
                        help="the FEM's pull: force (stepped up until no equilibrium, default) or displacement "
                             "(drawn through a stiff spring; the limit is the pull's first maximum along the slide)")
    parser.add_argument("--out", metavar="DIR", help="write result.json (or hold_map.csv, hold_map.png) here")
    add_design_option(parser)
    add_json_option(parser)
    add_progress_option(parser)


def run(args) -> int:
    from softhand.reduced.holding import hold

    design = design_from_args(args)
    obj = object_from_args(args)
    pull = pull_direction(args.pull)
    max_pump = checked_option(args, "--max-pump-mpa")
    if args.out:  # a file or folder of the user's where an output goes: refused before any work
        from softhand.studies.io.outputs import check_owned

        check_owned(args.out, OUTPUT_NAMES, "--out", "hold")
    if args.pull_control is not None and args.model != "fem" and not args.check:
        raise InputError("--pull-control", args.pull_control, "is the FEM hold's; give --model fem (or --map with --check)")
    if args.map:
        return _run_map(args, design, obj, pull, max_pump)
    if args.check:
        raise InputError("--check", True, "runs the FEM at points of a map; give --map too")
    P_pump, P_cav = checked_option(args, "--pressure-mpa"), checked_option(args, "--cavity-pressure-mpa")
    if P_pump is None and P_cav is None:
        return _run_least(args, design, obj, pull, max_pump)
    if args.margin is not None or args.pull_n is not None:
        raise InputError("--margin" if args.margin is not None else "--pull-n",
                         args.margin if args.margin is not None else args.pull_n,
                         "asks for the least pressure; give no --pressure-mpa with it")
    if P_pump is not None and P_pump > max_pump:
        raise InputError("--pressure-mpa", P_pump, f"is above the pump's limit --max-pump-mpa = {max_pump:g} "
                                                   "(raise that limit to hold there)")
    d = hold.hold_fast.finger_design(design, args.finger)
    placed = hold.place_object(obj, d)
    if P_cav is None:
        P_cav = hold.cavity_pressure(P_pump, placed, d)
    if args.model == "fem":
        result = _fem_hold(args, design, obj, P_cav, P_pump, pull)
        if result is None:
            return 1
    else:
        result = hold.solve_hold(design, obj, P_cavity_MPa=P_cav, pull_direction=pull, finger_model=args.finger,
                                 placed=placed)
        write_output(args, result.to_json(), "result.json")
    if args.json:
        print_json(result.to_json())
    else:
        _print(result)
    return 0


def _fem_options(args):
    """The FEM hold's options: the defaults, with the pull's control if given."""
    from softhand.fem.hand.hold_options import HoldOptions

    return HoldOptions() if args.pull_control is None else HoldOptions(pull_control=args.pull_control)


def _fem_hold(args, design, obj, P_cav, P_pump, pull):
    """The whole-hand FEM hold with a progress bar (one tick per converged load step); with
    --out its result.json and hold.pvd (every finger, the object, the contact forces per load
    step). None (after one line) when the FEM stops while the fingers close."""
    import math

    from tqdm import tqdm

    from softhand.fem.newton import NotConverged

    from softhand.fem.hand.hold import solve_hold
    from softhand.fem.hand.hold_options import check_hold

    check_hold(design, obj, tuple(pull))  # what the FEM hold refuses: one line, before its bar
    bar = tqdm(desc="hold (FEM)", unit="step", file=sys.stderr, leave=False,
               disable=args.json or args.no_progress)

    def tick(record):
        bar.update(1)
        bar.set_postfix_str(f"{record.stage} P={record.P:.3g} MPa pull={record.pull_N:.3g} N")

    def path_tick(k, support_N):  # letting go off the hand's symmetry, followed as a path
        bar.set_postfix_str(f"letting go: path step {k + 1}, support {support_N:.3g} N")
    try:
        result, path = solve_hold(design, obj, P_cavity_MPa=P_cav, pull_direction=tuple(pull), progress=tick,
                                  path_progress=path_tick, keep_path=True, options=_fem_options(args),
                                  P_pump_MPa=math.nan if P_pump is None else P_pump)
    except NotConverged as exc:
        print(f"softhand hold: error: the FEM did not converge while the fingers closed: "
              f"{str(exc).split(';')[0]}", file=sys.stderr)
        return None
    finally:
        bar.close()
    if args.out:
        from softhand.fem.hand.hold_output import write_hold

        with staged(args) as stage:
            write_hold(path, result, stage)
    return result


def _print(r) -> None:
    weight = r.mass_kg * 9.80665
    print(f"model {r.model}: {r.object.get('shape')} {r.mass_kg:g} kg, mu = {r.friction:g}, "
          f"P_pump_MPa = {r.P_pump_MPa:.4g}, P_cavity_MPa = {r.P_cavity_MPa:.4g}")
    print(f"held: {'yes' if r.held else 'no'}; holding limit along the pull {[round(float(v), 4) for v in r.pull_direction]}: "
          f"{r.holding_limit_N:.4g} N ({r.holding_limit_kg:.4g} kg) beyond the weight {weight:.4g} N")
    for c in r.contacts:
        print(f"  finger {c.finger} pad {c.link}: normal {c.normal_N:.4g} N, friction {c.friction_N:.4g} N, {c.state}")
    at_limit = r.steps[-1].displacement_mm if r.steps else r.displacement_mm
    if max(abs(float(v)) for v in (*r.displacement_mm, *at_limit)) > 0.01:
        mm = lambda v: [round(float(x), 2) for x in v]  # noqa: E731
        print(f"  the object moved {mm(r.displacement_mm)} mm under its weight, {mm(at_limit)} mm at the holding limit")
    for note in r.notes:
        print(f"  note: {note}")


def _run_least(args, design, obj, pull, max_pump) -> int:
    from softhand.reduced.holding import hold

    if args.model == "fem":
        raise InputError("--model", "fem", "the least pressure is searched with the fast model; give "
                                           "--pressure-mpa to run the FEM at one pressure")
    margin = checked_option(args, "--margin")
    pull_n = checked_option(args, "--pull-n")
    bar, update = progress_bar(not args.no_progress, "hold: least pressure")
    try:
        least = hold.least_pressure(design, obj, max_pump_MPa=max_pump, margin=margin or 1.0, pull_N=pull_n,
                                    pull_direction=pull, finger_model=args.finger, progress=update)
    finally:
        bar.close()
    data = {**least.result.to_json(), "least_P_pump_MPa": least.P_pump_MPa,
            "least_P_cavity_MPa": least.P_cavity_MPa, "required_holding_limit_N": least.required_N,
            "max_pump_MPa": max_pump}
    write_output(args, data, "result.json")
    if args.json:
        print_json(data)
    else:
        print(f"least pump pressure P_pump_MPa = {least.P_pump_MPa:.4g} (cavity P_cavity_MPa = "
              f"{least.P_cavity_MPa:.4g}) holds it with a holding limit >= {least.required_N:.4g} N along the pull")
        _print(least.result)
    return 0


def _axis(text: str):
    from softhand.studies.hold import AXES

    name, eq, values = text.partition("=")
    if not eq or name not in AXES:
        raise InputError("--map", text, f"must be NAME=RANGE with NAME one of {', '.join(AXES)}")
    return name, tuple(float(v) for v in parse_values(values, f"--map {name}", 2500, more=None))


def _run_map(args, design, obj, pull, max_pump) -> int:
    from softhand.studies.hold import HoldMap, run_map, write_map

    x, y = (_axis(t) for t in args.map)
    _refuse_with_map(args, (x[0], y[0]))
    pressure = checked_option(args, "--pressure-mpa")
    if pressure is None and "pressure" not in (x[0], y[0]):
        raise InputError("--pressure-mpa", None, "is required when pressure is not an axis of the map")
    m = HoldMap(design, obj, x, y, pressure_MPa=pressure if pressure is not None else 0.0, pull=tuple(pull),
                max_pump_MPa=max_pump, finger_model=args.finger)
    if args.check:  # what the FEM hold refuses, before the map, not after it
        from softhand.fem.hand.hold_options import check_hold

        check_hold(design, obj, tuple(pull))
    bar, update = progress_bar(not args.no_progress, "hold map")
    try:
        rows = run_map(m, progress=update)
    finally:
        bar.close()
    checks = _map_checks(m, rows, design, _fem_options(args)) if args.check else []
    if args.out:
        with staged(args) as stage:
            write_map(m, rows, stage)
    if args.json:
        print_json({"rows": rows, "checks": checks, "max_pump_MPa": max_pump})
    else:
        held = sum(r["held"] for r in rows)
        print(f"hold map {x[0]} x {y[0]}: {held} of {len(rows)} points held"
              + (f"; written to {args.out}" if args.out else ""))
        for c in checks:
            print(f"  check at {c['at']}: reduced {c['reduced_N']:.4g} N, fem {c['fem_N']:.4g} N")
    return 0


def _refuse_with_map(args, axes) -> None:
    """The options a map does not use (it would ignore them): one line each."""
    given = [("--model", args.model, args.model == "fem", "a map runs the fast model; --check runs the "
              "FEM at its corners and centre"),
             ("--margin", args.margin, args.margin is not None, "asks for the least pressure, not a map "
              "(the map's contours are the holding margin)"),
             ("--pull-n", args.pull_n, args.pull_n is not None, "asks for the least pressure, not a map"),
             ("--cavity-pressure-mpa", args.cavity_pressure_mpa, args.cavity_pressure_mpa is not None,
              "a map is over the pump pressure; give --pressure-mpa"),
             ("--pressure-mpa", args.pressure_mpa, args.pressure_mpa is not None and "pressure" in axes,
              "pressure is an axis of the map"),
             ("--pull", args.pull, args.pull != "down" and "pull" in axes, "pull is an axis of the map "
              "(its angle from straight down towards finger 0)")]
    for option, value, refused, why in given:
        if refused:
            raise InputError(option, value, f"is not used with --map: {why}")


def _map_checks(m, rows, design, options) -> list[dict]:
    """The FEM at the map's corners and centre (the FEM's solver is required)."""
    from softhand.studies.hold import map_point

    from softhand.fem.hand.hold import solve_hold as solve

    (xn, xs), (yn, ys) = m.x, m.y
    picks = {(xs[0], ys[0]), (xs[-1], ys[0]), (xs[0], ys[-1]), (xs[-1], ys[-1]), (xs[len(xs) // 2], ys[len(ys) // 2])}
    out = []
    for xv, yv in sorted(picks):
        row = next(r for r in rows if r[xn] == xv and r[yn] == yv)
        obj, _, pull = map_point(m, {xn: xv, yn: yv})
        r = solve(design, obj, P_cavity_MPa=row["P_cavity_MPa"], pull_direction=tuple(pull), options=options)
        out.append({"at": {xn: xv, yn: yv}, "reduced_N": row["holding_limit_N"], "fem_N": r.holding_limit_N,
                    "reduced_held": row["held"], "fem_held": r.held})
    return out
