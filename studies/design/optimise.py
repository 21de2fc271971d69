r"""Size the hand for a task on the reduced model: evaluation, constraints, optimiser, Pareto front.

For a design the task's object is placed as in the grasp FEM (:func:`reduced.contact.object_depth`),
the finger closes with equal hinge angles until a pad touches (the **grasp angle** theta_g,
:func:`reduced.contact.contact_angle`), and the virtual displacement w is the rolling motion
that keeps that pad on the object (:func:`reduced.contact.rolling_weights`). Eqs. (25), (29)
at theta_g then give

* ``P_grasp``: the pump pressure at which each finger presses with the required F_v
  (:func:`reduced.grasp.pressure_to_hold`, with the reservoir);
* ``P_contact``: the free hand's pump pressure at theta_g (eq. (27)), where the fingers touch;
* ``F_v`` at the pump limit, and the margin over the requirement;
* the tube's peak principal stretch by eq. (8), 1 + (d + a + b) theta_g / l0 (the outer fibre
  on the far side of the hinge plate).

Constraints (each ``(name, value, limit, sense)``, normalised slack >= 0 when met): the tube
fits its links (a + b < d), walls (b >= min wall, t > 0), the reservoir keeps oil at theta_g
and sits below the first pressure maximum of its model p_r(V) (limit point), peak stretch,
pump pressure, the open hand passes the object, and the finger model's calibrated range
when it has one. The whole model's P(theta) and theta(P) are those of
``design.finger_model``/``design.reservoir_model`` through :mod:`reduced.hand`, so another
finger model changes the answer by a design key alone.

Optimiser: :func:`scipy.optimize.differential_evolution` (seeded, one worker: deterministic)
with the constraints as a :class:`~scipy.optimize.NonlinearConstraint` (feasibility rules:
a task that cannot be met ends at the least-violating design), then an SLSQP polish from
its best point. ``benchmarks/bench_design.py`` measures it against SLSQP alone.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from scipy.optimize import NonlinearConstraint, differential_evolution, minimize

from softhand.reduced import contact, finger, grasp, hand, reservoir
from softhand.reduced.design import HandDesign, design_from_dict
from softhand.reduced.errors import InputError
from softhand.studies.design.task import Task


@dataclass(frozen=True)
class Constraint:
    name: str
    value: float
    limit: float
    sense: str  #: "<=" or ">="
    scale: float | None = None  #: of the normalised slack; None: |limit|

    @property
    def slack(self) -> float:
        """Normalised distance to the limit, >= 0 when met."""
        if not math.isfinite(self.value):
            return -1e3
        if not math.isfinite(self.limit):  # no limit (e.g. no limit point): met, by far
            return 1e3
        gap = self.limit - self.value if self.sense == "<=" else self.value - self.limit
        scale = self.scale if self.scale is not None else abs(self.limit)
        return min(gap / max(scale, 1e-9), 1e3)

    @property
    def satisfied(self) -> bool:
        return self.slack >= -1e-9

    def as_dict(self) -> dict:
        return {"name": self.name, "value": self.value, "limit": self.limit, "sense": self.sense,
                "satisfied": self.satisfied}


@dataclass(frozen=True)
class Evaluation:
    """The reduced model's answer for one design (mm, N, MPa, rad)."""

    design: HandDesign
    depth: float               #: object centre below the palm [mm]
    theta_grasp: float         #: grasp angle theta_g [rad]
    link: int                  #: the pad that touches (0 = base link)
    w: np.ndarray              #: rolling weight vector at theta_g
    P_grasp: float             #: pump pressure holding the object with the required F_v [MPa]
    P_contact: float           #: free hand's pump pressure at theta_g (27) [MPa]
    F_v: float                 #: required normal force per finger [N]
    F_v_at_limit: float        #: F_v at the pump limit [N]
    stretch: float             #: the tube's peak principal stretch, eq. (8)
    sheet_stretch: float       #: the reservoir sheet's stretch at V0, eq. (16)
    constraints: tuple[Constraint, ...]

    @property
    def rubber_stretch(self) -> float:
        """The larger of the tube's and the sheet's stretch (the Pareto front's axis)."""
        return max(self.stretch, self.sheet_stretch)

    @property
    def feasible(self) -> bool:
        return all(c.satisfied for c in self.constraints)

    def predicted(self) -> dict:
        return {"P_grasp_MPa": self.P_grasp, "P_contact_MPa": self.P_contact,
                "theta_grasp_deg": math.degrees(self.theta_grasp), "F_v_N": self.F_v,
                "F_v_at_pump_limit_N": self.F_v_at_limit, "margin_N": self.F_v_at_limit - self.F_v,
                "w": self.w.tolist(), "touching_link": self.link, "depth_mm": self.depth,
                "max_principal_stretch": self.stretch, "sheet_stretch": self.sheet_stretch,
                **self.contact_parts()}

    def contact_parts(self) -> dict:
        """P_contact's two parts: the finger's pressure (28) and the reservoir's p_r at theta_g [MPa]."""
        try:
            P_finger = float(hand.pressure(self.theta_grasp, self.design, reservoir=False))
        except InputError:
            return {}
        return {"P_finger_at_contact_MPa": P_finger,
                "reservoir_pressure_at_contact_MPa": P_finger - self.P_contact}


