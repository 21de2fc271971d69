"""``softhand bend``: free bending of the finger FEM under pressure, against eqs. (28) and (2).

Per pressure: P_MPa, theta_deg, hinge_deg, dQ_mm3, radial_stretch_max,
max_principal_stretch, theta_reduced_deg (eq. (28) at the same P), dQ_reduced_mm3 (eq. (2)
at the FEM's theta), max_von_mises_MPa, newton_iterations. Then, unless ``--peak-mpa 0``,
the path goes on to 2.0 MPa and the peak stretch and stress there are reported.
Files in ``--out DIR``: result.json, table.csv, the VTK series finger.pvd (one .vtm scene per
pressure: tube, links, hinges; see ``softhand inspect``).
"""
from __future__ import annotations

import sys
from pathlib import Path

from studies.args import add_design_option, add_json_option, design_from_args, parse_values, \
    print_json, print_table

HELP = "finger FEM: free bending under pressure vs the reduced model (eqs. 28, 2)"


def configure(parser) -> None:
    parser.add_argument("--pressure-mpa", metavar="RANGE", default="0:0.8:0.1",
                        help="pressures [MPa]: start:stop:step (stop included) or a,b,c "
                             "(default 0:0.8:0.1)")
    parser.add_argument("--mesher", choices=("layered", "gmsh"), default=None,
                        help="layered: structured mesh, thin layers at the cavity (default); "
                             "gmsh: unstructured (implied by --mesh-size-mm or --edge-ratio)")
    parser.add_argument("--axial-size-mm", metavar="DX", type=float, default=None,
                        help="layered mesh: largest slice length along the finger [mm] (default 2.5)")
    parser.add_argument("--mesh-size-mm", metavar="H", type=float, default=None,
                        help="gmsh mesh: element size [mm], before --refine (default 6)")
    parser.add_argument("--edge-ratio", metavar="R", type=float, default=None,
                        help="element size at the ring edges and the cavity's cap corner over H "
                             "(default 1: uniform; e.g. 0.5: half, growing back to H over 3 mm)")
    parser.add_argument("--refine", metavar="N", type=int, default=None,
                        help="halve every spacing (layered) or split every element (gmsh) N times: "
                             "nested meshes (default 0; gmsh with 6 mm and 0: the CI mesh)")
    parser.add_argument("--fiber-intorder", metavar="N", type=int, default=None,
                        help="degree of the windings' quadrature rule (default 5; 2: the "
                             "rubber's 4-point rule, which misses the taut cavity wall)")
    parser.add_argument("--tie", choices=("ring", "full"), default="ring",
                        help="outer surface held by the links: a ring in each link's middle "
                             "(default) or the whole link but a gap at the hinges")
    parser.add_argument("--tie-width-mm", type=float, default=None,
                        help="width of each ring for --tie ring [mm]; overrides the design's "
                             "tie_width_mm (default 10)")
    parser.add_argument("--peak-mpa", type=float, default=2.0,
                        help="go on to this pressure and report peak stretch and stress "
                             "(default 2.0; 0: skip)")
    parser.add_argument("--hand", action="store_true",
                        help="also the whole hand: P = p_finger - p_reservoir(V0 - n dQ) with the "
                             "reservoir-sheet FEM, against eq. (27)")
    parser.add_argument("--plot", metavar="FILE.png",
                        help="theta vs P: FEM points, eqs. (28) (and (27) with --hand) as lines")
    parser.add_argument("--out", metavar="DIR", default="results/bend",
                        help="folder for result.json, table.csv and the VTK series")
    add_design_option(parser)
    add_json_option(parser)


def _options(args):
    from fem.finger import FingerOptions
    from reduced.errors import InputError

    mesher = args.mesher or ("gmsh" if args.mesh_size_mm is not None or args.edge_ratio is not None
                             else None)
    if mesher == "layered" and (args.mesh_size_mm is not None or args.edge_ratio is not None):
        raise InputError("--mesh-size-mm/--edge-ratio", args.mesh_size_mm or args.edge_ratio,
                         "apply to --mesher gmsh only")
    if mesher == "gmsh" and args.axial_size_mm is not None:
        raise InputError("--axial-size-mm", args.axial_size_mm, "applies to --mesher layered only")
    given = {"mesher": mesher, "mesh_size": args.mesh_size_mm,
             "axial_size": args.axial_size_mm, "edge_ratio": args.edge_ratio,
             "fiber_intorder": args.fiber_intorder, "mesh_refine": args.refine}
    return FingerOptions(tie=args.tie, **{k: v for k, v in given.items() if v is not None})


