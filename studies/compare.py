r"""The whole hand without load: pump pressure against bend angle from the two FEM models.

Eq. (25) without grasp forces, with the reservoir's pressure p_r(V) = dW_r/dV, gives

.. math:: P(\theta) = p_\text{finger}(\theta) - p_r\bigl(V_0 - n\,\Delta Q(\theta)\bigr),

where p_finger(theta) is the cavity pressure that bends a free finger to theta and
Delta Q(theta) its cavity volume change. Here both come from the finger FEM (a bending
sweep's (P, theta, dQ) rows), p_r from the reservoir-sheet FEM (:mod:`softhand.fem.hand.reservoir`) at
the oil volumes left; the reduced counterpart is eq. (27) (eq. (28) + the ellipse model with
eq. (2)'s volume). The reservoir's pressure offset p_r(V0) is what the paper reads off
Fig. 7 as "0.1 MPa lower pressure". The result summarises and writes itself; the bending
study (:mod:`softhand.studies.bending`) runs it with ``hand=True``.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softhand.fem.hand.reservoir import SheetModel, inflate
from softhand.reduced.equations import hand
from softhand.reduced.vocabulary import paper
from softhand.reduced.equations import reservoir as ellipse
from softhand.reduced.vocabulary.design import HandDesign


@dataclass(frozen=True)
class WholeHandResult:
    """The hand's pump pressure from both FEMs against eq. (27), per bending row."""

    rows: list                  #: theta, P_cavity_fem, V, p_reservoir_fem, P_pump_fem, eqs. (27), (28)
    offset_fem_MPa: float       #: p_r(V0), reservoir-sheet FEM
    offset_ellipse_MPa: float   #: p_r(V0), the ellipse model
    reservoir_ndofs: int
    reservoir_seconds: float

    def summary(self) -> dict:
        """The rows, the offsets (with the paper's) and the sheet FEM's size and time."""
        return {"rows": self.rows, "offset_fem_MPa": self.offset_fem_MPa,
                "offset_ellipse_MPa": self.offset_ellipse_MPa, "offset_paper_MPa": paper.RESERVOIR_OFFSET_MPA,
                "reservoir_ndofs": self.reservoir_ndofs, "reservoir_seconds": self.reservoir_seconds}

    def write(self, out) -> list[str]:
        """hand.csv (the rows) into the folder ``out``; the names written."""
        from softhand.studies.io.files import write_csv

        write_csv(Path(out) / "hand.csv", self.rows)
        return ["hand.csv"]

    def max_abs_difference_MPa(self) -> float:
        """Largest ``|P_pump,FEM - P_eq.(27)|`` over the rows [MPa]."""
        return float(np.nanmax([abs(r["P_pump_fem_MPa"] - r["P_pump_eq27_MPa"]) for r in self.rows]))


def whole_hand(rows: list[dict], design: HandDesign, **sheet_mesh) -> WholeHandResult:
    """Per bending row (P_cavity_MPa, theta_deg, dQ_mm3): the hand's pump pressure from the FEM
    finger + FEM reservoir, and eq. (27) at the same theta."""
    dQ = np.array([r["dQ_mm3"] for r in rows])
    V = ellipse.oil_left(dQ, design)
    wet = V > 0  # beyond, the fingers would take more oil than the reservoir holds: no hand
    if not wet.all():
        warnings.warn(f"the {design.n} FEM fingers take more oil than V0 = {design.V0:g} mm^3 from "
                      f"{rows[int(np.argmin(wet))]['theta_deg']:.4g} deg on: no whole-hand pressure there")
    sheet = inflate(SheetModel.from_design(design, **sheet_mesh), np.append(V[wet], design.V0))
    p_res = np.full(V.size, math.nan)
    p_res[wet] = [s.pressure for s in sheet.states[:-1]]
    P_hand = ellipse.pump_pressure(np.array([r["P_cavity_MPa"] for r in rows]), V, design,
                                   p_r=lambda _: p_res)  # the sheet FEM at each row's oil left
    out = []
    for r, v, pr, P in zip(rows, V, p_res, P_hand):
        theta = math.radians(r["theta_deg"])
        out.append({
            "theta_deg": r["theta_deg"],
            "P_cavity_fem_MPa": r["P_cavity_MPa"],
            "V_mm3": float(v),
            "p_reservoir_fem_MPa": float(pr),
            "P_pump_fem_MPa": float(P),
            "P_pump_eq27_MPa": float(hand.pressure(theta, design, reservoir=True)) if v > 0 else math.nan,
            "P_cavity_eq28_MPa": float(hand.pressure(theta, design, reservoir=False)),
        })
    return WholeHandResult(out, float(sheet.states[-1].pressure), float(ellipse.pressure(design.V0, design)),
                           int(sheet.ndofs), sheet.wall_time)
