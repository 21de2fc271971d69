"""The design optimiser on the reduced model: differential evolution (several settings) against
SLSQP alone from the base design and from random starts. Prints the objective, whether the
result is feasible, evaluations, wall time and CPU time (the wall time of a loaded machine
is a multiple of the CPU time) for each.

    PYTHONPATH=. python benchmarks/bench_design.py [TASK.toml ...]
"""
from __future__ import annotations

import sys
import time

import numpy as np
from scipy.optimize import minimize

from softhand.studies.design import optimise as design_opt
from softhand.studies.design.task import load_task

TASKS = ["studies/designs/tasks/paper_task.toml", "studies/designs/tasks/small_object.toml",
         "studies/designs/tasks/large_object.toml", "studies/designs/tasks/low_pressure.toml"]


def slsqp(task, x0):
    """SLSQP alone (finite-difference gradients) from x0, variables scaled to [0, 1]."""
    t0, cpu = time.perf_counter(), time.process_time()
    problem = design_opt.Problem(task)
    lo, hi = np.array(problem.bounds).T
    to_x = lambda z: lo + z * (hi - lo)  # noqa: E731
    res = minimize(lambda z: problem.f(to_x(z)), (np.asarray(x0) - lo) / (hi - lo), method="SLSQP",
                   bounds=[(0.0, 1.0)] * len(lo), options={"ftol": 1e-12, "maxiter": 200},
                   constraints=[{"type": "ineq", "fun": lambda z: problem.slacks(to_x(z))}])
    x = np.clip(to_x(res.x), lo, hi)
    ev = problem.evaluation(x)
    return (design_opt.objective(ev, task), ev.feasible, problem.evaluations, time.perf_counter() - t0,
            time.process_time() - cpu)


def main(paths) -> None:
    for path in paths:
        task = load_task(path)
        print(f"== {path} (objective: {task.objective}; free: {', '.join(k for k, _, _ in task.free)})")
        default = design_opt.OptimiserOptions()
        for opts in (default, design_opt.OptimiserOptions(popsize=8, maxiter=100)):
            cpu = time.process_time()
            opt = design_opt.optimise(task, opts)
            print(f"DE popsize {opts.popsize:2d} maxiter {opts.maxiter} tol {opts.tol:.0e} + polish"
                  f"{' (the default)' if opts == default else ''}: objective "
                  f"{design_opt.objective(opt.evaluation, task):.6g}, feasible {opt.evaluation.feasible}, "
                  f"{opt.evaluations} evaluations, {opt.generations} generations, {opt.seconds:.1f} s wall, "
                  f"{time.process_time() - cpu:.1f} s CPU")
        base = [task.base.to_dict()[k] for k, _, _ in task.free]
        starts = [np.clip(base, *np.array([(lo, hi) for _, lo, hi in task.free]).T)]
        rng = np.random.default_rng(0)
        starts += [rng.uniform(*np.array([(lo, hi) for _, lo, hi in task.free]).T) for _ in range(4)]
        for i, x0 in enumerate(starts):
            f, ok, n, s, c = slsqp(task, x0)
            print(f"SLSQP from {'the base design' if i == 0 else f'random start {i}'}: objective {f:.6g}, "
                  f"feasible {ok}, {n} evaluations, {s:.1f} s wall, {c:.1f} s CPU")


if __name__ == "__main__":
    main(sys.argv[1:] or TASKS[:1])
