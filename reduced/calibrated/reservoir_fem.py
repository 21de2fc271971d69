r"""Reservoir model ``"fem"``: the sheet's p(V) calibrated from the axisymmetric FEM.

The FEM (``fem/hand/reservoir.py``: clamped Neo-Hookean sheet, Q2/P1disc, volume control) gives
the strain energy W(V) and the pressure p = dW/dV of the sheet. By dimensional analysis a
Neo-Hookean sheet of radius R, thickness t and modulus μ has

.. math:: p = \frac{μ t}{R}\,\tilde p(v, t/R), \qquad W = μ t R^2\,\tilde W(v, t/R),
          \qquad v = V / R^3,\ \tilde p = d\tilde W/dv,

and the dependence on τ = t/R is the bending share (mostly the clamp's boundary layer;
measured close to linear in τ: p̃ at V0 is 1.435, 1.463, 1.512 for τ = 1/48, 1/24, 1/12).
The file ``reduced/calibrated/data/reservoir_fem.csv`` holds :math:`\tilde W, \tilde p, \tilde h = h/R`
(and the converged rubber stretch less 1, ``s_tilde``)
on the same v grid at τ = 1/24 (Table I) and τ = 1/12, with its provenance in the header;
this model rescales them to the design's R, t, μ_sr and interpolates linearly in τ
(extrapolates outside [1/24, 1/12]; at τ = 1/48 that is within 0.5 %, see
``tests/fem/test_reservoir.py``). Between table points W̃ is the cubic Hermite interpolant of
the values W̃ and slopes p̃, and p̃ its derivative, so p = dW/dV holds exactly within the
model (energy-consistent, p continuous). Above the table's last volume p̃ continues
linearly (W̃ quadratically); V <= 0 is an error, as in the ellipse model.

NumPy only; registered as ``"fem"`` in :mod:`softhand.reduced.equations.reservoir`.
"""
from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np

from softhand.reduced.materials.rubber_parameters import CRITICAL_DISTANCE_MM, between_sizes
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.vocabulary.inputfiles import read_number_table
from softhand.reduced.equations import reservoir as ellipse
from softhand.reduced.equations.reservoir import register_model

__all__ = ["TABLE_FILE", "table", "pressure", "strain_energy", "height", "rubber_stretch", "R_RHO", "SIZE_STRETCH"]

TABLE_FILE = Path(__file__).resolve().parent / "data" / "reservoir_fem.csv"
COLUMNS = ("v", "p_tilde", "W_tilde", "h_tilde")
#: the optional column: the FEM's converged rubber stretch less 1 (fem.rubber_stretch)
STRETCH = "s_tilde"
#: R / rho of the optional last columns: the stretch less 1 averaged over a ball of radius R / x
#: (rho the rubber's critical distance, so the measure is not v and tau's alone: the sheet's
#: worst place is its clamp, where the average over 1 or 4 mm differs by 10-30 %); R = 12 to
#: 48 mm at 2 mm
R_RHO = (6.0, 8.0, 12.0, 16.0, 24.0)
SIZE_STRETCH = tuple(f"s_R_rho_{x:g}" for x in R_RHO)


@lru_cache(maxsize=1)
def table() -> dict:
    """The calibration tables: τ = t/R -> {v = V/R³, p̃ = pR/(μt), W̃ = W/(μtR²), h̃ = h/R}."""
    _, header, values = read_number_table(TABLE_FILE, "reservoir_table", "the reservoir calibration CSV "
                                          "(softhand reservoir --write-calibration)", ("tau", *COLUMNS),
                                          optional=(STRETCH, *SIZE_STRETCH))
    tau = values[:, 0]
    return {float(t): {name: values[tau == t, header.index(name)] for name in (*COLUMNS, STRETCH, *SIZE_STRETCH)
                       if name in header}
            for t in np.unique(tau)}


def _weights(design: HandDesign):
    """((tab_a, 1 - s), (tab_b, s)): linear in τ = t/R between (or beyond) the two tables."""
    (ta, a), (tb, b) = sorted(table().items())
    s = (design.t / design.R - ta) / (tb - ta)
    return (a, 1.0 - s), (b, s)


def _locate(V, design: HandDesign, tab: dict):
    v = np.asarray(V, dtype=float) / design.R**3
    if np.any(v <= 0.0):
        raise InputError("V_mm3", float(np.min(V)), "reservoir volume must be positive")
    x = tab["v"]
    i = np.minimum(np.maximum(np.searchsorted(x, v) - 1, 0), x.size - 2)
    dx = x[i + 1] - x[i]
    return v, np.minimum((v - x[i]) / dx, 1.0), i, dx


