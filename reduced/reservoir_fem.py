r"""Reservoir model ``"fem"``: the sheet's p(V) calibrated from the axisymmetric FEM.

The FEM (``fem/reservoir.py``: clamped Neo-Hookean sheet, Q2/P1disc, volume control) gives
the strain energy W(V) and the pressure p = dW/dV of the sheet. By dimensional analysis a
Neo-Hookean sheet of radius R, thickness t and modulus μ has

.. math:: p = \frac{μ t}{R}\,\tilde p(v, t/R), \qquad W = μ t R^2\,\tilde W(v, t/R),
          \qquad v = V / R^3,\ \tilde p = d\tilde W/dv,

and the dependence on t/R is only the bending share, O((t/R)²) of the membrane energy.
The table ``reduced/data/reservoir_fem.csv`` holds :math:`\tilde W, \tilde p, \tilde h = h/R`
at t/R = 1/24 (Table I) with its provenance in the header; this model rescales it to the
design's R, t, μ_sr. Between table points W̃ is the cubic Hermite interpolant of the
values W̃ and slopes p̃, and p̃ its derivative, so p = dW/dV holds exactly within the
model (energy-consistent, p continuous). Above the table's last volume p̃ continues
linearly (W̃ quadratically); V <= 0 is an error, as in the ellipse model.

NumPy only; registered as ``"fem"`` in :mod:`reduced.reservoir`.
"""
from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np

from .design import HandDesign
from .errors import InputError
from .reservoir import register_model

__all__ = ["TABLE_FILE", "table", "pressure", "strain_energy", "height"]

TABLE_FILE = Path(__file__).resolve().parent / "data" / "reservoir_fem.csv"
COLUMNS = ("v", "p_tilde", "W_tilde", "h_tilde")


@lru_cache(maxsize=1)
def table() -> dict:
    """The calibration table: v = V/R³, p̃ = pR/(μt), W̃ = W/(μtR²), h̃ = h/R (arrays)."""
    lines = [line for line in TABLE_FILE.read_text().splitlines()
             if line.strip() and not line.startswith("#")]
    header = lines[0].split(",")
    values = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    return {name: values[:, header.index(name)] for name in COLUMNS}


def _locate(V, design: HandDesign):
    v = np.asarray(V, dtype=float) / design.R**3
    if np.any(v <= 0.0):
        raise InputError("V_mm3", float(np.min(V)), "reservoir volume must be positive")
    tab = table()
    x = tab["v"]
    i = np.clip(np.searchsorted(x, v) - 1, 0, x.size - 2)
    dx = x[i + 1] - x[i]
    return v, np.minimum((v - x[i]) / dx, 1.0), i, dx, tab


def _dimensionless_pressure(V, design):
    """p̃(v): derivative of the Hermite W̃; linear beyond the last table point."""
    v, s, i, dx, tab = _locate(V, design)
    W, p = tab["W_tilde"], tab["p_tilde"]
    dh00, dh10, dh11 = 6 * s**2 - 6 * s, 3 * s**2 - 4 * s + 1, 3 * s**2 - 2 * s
    inside = (W[i] - W[i + 1]) * dh00 / dx + p[i] * dh10 + p[i + 1] * dh11
    end_slope = (p[-1] - p[-2]) / (tab["v"][-1] - tab["v"][-2])
    return np.where(v > tab["v"][-1], p[-1] + end_slope * (v - tab["v"][-1]), inside)


def pressure(V, design: HandDesign):
    """Reservoir gauge pressure p_r(V) = dW/dV [MPa] of the FEM-calibrated sheet, V [mm^3]."""
    return design.mu_sr * design.t / design.R * _dimensionless_pressure(V, design)


def strain_energy(V, design: HandDesign):
    """Strain energy W(V) [N mm] of the FEM-calibrated sheet (Hermite W̃; quadratic beyond)."""
    v, s, i, dx, tab = _locate(V, design)
    W, p, x = tab["W_tilde"], tab["p_tilde"], tab["v"]
    h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
    inside = W[i] * h00 + dx * p[i] * h10 + W[i + 1] * h01 + dx * p[i + 1] * h11
    e = v - x[-1]
    beyond = W[-1] + p[-1] * e + 0.5 * (p[-1] - p[-2]) / (x[-1] - x[-2]) * e**2
    return design.mu_sr * design.t * design.R**2 * np.where(v > x[-1], beyond, inside)


def height(V, design: HandDesign):
    """FEM apex height h(V) [mm] of the wet surface (linear interpolation of h̃)."""
    tab = table()
    return design.R * np.interp(np.asarray(V, float) / design.R**3, tab["v"], tab["h_tilde"])


register_model("fem", pressure)
