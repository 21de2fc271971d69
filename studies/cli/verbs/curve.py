"""``softhand curve``: pump pressure <-> bend angle of the free hand, eqs. (27) and (28).

``--theta-deg RANGE`` gives, per angle, the pressure with and without the reservoir and the
reservoir's state (V (15), its pressure p_r, and for the ellipse model h (14), lambda_r (16)); ``--pressure-mpa RANGE`` gives, per
pressure, the bend angle with and without the reservoir. ``--plot FILE.png`` draws the
analogue of the paper's Fig. 7. Only numpy and the reduced model are imported unless a plot
is asked for.
"""
from __future__ import annotations

import numpy as np

from softhand.reduced import hand, reservoir
from softhand.reduced.design import HandDesign
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


def rows_at_angles(theta_deg: np.ndarray, design: HandDesign) -> list[dict]:
    """Per bend angle [deg]: P with / without reservoir [MPa], the reservoir's V [mm^3] and
    :func:`softhand.reduced.reservoir.state` (p_r; h, lambda_r for the ellipse model)."""
    theta = hand.check_theta(np.radians(theta_deg))
    V = reservoir.oil_volume(theta, design)
    columns = {"theta_deg": theta_deg, "P_MPa": hand.pressure(theta, design),
               "P_no_reservoir_MPa": hand.pressure(theta, design, reservoir=False), "V_mm3": V,
               **reservoir.state(V, design)}
    return [{k: float(v[i]) for k, v in columns.items()} for i in range(len(theta_deg))]


def rows_at_pressures(P: np.ndarray, design: HandDesign) -> list[dict]:
    """Per pump pressure [MPa]: the free bend angle with / without reservoir [deg]."""
    # rounded to 1e-10 deg, far below the inverse's error (~1e-11 rad), so that an exact
    # zero prints as 0 (+ 0.0 turns -0.0 into 0.0)
    theta, theta_free = (np.round(np.degrees(t), 10) + 0.0 for t in hand.bend_angles(P, design))
    return [{"P_MPa": float(p), "theta_deg": float(t), "theta_no_reservoir_deg": float(u)}
            for p, t, u in zip(P, theta, theta_free)]


def run(args) -> int:
    from softhand.reduced.errors import InputError

    limit = max_cases(args, MAX_POINTS, MOST_POINTS)
    design = design_from_args(args)
    option = "--theta-deg" if args.theta_deg is not None else "--pressure-mpa"
    values = parse_values(args.theta_deg if args.theta_deg is not None else args.pressure_mpa, option,
                          limit)
    try:
        rows = (rows_at_angles if args.theta_deg is not None else rows_at_pressures)(values, design)
    except InputError as exc:  # named as the option the user typed
        if exc.field in ("theta_deg", "pressure_MPa"):
            raise exc.renamed(option) from None
        raise
    for row in rows:
        require_finite(row, args, f"at {option} {row['theta_deg' if option == '--theta-deg' else 'P_MPa']:g}")
    if args.plot:
        from softhand.studies.io.files import kept_if_unwritable

        with kept_if_unwritable(args.plot, "curve"):
            plot_curve(args.plot, design, rows, by_pressure=args.theta_deg is None)
    if args.json:
        print_json({"rows": rows, "design": design.to_dict()})
    else:
        print_table(rows)
    return 0


def plot_curve(path, design: HandDesign, rows: list[dict], *, by_pressure: bool = False):
    """Bend angle vs pump pressure with and without the reservoir (Fig. 7) over the span of
    ``rows`` (their pressures if ``by_pressure``, else their angles) -> PNG at ``path``."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from softhand.studies.io.files import save_figure

    key = "P_MPa" if by_pressure else "theta_deg"
    lo, hi = min(r[key] for r in rows), max(r[key] for r in rows)
    span = np.linspace(lo, hi, 200) if hi > lo else np.array([lo])
    if by_pressure:
        P = P_free = span
        theta, theta_free = (np.degrees(t) for t in hand.bend_angles(span, design))
    else:
        theta = theta_free = span
        P, P_free = (hand.pressure(np.radians(span), design, reservoir=res) for res in (True, False))
    fig, ax = plt.subplots(figsize=(5.5, 4.0))
    ax.plot(P, theta, "-", label="with reservoir (27)")
    ax.plot(P_free, theta_free, ":", label="without reservoir (28)")
    ax.plot([r["P_MPa"] for r in rows], [r["theta_deg"] for r in rows], "o", ms=4,
            label="rows printed (with reservoir)")
    ax.set_xlabel("pump pressure P [MPa]")
    ax.set_ylabel("bend angle theta [deg]")
    ax.axvline(0.0, color="0.7", lw=0.8)
    ax.grid(alpha=0.3)
    ax.legend()
    ax.set_title("Free bending, reduced model (paper Fig. 7)")
    save_figure(fig, path)