def _p_tilde(V, design, tab):
    """p̃(v) of one table: derivative of the Hermite W̃; linear beyond the last point."""
    v, s, i, dx = _locate(V, design, tab)
    W, p, x = tab["W_tilde"], tab["p_tilde"], tab["v"]
    dh00, dh10, dh11 = 6 * s**2 - 6 * s, 3 * s**2 - 4 * s + 1, 3 * s**2 - 2 * s
    inside = (W[i] - W[i + 1]) * dh00 / dx + p[i] * dh10 + p[i + 1] * dh11
    return np.where(v > x[-1], p[-1] + (p[-1] - p[-2]) / (x[-1] - x[-2]) * (v - x[-1]), inside)


def _W_tilde(V, design, tab):
    """W̃(v) of one table: cubic Hermite of (W̃, p̃); quadratic beyond the last point."""
    v, s, i, dx = _locate(V, design, tab)
    W, p, x = tab["W_tilde"], tab["p_tilde"], tab["v"]
    h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
    inside = W[i] * h00 + dx * p[i] * h10 + W[i + 1] * h01 + dx * p[i + 1] * h11
    e = v - x[-1]
    beyond = W[-1] + p[-1] * e + 0.5 * (p[-1] - p[-2]) / (x[-1] - x[-2]) * e**2
    return np.where(v > x[-1], beyond, inside)


def pressure(V, design: HandDesign):
    """Reservoir gauge pressure p_r(V) = dW/dV [MPa] of the FEM-calibrated sheet, V [mm^3];
    another rubber than Neo-Hookean times :func:`rubber_factor`."""
    p = sum(w * _p_tilde(V, design, tab) for tab, w in _weights(design))
    return design.mu_sr * design.t / design.R * p * rubber_factor(V, design)


def rubber_factor(V, design: HandDesign):
    """The design's sheet rubber over a Neo-Hookean one of its initial shear modulus mu_sr, in
    the equi-biaxial stretch lambda_r(V) of the ellipse model (eq. (16)): the equibiaxial
    nominal stress of the rubber over mu_sr (lambda - lambda^-5); 1 for Neo-Hookean."""
    if design.reservoir_is_neo_hookean:
        return 1.0
    lam = np.maximum(ellipse.stretch(np.asarray(V, float), design), 1.0 + 1e-6)  # 0/0 at the flat sheet
    return design.reservoir_rubber.nominal_stress("equibiaxial", lam) / (design.mu_sr * (lam - lam**-5))


def strain_energy(V, design: HandDesign):
    """Strain energy W(V) [N mm] of the FEM-calibrated sheet; for another rubber than
    Neo-Hookean the integral of :func:`pressure` from the flat sheet (composite Gauss)."""
    if not design.reservoir_is_neo_hookean:
        return _integral_of_pressure(np.asarray(V, float), design)
    W = sum(w * _W_tilde(V, design, tab) for tab, w in _weights(design))
    return design.mu_sr * design.t * design.R**2 * W


def _integral_of_pressure(V, design: HandDesign, panels: int = 64):
    """int_0^V p dV [N mm], 4-point Gauss on ``panels`` equal panels (p is C1: relative error
    ~1e-8 at the table's spacing)."""
    x, w = np.polynomial.legendre.leggauss(4)
    s = (np.arange(panels)[:, None] + 0.5 * (x + 1.0)) / panels  # (panels, 4) in (0, 1)
    weights = np.broadcast_to(0.5 * w / panels, s.shape).ravel()
    return (pressure(np.multiply.outer(V, s.ravel()), design) @ weights) * V


def height(V, design: HandDesign):
    """FEM apex height h(V) [mm] of the wet surface (h̃ linear in v and in τ)."""
    v = np.asarray(V, float) / design.R**3
    return design.R * sum(w * np.interp(v, tab["v"], tab["h_tilde"]) for tab, w in _weights(design))


def rubber_stretch(V, design: HandDesign):
    """The sheet's converged rubber stretch (the FEM's ``rubber_stretch``) at oil volume V
    [mm^3]: s_tilde linear in v and in tau, continued linearly beyond the table's last volume,
    and where the table has it at each R/rho, linear in ln(R/rho) between those (the end
    columns' line beyond them): a Neo-Hookean sheet's stretch depends on v, tau and, as the
    averaging radius rho is the rubber's, on the sheet's size R/rho. None if the table has no
    stretch column."""
    tables = table().values()
    columns = SIZE_STRETCH if all(SIZE_STRETCH[0] in tab for tab in tables) else (STRETCH,)
    if any(columns[0] not in tab for tab in tables):
        return None
    v = np.asarray(V, float) / design.R**3
    s = [sum(w * _linear(v, tab["v"], tab[c]) for tab, w in _weights(design)) for c in columns]
    return 1.0 + (between_sizes(s, R_RHO, design.R / CRITICAL_DISTANCE_MM) if len(columns) > 1 else s[0])


def _linear(v, x, y):
    """y(v) piecewise linear in the table, continued by its last segment beyond it."""
    slope = (y[-1] - y[-2]) / (x[-1] - x[-2])
    return np.where(v > x[-1], y[-1] + slope * (v - x[-1]), np.interp(v, x, y))


register_model("fem", pressure)
