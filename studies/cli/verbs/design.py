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

import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from softhand.reduced.errors import InputError, MeshRejected, MeshTooLarge
from softhand.studies.cli.args import add_json_option, add_progress_option, print_json, print_table

HELP = "size finger and reservoir for an object (reduced model, optimiser) and prove it with the FEM"
#: what a design run writes into --out (an earlier run's are removed before it writes)
OUTPUT_FILES = ("result.json", "design.toml", "rejected_design.toml", "pareto.png", "grasp.pvd")
OUTPUT_FOLDERS = ("knee", "grasp")


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
    from softhand.studies.design import optimise as design_opt
    from softhand.studies.design.task import load_task
    from softhand.studies.design.task import LOWER, UPPER
    from softhand.studies.cli.checks import check_writable
    from softhand.studies.io.files import check_output_tree, replaced_outputs, write_atomic, write_json

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
    out = Path(args.out) if args.out else Path("results") / "design" / task.name
    check_writable(out, "dir", "--out")  # also the default folder, which argparse's checks do not see
    check_output_tree(out, "--out", files=OUTPUT_FILES, folders=OUTPUT_FOLDERS)
    if not args.no_fem:
        _check_proof_size(task, args)
    say = (lambda text: print(f"softhand design: {text}", file=sys.stderr)) if args.json else print
    options = design_opt.OptimiserOptions(seed=args.seed)
    opt = _optimise(task, options, args)
    ev = opt.evaluation
    base = design_opt.evaluate(task.base, task)
    if not ev.feasible:  # the documented outcome, before anything is written
        result = {**_result(task, opt, base, None, args.seed), "report": design_opt.infeasible_report(task, opt)}
        print_json(result) if args.json else _print(result, task, opt)
        return 1
    # an earlier run's outputs go first (the folder never mixes two runs), and a run stopped
    # mid-proof leaves none of its own
    with replaced_outputs(out, OUTPUT_FILES + OUTPUT_FOLDERS):
        out.mkdir(parents=True, exist_ok=True)
        design_file = write_atomic(out / "design.toml", ev.design.to_toml())
        result = _result(task, opt, base, design_file, args.seed)
        if args.pareto:
            from softhand.studies.design import pareto as design_pareto

            rows = design_pareto.front(task, opt, options)
            plot = design_pareto.plot(rows, args.plot or out / "pareto.png", task=task, base=base)
            result["pareto"] = {"rows": rows, "knee": design_pareto.knee(rows), "plot": str(plot)}
        if not args.no_fem:
            result = _prove_and_correct(result, task, opt, base, args, out, say, options)
            if args.pareto:
                result["pareto"]["knee_proof"] = _prove_knee(result["pareto"], task, args, out, say)
        ok = result["feasible"] and "fem_report" not in result and "report" not in result
        result["proven"] = None if args.no_fem else ok  # by the FEM; None: not asked (--no-fem)
        write_json(out / "result.json", result)
    if args.json:
        print_json(result)
    else:
        _print(result, task, opt)
    return 0 if ok else 1


def _optimise(task, options, args):
    """The optimiser, with a bar of its generations on stderr (one second of evaluations each
    for a heavy object, where one pad's force is found by bracketing)."""
    from tqdm import tqdm

    from softhand.studies.design import optimise as design_opt

    with tqdm(total=options.maxiter, desc="optimiser", unit="gen", file=sys.stderr, leave=False,
              disable=args.no_progress) as bar:
        def step(evaluations):
            bar.set_postfix_str(f"{evaluations} evaluations", refresh=False)
            bar.update()

        return design_opt.optimise(task, options, progress=step,
                                   say=lambda text: bar.write(f"softhand design: {text}", file=sys.stderr))


