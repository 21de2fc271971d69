r"""A design judged on the reduced model for a task: grasp angle, pressures, forces, constraints.

For a design the task's object is placed as in the grasp FEM (:func:`softhand.reduced.equations.contact.object_depth`),
the finger closes with equal hinge angles until a pad touches (the **grasp angle** theta_g,
:func:`softhand.reduced.equations.contact.contact_angle`), and the virtual displacement w is the rolling motion
that keeps that pad on the object (:func:`softhand.reduced.equations.contact.rolling_weights`). Then
:func:`softhand.studies.design.grasp_force.grasp_relation`, the one place where a design's F_v is computed, gives

* ``P_grasp``: the pump pressure at which each finger presses with the required F_v;
* ``P_contact``: the free hand's pump pressure at theta_g (eq. (27)), where the fingers touch;
* ``F_v`` at the pump limit, and the margin over the requirement (for the FEM-informed grasp
  at the highest pump pressure it answers for, if that is below the limit: where a second
  pad touches the object);

for ``finger_model = "fem"`` by the FEM-informed grasp (:mod:`softhand.reduced.calibrated.grasp_hold`: the
calibrated finger in equilibrium hinge by hinge against the object, the reservoir's pressure
at the oil taken), for the paper's finger model by eqs. (25), (29) at theta_g with the
rolling w. The tube's rubber stretch in the grasp is the calibrated finger table's prediction
of the FEM's converged stretch at the free finger's bend under the grasp's cavity pressure
(:func:`tube_stretch`) where the table holds it; else eq. (8) at the bend that holds the object, 1 + (d + a + b) theta / l0 (the outer fibre on the far side of the hinge
plate), with its strain lambda - 1 scaled by the task's ``stretch_factor`` once an FEM proof
has measured how far the FEM's stretch (at the tied rings and the end cap) lies above it.

The constraints the design is judged by (:func:`softhand.studies.design.constraints.design_constraints`)
are listed in :mod:`softhand.studies.design.constraints`. The whole model's P(theta) and theta(P) are those of
``design.finger_model``/``design.reservoir_model`` through :mod:`softhand.reduced.equations.hand`, so another
finger model changes the answer by a design key alone.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from softhand.reduced.calibrated import finger_fem, reservoir_fem
from softhand.reduced.equations import contact, finger, hand, reservoir
from softhand.reduced.vocabulary.design import HandDesign, hinges_for
from softhand.reduced.vocabulary.design_files import design_from_dict
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.design.constraints import Constraint, design_constraints
from softhand.studies.design.grasp_force import asks_force_at_limit, grasp_relation
from softhand.studies.design.task import Task


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
    F_v_at_limit: float        #: F_v at the pump limit, or at P_margin below it (see margin_edge) [N]
    stretch: float             #: the tube's rubber stretch in the grasp (:func:`tube_stretch`)
    sheet_stretch: float       #: the reservoir sheet's rubber stretch at V0 (:func:`sheet_stretch`)
    constraints: tuple[Constraint, ...]
    theta_hold: float = math.nan  #: the finger's bend when it presses with the required F_v [rad]
    P_margin: float = math.nan    #: the pump pressure F_v_at_limit is at: the limit, or lower (margin_edge) [MPa]
    margin_edge: str = ""         #: why F_v_at_limit is below the pump limit (the FEM-informed grasp's end), or ""
    no_grasp: str = ""            #: why there is no P_grasp (the required F_v not reached), or ""

    @property
    def rubber_stretch(self) -> float:
        """The larger of the tube's and the sheet's stretch (the Pareto front's axis)."""
        return max(self.stretch, self.sheet_stretch)

    @property
    def feasible(self) -> bool:
        return all(c.satisfied for c in self.constraints)

    def predicted(self) -> dict:
        return {"P_grasp_MPa": self.P_grasp, "P_contact_MPa": self.P_contact,
                "theta_grasp_deg": math.degrees(self.theta_hold), "F_v_N": self.F_v,
                "theta_contact_deg": math.degrees(self.theta_grasp),
                "F_v_at_pump_limit_N": None if self.margin_edge else _number(self.F_v_at_limit),
                "margin_N": _number(self.F_v_at_limit - self.F_v),
                **({"margin_at_pump_pressure_MPa": self.P_margin, "margin_below_pump_limit": self.margin_edge}
                   if self.margin_edge else {}),
                **({"no_P_grasp": self.no_grasp} if self.no_grasp else {}),
                "w": self.w.tolist(), "touching_link": self.link, "depth_mm": self.depth,
                "rubber_stretch": self.stretch, "sheet_stretch": self.sheet_stretch,
                **self.contact_parts()}

    def contact_parts(self) -> dict:
        """P_contact's two parts: the finger's pressure (28) and the reservoir's p_r at theta_g [MPa]."""
        try:
            P_finger = float(hand.pressure(self.theta_grasp, self.design, reservoir=False))
        except InputError:
            return {}
        return {"P_finger_at_contact_MPa": P_finger,
                "reservoir_pressure_at_contact_MPa": P_finger - self.P_contact}


def _number(x: float) -> float | None:
    """x, or None where it was not computed (nan)."""
    return None if math.isnan(x) else x


def design_at(task: Task, x) -> HandDesign:
    """The base design with the free keys set to x (public units); l0 scales the hinges
    (:func:`softhand.reduced.vocabulary.design_files.design_from_dict`)."""
    values = {key: float(v) for (key, _, _), v in zip(task.free, np.asarray(x, dtype=float))}
    return design_from_dict(values, task.base, source="free")


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
        l0=l0, hinge_s=hinges_for(design, l0, design.n_s))) for l0 in (lo, lo + L0_STEP)]
    near = ends[int(t >= 0.5)]
    lerp = lambda i: (1 - t) * ends[0][i] + t * ends[1][i]  # noqa: E731
    return contact.Geometry(lerp(0), lerp(1), near.link, near.w, lerp(4))


