r"""The whole hand without load: pump pressure against bend angle from the two FEM models.

Eq. (25) without grasp forces, with the reservoir's pressure p_r(V) = dW_r/dV, gives

.. math:: P(\theta) = p_\text{finger}(\theta) - p_r\bigl(V_0 - n\,\Delta Q(\theta)\bigr),

where p_finger(theta) is the cavity pressure that bends a free finger to theta and
Delta Q(theta) its cavity volume change. Here both come from the finger FEM (a bending
sweep's (P, theta, dQ) rows), p_r from the reservoir-sheet FEM (:mod:`fem.hand.reservoir`) at
the oil volumes left; the reduced counterpart is eq. (27) (eq. (28) + the ellipse model with
eq. (2)'s volume). The reservoir's pressure offset p_r(V0) is what the paper reads off
Fig. 7 as "0.1 MPa lower pressure".
"""
from __future__ import annotations

import math

import numpy as np

from softhand.fem.hand.reservoir import SheetModel, inflate
from softhand.reduced import hand
from softhand.reduced import reservoir as ellipse
from softhand.reduced.design import HandDesign


def whole_hand(rows: list[dict], design: HandDesign, **sheet_mesh) -> dict:
    """Per bending row (P_MPa, theta_deg, dQ_mm3): the hand's pump pressure from the FEM
    finger + FEM reservoir, and eq. (27) at the same theta. Returns rows and the offset."""
    dQ = np.array([r["dQ_mm3"] for r in rows])
    V = design.V0 - design.n * dQ
    sheet = inflate(SheetModel.from_design(design, **sheet_mesh), np.append(V, design.V0))
    p_res = np.array([s.pressure for s in sheet.states])
    out = []
    for r, v, pr in zip(rows, V, p_res[:-1]):
        theta = math.radians(r["theta_deg"])
        out.append({
            "theta_deg": r["theta_deg"],
            "P_finger_fem_MPa": r["P_MPa"],
            "V_mm3": float(v),
            "p_reservoir_fem_MPa": float(pr),
            "P_hand_fem_MPa": r["P_MPa"] - float(pr),
            "P_hand_eq27_MPa": float(hand.pressure(theta, design, reservoir=True)),
            "P_finger_eq28_MPa": float(hand.pressure(theta, design, reservoir=False)),
        })
    return {
        "rows": out,
        "offset_fem_MPa": float(p_res[-1]),
        "offset_ellipse_MPa": float(ellipse.pressure(design.V0, design)),
        "offset_paper_MPa": 0.1,
        "reservoir_ndofs": int(sheet.ndofs),
        "reservoir_seconds": sheet.wall_time,
    }
