"""A design run, start to end: the optimum of the reduced model for a task, its FEM proof (a
re-optimisation if the FEM's peak stretch breaks the limit), the Pareto front and its knee,
and the files (design.toml, result.json, the VTK of the proof). ``softhand design`` checks
its options, calls :func:`run_task` and prints the record.
"""
from __future__ import annotations

import sys
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from softhand.reduced.vocabulary.errors import InputError, MeshRejected, MeshTooLarge
from softhand.studies.design import optimise as design_opt
from softhand.studies.design import evaluate, proof, proof_sizes, proof_steps
from softhand.studies.io.files import kept_if_unwritable, write_atomic, write_json
from softhand.studies.io.outputs import replaced_outputs

#: what a design run writes into its folder (its manifest: an earlier run's are replaced whole)
OUTPUT_FILES = ("result.json", "design.toml", "rejected_design.toml", "pareto.png", "grasp.pvd")
OUTPUT_FOLDERS = ("knee", "grasp")


@dataclass(frozen=True)
class DesignRun:
    """How to run a design task."""

    seed: int = 1                     #: the optimiser's seed
    pareto: bool = False              #: also trace the Pareto front (pump pressure vs peak stretch)
    plot: str | None = None           #: the front's plot (default <out>/pareto.png)
    fem: bool = True                  #: prove the optimum with the FEM
    correct: bool = True              #: re-optimise with the FEM's stretch factor if the limit breaks
    mesh_size_mm: float | None = None  #: finger mesh of the proof (None: the task's)
    show_progress: bool = True        #: the optimiser's and the FEM proof's bars on stderr


def run_task(task, out, run: DesignRun = DesignRun(), say=print):
    """(record, optimum, ok) of the task: nothing written if it cannot be met (the record has
    the ``report``), else the design, result.json and the proof's files in ``out``, written into
    a private staging folder renamed into place when the run is complete (the earlier run's
    result stays whole until then; a run stopped mid-proof leaves none of its own). The record
    names the final paths. ``ok``: met, and proven by the FEM unless ``run.fem`` is False."""
    out = Path(out)
    options = design_opt.OptimiserOptions(seed=run.seed)
    opt = optimise_task(task, options, show_progress=run.show_progress)
    ev = opt.evaluation
    try:
        base = design_opt.evaluate(task.base, task)
    except InputError:  # the base design has no answer (the object does not fit it): as the optimiser's
        base = evaluate.unanswered(task)
    if not ev.feasible:  # the documented outcome, before anything is written
        return {**result_record(task, opt, base, None, run.seed),
                "report": design_opt.infeasible_report(task, opt)}, opt, False
    with replaced_outputs(out, OUTPUT_FILES + OUTPUT_FOLDERS, verb="design") as stage:
        dirs = (stage, out)
        with kept_if_unwritable(out / "design.toml", "design"):
            write_atomic(stage / "design.toml", ev.design.to_toml())
        result = result_record(task, opt, base, out / "design.toml", run.seed)
        if run.pareto:
            from softhand.studies.design import pareto as design_pareto

            rows = design_pareto.front(task, opt, options)
            plot = Path(run.plot) if run.plot else out / "pareto.png"
            inside = plot.resolve() == (out / "pareto.png").resolve()  # the run's own: staged with it
            with kept_if_unwritable(plot, "design"):
                design_pareto.plot(rows, stage / "pareto.png" if inside else plot, task=task, base=base)
            result["pareto"] = {"rows": rows, "knee": design_pareto.knee(rows), "plot": str(plot)}
        if run.fem:
            result = prove_and_correct(result, task, opt, base, run, dirs, say, options)
            if run.pareto:
                result["pareto"]["knee_proof"] = prove_knee(result["pareto"], task, run, dirs, say)
        ok = result["feasible"] and "fem_report" not in result and "report" not in result
        result["proven"] = ok if run.fem else None  # by the FEM; None: not asked
        with kept_if_unwritable(out / "result.json", "design"):
            write_json(stage / "result.json", result)
    return result, opt, ok


def optimise_task(task, options, *, show_progress: bool = True):
    """The optimiser, with a bar of its generations on stderr (one second of evaluations each
    for a heavy object, where one pad's force is found by bracketing)."""
    from tqdm import tqdm

    with tqdm(total=options.maxiter, desc="optimiser", unit="gen", file=sys.stderr, leave=False,
              disable=not show_progress) as bar:
        def step(evaluations):
            bar.set_postfix_str(f"{evaluations} evaluations", refresh=False)
            bar.update()

        return design_opt.optimise(task, options, progress=step,
                                   say=lambda text: bar.write(f"softhand design: {text}", file=sys.stderr))


