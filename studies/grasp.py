"""Grasping forces at one state of the hand: eqs. (24), (25), (29), or the FEM-informed model.

:func:`state` -- pump pressure, bend angle, mass and a weight vector w -> F_x (25), F_y (24),
F_v (29) in N and kgf, with the free finger's pressure at that angle; :func:`state_fem` -- the
same state by the calibrated finger in equilibrium against the object (:mod:`softhand.reduced.calibrated.grasp_fem`).
``softhand grasp`` and the batch kind ``grasp`` only choose the inputs. Axes and signs:
docs/conventions.md (F_v > 0: the finger squeezes).
"""
from __future__ import annotations

import math

import numpy as np

from softhand.reduced.equations import grasp, hand
from softhand.reduced.vocabulary.errors import InputError


def state(P: float, theta_deg: float, mass: float, w, design) -> dict:
    """One grasp state -> the flat result (forces in N and kgf, the w used, the free pressure)."""
    theta = math.radians(theta_deg)
    F = grasp.grasp_forces(P, theta, mass, w, design)
    return {"P_pump_MPa": P, "theta_deg": theta_deg, "mass_kg": mass,
            "F_x_N": float(F.F_x), "F_y_N": float(F.F_y), "F_v_N": float(F.F_v),
            "F_v_kgf": float(F.F_v) / grasp.KGF,
            "w": [float(x) for x in w], "w_sum": float(np.sum(w)),
            "P_pump_free_MPa": float(hand.pressure(theta, design))}


def state_fem(P: float, theta_deg: float, mass: float, diameter: float, design) -> dict:
    """One grasp state by the FEM-informed model at pump pressure P [MPa] -> the flat result."""
    from softhand.reduced.calibrated import finger_hinges, grasp_fem

    theta = math.radians(theta_deg)
    fem = finger_hinges.fem_finger(design)
    P_free = float(hand.pressure(theta, fem))  # the pump pressure of the free finger at theta
    P_cavity = P + float(hand.finger_pressure(theta, fem)) - P_free  # the same reservoir offset at P
    s = grasp_fem.grasp_state_at_angle(design, diameter, P_cavity, theta, mass)
    if s.link < 0:  # at or past the free bend: no placement of the object is touched there
        raise InputError("theta_deg", theta_deg, untouched(P, P_cavity, s, diameter, theta, fem))
    return {"P_pump_MPa": P, "theta_deg": theta_deg, "mass_kg": mass,
            "F_x_N": float(s.F[0]), "F_y_N": float(s.F[1]), "F_v_N": s.F_v, "F_v_kgf": s.F_v / grasp.KGF,
            "model": "fem", "diameter_mm": diameter, "P_cavity_MPa": P_cavity,
            "contact_link": s.link, "contact_force_N": s.N, "contact_point_mm": s.point.tolist() if s.link >= 0 else None,
            **({} if s.crease is None else {"crease_link": s.link + 1, "crease_force_N": s.crease[0],
                                            "crease_point_mm": s.crease[1].tolist()}),
            "depth_mm": s.depth, "hinge_deg": np.degrees(s.q).tolist(),
            "P_pump_free_MPa": P_free}


def untouched(P: float, P_cavity: float, s, diameter: float, theta: float, fem) -> str:
    """Why the finger at pump pressure P [MPa] touches no placement of the object at bend theta
    [rad] (``s`` the free finger's state there): the bend it reaches free, below which it would
    press, and the pump pressure from which it would press at theta."""
    free = math.degrees(s.theta)
    return (f"at P_pump = {P:g} MPa (P_cavity {P_cavity:.4g} MPa) the free finger bends only to "
            f"{free:.4g} deg, so no placement of the {diameter:g} mm object lets it press at this bend: "
            f"it presses at bends below {free:.4g} deg, or at this one from P_pump = "
            f"{float(hand.pressure(theta, fem)):.4g} MPa on")
