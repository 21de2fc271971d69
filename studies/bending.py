"""Free bending of the finger under pressure: the FEM against eqs. (28) and (2).

:func:`run` builds the finger FEM (:mod:`softhand.fem.hand.finger`), follows the pressures and returns
one row per pressure with the reduced model's values next to the FEM's:

* ``theta_reduced_deg``: eq. (28) (one finger, no reservoir) solved for theta at the same P;
* ``dQ_reduced_mm3``: eq. (2) per finger, a^2 pi d theta, at the FEM's theta, so that it
  checks the volume-angle relation on its own (the angle error is in the theta column).

Optionally the path continues to ``peak_mpa`` (2.0 MPa: the pressure the paper's FEM
says the finger withstands) and reports the peak stretch and stress there; with ``hand``
the whole hand follows, P = p_finger - p_r(V0 - n dQ) with the reservoir-sheet FEM
(:func:`softhand.studies.compare.whole_hand`).

The result is computed, plotted and written here once: :meth:`BendingResult.write` (result.json,
table.csv, hand.csv), :meth:`BendingResult.plot` (Fig. 7 with FEM points) and
:func:`vtk_writer` (the VTK series, state by state as the path converges). ``softhand bend``
and ``softhand reproduce`` only choose the inputs and print.
"""
from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from softhand.fem.hand.finger import FingerModel, FingerOptions, FingerState, SweepStats, ring_width, solve_pressures
from softhand.fem.newton import NotConverged
from softhand.reduced.equations import finger as reduced_finger
from softhand.reduced.equations import hand
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError

if TYPE_CHECKING:
    from softhand.studies.compare import WholeHandResult


@dataclass(frozen=True)
class BendingStudy:
    design: HandDesign = field(default_factory=HandDesign)
    pressures_mpa: tuple[float, ...] = tuple(np.round(np.arange(0.0, 0.81, 0.1), 10))
    options: FingerOptions = field(default_factory=FingerOptions)
    peak_mpa: float = 0.0  #: continue to this pressure after the sweep [MPa]; 0: no
    peak_step_mpa: float = 0.2  #: pressure increment on the way to peak_mpa [MPa]
    hand: bool = False  #: also the whole hand with the reservoir-sheet FEM

    def __post_init__(self):
        P = np.asarray(self.pressures_mpa, dtype=float)
        if P.size == 0 or np.any(P < 0) or np.any(np.diff(P) <= 0):
            raise InputError("pressure_mpa", list(P), "must be increasing values >= 0 MPa")
        if self.peak_mpa and self.peak_mpa <= P[-1]:
            raise InputError("peak_mpa", self.peak_mpa, f"must exceed the last pressure {P[-1]} MPa")


@dataclass
class BendingResult:
    rows: list[dict]            #: one per pressure (see :func:`row`)
    peak: dict | None           #: the state at peak_mpa, or None
    ndofs: int                  #: unknowns of the reduced FEM system
    nelements: int              #: quadratic tetrahedra in the half model
    stats: SweepStats           #: cost of the sweep (without the peak run)
    build_seconds: float        #: meshing (cached) and setting up the model
    model: FingerModel = field(repr=False)
    states: list[FingerState] = field(repr=False)
    hand: WholeHandResult | None = None  #: the whole hand (:func:`softhand.studies.compare.whole_hand`), or None

    def summary(self) -> dict:
        """Numbers and provenance for result.json."""
        out = {"rows": self.rows, "peak": self.peak, "ndofs": self.ndofs,
               "nelements": self.nelements, "build_seconds": self.build_seconds,
               "stats": asdict(self.stats), "options": {**asdict(self.model.options),  # the ring width in effect
                                 "tie_width": ring_width(self.model.design, self.model.options)},
               "design": self.model.design.to_dict(), "design_hash": self.model.design.hash()}
        return out if self.hand is None else {**out, "hand": self.hand.summary()}

    def write(self, out) -> list[str]:
        """result.json (:meth:`summary`), table.csv (the rows) and, with the hand, hand.csv
        into the folder ``out``; the names written."""
        from softhand.studies.io.files import write_csv, write_json

        out = Path(out)
        names = self.hand.write(out) if self.hand else []
        write_json(out / "result.json", self.summary())
        write_csv(out / "table.csv", self.rows)
        return ["result.json", "table.csv", *names]

    def plot(self, path, **labels) -> None:
        """Fig. 7 with FEM points (:func:`softhand.studies.io.bend_plot.plot_bending`)."""
        from softhand.studies.io.bend_plot import plot_bending

        plot_bending(path, self.rows, self.model.design, self.hand and self.hand.rows, **labels)


