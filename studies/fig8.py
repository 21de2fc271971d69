"""The Fig. 8 analogue by grasp FEM: F_v against theta at several pressures, against eq. (25).

For one object (:class:`softhand.studies.weights.WeightsCase`: diameter, mass, design, mesh) the object
is placed at its default depth plus each offset, and the pressures are followed in turn;
every point is a converged FEM contact state with its own w (from P and P + dP). Eq. (25)
-> (29) is evaluated at the same (P, theta) with that w and with the paper's w for the
diameter (when it has one). :func:`run` returns a :class:`Fig8Result` that summarises
(the rows and the errors of eq. (25)), writes (the CSV) and plots itself; ``softhand weights
--fig8`` and the ``fig8_fem`` section of ``softhand reproduce`` only choose the inputs.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softhand.reduced.equations import grasp
from softhand.reduced.vocabulary import paper
from softhand.studies.weights import WeightsCase, finger_options
from softhand.studies.weights_rows import reduced_F_v, state_row


@dataclass(frozen=True)
class Fig8Study:
    case: WeightsCase             #: the object and the mesh (its diameter_mm, mass_kg, dP_mpa)
    pressures_mpa: tuple = ()     #: cavity pressures [MPa], followed in increasing order
    depth_offsets_mm: tuple = (0.0, 10.0, 20.0)  #: below the default object depth [mm]


@dataclass(frozen=True)
class Fig8Result:
    case: WeightsCase
    rows: list  #: one FEM contact state per (depth, pressure), see :func:`run`

    def errors(self) -> dict:
        """RMS and largest ``|F_v(eq. 25) - F_v_fem|`` [kgf] over the points, with the FEM's own w at
        each point and (``paper_w_*``) with the paper's w when it has one (None: no point)."""
        out = {}
        for prefix, key in (("", "F_v_reduced_N"), ("paper_w_", "F_v_reduced_paper_w_N")):
            e = np.array([(r[key] - r["F_v_fem_N"]) / grasp.KGF for r in self.rows if r.get(key) is not None])
            out[f"{prefix}rms_error_kgf"] = float(np.sqrt(np.mean(e ** 2))) if e.size else None
            out[f"{prefix}max_abs_error_kgf"] = float(np.abs(e).max()) if e.size else None
        return out

    def summary(self) -> dict:
        """The rows and :meth:`errors` (``softhand weights --fig8 --json``)."""
        return {"rows": self.rows, **self.errors()}

    def write(self, out) -> list[str]:
        """The rows as fig8_fem_<D>mm.csv into the folder ``out``; the names written."""
        from softhand.studies.io.files import write_csv

        name = f"fig8_fem_{self.case.diameter_mm:.0f}mm.csv"
        write_csv(Path(out) / name, self.rows)
        return [name]

    def model_lines(self) -> list[tuple]:
        """Per pressure (P [MPa], theta [deg], F_v [kgf]): eq. (25) with that pressure's mean FEM
        w, on 50 angles from 5 deg below to 5 deg above its points (nan where J_x w = 0)."""
        lines = []
        for P in sorted({r["P_cavity_MPa"] for r in self.rows}):
            pts = [r for r in self.rows if r["P_cavity_MPa"] == P]
            w = np.mean([r["w"] for r in pts], axis=0)
            theta = np.linspace(min(r["theta_deg"] for r in pts) - 5, max(r["theta_deg"] for r in pts) + 5, 50)
            F = [reduced_F_v(P, math.radians(t), self.case.mass_kg, w, self.case.design) for t in theta]
            lines.append((P, theta, np.array([np.nan if f is None else f / grasp.KGF for f in F])))
        return lines

    def plot(self, path) -> None:
        """F_v [kgf] vs theta: FEM points, eq. (25) lines (:func:`softhand.studies.io.weights_plot.plot_fig8`)."""
        from softhand.studies.io.weights_plot import plot_fig8

        plot_fig8(path, self)

    def draw(self, ax) -> None:
        """The same on the matplotlib axes ``ax`` (one panel of a larger figure)."""
        from softhand.studies.io.weights_plot import draw_fig8

        draw_fig8(ax, self)


def run(study: Fig8Study) -> Fig8Result:
    """At each depth the pressures in turn; each point a FEM contact state with its own w."""
    from softhand.fem.hand.finger import FingerModel
    from softhand.fem.hand.grasp import GraspModel, grasp_weights

    case = study.case
    finger = FingerModel(case.design, finger_options(case.mesh_size_mm))
    base = GraspModel(finger, case.diameter_mm, mass=case.mass_kg).depth
    rows = []
    for offset in study.depth_offsets_mm:
        model = GraspModel(finger, case.diameter_mm, mass=case.mass_kg, depth=base + offset)
        state = None
        for P in sorted(study.pressures_mpa):
            pair = grasp_weights(model, P, case.dP_mpa, start=state)
            state, w = pair.state, pair.w
            rows.append({"depth_mm": model.depth, "w": w.tolist(),
                         **state_row(state, w, case.mass_kg, case.design),
                         "F_v_reduced_paper_w_N": paper_w_F_v(state.P, state.theta, case)})
    return Fig8Result(case, rows)


def paper_w_F_v(P: float, theta: float, case: WeightsCase) -> float | None:
    """Eq. (25) -> (29) with the paper's w for this diameter, normalised (None if it has none)."""
    w = paper.WEIGHTS.get(float(case.diameter_mm))
    if w is None:
        return None
    return reduced_F_v(P, theta, case.mass_kg, np.array(w) / np.sum(w), case.design)
