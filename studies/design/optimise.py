r"""Size the hand for a task on the reduced model: the optimiser over the task's free keys.

Each design is judged by :func:`softhand.studies.design.evaluate.evaluate` (grasp angle, pressures,
forces, constraints). Optimiser: :func:`scipy.optimize.differential_evolution` (seeded, one
worker: deterministic) with the constraints as a :class:`~scipy.optimize.NonlinearConstraint`
(feasibility rules: a task that cannot be met ends at the least-violating design), then an
SLSQP polish from its best point. ``benchmarks/bench_design.py`` measures it against SLSQP alone.

SciPy's DE never converges while a member of its population breaks a constraint, so a task
no design meets would run every generation: :class:`Stall` stops it once no member has met the
constraints for ``OptimiserOptions.stall`` generations and the least violation, at the pace it
fell over them, would still be above zero at the last generation. Whenever DE ends with no
feasible member, SLSQP is tried from the least-violating design before the task is called
infeasible.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from scipy.optimize import NonlinearConstraint, differential_evolution, minimize

from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.design.constraints import Constraint
from softhand.studies.design.evaluate import Evaluation, design_at, unanswered
from softhand.studies.design.evaluate import evaluate as grasp_evaluate
from softhand.studies.design.hold_eval import evaluate_hold
from softhand.studies.design.task import Task

__all__ = ["design_at", "evaluate", "objective", "Problem", "OptimiserOptions",
           "Optimum", "Stall", "optimise", "on_bounds", "polish", "binding", "infeasible_report", "open_span"]


def evaluate(design, task: Task, *, exact: bool = True) -> Evaluation:
    """A design judged for the task: a hold task (an object of any shape) by the fast hold model
    (:func:`softhand.studies.design.hold_eval.evaluate_hold`), else by :func:`softhand.studies.design.evaluate.evaluate`."""
    if task.obj is not None:
        return evaluate_hold(design, task)
    return grasp_evaluate(design, task, exact=exact)


def objective(ev: Evaluation, task: Task) -> float:
    """What the optimiser minimises: the pump pressure [MPa], or minus the margin [N]."""
    if task.objective == "pressure":
        return ev.P_grasp if math.isfinite(ev.P_grasp) else 1e3
    margin = ev.F_v_at_limit - ev.F_v
    return -margin if math.isfinite(margin) else 1e6


@dataclass
class Problem:
    """The optimisation problem on the task's free keys, with one evaluation per x (memo)."""

    task: Task
    #: what is minimised (default: the task's :func:`objective`); the Pareto front's end minimises the stretch
    measure: Callable[[Evaluation], float] | None = None
    evaluations: int = 0
    answered: int = 0  #: evaluations the model had an answer for
    refusal: InputError | None = field(default=None, repr=False)  #: the first it had none for
    _memo: dict = field(default_factory=dict, repr=False)

    def evaluation(self, x) -> Evaluation:
        k = np.asarray(x, dtype=float).tobytes()
        if k not in self._memo:
            if len(self._memo) > 20000:
                self._memo.clear()
            self.evaluations += 1
            exact = "l0_mm" not in (key for key, _, _ in self.task.free)
            try:
                self._memo[k] = evaluate(design_at(self.task, x), self.task, exact=exact)
                self.answered += 1
            except InputError as exc:  # no such design (a + b >= d, t >= R, ...) or no answer (no contact)
                self._memo[k] = unanswered(self.task)
                self.refusal = self.refusal or exc
        return self._memo[k]

    def f(self, x) -> float:
        ev = self.evaluation(x)
        return objective(ev, self.task) if self.measure is None else self.measure(ev)

    def slacks(self, x) -> np.ndarray:
        return np.array([c.slack for c in self.evaluation(x).constraints])

    def violation(self, x) -> float:
        """The total constraint violation at x (0 when every constraint is met), as SciPy sums it."""
        return float(np.sum(np.maximum(-self.slacks(x), 0.0)))

    @property
    def bounds(self):
        return [(lo, hi) for _, lo, hi in self.task.free]


#: SLSQP iterations from the least-violating design when DE ends with none feasible (each
#: iteration a finite-difference gradient: about 1 + free keys evaluations; a sliver of
#: feasible designs next to it took 6-8)
RESCUE_ITERATIONS = 10


