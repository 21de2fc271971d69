"""``softhand curve``: pump pressure <-> bend angle of the free hand, eqs. (27) and (28).

``--theta-deg RANGE`` gives, per angle, the pressure with and without the reservoir and the
reservoir's state (V (15), its pressure p_r, and for the ellipse model h (14), lambda_r (16)); ``--pressure-mpa RANGE`` gives, per
pump pressure, the bend angle with the reservoir, the cavity pressure there and the bend
without the reservoir. ``--plot FILE.png`` draws the analogue of the paper's Fig. 7, titled
with the design and the finger model. ``--model paper,fem`` computes the curve on each finger
model, ``--compare A.toml B.toml ...`` on each design (after ``--design``'s, if given); all
curves go on one plot. Only numpy and the reduced model are imported unless a plot is asked for.
"""
from __future__ import annotations

import numpy as np

from softhand.reduced.vocabulary.design import HandDesign
from softhand.studies import curve
from softhand.studies.cli.args import MAX_POINTS, MOST_POINTS, add_design_option, add_json_option, \
    add_max_cases_option, design_from_args, max_cases, parse_values, print_json, print_table, require_finite

HELP = "pressure <-> bend angle of the free hand, with and without reservoir (eqs. 27, 28)"


def configure(parser) -> None:
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument("--theta-deg", metavar="RANGE",
                      help="bend angles [deg]: start:stop:step (stop included) or a,b,c")
    what.add_argument("--pressure-mpa", metavar="RANGE",
                      help="pump pressures [MPa]: start:stop:step (stop included) or a,b,c")
    parser.add_argument("--plot", metavar="FILE.png", help="draw P vs bend angle (the paper's Fig. 7)")
    parser.add_argument("--model", metavar="paper,fem", default=None,
                        help="finger model(s), comma-separated: paper (eqs. 10, 27) or fem (calibrated by "
                             "the finger FEM); default: the design's own (finger_model)")
    parser.add_argument("--compare", metavar="DESIGN.toml", nargs="+", default=None,
                        help="curves of these designs too (after --design's, if given), on one plot")
    add_max_cases_option(parser, MAX_POINTS, MOST_POINTS)
    add_design_option(parser)
    add_json_option(parser)


def rows_at_pressures(P: np.ndarray, design: HandDesign) -> list[dict]:
    """:func:`softhand.studies.curve.at_pressures`, the angles rounded to 1e-10 deg for printing: far
    below the inverse's error (~1e-11 rad), so that an exact zero prints as 0 (+ 0.0 turns -0.0
    into 0.0)."""
    return [{**r, "theta_deg": round(r["theta_deg"], 10) + 0.0,
             "theta_no_reservoir_deg": round(r["theta_no_reservoir_deg"], 10) + 0.0}
            for r in curve.at_pressures(P, design)]


#: --model: the finger models a curve can be drawn on
FINGER_MODELS = ("paper", "fem")


def curves(args) -> list[tuple[str, HandDesign]]:
    """(label, design) of every curve asked for: each design (``--design``, then ``--compare``'s)
    on each finger model of ``--model`` (default: the design's own)."""
    from argparse import Namespace

    from softhand.reduced.vocabulary.errors import InputError
    from softhand.studies.cli.checks import check_choices

    files = [args.design] if args.design is not None or not args.compare else []
    files += list(args.compare or [])
    models = None
    if args.model is not None:
        models = tuple(m.strip() for m in args.model.split(","))
        check_choices("--model", models, FINGER_MODELS, "finger model", shown=args.model)
    out = []
    for k, path in enumerate(files):
        try:
            design = design_from_args(Namespace(design=path))
        except InputError as exc:
            if exc.field == "--design" and k >= len(files) - len(args.compare or []):
                raise exc.renamed("--compare") from None  # a file of --compare is named as one
            raise
        for model in models or (design.finger_model,):
            label = f"{design_name(path)}, finger model {model}"
            if any(label == seen for seen, _ in out):
                raise InputError("--compare", path, "names a design already compared")
            out.append((label, design.replace(finger_model=model)))
    return out


def design_name(path) -> str:
    """How a plot names a design: its file's name (with its folder's if that is all ``design``,
    as ``softhand design`` writes it), or the paper's."""
    from pathlib import Path

    if path is None:
        return "the paper's design"
    path = Path(path)
    return f"{path.parent.name}/{path.stem}" if path.stem == "design" and path.parent.name else path.stem


def run(args) -> int:
    from softhand.reduced.vocabulary.errors import InputError

    limit = max_cases(args, MAX_POINTS, MOST_POINTS)
    chosen = curves(args)
    option = "--theta-deg" if args.theta_deg is not None else "--pressure-mpa"
    values = parse_values(args.theta_deg if args.theta_deg is not None else args.pressure_mpa, option,
                          limit)
    found = []
    for label, design in chosen:
        try:
            rows = (curve.at_angles if args.theta_deg is not None else rows_at_pressures)(values, design)
        except InputError as exc:  # named as the option the user typed
            if exc.field in ("theta_deg", "pressure_MPa"):
                raise exc.renamed(option) from None
            raise
        for row in rows:
            where = row['theta_deg' if option == '--theta-deg' else 'P_pump_MPa']
            require_finite(row, args, f"at {option} {where:g}" + (f" ({label})" if len(chosen) > 1 else ""))
        found.append((label, design, rows))
    if args.plot:
        from softhand.studies.io.files import kept_if_unwritable

        with kept_if_unwritable(args.plot, "curve"):
            curve.plot_curves(args.plot, found, by_pressure=args.theta_deg is None)
    if args.json and len(found) == 1:
        print_json({"rows": found[0][2], "design": found[0][1].to_dict()})
    elif args.json:
        print_json({"curves": [{"label": label, "rows": rows, "design": design.to_dict()}
                               for label, design, rows in found]})
    else:
        for i, (label, _, rows) in enumerate(found):
            if len(found) > 1:
                print(f"{chr(10) if i else ''}# {label}")
            print_table(rows)
    return 0