def row(state: FingerState, design: HandDesign) -> dict:
    """One output row: the FEM state and eqs. (28), (2) at the same pressure."""
    theta_red = float(hand.bend_angle(state.P, design, reservoir=False)) if state.P > 0 else 0.0
    dQ_red = float(reduced_finger.Q(state.theta, design) - reduced_finger.Q(0.0, design)) / design.n
    return {
        "P_cavity_MPa": state.P,
        "theta_deg": math.degrees(state.theta),
        "hinge_deg": [round(math.degrees(q), 4) for q in state.q],
        "dQ_mm3": state.dQ,
        "radial_stretch_max": state.radial_stretch_max,
        "radial_stretch_q99": state.radial_stretch_q99,
        "radial_stretch": state.radial_stretch,
        "rubber_stretch": state.rubber_stretch,
        "max_principal_stretch": state.max_principal_stretch,
        "theta_reduced_deg": math.degrees(theta_red),
        "dQ_reduced_mm3": dQ_red,
        "max_von_mises_MPa": state.max_von_mises,
        "newton_iterations": state.iterations,
    }


def run(study: BendingStudy, *, on_state=None, model: FingerModel | None = None) -> BendingResult:
    """Run the bending study; ``on_state(model, state)`` after each converged pressure.
    ``model``: the study's finger FEM if already built (its mesh checked before outputs are touched)."""
    t0 = time.perf_counter()
    model = FingerModel(study.design, study.options) if model is None else model
    build = time.perf_counter() - t0
    callback = None if on_state is None else (lambda s: on_state(model, s))
    states, stats = solve_pressures(model, study.pressures_mpa, callback=callback)
    peak = _peak(model, study, states[-1], on_state) if study.peak_mpa else None
    rows = [row(s, study.design) for s in states]
    hand_result = None
    if study.hand:
        from softhand.studies.compare import whole_hand

        hand_result = whole_hand(rows, study.design)
    return BendingResult(rows, peak, model.ndofs, model.mesh.nelements, stats, build, model,
                         states, hand_result)


def vtk_writer(path, then=None):
    """An ``on_state`` callback for :func:`run` that adds each converged state to the VTK scene
    series at ``path`` (finger.pvd: tube, links, hinges per pressure), then calls
    ``then(model, state)``. Its ``write(model, y, P)`` adds any other state."""
    from softhand.fem.hand.scene import finger_scene
    from softhand.fem.io import SceneSeries

    series = SceneSeries(path)

    def write(model, y, P):
        series.write(P, *finger_scene(model, y, P))

    def on_state(model, state):
        write(model, state.y, state.P)
        if then is not None:
            then(model, state)

    on_state.write = write
    return on_state


def _peak(model: FingerModel, study: BendingStudy, start: FingerState, on_state) -> dict:
    """Continue from ``start`` to peak_mpa; the last converged state if Newton gives up."""
    P_last = start.P
    n = max(1, math.ceil((study.peak_mpa - P_last) / study.peak_step_mpa - 1e-9))
    reached = [start]

    def keep(state):
        reached.append(state)
        if on_state is not None:
            on_state(model, state)

    failure = None
    try:
        solve_pressures(model, np.linspace(P_last, study.peak_mpa, n + 1)[1:], y0=start.y,
                        callback=keep)
    except NotConverged as exc:
        failure = str(exc).split(";")[0]
    s = reached[-1]
    return {"P_cavity_MPa": s.P, "theta_deg": math.degrees(s.theta),
            "rubber_stretch": s.rubber_stretch, "max_principal_stretch": s.max_principal_stretch,
            "max_von_mises_MPa": s.max_von_mises, "radial_stretch": s.radial_stretch,
            "radial_stretch_max": s.radial_stretch_max,
            "max_fiber_stress_MPa": s.max_fiber_stress, "target_P_cavity_MPa": study.peak_mpa,
            "failure": failure}
