"""``softhand bend``: free bending of the finger FEM under pressure, against eqs. (28) and (2).

Per cavity pressure: P_cavity_MPa, theta_deg, hinge_deg, dQ_mm3, radial_stretch_max, radial_stretch_q99,
radial_stretch (the windings' hoop stretch averaged like rubber_stretch), rubber_stretch (the
principal stretch averaged over a 2 mm ball at its worst place: converges under mesh
refinement), max_principal_stretch (the pointwise peak at a bonded corner: mesh-dependent),
theta_reduced_deg (eq. (28) at the same P), dQ_reduced_mm3 (eq. (2)
at the FEM's theta), max_von_mises_MPa, newton_iterations. Then, unless ``--peak-mpa 0``,
the path goes on to 2.0 MPa and the peak stretch and stress there are reported.
Files in ``--out DIR``: result.json, table.csv, the VTK series finger.pvd (one .vtm scene per
pressure: tube, links, hinges; see ``softhand inspect``).
"""
from __future__ import annotations

import sys
from pathlib import Path

from softhand.studies.cli.args import MAX_FEM_POINTS, MOST_FEM_POINTS, add_design_option, add_json_option, \
    add_max_cases_option, add_progress_option, design_from_args, max_cases, parse_values, print_json, print_table

HELP = "finger FEM: free bending under pressure vs the reduced model (eqs. 28, 2)"