def prove_and_correct(result: dict, task, opt, base, run: DesignRun, dirs, say, options) -> dict:
    """The FEM proof of the optimum; if the FEM's peak stretch breaks the task's limit, one
    re-optimisation with eq. (8)'s strain scaled to the FEM's and the proof of that design
    (the first optimum is kept under ``rejected``). ``dirs``: (staging folder written, output
    folder named)."""
    ev = opt.evaluation
    stage, out = dirs
    if task.obj is not None:  # a hold task: the whole-hand FEM hold confirms the fast model's holding limit
        from softhand.studies.design.hold_eval import prove_hold

        result["fem"] = prove_hold(ev, task, say)
        if "report" in result["fem"]:
            result["fem_report"] = result["fem"]["report"]
        return result
    result["fem"] = prove_on_meshes(ev, task, run.mesh_size_mm, stage, say, show_progress=run.show_progress)
    report = proof.fem_report(result["fem"], ev)
    if not report:
        return result
    result["fem_report"] = report
    corrected = None if not run.correct else proof.corrected_task(task, ev, result["fem"])
    if corrected is None:
        return result
    say(f"the FEM's peak stretch is {corrected.stretch_factor:.3g} x eq. (8)'s strain: optimising again with it")
    rejected = {k: result[k] for k in ("design", "predicted", "fem", "constraints", "fem_report")}
    rejected["design_file"] = str(out / "rejected_design.toml")
    with kept_if_unwritable(out / "rejected_design.toml", "design"):
        write_atomic(stage / "rejected_design.toml", ev.design.to_toml())
    opt = optimise_task(corrected, options, show_progress=run.show_progress)
    with kept_if_unwritable(out / "design.toml", "design"):
        write_atomic(stage / "design.toml", opt.evaluation.design.to_toml())
    new = {**result_record(corrected, opt, base, out / "design.toml", run.seed), "stretch_factor": corrected.stretch_factor,
           "rejected": rejected, **{k: result[k] for k in ("pareto",) if k in result}}
    if not opt.evaluation.feasible:
        new["report"] = design_opt.infeasible_report(corrected, opt)
        return new
    new["fem"] = prove_on_meshes(opt.evaluation, corrected, run.mesh_size_mm, stage, say,
                                 show_progress=run.show_progress)
    report = proof.fem_report(new["fem"], opt.evaluation)
    if report:
        new["fem_report"] = report
    return new


def prove_knee(pareto: dict, task, run: DesignRun, dirs, say) -> dict | None:
    """The FEM proof of the Pareto front's knee (None if the knee is the optimum): its design
    (knee/design.toml), prediction and FEM, the VTK in knee/."""
    row = pareto["rows"][pareto["knee"]]
    if pareto["knee"] == 0:
        return None
    sub = replace(task, max_stretch=row["stretch_limit"])
    ev = design_opt.Problem(sub).evaluation(np.array([row["free"][k] for k, _, _ in task.free]))
    stage, out = dirs
    (stage / "knee").mkdir(exist_ok=True)
    say(f"FEM proof of the Pareto knee (stretch {row['rubber_stretch']:.4g})")
    with kept_if_unwritable(out / "knee" / "design.toml", "design"):
        write_atomic(stage / "knee" / "design.toml", ev.design.to_toml())
    return {"design_file": str(out / "knee" / "design.toml"),
            "stretch_limit": row["stretch_limit"], "predicted": ev.predicted(),
            "fem": prove_on_meshes(ev, sub, run.mesh_size_mm, stage / "knee", say,
                                   show_progress=run.show_progress)}


def prove_on_meshes(ev, task, mesh_size_mm: float | None, out, say, *, show_progress: bool = False) -> dict:
    """The FEM proof of the evaluated design on the finger mesh ``mesh_size_mm`` (None: the
    task's), a mesh that fails retried on the next finer one
    (:func:`~softhand.studies.design.proof_sizes.proof_meshes`), which is said as information; with
    ``show_progress`` a bar of its phases (free bend, sheet, grasp states) on stderr. The
    proof's record, or its error and the meshes that failed."""
    import sys

    from tqdm import tqdm

    from softhand.fem.newton import NotConverged

    failed = []
    sizes = proof_sizes.proof_meshes(ev.design, mesh_size_mm if mesh_size_mm is not None else task.mesh_size)
    with tqdm(desc="FEM proof", unit="phase", file=sys.stderr, leave=False, disable=not show_progress) as bar:
        def phase(text):  # each line the proof says starts a phase
            with bar.external_write_mode(file=sys.stderr):
                say(text)
            bar.set_postfix_str("", refresh=False)
            bar.update()

        for k, size in enumerate(sizes):
            try:
                options = proof_steps.ProofOptions(mesh_size_mm=size, dP_mpa=task.dP, edge_ratio=task.edge_ratio)
                fem = proof.prove(ev, task, options, out=out, progress=phase,
                                  tick=lambda text: bar.set_postfix_str(text))
                return {**fem, "failed_meshes": failed} if failed else fem
            except (NotConverged, RuntimeError, MeshRejected) as exc:
                failed.append({"mesh_size_mm": size, "error": str(exc)[:300]})  # e.g. folded elements
                if isinstance(exc, MeshTooLarge):  # a finer mesh would be larger still
                    phase(f"the FEM proof on the {size:g} mm finger mesh failed: {str(exc)[:300]}")
                    return {"error": failed[-1]["error"], "failed_meshes": failed, "too_large": True}
                if k + 1 < len(sizes):
                    phase(f"note: the {size:g} mm finger mesh did not serve ({str(exc)[:200]}); "
                          f"proving on the {sizes[k + 1]:g} mm mesh instead")
                else:
                    phase(f"the FEM proof on the {size:g} mm finger mesh failed: {str(exc)[:300]}")
    return {"error": failed[-1]["error"], "failed_meshes": failed}


def result_record(task, opt, base, design_file, seed: int) -> dict:
    """The record of a design run (result.json) before the FEM proof."""
    ev = opt.evaluation
    return {
        "task": task.name, "feasible": ev.feasible, "objective": task.objective,
        "models": evaluate.models(ev.design, task),
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
