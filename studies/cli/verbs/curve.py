"""``softhand curve``: pump pressure <-> bend angle of the free hand, eqs. (27) and (28).

``--theta-deg RANGE`` gives, per angle, the pressure with and without the reservoir and the
reservoir's state (V (15), its pressure p_r, and for the ellipse model h (14), lambda_r (16)); ``--pressure-mpa RANGE`` gives, per
pressure, the bend angle with and without the reservoir. ``--plot FILE.png`` draws the
analogue of the paper's Fig. 7. Only numpy and the reduced model are imported unless a plot
is asked for.
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


def run(args) -> int:
    from softhand.reduced.vocabulary.errors import InputError

    limit = max_cases(args, MAX_POINTS, MOST_POINTS)
    design = design_from_args(args)
    option = "--theta-deg" if args.theta_deg is not None else "--pressure-mpa"
    values = parse_values(args.theta_deg if args.theta_deg is not None else args.pressure_mpa, option,
                          limit)
    try:
        rows = (curve.at_angles if args.theta_deg is not None else rows_at_pressures)(values, design)
    except InputError as exc:  # named as the option the user typed
        if exc.field in ("theta_deg", "pressure_MPa"):
            raise exc.renamed(option) from None
        raise
    for row in rows:
        require_finite(row, args, f"at {option} {row['theta_deg' if option == '--theta-deg' else 'P_MPa']:g}")
    if args.plot:
        from softhand.studies.io.files import kept_if_unwritable

        with kept_if_unwritable(args.plot, "curve"):
            curve.plot_curve(args.plot, design, rows, by_pressure=args.theta_deg is None)
    if args.json:
        print_json({"rows": rows, "design": design.to_dict()})
    else:
        print_table(rows)
    return 0
