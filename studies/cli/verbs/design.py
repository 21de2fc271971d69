"""``softhand design``: size finger and reservoir for a task on the reduced model, prove it by FEM.

The task file (see ``studies/designs/tasks/``) names the object, the grasp requirement, the
pump, the limits and the free design keys with their bounds. The optimum of the reduced
model (differential evolution, seeded) goes through the FEM -- free bend with the reservoir
and the grasp at the task's object -- unless ``--no-fem``. Written to ``--out DIR``: the
design TOML (usable by every verb), ``result.json``, with ``--pareto`` the front's plot and the
FEM proof of its knee (``knee/``), and the VTK of the verified grasp (``grasp.pvd``). A task that cannot be met: one paragraph
naming the binding constraint and the nearest design, exit code 1, and nothing written (no ``--out``
folder: its design is not one to use; ``--json`` prints the whole record).
"""
from __future__ import annotations

import sys
from pathlib import Path

from softhand.reduced.vocabulary.errors import InputError, MeshTooLarge
from softhand.studies.cli.args import add_json_option, add_progress_option, print_json, print_table
from softhand.studies.design.summary import knee_line, margin_lines, relative_difference

HELP = "size finger and reservoir for an object (reduced model, optimiser) and prove it with the FEM"


def configure(parser) -> None:
    parser.add_argument("--task", required=True, metavar="FILE.toml", help="the design task")
    parser.add_argument("--seed", type=int, default=1, help="optimiser seed (default 1)")
    parser.add_argument("--pareto", action="store_true",
                        help="also trace pump pressure against peak stretch (front, knee, plot)")
    parser.add_argument("--out", metavar="DIR", help="output folder (default results/design/TASK)")
    parser.add_argument("--plot", metavar="FILE.png", help="the Pareto plot (default DIR/pareto.png)")
    parser.add_argument("--no-fem", action="store_true", help="skip the FEM proof (reduced model only)")
    parser.add_argument("--no-correct", action="store_true",
                        help="keep the first optimum when the FEM's peak stretch breaks the limit "
                             "(default: optimise once more with eq. (8) scaled to the FEM's stretch, prove that)")
    parser.add_argument("--mesh-size-mm", type=float, metavar="H",
                        help="finger element size of the FEM proof [mm] (default: the task's, 6; "
                             "at most 6 for walls b > 5 mm)")
    add_progress_option(parser)
    add_json_option(parser)


def run(args) -> int:
    from softhand.studies.cli.checks import check_writable
    from softhand.studies.design.task import load_task
    from softhand.studies.design.task_values import LOWER, UPPER
    from softhand.studies.design.workflow import OUTPUT_FILES, OUTPUT_FOLDERS, DesignRun, run_task
    from softhand.studies.io.outputs import check_output_tree, check_owned

    lo, hi = LOWER["mesh_size_mm"], UPPER["mesh_size_mm"]
    if args.mesh_size_mm is not None and not lo <= args.mesh_size_mm <= hi:
        raise InputError("--mesh-size-mm", args.mesh_size_mm, f"must be a number in [{lo:g}, {hi:g}]")
    if not 0 <= args.seed < 2**32:
        raise InputError("--seed", args.seed, "must be a whole number in [0, 4294967295]")
    if args.plot is not None and not args.pareto:
        raise InputError("--plot", args.plot, "is the Pareto front's plot: give --pareto too")
    if args.no_fem:
        for option, value in (("--mesh-size-mm", args.mesh_size_mm), ("--no-correct", args.no_correct or None)):
            if value is not None:
                raise InputError(option, value, "sets the FEM proof, which --no-fem skips")
    task = load_task(args.task)
    out = Path(args.out) if args.out else _default_out(task, args.task)
    check_writable(out, "dir", "--out")  # also the default folder, which argparse's checks do not see
    check_output_tree(out, "--out")
    check_owned(out, OUTPUT_FILES + OUTPUT_FOLDERS, "--out", "design")
    if not args.no_fem:
        _check_proof_size(task, args)
    say = (lambda text: print(f"softhand design: {text}", file=sys.stderr)) if args.json else print
    run = DesignRun(seed=args.seed, pareto=args.pareto, plot=args.plot, fem=not args.no_fem,
                    correct=not args.no_correct, mesh_size_mm=args.mesh_size_mm, show_progress=not args.no_progress)
    result, opt, ok = run_task(task, out, run, say)
    if args.json:
        print_json(result)
    else:
        _print(result, task, opt)
    return 0 if ok else 1