@dataclass(frozen=True)
class OptimiserOptions:
    seed: int = 1
    popsize: int = 4          #: DE population per free variable (the Sobol start rounds it up to 2^k)
    maxiter: int = 60         #: DE generations at most
    tol: float = 1e-2         #: DE relative tolerance on the population's objective spread
    polish: bool = True       #: SLSQP from the DE optimum
    stall: int = 10           #: generations with no feasible member over which :class:`Stall` judges the pace


@dataclass(frozen=True)
class Optimum:
    x: np.ndarray
    evaluation: Evaluation
    evaluations: int
    seconds: float
    generations: int
    message: str
    cpu_seconds: float = 0.0  #: the process's CPU time (the wall time of a loaded machine is a multiple)


class Stall:
    """Whether DE should stop on a task it is not meeting: no design in the population has met
    the constraints for ``window`` generations, and the least total violation, falling at the
    pace of those generations, would still be above zero after the last of ``maxiter``."""

    def __init__(self, window: int, maxiter: int):
        self.window, self.maxiter = window, maxiter
        self.least: list[float] = []  #: the least violation of each generation since one met them all
        self.stopped = False

    def __call__(self, generation: int, violation: float) -> bool:
        if violation <= 0.0:
            self.least.clear()
            return False
        self.least.append(violation)
        if len(self.least) <= self.window:
            return False
        pace = (self.least[-1 - self.window] - violation) / self.window  # fall per generation
        pace = 0.0 if math.isnan(pace) else pace  # an infinite violation that stays infinite
        self.stopped = violation - pace * (self.maxiter - generation) > 0.0
        return self.stopped

    def message(self, generations: int) -> str:
        return (f"no design met the constraints in {generations} generations, and the least violation "
                f"fell too slowly over the last {self.window} to reach zero within {self.maxiter}: stopped")


def optimise(task: Task, options: OptimiserOptions = OptimiserOptions(), *, progress=None,
             say=None) -> Optimum:
    """Differential evolution (seeded) + SLSQP polish on the reduced model. ``progress``: called
    after each generation with the model evaluations so far (at most ``options.maxiter`` calls);
    ``say``: told in one line when DE ends with no feasible design and SLSQP is tried."""
    t0, cpu = time.perf_counter(), time.process_time()
    problem = Problem(task)
    cons = NonlinearConstraint(problem.slacks, 0.0, np.inf)
    stall = Stall(options.stall, options.maxiter)

    def generation(intermediate_result):  # scipy's callback: this name is its new-style signature
        if progress is not None:
            progress(problem.evaluations)
        if stall(intermediate_result.nit, problem.violation(intermediate_result.x)):
            raise StopIteration

    res = differential_evolution(problem.f, problem.bounds, constraints=cons, seed=options.seed,
                                 popsize=options.popsize, maxiter=options.maxiter, tol=options.tol,
                                 polish=False, init="sobol", updating="immediate", workers=1,
                                 callback=generation)
    x = np.asarray(res.x, dtype=float)
    if not problem.answered:  # nothing to rescue from: every point DE tried has no answer
        raise _unanswerable(task, problem.refusal)
    message = stall.message(int(res.nit)) if stall.stopped else str(res.message)
    if options.polish and not problem.evaluation(x).feasible:  # SLSQP may step where DE's population did not
        if say is not None:
            say(f"no design met the constraints after {int(res.nit)} generations ({problem.evaluations} "
                f"evaluations): trying SLSQP from the least-violating one")
        x = polish(problem, x, require_better=False, maxiter=RESCUE_ITERATIONS)
        if problem.evaluation(x).feasible:
            message += "; SLSQP from the least-violating design met the constraints"
    if options.polish and problem.evaluation(x).feasible:
        x = polish(problem, x)
    x = on_bounds(x, problem.bounds)
    try:
        ev = evaluate(design_at(task, x), task)  # exact kinematics
    except InputError as exc:  # the point SLSQP ended at has none: every constraint violated
        ev = unanswered(task)
        problem.refusal = problem.refusal or exc
    return Optimum(x, ev, problem.evaluations, time.perf_counter() - t0, int(res.nit), message,
                   time.process_time() - cpu)