def _prove_and_correct(result, task, opt, base, args, out, say, options) -> dict:
    """The FEM proof of the optimum; if the FEM's peak stretch breaks the task's limit, one
    re-optimisation with eq. (8)'s strain scaled to the FEM's and the proof of that design
    (the first optimum is kept under ``rejected``)."""
    from softhand.studies.design import optimise as design_opt
    from softhand.studies.design.proof import corrected_task, fem_report
    from softhand.studies.io.files import write_atomic

    ev = opt.evaluation
    if task.obj is not None:  # a hold task: the whole-hand FEM hold confirms the fast model's holding limit
        from softhand.studies.design.hold_eval import prove_hold

        result["fem"] = prove_hold(ev, task, say)
        if "report" in result["fem"]:
            result["fem_report"] = result["fem"]["report"]
        return result
    result["fem"] = _prove(ev, task, args, out, say)
    report = fem_report(result["fem"], ev)
    if not report:
        return result
    result["fem_report"] = report
    corrected = None if args.no_correct else corrected_task(task, ev, result["fem"])
    if corrected is None:
        return result
    say(f"the FEM's peak stretch is {corrected.stretch_factor:.3g} x eq. (8)'s strain: optimising again with it")
    rejected = {k: result[k] for k in ("design", "predicted", "fem", "constraints", "fem_report")}
    rejected["design_file"] = str(write_atomic(out / "rejected_design.toml", ev.design.to_toml()))
    opt = _optimise(corrected, options, args)
    design_file = write_atomic(out / "design.toml", opt.evaluation.design.to_toml())
    new = {**_result(corrected, opt, base, design_file, args.seed), "stretch_factor": corrected.stretch_factor,
           "rejected": rejected, **{k: result[k] for k in ("pareto",) if k in result}}
    if not opt.evaluation.feasible:
        new["report"] = design_opt.infeasible_report(corrected, opt)
        return new
    new["fem"] = _prove(opt.evaluation, corrected, args, out, say)
    report = fem_report(new["fem"], opt.evaluation)
    if report:
        new["fem_report"] = report
    return new


def _prove_knee(pareto: dict, task, args, out, say) -> dict | None:
    """The FEM proof of the Pareto front's knee (None if the knee is the optimum): its design
    (knee/design.toml), prediction and FEM, the VTK in knee/."""
    from softhand.studies.design import optimise as design_opt
    from softhand.studies.io.files import write_atomic

    row = pareto["rows"][pareto["knee"]]
    if pareto["knee"] == 0:
        return None
    sub = replace(task, max_stretch=row["stretch_limit"])
    ev = design_opt.Problem(sub).evaluation(np.array([row["free"][k] for k, _, _ in task.free]))
    (out / "knee").mkdir(exist_ok=True)
    say(f"FEM proof of the Pareto knee (stretch {row['max_principal_stretch']:.4g})")
    return {"design_file": str(write_atomic(out / "knee" / "design.toml", ev.design.to_toml())),
            "stretch_limit": row["stretch_limit"], "predicted": ev.predicted(),
            "fem": _prove(ev, sub, args, out / "knee", say)}


def _check_proof_size(task, args) -> None:
    """A proof mesh too large for this machine: one line now, not after the optimiser's minutes."""
    from softhand.studies.design.proof import check_proof_size

    given = args.mesh_size_mm is not None
    size = args.mesh_size_mm if given else task.mesh_size
    try:
        check_proof_size(task, size)
    except MeshTooLarge as exc:
        raise InputError("--mesh-size-mm" if given else "fem.mesh_size_mm", size, exc.allowed) from None


def _prove(ev, task, args, out, say) -> dict:
    from softhand.fem.newton import NotConverged
    from softhand.studies.design.proof import ProofOptions, proof_meshes, prove

    failed = []
    for size in proof_meshes(ev.design, args.mesh_size_mm if args.mesh_size_mm is not None else task.mesh_size):
        try:  # a finger mesh that fails is retried on the next finer one
            options = ProofOptions(mesh_size_mm=size, dP_mpa=task.dP, edge_ratio=task.edge_ratio)
            fem = prove(ev, task, options, out=out, progress=say)
            return {**fem, "failed_meshes": failed} if failed else fem
        except (NotConverged, RuntimeError, MeshRejected) as exc:
            say(f"the FEM proof on the {size:g} mm finger mesh failed: {str(exc)[:300]}")  # e.g. folded
            failed.append({"mesh_size_mm": size, "error": str(exc)[:300]})
            if isinstance(exc, MeshTooLarge):  # a finer mesh would be larger still
                return {"error": failed[-1]["error"], "failed_meshes": failed, "too_large": True}
    return {"error": failed[-1]["error"], "failed_meshes": failed}


def _result(task, opt, base, design_file, seed: int) -> dict:
    ev = opt.evaluation
    return {
        "task": task.name, "feasible": ev.feasible, "objective": task.objective,
        "design": ev.design.to_dict(),
        "free": {k: float(v) for (k, _, _), v in zip(task.free, opt.x)},
        "free_bounds": {k: [lo, hi] for k, lo, hi in task.free},
        "bounds_clipped_from": {k: [lo, hi] for k, lo, hi in task.clipped},
        "predicted": ev.predicted(),
        "fem": None,
        "proven": None,  # set once the FEM proof is done: True if it met the task (see run)
        "base_design": {"design": task.base.to_dict(), "predicted": base.predicted(),
                        "feasible": base.feasible},
        "constraints": [c.as_dict() for c in ev.constraints],
        "design_file": None if design_file is None else str(design_file),
        "optimiser": {"method": "differential_evolution + SLSQP polish", "seed": seed,
                      "evaluations": opt.evaluations, "generations": opt.generations,
                      "seconds": opt.seconds, "cpu_seconds": opt.cpu_seconds, "message": opt.message},
    }