def configure(parser) -> None:
    parser.add_argument("--pressure-mpa", metavar="RANGE", default="0:0.8:0.1",
                        help="cavity pressures [MPa] (one finger, no reservoir): start:stop:step (stop included) or a,b,c "
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
    parser.add_argument("--peak-mpa", type=float, default=None,
                        help=f"go on to this cavity pressure [MPa] and report peak stretch and stress "
                             f"(default {PEAK_MPA:g} when above the last pressure; 0: skip)")
    parser.add_argument("--hand", action="store_true",
                        help="also the whole hand: P = p_finger - p_reservoir(V0 - n dQ) with the "
                             "reservoir-sheet FEM, against eq. (27)")
    parser.add_argument("--plot", metavar="FILE.png",
                        help="theta vs P: FEM points, eqs. (28) (and (27) with --hand) as lines")
    parser.add_argument("--out", metavar="DIR", default="results/bend",
                        help="folder for result.json, table.csv and the VTK series")
    add_max_cases_option(parser, MAX_FEM_POINTS, MOST_FEM_POINTS)
    add_design_option(parser)
    add_json_option(parser)
    add_progress_option(parser)


#: option -> (lowest, highest) allowed; the mesh and quadrature options of the finger FEM
LIMITS = {"--axial-size-mm": (0.25, 20.0), "--mesh-size-mm": (0.5, 12.0),
          "--edge-ratio": (0.05, 1.0), "--refine": (0, 3), "--tie-width-mm": (0.5, 100.0),
          "--peak-mpa": (0.0, 5.0)}
#: quadrature degrees of the windings' rule: tetrahedral rules with positive weights, >= 2
FIBER_INTORDERS = (2, 5, 6, 7)
#: pressures the finger FEM is run at [MPa]
PRESSURE_RANGE = (0.0, 5.0)
#: the pressure the path goes on to for the peak stretch and stress, when not given [MPa]
PEAK_MPA = 2.0


def _check(args) -> tuple[float, ...]:
    """Every numeric option in its range before any FEM work; the pressures."""
    import numpy as np

    from softhand.reduced.vocabulary.errors import InputError
    from softhand.studies.cli.args import check_range

    for option, (lo, hi) in LIMITS.items():
        value = getattr(args, option[2:].replace("-", "_"))
        if value is not None:
            check_range(option, value, lo, hi)
    if args.fiber_intorder is not None and args.fiber_intorder not in FIBER_INTORDERS:
        raise InputError("--fiber-intorder", args.fiber_intorder,
                         f"must be one of {', '.join(map(str, FIBER_INTORDERS))}")
    pressures = parse_values(args.pressure_mpa, "--pressure-mpa",
                             max_cases(args, MAX_FEM_POINTS, MOST_FEM_POINTS))
    lo, hi = PRESSURE_RANGE
    if pressures.min() < lo or pressures.max() > hi:
        raise InputError("--pressure-mpa", args.pressure_mpa, f"pressures must be in [{lo:g}, {hi:g}] MPa")
    if np.any(np.diff(pressures) <= 0):
        raise InputError("--pressure-mpa", args.pressure_mpa, "pressures must increase (a load path)")
    if args.peak_mpa is not None and 0 < args.peak_mpa <= pressures[-1]:
        raise InputError("--peak-mpa", args.peak_mpa, f"must be 0 (no peak) or above the last "
                                                      f"pressure, {pressures[-1]:g} MPa")
    if args.tie == "full" and args.tie_width_mm is not None:
        raise InputError("--tie-width-mm", args.tie_width_mm, "is the ring's width, for --tie ring "
                                                              "only")
    return tuple(float(p) for p in pressures)


def _peak(peak_mpa, pressures) -> float:
    """The peak pressure asked for (checked), or the default when above the path, else 0 (none)."""
    if peak_mpa is not None:
        return peak_mpa
    return PEAK_MPA if PEAK_MPA > pressures[-1] else 0.0


def _options(args):
    from softhand.fem.hand.finger import FingerOptions
    from softhand.reduced.vocabulary.errors import InputError

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
    import time
    from dataclasses import replace

    from tqdm import tqdm

    from softhand.fem.hand.finger import FingerModel

    from softhand.fem.newton import NotConverged
    from softhand.studies.bending import BendingStudy, run as run_study, vtk_writer
    from softhand.studies.io.files import kept_if_unwritable, unwritable_tolerant
    from softhand.studies.io.outputs import check_owned, replaced_outputs

    pressures = _check(args)
    out = Path(args.out)
    check_owned(out, OUTPUT_NAMES, "--out", "bend")
    design = design_from_args(args)
    if args.tie_width_mm is not None and args.tie_width_mm >= min(design.link_lengths):
        from softhand.reduced.vocabulary.errors import InputError

        raise InputError("--tie-width-mm", args.tie_width_mm,
                         f"must be shorter than every link (shortest {min(design.link_lengths):g} mm)")
    if args.tie_width_mm is not None:
        design = design.replace(tie_width=args.tie_width_mm)
    study = BendingStudy(design, pressures, _options(args),
                         peak_mpa=_peak(args.peak_mpa, pressures),
                         hand=args.hand)
    # the finger FEM first: a mesh it refuses (too large, folded) leaves the last run's outputs
    t0 = time.perf_counter()
    model = FingerModel(study.design, study.options)
    build = time.perf_counter() - t0
    n_steps = len(pressures) + (1 if study.peak_mpa else 0)
    bar = tqdm(total=n_steps, desc="bend", unit="pressure", file=sys.stderr, leave=False,
               disable=args.no_progress)
    converged = []

    def progress(model, state):
        converged.append((model, state))
        bar.set_postfix(P=f"{state.P:.2f}", theta=f"{state.theta * 57.29578:.1f}deg")
        bar.update(0 if state.P > pressures[-1] and state.P < study.peak_mpa else 1)

    # written into a private staging folder, renamed into place when complete: stopped (Ctrl-C,
    # SIGTERM, SIGKILL), the earlier run's result stays whole and no half-written series shows
    with replaced_outputs(out, OUTPUT_NAMES, verb="bend") as stage:
        write = unwritable_tolerant(vtk_writer(stage / "finger.pvd").write, out / "finger.pvd", "bend")

        def on_state(model, state):
            write(model, state.y, state.P)
            progress(model, state)

        try:
            result = replace(run_study(study, on_state=on_state, model=model), build_seconds=build)
        except NotConverged as exc:  # Newton gave up: its last converged state is kept, with a record
            return _failed(exc, converged, study, write, stage, out)
        finally:
            bar.close()
        summary = result.summary()
        with kept_if_unwritable(f"{out}/result.json, table.csv", "bend"):
            result.write(stage)
    if args.plot:
        with kept_if_unwritable(args.plot, "bend"):
            result.plot(args.plot)
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
                print(f"# Newton gave up on the way to {p['target_P_cavity_MPa']} MPa ({p['failure']}); "
                      f"last converged state:")
            print(f"# at {p['P_cavity_MPa']:.2f} MPa: theta {p['theta_deg']:.1f} deg, rubber stretch "
                  f"{p['rubber_stretch']:.3f} (corner peak {p['max_principal_stretch']:.3f}, mesh-dependent), "
                  f"max von Mises {p['max_von_mises_MPa']:.2f} MPa, hoop stretch {p['radial_stretch']:.4f} "
                  f"(peak {p['radial_stretch_max']:.4f})")
        print(f"# files in {out}")
    return 0


#: the files and folders a bend run writes into --out (its manifest: an earlier run's are replaced whole)
OUTPUT_NAMES = ("result.json", "table.csv", "hand.csv", "finger.pvd", "finger")


def _failed(exc, converged, study, write_vtk, stage: Path, out: Path) -> int:
    """Newton gave up: the last converged state (VTK + result.json, into the run's ``stage``)
    and one error line naming the pressure reached; exit code 1. ``write_vtk(model, y, P)``
    adds a state to the VTK series."""
    from softhand.studies.bending import row
    from softhand.studies.io.failure import save_last_converged
    from softhand.studies.io.files import write_csv

    rows = [row(state, study.design) for _, state in converged]
    reached = getattr(exc, "pressure", None)
    last_y = exc.last_converged[1] if exc.last_converged is not None else None
    if converged and reached is not None and last_y is not None and reached > converged[-1][1].P:
        model = converged[-1][0]  # the cut-back's last converged state, past the last requested P
        state = model.state(last_y, reached)
        write_vtk(model, last_y, reached)
        rows.append(row(state, study.design))
    message = str(exc).split(";")[0]
    last = rows[-1]["P_cavity_MPa"] if rows else 0.0
    return save_last_converged(
        stage, "bend", "finger FEM", message, f"P_cavity = {last:.4g} MPa",
        {"last_converged_P_cavity_MPa": last, "rows": rows, "design": study.design.to_dict()},
        write_files=(lambda folder: write_csv(folder / "table.csv", rows)) if rows else None, files="finger.pvd",
        shown=out)