def _unanswerable(task: Task, exc: InputError) -> InputError:
    bounds = {key: [lo, hi] for key, lo, hi in task.free}
    return InputError("free", bounds, f"no design within these bounds is one the model can answer "
                                      f"for this task; the optimiser's try: {exc}")


def on_bounds(x, bounds, rtol: float = 1e-9) -> np.ndarray:
    """x with the values within rtol (of the bounds' span) of a bound set to that bound: SLSQP
    ends at 4.500000000000008 for a wall on its bound 4.5, and the FEM proof's mesher would
    mesh a different wall."""
    lo, hi = np.array(bounds, dtype=float).T
    x = np.asarray(x, dtype=float)
    tol = rtol * (hi - lo)
    return np.where(np.abs(x - lo) < tol, lo, np.where(np.abs(x - hi) < tol, hi, x))


def polish(problem: Problem, x0, *, require_better: bool = True, maxiter: int = 200) -> np.ndarray:
    """SLSQP (finite-difference gradients, at most ``maxiter`` iterations) from x0 in variables
    scaled to [0, 1]; the result is kept if feasible (and, with ``require_better``, no worse
    than x0), else x0."""
    lo, hi = np.array(problem.bounds).T
    to_x = lambda z: lo + z * (hi - lo)  # noqa: E731
    res = minimize(lambda z: problem.f(to_x(z)), (x0 - lo) / (hi - lo), method="SLSQP",
                   bounds=[(0.0, 1.0)] * len(lo), options={"ftol": 1e-12, "maxiter": maxiter},
                   constraints=[{"type": "ineq", "fun": lambda z: problem.slacks(to_x(z))}])
    x = np.clip(to_x(res.x), lo, hi)
    better = problem.f(x) <= problem.f(x0) or not require_better
    return x if better and problem.evaluation(x).feasible else np.asarray(x0, dtype=float)


def binding(ev: Evaluation, tol: float = 1e-4) -> list[Constraint]:
    """The violated constraints, worst first; if none, the active ones (slack below tol)."""
    cons = sorted(ev.constraints, key=lambda c: c.slack)
    violated = [c for c in cons if not c.satisfied]
    return violated or [c for c in cons if c.slack < tol]


def open_span(design) -> float:
    """The tips' span [mm] of the straight hand (every hinge at 0), the widest it opens."""
    from softhand.reduced.equations import kinematics

    return float(2.0 * kinematics.tip_position(np.zeros(design.n_s), design)[0])


def infeasible_report(task: Task, opt: Optimum) -> str:
    """One paragraph: the task cannot be met, the binding constraint, the nearest design."""
    ev = opt.evaluation
    worst = binding(ev)
    names = "; ".join(f"{c.name} = {c.value:.4g} against the limit {c.limit:.4g} ({c.sense})"
                      for c in worst)
    free = ", ".join(f"{k} = {v:.4g}" for (k, _, _), v in zip(task.free, opt.x))
    if any(c.name.startswith("opening") and not math.isfinite(c.value) for c in worst):
        names += (f" (no bend opens the hand that wide: straight, its tips span "
                  f"{open_span(ev.design):.4g} mm; l0_mm, theta0_deg and base_offset_mm set that span)")
    if ev.no_grasp:
        force = (f"has no pump pressure for F_v = {ev.F_v:.4g} N (the pump limit {task.max_pressure:.4g} MPa): "
                 f"{ev.no_grasp}.")
    else:
        force = (f"would need {ev.P_grasp:.4g} MPa (bent to {math.degrees(ev.theta_hold):.2f} deg) for F_v = "
                 f"{ev.F_v:.4g} N")
        if not math.isfinite(ev.F_v_at_limit):
            force += f" against the pump limit {task.max_pressure:.4g} MPa."
        elif ev.margin_edge:
            force += (f", and presses with {ev.F_v_at_limit:.4g} N at {ev.P_margin:.4g} MPa, below the pump "
                      f"limit {task.max_pressure:.4g} MPa, where {ev.margin_edge}.")
        else:
            force += f", and presses with {ev.F_v_at_limit:.4g} N at the pump limit {task.max_pressure:.4g} MPa."
    return (f"The task cannot be met within the free bounds: the binding constraint is {names}. "
            f"The nearest design (least constraint violation found by the optimiser) has {free}: "
            f"it touches the object at {math.degrees(ev.theta_grasp):.2f} deg and {force}")