def design_at(task: Task, x) -> HandDesign:
    """The base design with the free keys set to x (public units); l0 scales the hinges."""
    base, values = task.base, {}
    for (key, _, _), v in zip(task.free, np.asarray(x, dtype=float)):
        values[key] = float(v)
        if key == "l0_mm":
            values["hinge_s_mm"] = [s * float(v) / base.l0 for s in base.hinge_s]
    return design_from_dict(values, base, source="free")


#: tube lengths on which the kinematics are tabulated while the optimiser varies l0 [mm]
L0_STEP = 0.5


def grasp_geometry(design: HandDesign, task: Task, *, exact: bool = True) -> contact.Geometry:
    """The task's kinematics for this design (cached). ``exact=False``: linear in l0 between
    the neighbours on the L0_STEP grid (hinges scaled with l0; w and the link of the nearer)."""
    if exact:
        return contact.grasp_geometry(task.diameter, task.opening_mm, design)
    lo = math.floor(design.l0 / L0_STEP) * L0_STEP
    t = (design.l0 - lo) / L0_STEP
    ends = [contact.grasp_geometry(task.diameter, task.opening_mm, design.replace(
        l0=l0, hinge_s=tuple(s * l0 / design.l0 for s in design.hinge_s))) for l0 in (lo, lo + L0_STEP)]
    near = ends[int(t >= 0.5)]
    lerp = lambda i: (1 - t) * ends[0][i] + t * ends[1][i]  # noqa: E731
    return contact.Geometry(lerp(0), lerp(1), near.link, near.w, lerp(4))


def peak_stretch(theta, design: HandDesign) -> float:
    """Eq. (8) at the tube's outer fibre (r = b, phi = pi/2): 1 + (d + a + b) theta / l0."""
    return 1.0 + (design.d + design.a + design.b) * theta / design.l0


@lru_cache(maxsize=4096)
def limit_point_volume(design: HandDesign) -> float:
    """Oil volume [mm^3] of the first pressure maximum of p_r(V) up to 4 V0 (inf: none)."""
    V = np.linspace(0.01, 4.0, 201) * design.V0
    p = reservoir.pressure(V, design)
    falls = np.flatnonzero(np.diff(p) <= 0.0)
    return float(V[falls[0]]) if falls.size else math.inf