def _print(result: dict, task, opt) -> None:
    free = ", ".join(f"{k} = {v:.5g}" for k, v in result["free"].items())
    print(f"task {task.name}: {task.diameter:g} mm, {task.mass:g} kg, F_v >= {task.required_F_v():.4g} N "
          f"per finger, pump <= {task.max_pressure:g} MPa; objective: {task.objective}")
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
    keys = ("P_grasp_MPa", "P_contact_MPa", "theta_grasp_deg", "F_v_N", "max_principal_stretch", "w") + \
        (("F_v_at_pump_limit_N", "margin_N") if task.objective == "margin" else ())
    fem = result.get("fem") or {}
    base = result["base_design"]["predicted"]
    table = [{"quantity": k, "base design": base.get(k), "predicted": result["predicted"].get(k),
              "FEM": fem.get(k), "FEM / predicted - 1": _rel(fem.get(k), result["predicted"].get(k))}
             for k in keys]
    print_table(table)
    predicted = result["predicted"]
    if predicted.get("margin_below_pump_limit"):
        print(f"# margin_N: F_v at {predicted['margin_at_pump_pressure_MPa']:.4g} MPa, below the pump limit, less "
              f"the required F_v; the FEM-informed grasp ends there: {predicted['margin_below_pump_limit']}")
    if fem.get("margin"):
        _print_margin(fem, task)
    if fem.get("constraints"):
        print_table(fem["constraints"])
    if fem.get("wall_seconds"):
        print(f"# FEM proof: finger {fem['finger_ndofs']} unknowns (mesh {fem['mesh_size_mm']:g} mm), "
              f"sheet {fem['sheet_ndofs']}, {fem['wall_seconds']:.0f} s; F_v at the FEM's P_grasp "
              f"{fem['F_v_at_P_grasp_N']:.4g} N")
    if "pareto" in result:
        k = result["pareto"]["knee"]
        print(f"Pareto front: {len(result['pareto']['rows'])} points, knee at stretch "
              f"{result['pareto']['rows'][k]['max_principal_stretch']:.4g}; plot {result['pareto']['plot']}")
        knee = result["pareto"].get("knee_proof")
        if knee and "P_grasp_MPa" in knee["fem"]:
            print(_knee_line(knee))
    print(f"design: {result['design_file'] or 'none written (the task cannot be met)'}")


def _knee_line(knee: dict) -> str:
    """The Pareto knee's prediction beside its FEM proof (and the margin, if the proof has one)."""
    predicted, fem = knee["predicted"], knee["fem"]
    margin = "" if fem.get("margin_N") is None else \
        f"margin {predicted['margin_N']:.4g} N predicted, {fem['margin_N']:.4g} N FEM; "
    return (f"knee: P_grasp {predicted['P_grasp_MPa']:.4g} MPa predicted, {fem['P_grasp_MPa']:.4g} MPa FEM; "
            f"F_v {predicted['F_v_N']:.4g} N predicted, {fem['F_v_N']:.4g} N FEM; {margin}"
            f"design {knee['design_file']}")


def _print_margin(fem: dict, task) -> None:
    """The FEM's grasp at the margin's pump pressure, and at the pump limit if it went on to it."""
    def on(row):
        links = row["links_in_contact"]
        return f"on the object: link{'s' if len(links) > 1 else ''} {', '.join(map(str, links)) or 'none'} (0 = base)"

    m = fem["margin"]
    if "error" in m:
        print(f"# FEM margin: not computed ({m['error']}); predicted F_v {m['predicted_F_v_N']:.4g} N")
        return
    print(f"# FEM margin: F_v {m['F_v_N']:.4g} N at the pump pressure {m['pump_pressure_MPa']:.4g} MPa "
          f"(cavity {m['cavity_pressure_MPa']:.4g} MPa, {on(m)}), predicted {m['predicted_F_v_N']:.4g} N")
    limit = fem.get("at_pump_limit")
    if limit and "error" in limit:
        print(f"# FEM at the pump limit {task.max_pressure:g} MPa: not reached ({limit['error']})")
    elif limit:
        print(f"# FEM at the pump limit {task.max_pressure:g} MPa, beyond the reduced model's one-pad grasp: "
              f"F_v {limit['F_v_N']:.4g} N, margin {limit['margin_N']:.4g} N ({on(limit)})")


def _rel(a, b):
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and b and math.isfinite(b):
        return a / b - 1.0
    return None
