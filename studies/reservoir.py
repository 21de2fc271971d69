"""The reservoir study: FEM inflation of the sheet against the paper's ellipse model (11)–(18).

``run(study)`` inflates the clamped sheet (:mod:`softhand.fem.hand.reservoir`) through the requested oil
volumes and through the operating range, and returns per volume the FEM pressure, apex
height, strain energy, the ellipse model's values at the same volume, the largest vertical
gap between the FEM wet-surface profile and the half-ellipse, and the verdict: the ellipse
model's errors over the operating range (fingers from 0 to ``theta_max``). The result is
summarised, written and plotted by its own methods (:meth:`ReservoirStudyResult.summary`,
``write``, ``plot``); ``softhand reservoir``, the batch kind and ``softhand reproduce``
only choose the inputs.

The operating range is V0 - n a² π d θ_max <= V <= V0 (eq. (15)); the stroke pressure change
Δp = p(V0) - p(V0 - ΔV) is what the reservoir takes off the pump pressure between a straight
and a fully bent finger.
"""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from softhand.fem.hand.reservoir import ReservoirResult, SheetModel, inflate, rubber_stretches
from softhand.reduced.calibrated.reservoir_fem import R_RHO, SIZE_STRETCH
from softhand.reduced.equations import finger
from softhand.reduced.equations import reservoir as ellipse
from softhand.reduced.vocabulary.design import HandDesign
from softhand.studies.calibration.tables import write_table, written_by

__all__ = ["ReservoirStudy", "ReservoirStudyResult", "run", "stroke_volume", "COLUMNS"]

#: table columns of the CLI, in order
COLUMNS = ["V_mm3", "p_MPa", "h_mm", "W_Nmm", "p_ellipse_MPa", "h_ellipse_mm", "W_ellipse_Nmm",
           "lambda_r", "lambda_fem", "rubber_stretch", "max_gap_mm"]


@dataclass(frozen=True)
class ReservoirStudy:
    """Which volumes, which design, how fine a mesh."""

    design: HandDesign = field(default_factory=HandDesign)
    volumes_mm3: tuple = ()  #: requested oil volumes [mm^3]; empty: stroke ends, V0, V0 + 2000
    theta_max: float = math.pi / 2  #: largest finger bend of the operating range [rad]
    n_range: int = 9  #: FEM volumes sampled over the operating range for the verdict
    n_radial: int = 40  #: Q2 elements along the radius
    n_thick: int = 2  #: Q2 elements through the thickness

    def model(self) -> SheetModel:
        return SheetModel.from_design(self.design, n_radial=self.n_radial, n_thick=self.n_thick)


@dataclass(frozen=True)
class ReservoirStudyResult:
    study: ReservoirStudy
    rows: list  #: one dict per requested volume, keys COLUMNS
    states: tuple = field(repr=False)  #: fem.hand.reservoir.SheetState per requested volume
    fem: ReservoirResult = field(repr=False)  #: the whole FEM path
    verdict: dict = field(default_factory=dict)  #: ellipse-model errors over the operating range

    def summary(self) -> dict:
        """The pressure maximum, the verdict, the mesh, cost and provenance (for result.json)."""
        fem = self.fem
        pm = fem.pressure_max
        return {
            "pressure_max": None if pm is None else {"V_mm3": pm[0], "p_MPa": pm[1]},
            "path_max_volume_mm3": float(fem.path_volume[-1]),
            "verdict": self.verdict, "design": self.study.design.to_dict(),
            "design_hash": self.study.design.hash(),
            "mesh": {"n_radial": fem.model.n_radial, "n_thick": fem.model.n_thick, "ndofs": fem.ndofs,
                     "element": "Q2/P1disc axisymmetric", "kappa_over_mu": fem.model.kappa_ratio},
            "newton_iterations": fem.newton_iterations, "load_steps": len(fem.path_volume) - 1,
            "wall_time_s": fem.wall_time,
        }

    def write(self, out) -> list[str]:
        """Into the folder ``out``: result.json (rows, :meth:`summary`, the wet-surface profiles
        z(r) and mid-surface stretches per volume, the whole p(V), W(V) path), rows.csv and
        the VTK of the deformed sheet per volume; the names written."""
        from softhand.studies.io.files import write_csv, write_json

        out = Path(out)
        profiles = [{"V_mm3": s.volume, "r_mm": s.r, "z_mm": s.z, "r0_mid_mm": s.r0_mid,
                     "lambda_meridian": s.lambda_meridian, "lambda_hoop": s.lambda_hoop,
                     "lambda_thickness": s.lambda_thickness} for s in self.states]
        path = {"V_mm3": self.fem.path_volume, "p_MPa": self.fem.path_pressure,
                "W_Nmm": self.fem.path_energy}
        write_json(out / "result.json", {"rows": self.rows, **self.summary(), "profiles": profiles,
                                         "path": path})
        write_csv(out / "rows.csv", self.rows)
        return ["result.json", "rows.csv", *self.write_vtk(out)]

    def write_vtk(self, out) -> list[str]:
        """sheet.pvd (3D scenes) and sheet_V<volume>_rz.vtu (r-z sections) into ``out``."""
        from softhand.studies.io.reservoir_files import write_sheet_vtk

        return write_sheet_vtk(self, Path(out))

    def plot(self, path) -> None:
        """Profiles, p(V) of both models and P(theta) with both reservoir models."""
        from softhand.studies.io.reservoir_files import plot_reservoir

        plot_reservoir(path, self)