def evaluate(design: HandDesign, task: Task, *, exact: bool = True) -> Evaluation:
    """Grasp angle, pressures, forces, stretch and every constraint of ``design`` for ``task``
    (``exact=False``: the kinematics interpolated in l0, see :func:`grasp_geometry`)."""
    depth, theta, link, w, theta_open = grasp_geometry(design, task, exact=exact)
    F_req = task.required_F_v()
    try:  # the oil of the design's finger model; outside its calibrated range: none (see below)
        oil = design.n * float(finger.oil_taken(theta, design))
    except InputError:
        oil = math.inf
    try:
        P_grasp, P_contact, P_open, F_lim = grasp_relation(design, task, theta, w, theta_open)
    except InputError:  # e.g. V0 too small for the oil, a design outside the calibrated range
        P_grasp, P_contact, P_open, F_lim = math.inf, math.inf, -math.inf, -math.inf
    stretch = peak_stretch(theta, design)
    sheet = float(reservoir.stretch(design.V0, design))
    cons = [
        Constraint("tube_fits_links (a + b < d) [mm]", design.a + design.b, design.d, "<="),
        Constraint("tube_wall b [mm]", design.b, task.min_wall, ">="),
        Constraint("sheet_thickness t [mm]", design.t, 0.0, ">=", 1.0),
        Constraint("reservoir_oil the fingers take at the grasp [mm^3]", oil, design.V0, "<="),
        Constraint("reservoir_below_limit_point V0 [mm^3]", design.V0, limit_point_volume(design), "<="),
        Constraint("max_principal_stretch", stretch, task.max_stretch, "<="),
        Constraint("sheet_stretch at V0, eq. (16)", sheet, task.max_stretch, "<="),
        Constraint("pump_pressure at the grasp [MPa]", P_grasp, task.max_pressure, "<="),
        Constraint("F_v at the pump limit [N]", F_lim, F_req, ">="),
        Constraint("opening: P(theta_open), the free hand's pump pressure where the tips "
                   f"span {task.opening_mm:g} mm [MPa]", P_open, 0.0, ">=", task.max_pressure),
        *calibrated_range(design),
    ]
    return Evaluation(design, depth, theta, link, w, P_grasp, P_contact, F_req, F_lim, stretch, sheet,
                      tuple(cons))


class GraspRelation(NamedTuple):
    P_grasp: float     #: pump pressure at which each finger presses with the required F_v [MPa]
    P_contact: float   #: free hand's pump pressure at the grasp angle (27) [MPa]
    P_open: float      #: free hand's pump pressure where the tips span the opening [MPa]; -inf: never
    F_at_limit: float  #: F_v at the pump limit [N]


def grasp_relation(design: HandDesign, task: Task, theta: float, w, theta_open: float) -> GraspRelation:
    """The design's pump pressure <-> normal force F_v at the grasp angle theta [rad] with the
    rolling w: eqs. (25), (29) of the design's finger and reservoir models. The one place where
    the design's F_v is computed (another grasp-force estimate replaces this function alone)."""
    F_req = task.required_F_v()
    # eq. (25) is linear in F_v: one call for F_v = 0, 1 N, F_req and the free hand (27)
    P0, P1, P_grasp, P_contact, P_open = (float(p) for p in grasp.pressure_to_hold(
        np.array([task.mass, task.mass, task.mass, 0.0, 0.0]),
        np.array([theta] * 4 + [theta_open if math.isfinite(theta_open) else 0.0]), w, design,
        F_v=np.array([0.0, 1.0, F_req, 0.0, 0.0])))
    F_lim = (task.max_pressure - P0) / (P1 - P0)  # [N]: F_v at P0 is 0, at P1 1 N
    return GraspRelation(P_grasp, P_contact, P_open if math.isfinite(theta_open) else -math.inf, F_lim)


def calibrated_range(design: HandDesign) -> list[Constraint]:
    """The FEM-calibrated finger model's space (its table's group ranges) as constraints;
    none for the paper's model."""
    if getattr(design, "finger_model", "paper") == "paper":
        return []
    from softhand.reduced import finger_fem

    table = _finger_table(design.finger_table or str(finger_fem.TABLE_FILE))
    groups = finger_fem.groups_of(design)
    out = []
    for g in finger_fem.GROUPS:
        lo, hi = table.ranges[g]
        label = f"calibrated range of {finger_fem.LABELS[g]}"
        out += [Constraint(label, groups[g], lo, ">="), Constraint(label, groups[g], hi, "<=")]
    return out


@lru_cache(maxsize=4)
def _finger_table(path: str):
    from softhand.reduced import finger_fem

    return finger_fem.read_table(path)


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
    evaluations: int = 0
    _memo: dict = field(default_factory=dict, repr=False)

    def evaluation(self, x) -> Evaluation:
        k = np.asarray(x, dtype=float).tobytes()
        if k not in self._memo:
            if len(self._memo) > 20000:
                self._memo.clear()
            self.evaluations += 1
            exact = "l0_mm" not in (key for key, _, _ in self.task.free)
            self._memo[k] = evaluate(design_at(self.task, x), self.task, exact=exact)
        return self._memo[k]

    def f(self, x) -> float:
        return objective(self.evaluation(x), self.task)

    def slacks(self, x) -> np.ndarray:
        return np.array([c.slack for c in self.evaluation(x).constraints])

    @property
    def bounds(self):
        return [(lo, hi) for _, lo, hi in self.task.free]


