"""Pump pressure against rubber stretch: the Pareto front of a design task, its knee and plot.

The stretch is the rubber's: the larger of the tube's and the reservoir sheet's (their
calibrated converged stretches where the models' tables hold them, else eqs. (8) and (16);
:mod:`softhand.studies.design.evaluate`). A fuller sheet or a longer lever arm needs less pump pressure but stretches the
rubber more.
The front is traced by the epsilon-constraint method: the least stretch any feasible design
reaches (differential evolution on the stretch, polished by SLSQP), then the task's objective with the stretch
limit lowered step by step from the optimum's stretch to that least one, each step an SLSQP
solve started from the previous point (the front is continuous, so the continuation keeps
the work to ~100 model evaluations a point). The knee is the point farthest from the chord
between the two ends, on axes scaled to [0, 1].
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from scipy.optimize import NonlinearConstraint, differential_evolution

from softhand.studies.design import optimise as design_opt
from softhand.studies.design.task import Task


def least_stretch(task: Task, options: design_opt.OptimiserOptions) -> tuple[np.ndarray, float]:
    """The feasible design (free values) with the least peak stretch, and that stretch:
    differential evolution to the task's tolerance, then SLSQP from its best point (as the
    optimiser does; DE alone to a tight tolerance took 3-8 times as long and ended higher)."""
    problem = design_opt.Problem(task, measure=lambda ev: ev.rubber_stretch)
    res = differential_evolution(problem.f, problem.bounds,
                                 constraints=NonlinearConstraint(problem.slacks, 0.0, np.inf),
                                 seed=options.seed, popsize=max(5, options.popsize // 2),
                                 maxiter=options.maxiter, tol=options.tol, polish=False, init="sobol",
                                 updating="immediate", workers=1)
    x = design_opt.polish(problem, np.asarray(res.x, dtype=float))
    return x, problem.f(x)


def front(task: Task, optimum: design_opt.Optimum, options: design_opt.OptimiserOptions,
          points: int = 8) -> list[dict]:
    """Points (stretch, objective, free values), from the optimum to the least stretch."""
    _, lam_min = least_stretch(task, options)
    lam_opt = optimum.evaluation.rubber_stretch
    rows = [_row(task, optimum.x, optimum.evaluation)]
    x = optimum.x
    for eps in np.linspace(lam_opt, lam_min, points)[1:]:
        sub = replace(task, max_stretch=float(eps))
        problem = design_opt.Problem(sub)
        x_new = design_opt.polish(problem, x, require_better=False)
        ev = problem.evaluation(x_new)
        if not ev.feasible:
            continue
        x = x_new
        rows.append(_row(sub, x, ev))
    return rows


def _row(task: Task, x, ev: design_opt.Evaluation) -> dict:
    return {"stretch_limit": task.max_stretch, "rubber_stretch": ev.rubber_stretch,
            "P_grasp_MPa": ev.P_grasp, "margin_N": ev.predicted()["margin_N"],
            "objective": design_opt.objective(ev, task),
            "free": {k: float(v) for (k, _, _), v in zip(task.free, x)}}


def knee(rows: list[dict]) -> int:
    """Index of the point farthest from the chord between the front's ends (scaled axes)."""
    if len(rows) < 3:
        return 0
    xy = np.array([[r["rubber_stretch"], r["objective"]] for r in rows])
    span = np.ptp(xy, axis=0)
    xy = (xy - xy.min(axis=0)) / np.where(span > 0, span, 1.0)
    a, b = xy[0], xy[-1]
    chord = (b - a) / max(np.linalg.norm(b - a), 1e-12)
    rel = xy - a
    dist = np.abs(rel[:, 0] * chord[1] - rel[:, 1] * chord[0])
    return int(np.argmax(dist))


def plot(rows: list[dict], path, *, task: Task, base: design_opt.Evaluation | None = None):
    """Objective against peak stretch; the optimum, the knee and the base design marked."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from softhand.studies.io.files import save_figure

    label = "pump pressure at the grasp [MPa]" if task.objective == "pressure" else "- F_v margin [N]"
    fig, ax = plt.subplots(figsize=(5.5, 4))
    lam = [r["rubber_stretch"] for r in rows]
    obj = [r["objective"] for r in rows]
    ax.plot(lam, obj, "o-", label="Pareto front (reduced model)")
    ax.plot(lam[0], obj[0], "s", ms=9, mfc="none", label="optimum")
    k = knee(rows)
    ax.plot(lam[k], obj[k], "D", ms=9, mfc="none", label="knee")
    if base is not None and math.isfinite(design_opt.objective(base, task)):
        ax.plot(base.rubber_stretch, design_opt.objective(base, task), "x", ms=9, label="base design")
    ax.set_xlabel("rubber stretch of the tube and the sheet (the larger)")
    ax.set_ylabel(label)
    ax.set_title(f"{task.name}: {task.diameter:g} mm, {task.mass:g} kg")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return save_figure(fig, path)