def _default_out(task, path) -> Path:
    """results/design/<task's name>, the name checked: one that is no plain folder name (a task
    file named '...toml' gives '..') would write elsewhere, e.g. into results/ itself."""
    from softhand.studies.batch.studyfile import is_folder_name

    if not is_folder_name(task.name):
        raise InputError("--task", str(path), f"its name {task.name!r} cannot name the output folder "
                         "results/design/NAME (letters, digits, '_', '-', '.', starting with a letter "
                         "or digit); rename the file or give --out DIR")
    return Path("results") / "design" / task.name


def _check_proof_size(task, args) -> None:
    """A proof mesh too large for this machine: one line now, not after the optimiser's minutes."""
    from softhand.studies.design.proof_sizes import check_proof_size

    given = args.mesh_size_mm is not None
    size = args.mesh_size_mm if given else task.mesh_size
    try:
        check_proof_size(task, size)
    except MeshTooLarge as exc:
        raise InputError("--mesh-size-mm" if given else "fem.mesh_size_mm", size, exc.allowed) from None


def _print(result: dict, task, opt) -> None:
    free = ", ".join(f"{k} = {v:.5g}" for k, v in result["free"].items())
    print(f"task {task.name}: {task.diameter:g} mm, {task.mass:g} kg, F_v >= {task.required_F_v():.4g} N "
          f"per finger, pump <= {task.max_pressure:g} MPa; objective: {task.objective}")
    m = result["models"]
    print(f"models: finger {m['finger_model']!r} ({m['tube_rubber']} tube), reservoir {m['reservoir_model']!r} "
          f"({m['sheet_rubber']} sheet); rubber stretch of the tube: {m['tube_stretch']}, of the sheet: "
          f"{m['sheet_stretch']}")
    print(f"optimum: {free}  ({opt.evaluations} model evaluations, {opt.seconds:.1f} s wall, "
          f"{opt.cpu_seconds:.1f} s CPU)")
    if not opt.evaluation.feasible:  # why the search ended where it did
        print(f"# the search: {opt.message}")
    for key, lo, hi in task.clipped:
        print(f"# free {key} = [{lo:g}, {hi:g}] clipped to {result['free_bounds'][key]}: the space "
              f"finger_model \"fem\" is calibrated on")
    if "rejected" in result:
        r = result["rejected"]
        print(f"{r['fem_report']} Optimised again with eq. (8)'s strain x {result['stretch_factor']:.3g} "
              f"(the FEM's over the prediction); the rejected design: {r['design_file']}")
    for key in ("report", "fem_report"):
        if key in result:
            print(result[key])
    rows = [{"constraint": c["name"], "value": c["value"], "sense": c["sense"], "limit": c["limit"],
             "satisfied": c["satisfied"]} for c in result["constraints"]]
    print_table(rows)
    keys = ("P_grasp_MPa", "P_contact_MPa", "theta_grasp_deg", "F_v_N", "rubber_stretch", "w") + \
        (("F_v_at_pump_limit_N", "margin_N") if task.objective == "margin" else ())
    fem = result.get("fem") or {}
    base = result["base_design"]["predicted"]
    table = [{"quantity": k, "base design": base.get(k), "predicted": result["predicted"].get(k),
              "FEM": fem.get(k), "FEM / predicted - 1": relative_difference(fem.get(k), result["predicted"].get(k))}
             for k in keys]
    print_table(table)
    predicted = result["predicted"]
    if predicted.get("margin_below_pump_limit"):
        print(f"# margin_N: F_v at {predicted['margin_at_pump_pressure_MPa']:.4g} MPa, below the pump limit, less "
              f"the required F_v; the FEM-informed grasp ends there: {predicted['margin_below_pump_limit']}")
    if fem.get("margin"):
        print(*margin_lines(fem, task), sep="\n")
    if fem.get("constraints"):
        print_table(fem["constraints"])
    if fem.get("wall_seconds"):
        print(f"# FEM proof: finger {fem['finger_ndofs']} unknowns (mesh {fem['mesh_size_mm']:g} mm), "
              f"sheet {fem['sheet_ndofs']}, {fem['wall_seconds']:.0f} s; F_v at the FEM's P_grasp "
              f"{fem['F_v_at_P_grasp_N']:.4g} N")
    if "pareto" in result:
        k = result["pareto"]["knee"]
        print(f"Pareto front: {len(result['pareto']['rows'])} points, knee at stretch "
              f"{result['pareto']['rows'][k]['rubber_stretch']:.4g}; plot {result['pareto']['plot']}")
        knee = result["pareto"].get("knee_proof")
        if knee and "P_grasp_MPa" in knee["fem"]:
            print(knee_line(knee))
    print(f"design: {result['design_file'] or 'none written (the task cannot be met)'}")