def peak_stretch(theta, design: HandDesign) -> float:
    """Eq. (8) at the tube's outer fibre (r = b, phi = pi/2): 1 + (d + a + b) theta / l0."""
    return 1.0 + (design.d + design.a + design.b) * theta / design.l0


def tube_stretch(theta, design: HandDesign, task: Task, P_cavity: float = math.nan) -> float:
    """The tube's rubber stretch in the grasp at bend theta [rad] and cavity pressure ``P_cavity``
    [MPa] (nan: unknown, the bend alone): the calibrated finger table's (finger_model "fem" with a table that holds the FEM's
    converged stretch, reduced.finger_fem.rubber_stretch) at the bend the free finger reaches at
    the grasp's cavity pressure, else eq. (8) at theta with its strain x the task's stretch_factor.

    The table's stretch is the free finger's, at a pressure and bend that go together. In a
    grasp the object holds the bend back while the pressure rises, and the stretch follows the
    pressure more than the bend (the tube's axial pull and the tied rings' corners): for the
    large-object task, held at 5 deg by 0.81 MPa, the proof's FEM read 1.19 where the table at
    5 deg gives 1.06 and at the free bend of that pressure (25 deg) 1.26. The free bend at the
    same pressure is the larger, so the prediction stays on the safe side (+4 to +6 % over the
    proofs' FEM on the 10 mm mesh, which reads a few per cent low; docs/finger.md)."""
    if design.finger_model == "fem":
        free = theta
        if math.isfinite(P_cavity):
            try:
                free = max(theta, float(hand.bend_angle(P_cavity, design, reservoir=False)))
            except InputError:  # no free bend at that pressure: the held one
                free = theta
        try:
            calibrated = finger_fem.rubber_stretch(free, design)
        except InputError:  # outside the calibrated range: eq. (8), the range constraint says so
            calibrated = None
        if calibrated is not None:
            return float(calibrated)
    return 1.0 + task.stretch_factor * (peak_stretch(theta, design) - 1.0)


def calibrated_tube(design: HandDesign) -> bool:
    """Whether the design's tube stretch is the FEM-calibrated one (finger_model "fem", its
    table holding the converged stretch, the design inside the table's range)."""
    try:
        return design.finger_model == "fem" and finger_fem.rubber_stretch(0.1, design) is not None
    except InputError:
        return False