def stroke_volume(design: HandDesign, theta_max: float) -> float:
    """Oil the n fingers take from the reservoir at bend theta_max [rad], eq. (15) [mm^3]."""
    return design.n * design.a**2 * math.pi * design.d * theta_max


def _ellipse_gap(state, design: HandDesign) -> float:
    """Largest vertical gap [mm] between the FEM wet surface and the half-ellipse of the same V."""
    r = np.linspace(0.0, design.R, 201)
    h = float(ellipse.height(state.volume, design))
    return float(np.max(np.abs(state.profile_at(r) - h * np.sqrt(1.0 - (r / design.R) ** 2))))


def _row(state, design: HandDesign) -> dict:
    V = state.volume
    return {
        "V_mm3": V, "p_MPa": state.pressure, "h_mm": state.apex, "W_Nmm": state.energy,
        "p_ellipse_MPa": float(ellipse.ellipse_pressure(V, design)),
        "h_ellipse_mm": float(ellipse.height(V, design)),
        "W_ellipse_Nmm": float(ellipse.strain_energy(V, design)),
        "lambda_r": float(ellipse.stretch(V, design)), "lambda_fem": state.mean_stretch,
        "rubber_stretch": state.rubber_stretch, "max_principal_stretch": state.max_principal_stretch,
        "max_gap_mm": _ellipse_gap(state, design),
    }


def _verdict(rows: list, design: HandDesign, dV: float) -> dict:
    """Relative errors of the ellipse model, (ellipse - FEM) / FEM, over the operating range
    (``rows`` from V0 - dV to V0), and the pressure offsets p_r(V(theta)) of both models."""
    def err(ell, fem):
        e = np.array([(r[ell] - r[fem]) / r[fem] for r in rows])
        return {"min": float(e.min()), "max": float(e.max()), "at_V0": float(e[-1])}

    theta = (design.V0 - np.array([r["V_mm3"] for r in rows])) / (stroke_volume(design, 1.0))
    diff = [r["p_ellipse_MPa"] - r["p_MPa"] for r in rows]
    dp_fem = rows[-1]["p_MPa"] - rows[0]["p_MPa"]
    dp_ell = rows[-1]["p_ellipse_MPa"] - rows[0]["p_ellipse_MPa"]
    return {
        "V_range_mm3": [rows[0]["V_mm3"], rows[-1]["V_mm3"]], "stroke_mm3": dV,
        "apex_height": err("h_ellipse_mm", "h_mm"), "mean_stretch": err("lambda_r", "lambda_fem"),
        "strain_energy": err("W_ellipse_Nmm", "W_Nmm"), "pressure": err("p_ellipse_MPa", "p_MPa"),
        "stroke_dp_fem_MPa": dp_fem, "stroke_dp_ellipse_MPa": dp_ell,
        "stroke_dp": (dp_ell - dp_fem) / dp_fem,
        "max_gap_mm": max(r["max_gap_mm"] for r in rows),
        # the reservoir's pressure offset in eq. (27), P = p_finger - p_r(V(theta))
        "offset_theta_deg": np.degrees(theta).tolist(),
        "offset_fem_MPa": [r["p_MPa"] for r in rows],
        "offset_ellipse_MPa": [r["p_ellipse_MPa"] for r in rows],
        "offset_difference_MPa": [min(diff), max(diff)],
    }


