"""A design's pump pressure against the normal force F_v each finger presses with, at the grasp
angle: :func:`~softhand.studies.design.grasp_force.grasp_relation`, the one place where a design's F_v is computed (the FEM-informed
grasp for ``finger_model = "fem"``, else eqs. (25), (29) with the rolling w), and whether F_v at
the pump limit is one of the design's constraints.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from softhand.reduced.calibrated import grasp_hold, grasp_hold_solve
from softhand.reduced.equations import grasp, hand
from softhand.reduced.vocabulary.design import HandDesign
from softhand.studies.design.task import Task


class GraspRelation(NamedTuple):
    P_grasp: float     #: pump pressure at which each finger presses with the required F_v [MPa]
    P_contact: float   #: free hand's pump pressure at the grasp angle (27) [MPa]
    P_open: float      #: free hand's pump pressure where the tips span the opening [MPa]; -inf: never
    F_at_limit: float  #: F_v at the pump limit (or at P_margin, see edge) [N]; nan: not asked (see grasp_relation)
    theta_hold: float  #: the finger's bend when it presses with the required F_v [rad]
    P_margin: float    #: the pump pressure of F_at_limit: the limit, or where the FEM-informed grasp ends [MPa]
    edge: str = ""     #: why P_margin is below the limit (:attr:`softhand.reduced.calibrated.grasp_hold_solve.Hold.edge`), or ""
    no_grasp: str = ""  #: why P_grasp is inf (the required F_v not reached by the FEM-informed grasp), or ""
    F_reached: float = math.nan  #: with no_grasp: F_v where the FEM-informed grasp ends (how far it comes) [N]
    P_cavity: float = math.nan  #: the FEM-informed grasp's cavity pressure at P_grasp [MPa]; nan: eq. (25)


def asks_force_at_limit(design: HandDesign, task: Task) -> bool:
    """Whether F_v at the pump limit is a constraint: always for the paper's finger model, for
    the FEM-informed grasp only with the "margin" objective. Decided by the task and the finger
    model alone, never by an evaluation's outcome, so that every design of one optimisation has
    the same constraints (the optimiser needs a constraint vector of fixed length)."""
    return design.finger_model != "fem" or task.objective == "margin" or task.obj is not None


def grasp_relation(design: HandDesign, task: Task, theta: float, w, theta_open: float) -> GraspRelation:
    """The design's pump pressure <-> normal force F_v at the grasp angle theta [rad]: for
    ``finger_model = "fem"`` the FEM-informed grasp (:mod:`softhand.reduced.calibrated.grasp_hold`), else eqs. (25),
    (29) with the rolling w. The one place where the design's F_v is computed."""
    if design.finger_model == "fem":
        return _fem_relation(design, task, theta, theta_open)
    F_req = task.required_F_v()
    # eq. (25) is linear in F_v: one call for F_v = 0, 1 N, F_req and the free hand (27)
    P0, P1, P_grasp, P_contact, P_open = (float(p) for p in grasp.pressure_to_hold(
        np.array([task.mass, task.mass, task.mass, 0.0, 0.0]),
        np.array([theta] * 4 + [theta_open if math.isfinite(theta_open) else 0.0]), w, design,
        F_v=np.array([0.0, 1.0, F_req, 0.0, 0.0])))
    F_lim = (task.max_pressure - P0) / (P1 - P0)  # [N]: F_v at P0 is 0, at P1 1 N
    return GraspRelation(P_grasp, P_contact, P_open if math.isfinite(theta_open) else -math.inf, F_lim,
                         theta, task.max_pressure)


def _fem_relation(design: HandDesign, task: Task, theta: float, theta_open: float) -> GraspRelation:
    """The FEM-informed grasp: P_grasp from the equilibrium with F_v = F_req; F_v at the pump
    limit only for the "margin" objective (for "pressure" the pump-pressure constraint on
    P_grasp is the same condition, F_v growing with the pump pressure: nan). Where the
    FEM-informed grasp ends below the pump limit (a second pad touches the object, the finger
    reaches its largest bend: :func:`softhand.reduced.calibrated.grasp_hold.at_pump`) F_v is the one there, at the
    highest pump pressure the model answers for, and ``edge`` says why."""
    P_contact = float(hand.pressure(theta, design))
    P_open = float(hand.pressure(theta_open, design)) if math.isfinite(theta_open) else -math.inf
    F_req = task.required_F_v()
    # F_v = 0 (a massless object, no margin): the fingers only touch it, at the contact pressure
    no_grasp, F_reached = "", math.nan
    try:
        held = grasp_hold.hold(design, task.diameter, task.mass, "F_v", F_req) if F_req > 0.0 else \
            grasp_hold_solve.Hold(math.nan, P_contact, 0.0, theta, -1, True)
    except grasp_hold.NotReached as refused:  # F_req beyond what the finger gives: no P_grasp, the rest stands
        held, no_grasp = grasp_hold_solve.Hold(math.nan, math.inf, math.nan, theta, -1, False), refused.allowed
        F_reached = refused.reached.F_v
    F_lim, P_margin, edge = math.nan, task.max_pressure, ""
    if asks_force_at_limit(design, task):
        at = grasp_hold_solve.Hold(math.nan, task.max_pressure, 0.0, theta, -1, True) \
            if task.max_pressure <= P_contact else \
            grasp_hold.at_pump(design, task.diameter, task.mass, task.max_pressure)
        F_lim, P_margin, edge = at.F_v, at.P_pump, at.edge
    return GraspRelation(held.P_pump, P_contact, P_open, F_lim, held.theta, P_margin, edge, no_grasp, F_reached,
                         held.P_cavity)