def models(design: HandDesign, task: Task) -> dict:
    """The reduced models a design is judged on: the finger's, the reservoir's and where the
    tube's and the sheet's rubber stretch come from."""
    tube = calibrated_tube(design)
    sheet = design.reservoir_model == "fem" and reservoir_fem.rubber_stretch(design.V0, design) is not None
    return {"finger_model": design.finger_model, "reservoir_model": design.reservoir_model,
            "tube_rubber": design.finger_rubber.model, "sheet_rubber": design.reservoir_rubber.model,
            "tube_stretch": "FEM-calibrated rubber_stretch" if tube else
            f"eq. (8), strain x {task.stretch_factor:.4g}",
            "sheet_stretch": "FEM-calibrated rubber_stretch" if sheet else "eq. (16)"}


def sheet_stretch(design: HandDesign) -> float:
    """The reservoir sheet's rubber stretch at V0: the calibrated sheet table's prediction of the
    FEM's converged stretch (reservoir_model "fem" with a table that holds it: at the clamp,
    where the sheet stretches most), else eq. (16)'s mean stretch."""
    if design.reservoir_model == "fem":
        calibrated = reservoir_fem.rubber_stretch(design.V0, design)
        if calibrated is not None:
            return float(calibrated)
    return float(reservoir.stretch(design.V0, design))


def evaluate(design: HandDesign, task: Task, *, exact: bool = True) -> Evaluation:
    """Grasp angle, pressures, forces, stretch and every constraint of ``design`` for ``task``
    (``exact=False``: the kinematics interpolated in l0, see :func:`grasp_geometry`); a hold task
    (an object of any shape) is judged by :func:`softhand.studies.design.hold_eval.evaluate_hold` instead
    (:func:`softhand.studies.design.optimise.evaluate` chooses)."""
    depth, theta, link, w, theta_open = grasp_geometry(design, task, exact=exact)
    F_req = task.required_F_v()
    P_margin, edge, no_grasp, F_reached, P_cavity = task.max_pressure, "", "", math.nan, math.nan
    try:
        P_grasp, P_contact, P_open, F_lim, theta_hold, P_margin, edge, no_grasp, F_reached, P_cavity = \
            grasp_relation(design, task, theta, w, theta_open)
    except InputError:  # e.g. V0 too small for the oil, a design outside the calibrated range
        F_lim = -math.inf if asks_force_at_limit(design, task) else math.nan
        P_grasp, P_contact, P_open, theta_hold = math.inf, math.inf, -math.inf, theta
    theta_hold = max(theta, theta_hold)
    try:  # the oil of the design's finger model; outside its calibrated range: none (see below)
        oil = design.n * float(finger.oil_taken(theta_hold, design))
    except InputError:
        oil = math.inf
    stretch = tube_stretch(theta_hold, design, task, P_cavity)
    sheet = sheet_stretch(design)
    # no P_grasp: how far short of F_req the finger comes (for the optimiser)
    shortfall = min(1.0, 1.0 - max(F_reached, 0.0) / F_req) if no_grasp and F_reached < F_req else None
    cons = design_constraints(design, task, oil, stretch, sheet, P_grasp, P_contact, F_lim, P_open, shortfall)
    return Evaluation(design, depth, theta, link, w, P_grasp, P_contact, F_req, F_lim, stretch, sheet,
                      tuple(cons), theta_hold, P_margin, edge, no_grasp)


def unanswered(task: Task) -> Evaluation:
    """The evaluation of free values the model has no answer for (the design rules refuse them,
    a + b >= d, t >= R, ...; the finger does not reach the object): the constraints of
    :func:`evaluate` for the task, each violated (value nan: slack -1e3), so that the optimiser
    sees as many constraints as anywhere else and leaves the point."""
    base, nan = task.base, math.nan
    cons = design_constraints(base, task, nan, nan, nan, math.inf, nan, nan, nan)
    return Evaluation(base, nan, nan, -1, np.full(base.n_s, nan), math.inf, math.inf, task.required_F_v(),
                      nan, nan, nan, tuple(replace(c, value=nan) for c in cons), nan)