def run(args) -> int:
    from tqdm import tqdm

    from fem.io import SceneSeries
    from fem.scene import finger_scene
    from fem.newton import NotConverged
    from studies.bending import BendingStudy, run as run_study
    from studies.output import write_csv, write_json

    pressures = tuple(float(p) for p in parse_values(args.pressure_mpa, "--pressure-mpa"))
    design = design_from_args(args)
    if args.tie_width_mm is not None:
        design = design.replace(tie_width=args.tie_width_mm)
    study = BendingStudy(design, pressures, _options(args),
                         peak_mpa=args.peak_mpa if args.peak_mpa > pressures[-1] else 0.0)
    out = Path(args.out)
    series = SceneSeries(out / "finger.pvd")
    n_steps = len(pressures) + (1 if study.peak_mpa else 0)
    bar = tqdm(total=n_steps, desc="bend", unit="pressure", file=sys.stderr, leave=False)

    def on_state(model, state):
        series.write(state.P, *finger_scene(model, state.y, state.P))
        bar.set_postfix(P=f"{state.P:.2f}", theta=f"{state.theta * 57.29578:.1f}deg")
        bar.update(0 if state.P > pressures[-1] and state.P < study.peak_mpa else 1)

    try:
        result = run_study(study, on_state=on_state)
    except NotConverged as exc:
        print(f"softhand bend: error: {str(exc).split(';')[0]}; converged states are in {out}",
              file=sys.stderr)
        return 1
    finally:
        bar.close()
    summary = result.summary()
    if args.hand:
        from studies.compare import whole_hand
        summary["hand"] = whole_hand(result.rows, study.design)
        write_csv(out / "hand.csv", summary["hand"]["rows"])
    write_json(out / "result.json", summary)
    write_csv(out / "table.csv", result.rows)
    if args.plot:
        plot_bending(args.plot, result.rows, study.design, summary.get("hand"))
    if args.json:
        print_json(summary)
    else:
        print_table(result.rows)
        if args.hand:
            h = summary["hand"]
            print_table(h["rows"])
            print(f"# reservoir offset p_r(V0): FEM {h['offset_fem_MPa']:.4f} MPa, ellipse model "
                  f"{h['offset_ellipse_MPa']:.4f} MPa, paper {h['offset_paper_MPa']} MPa")
        s = result.stats
        print(f"# {result.ndofs} unknowns, {result.nelements} P2 tets (half model), "
              f"{s.newton_iterations} Newton iterations, {s.wall_seconds:.1f} s; {s.solver}")
        if result.peak:
            p = result.peak
            if p["failure"]:
                print(f"# Newton gave up on the way to {p['target_MPa']} MPa ({p['failure']}); "
                      f"last converged state:")
            print(f"# at {p['P_MPa']:.2f} MPa: theta {p['theta_deg']:.1f} deg, max principal "
                  f"stretch {p['max_principal_stretch']:.3f}, max von Mises "
                  f"{p['max_von_mises_MPa']:.2f} MPa, hoop stretch {p['radial_stretch_max']:.4f}")
        print(f"# files in {out}")
    return 0


def plot_bending(path, rows: list[dict], design, hand_result: dict | None = None) -> None:
    """theta vs P (Fig. 7): FEM points and eq. (28); with the hand, its FEM points and eq. (27)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from reduced import hand
    from studies.output import save_figure

    P = np.array([r["P_MPa"] for r in rows])
    Pl = np.linspace(0.0, max(P.max(), 1e-3), 101)
    fig, ax = plt.subplots(figsize=(5.5, 4))
    ax.plot(Pl, np.degrees(hand.bend_angle(Pl, design, reservoir=False)), "k:",
            label="eq. (28), no reservoir")
    ax.plot(P, [r["theta_deg"] for r in rows], "o", label="finger FEM (no reservoir)")
    if hand_result is not None:
        th = np.radians(np.linspace(0.0, max(r["theta_deg"] for r in rows), 101))
        ax.plot(hand.pressure(th, design, reservoir=True), np.degrees(th), "k-",
                label="eq. (27), with reservoir")
        ax.plot([r["P_hand_fem_MPa"] for r in hand_result["rows"]],
                [r["theta_deg"] for r in hand_result["rows"]], "s", mfc="none",
                label="finger FEM + reservoir FEM")
    ax.set_xlabel("pressure P [MPa]")
    ax.set_ylabel("bend angle θ [deg]")
    ax.legend()
    ax.grid(alpha=0.3)
    save_figure(fig, path)
