"""The reported numbers of a grasp FEM state (:mod:`softhand.studies.weights`,
:mod:`softhand.studies.fig8`): the FEM's forces next to eq. (25)'s F_v at the same pressure,
bend and mass, why the two differ where they do, and the tube's rubber stretch.
"""
from __future__ import annotations

import math

import numpy as np

from softhand.reduced.equations import grasp
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError


def reduced_F_v(P: float, theta: float, mass: float, w, design: HandDesign) -> float | None:
    """Eq. (25) -> (29) at cavity pressure P [MPa], theta [rad]: F_v [N]; None if J_x w = 0."""
    try:
        return float(grasp.grasp_forces(P, theta, mass, w, design, reservoir=False).F_v)
    except InputError:
        return None


#: eq. (25)'s F_v further than this from the FEM's, relative, is printed with why
NOTE_RTOL = 0.1


def reduced_note(F_v_red: float | None, F_v_fem: float, N, design: HandDesign) -> str | None:
    """Why eq. (25)'s F_v [N] is not to be trusted where it is further than ``NOTE_RTOL`` from
    the FEM's (N: each link's contact force [N]); None where it is close."""
    if F_v_red is None or abs(F_v_red - F_v_fem) <= NOTE_RTOL * abs(F_v_fem):
        return None
    links = [k for k, n in enumerate(N) if n > 0]
    where = f"touches link {', '.join(map(str, links))} of {design.n_s}" if links else "is not touched"
    return (f"eq. (25) charges the pressure's work to a force at the fingertip, but the object {where}: "
            f"its F_v is {F_v_red / F_v_fem:.3g} x the FEM's; use F_v_fem_N" if F_v_fem > 0 else
            f"eq. (25) charges the pressure's work to a force at the fingertip, but the object {where}; "
            "use F_v_fem_N")


def state_row(state, w, mass: float, design: HandDesign) -> dict:
    """The reported numbers of one converged contact state (forces physical, hand frame)."""
    F_v_red = reduced_F_v(state.P, state.theta, mass, w, design)
    return {"P_cavity_MPa": state.P, "theta_deg": math.degrees(state.theta),
            "hinge_deg": np.degrees(state.q).tolist(), "contact_force_N": state.N.tolist(),
            "F_x_fem_N": float(state.F[0]), "F_y_fem_N": float(state.F[1]),
            "F_v_fem_N": state.F_v, "F_v_reduced_N": F_v_red,
            "F_v_error_kgf": None if F_v_red is None else (F_v_red - state.F_v) / grasp.KGF,
            "F_v_reduced_note": reduced_note(F_v_red, state.F_v, state.N, design),
            "max_penetration_mm": float(np.max(-state.gap[state.N > 0], initial=0.0)),
            "contact_updates": state.updates, "contact_penalty_N_per_mm": state.penalty,
            "newton_iterations": state.iterations, "factorizations": state.factorizations}


def rubber_stretches(finger, state) -> dict:
    """The tube's converged ``rubber_stretch`` and its corner peak ``max_principal_stretch``
    (mesh-dependent) at a grasp state (:mod:`softhand.fem.rubber_stretch`)."""
    fs = finger.state(state.y, state.P)
    return {"rubber_stretch": fs.rubber_stretch, "max_principal_stretch": fs.max_principal_stretch}
