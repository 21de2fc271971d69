r"""The fast hold model: the whole hand closes on any object, then its holding limit along a pull.

**Closing** (the object held in place, frictionless, as the FEM's path closes the hand before
the object is let go): every finger i, in its own plane, takes the hinge angles that make its
energy least with no pad inside the object,

.. math:: \min_{\hat\theta} E(\hat\theta; P) \quad \text{s.t.} \quad g_k(\hat\theta) \ge 0
          \ (k = 1..n_s),

E the hinges' energy at cavity pressure P, M_j = dE/d theta_hat_j
(:func:`softhand.reduced.holding.hold_finger.hinge_moments`), g_k the gap
of pad k to the object (:func:`softhand.reduced.holding.hand_layout.pad_distance`). Its optimality conditions
are the hinge equilibrium with the pads' contact forces, M_j = sum_k N_k dg_k/d theta_hat_j,
N_k >= 0, N_k g_k = 0: the one-finger grasp's equations (:mod:`softhand.reduced.calibrated.grasp_fem`)
for any number of touching pads, with the hinges coupled through the tube (the grasp's are the
blocked-hinge table's, uncoupled: on a frictionless circle in the bending plane the two differ by
the coupling alone, a test). Solved from the pose where the finger, closing towards its free hinge
angles, first touches: the touching pads' equations by Newton, pads added and dropped until every
gap is open and every force presses (SLSQP where that does not settle), to 1e-10.

**Holding**: the touching pads, their normals and closing forces, and each finger's hinge
moments M_j and stiffnesses dM_j/d theta_hat_j at the closed state go to the limit analysis of
:mod:`softhand.reduced.holding.hold_lp` (elastic fingers).

Finger models: ``"fem"`` (default), the calibrated finger hinge by hinge, from the finger FEM
(:mod:`softhand.reduced.calibrated.finger_hinges`: the blocked-hinge table coupled through the tube); ``"paper"``, the paper's finger (W_f, Q of eqs. (2), (10)) with its
energy shared equally by the hinges, M_j = -dQ/dtheta (P - P_free(n_s theta_hat_j)).
Where every finger sees the object alike (:func:`softhand.reduced.holding.hand_layout.symmetric`: a centred sphere,
an upright cylinder, a square box under four fingers), one finger is solved and its state turned to the others.

One finger's moments, energy and pads against the object: :mod:`softhand.reduced.holding.hold_finger`;
one finger closing: :mod:`softhand.reduced.holding.hold_closing`; here the whole hand closing on
the object (:func:`close_hand`). Units: mm, N, MPa, rad.
"""
from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np

from softhand.reduced.calibrated import finger_hinges
from softhand.reduced.equations import finger, reservoir
from softhand.reduced.holding import hand_layout
from softhand.reduced.holding.hold_closing import FingerState, close_finger
from softhand.reduced.holding.hold_finger import FingerGeometry, finger_geometry
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.holding.object_geometry import Placed

#: the finger models of the fast hold
FINGER_MODELS = ("fem", "paper")


def finger_design(design: HandDesign, finger_model: str = "fem") -> HandDesign:
    """The design with the finger model of the hold (``"fem"``: calibrated; ``"paper"``)."""
    if finger_model not in FINGER_MODELS:
        raise InputError("finger_model", finger_model, f"must be one of {', '.join(FINGER_MODELS)}")
    if finger_model == "fem":
        return finger_hinges.fem_finger(design)
    return design if design.finger_model == "paper" else replace(design, finger_model="paper")


class Closed(NamedTuple):
    """The hand closed on the object at P."""

    P_cavity: float
    P_pump: float
    fingers: tuple          #: FingerState per finger
    symmetric: bool         #: one finger solved, turned to the others


def close_hand(P_cavity: float, placed: Placed, design: HandDesign, *, reservoir_on: bool = True,
               near: Closed | None = None) -> Closed:
    """Every finger closed on the object at cavity pressure P [MPa] (``design`` with its finger
    model, :func:`finger_design`); the pump pressure is P less the reservoir's at the oil taken.
    ``near``: the hand closed on the object at a pose nearby (each finger's start)."""
    sym = hand_layout.symmetric(placed, design)
    start = (lambda i: near.fingers[i]) if near is not None else (lambda i: None)  # noqa: E731
    if sym:
        one = close_finger(0, P_cavity, placed, design, start(0))
        states = _turned(one, placed, design)
    else:
        states = tuple(close_finger(i, P_cavity, placed, design, start(i)) for i in range(design.n))
    return Closed(P_cavity, pump_pressure(P_cavity, [s.q.sum() for s in states], design, reservoir_on),
                  states, sym)


def _turned(state: FingerState, placed: Placed, design: HandDesign) -> tuple:
    """Finger 0's state turned to every finger (the object symmetric): their geometry in one batch."""
    if design.n == 1:
        return (state,)
    others = finger_geometry(np.tile(state.q, (design.n - 1, 1)), np.arange(1, design.n), placed, design)
    return (state,) + tuple(FingerState(state.q, state.N, FingerGeometry(*(v[k] for v in others)),
                                        state.moments, state.residual) for k in range(design.n - 1))


def pump_pressure(P_cavity: float, thetas, design: HandDesign, reservoir_on: bool = True) -> float:
    """P_pump = P_cavity - p_r(V0 - sum_i (Q(theta_i) - Q(0))) [MPa] (the fingers' bends theta_i [rad])."""
    if not reservoir_on:
        return float(P_cavity)
    taken = float(np.sum(finger.oil_taken(np.asarray(thetas, float), design)))
    return float(P_cavity - reservoir.pressure(design.V0 - taken, design))