def run(study: ReservoirStudy, *, progress=None) -> ReservoirStudyResult:
    """Inflate the sheet through the requested volumes and the operating range; compare."""
    d = study.design
    dV = stroke_volume(d, study.theta_max)
    finger.check_volume(d, study.theta_max)
    requested = np.asarray(study.volumes_mm3 or (d.V0 - dV, d.V0, d.V0 + 2000.0), dtype=float)
    grid = np.linspace(d.V0 - dV, d.V0, study.n_range)
    volumes = np.concatenate([requested, grid])
    fem = inflate(study.model(), volumes, progress=progress)
    states = fem.states[:requested.size]
    rows = [_row(s, d) for s in states]
    verdict = _verdict([_row(s, d) for s in fem.states[requested.size:]], d, dV)
    return ReservoirStudyResult(study, rows, states, fem, verdict)


def calibration_rows(model: SheetModel, *, v_max: float = 1.75, n: int = 71, progress=None) -> list:
    """FEM table for :mod:`softhand.reduced.calibrated.reservoir_fem`: v = V/R³ in [0, v_max] on n points, with
    τ = t/R, p̃ = pR/(μt), W̃ = W/(μtR²), h̃ = h/R."""
    R, t, mu = model.R, model.t, model.mu
    v = np.linspace(0.0, v_max, n)[1:]
    fem = inflate(model, v * R**3, progress=progress)
    sizes = rubber_stretches(model, fem.states, [R / x for x in R_RHO])
    rows = [{"tau": t / R, "v": 0.0, "p_tilde": 0.0, "W_tilde": 0.0, "h_tilde": 0.0, "s_tilde": 0.0,
             **dict.fromkeys(SIZE_STRETCH, 0.0)}]
    rows += [{"tau": t / R, "v": s.volume / R**3, "p_tilde": s.pressure * R / (mu * t),
              "W_tilde": s.energy / (mu * t * R**2), "h_tilde": s.apex / R,
              "s_tilde": s.rubber_stretch - 1.0, **dict(zip(SIZE_STRETCH, lam - 1.0))}
             for s, lam in zip(fem.states, sizes)]
    return rows


def calibration_provenance(models: list, command: str) -> list[str]:
    """The reservoir table's provenance lines: who wrote it, and each sheet model's mesh."""
    head = [written_by("FEM calibration of reduced/calibrated/reservoir_fem.py"), command]
    for m in models:
        head.append(f"model: R={m.R} mm, t={m.t} mm (tau=t/R={m.t / m.R:.6g}), mu={m.mu} MPa, "
                    f"kappa/mu={m.kappa_ratio}, Q2/P1disc, {m.n_radial} x {m.n_thick} elements "
                    f"(clamp ratio {m.clamp_ratio})")
    head.append("tau = t/R, v = V/R^3, p_tilde = p R/(mu t), W_tilde = W/(mu t R^2), h_tilde = h/R, "
                "s_tilde = rubber_stretch - 1 (the converged stretch, softhand.fem.rubber_stretch); "
                "s_R_rho_X = the same, averaged over a ball of radius R/X (X = R/rho)")
    return head


#: the reservoir table's columns (:mod:`softhand.reduced.calibrated.reservoir_fem`)
CALIBRATION_COLUMNS = ("tau", "v", "p_tilde", "W_tilde", "h_tilde", "s_tilde", *SIZE_STRETCH)


def write_calibration(study: ReservoirStudy, path) -> int:
    """FEM tables at the design's thickness t and at 2t (twice the layers: same element shape),
    written to ``path`` with their provenance; the number of rows. A design with its own rubber
    gets the tables of a Neo-Hookean sheet of the rubber's initial shear modulus (the tables are
    dimensionless; the "fem" model applies the rubber on top of them), as ``calibrate finger``
    does for the tube, and a note says so."""
    if not study.design.reservoir_is_neo_hookean:
        print(f"note: the tables are built with a Neo-Hookean sheet of the rubber's initial shear modulus "
              f"mu_sr_MPa = {study.design.mu_sr:.6g}; reservoir_model \"fem\" applies a design's own rubber "
              f"({study.design.reservoir_material.model} here) on top of them", file=sys.stderr)
        study = replace(study, design=study.design.replace(reservoir_material=None))
    thin = study.model()
    thick = replace(thin, t=2 * thin.t, n_thick=2 * thin.n_thick)
    rows = calibration_rows(thin) + calibration_rows(thick)
    command = (f"softhand reservoir --write-calibration {Path(path).name} "
               f"--n-radial {thin.n_radial} --n-thick {thin.n_thick}")
    write_table(path, calibration_provenance([thin, thick], command), CALIBRATION_COLUMNS,
                [[r[c] for c in CALIBRATION_COLUMNS] for r in rows], {"v": ".6g"})
    return len(rows)