@dataclass(frozen=True)
class OptimiserOptions:
    seed: int = 1
    popsize: int = 4          #: DE population per free variable (the Sobol start rounds it up to 2^k)
    maxiter: int = 60         #: DE generations at most
    tol: float = 1e-2         #: DE relative tolerance on the population's objective spread
    polish: bool = True       #: SLSQP from the DE optimum


@dataclass(frozen=True)
class Optimum:
    x: np.ndarray
    evaluation: Evaluation
    evaluations: int
    seconds: float
    generations: int
    message: str


def optimise(task: Task, options: OptimiserOptions = OptimiserOptions()) -> Optimum:
    """Differential evolution (seeded) + SLSQP polish on the reduced model."""
    t0 = time.perf_counter()
    problem = Problem(task)
    cons = NonlinearConstraint(problem.slacks, 0.0, np.inf)
    res = differential_evolution(problem.f, problem.bounds, constraints=cons, seed=options.seed,
                                 popsize=options.popsize, maxiter=options.maxiter, tol=options.tol,
                                 polish=False, init="sobol", updating="immediate", workers=1)
    x = np.asarray(res.x, dtype=float)
    if options.polish and problem.evaluation(x).feasible:
        x = polish(problem, x)
    x = on_bounds(x, problem.bounds)
    ev = evaluate(design_at(task, x), task)  # exact kinematics
    return Optimum(x, ev, problem.evaluations, time.perf_counter() - t0, int(res.nit), str(res.message))


def on_bounds(x, bounds, rtol: float = 1e-9) -> np.ndarray:
    """x with the values within rtol (of the bounds' span) of a bound set to that bound: SLSQP
    ends at 4.500000000000008 for a wall on its bound 4.5, and the FEM proof's mesher would
    mesh a different wall."""
    lo, hi = np.array(bounds, dtype=float).T
    x = np.asarray(x, dtype=float)
    tol = rtol * (hi - lo)
    return np.where(np.abs(x - lo) < tol, lo, np.where(np.abs(x - hi) < tol, hi, x))


def polish(problem: Problem, x0, *, require_better: bool = True) -> np.ndarray:
    """SLSQP (finite-difference gradients) from x0 in variables scaled to [0, 1]; the result
    is kept if feasible (and, with ``require_better``, no worse than x0), else x0."""
    lo, hi = np.array(problem.bounds).T
    to_x = lambda z: lo + z * (hi - lo)  # noqa: E731
    res = minimize(lambda z: problem.f(to_x(z)), (x0 - lo) / (hi - lo), method="SLSQP",
                   bounds=[(0.0, 1.0)] * len(lo), options={"ftol": 1e-12, "maxiter": 200},
                   constraints=[{"type": "ineq", "fun": lambda z: problem.slacks(to_x(z))}])
    x = np.clip(to_x(res.x), lo, hi)
    better = problem.f(x) <= problem.f(x0) or not require_better
    return x if better and problem.evaluation(x).feasible else np.asarray(x0, dtype=float)


def binding(ev: Evaluation, tol: float = 1e-4) -> list[Constraint]:
    """The violated constraints, worst first; if none, the active ones (slack below tol)."""
    cons = sorted(ev.constraints, key=lambda c: c.slack)
    violated = [c for c in cons if not c.satisfied]
    return violated or [c for c in cons if c.slack < tol]


def infeasible_report(task: Task, opt: Optimum) -> str:
    """One paragraph: the task cannot be met, the binding constraint, the nearest design."""
    ev = opt.evaluation
    worst = binding(ev)
    names = "; ".join(f"{c.name} = {c.value:.4g} against the limit {c.limit:.4g} ({c.sense})"
                      for c in worst)
    free = ", ".join(f"{k} = {v:.4g}" for (k, _, _), v in zip(task.free, opt.x))
    return (f"The task cannot be met within the free bounds: the binding constraint is {names}. "
            f"The nearest design (least constraint violation found by the optimiser) has {free}: "
            f"it would need {ev.P_grasp:.4g} MPa at the grasp angle {math.degrees(ev.theta_grasp):.2f} deg "
            f"for F_v = {ev.F_v:.4g} N, and presses with {ev.F_v_at_limit:.4g} N at the pump limit "
            f"{task.max_pressure:.4g} MPa.")
