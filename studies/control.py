"""The control study: angle control (eqs. (30), (31)) against pressure control under a push.

:func:`run` simulates the hand (:mod:`softhand.reduced.dynamics.plant`) holding the object under angle control
to ``theta_ref`` with a push on the object, then under pressure control at the pressure angle
control held just before the push (:func:`softhand.reduced.dynamics.control.flexibility`), and returns a
:class:`ControlResult` that summarises (both runs, Table II's three states, the gains, the
plant), writes (the time series at the sensor rate and summary.json) and plots (Fig. 10)
itself. ``softhand control``, the batch kind ``control`` and the ``table2_control`` and
``fig10_control`` sections of ``softhand reproduce`` only choose the inputs.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path

from softhand.reduced.equations import grasp
from softhand.reduced.dynamics.control import FlexibilityResult, flexibility, ramp
from softhand.reduced.dynamics.controllers import Gains, default_gains
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.dynamics.plant import HandTables, PlantParams, Push

#: the files :meth:`ControlResult.write` writes
FILES = ("control_angle.csv", "control_pressure.csv", "summary.json")


@dataclass(frozen=True)
class ControlStudy:
    """The hand, the object, the push, the controller and the plant of one experiment."""

    design: HandDesign = field(default_factory=HandDesign)  #: the controller's model of the hand
    theta_ref: float = math.radians(50.0)  #: reference mean bend angle [rad]
    mass_kg: float = 2.0                   #: the grasped object [kg]
    diameter_mm: float = 180.0             #: picks the paper's weight vector w (180 or 240)
    push_n: float = 5.0                    #: push force [N] of the ramp
    push_at_s: float = 5.0                 #: push start [s]
    push_rise_s: float = 0.5               #: time the push takes to build up [s]
    disturbance: str | None = None         #: a push profile file t_s,force_N instead of the ramp
    push: Push = field(default_factory=Push)  #: its direction
    kp: float | None = None                #: proportional gain [MPa/rad]; None: from the plant
    ki: float | None = None                #: integral gain [MPa/(rad s)]; None: from the plant
    anti_windup: bool = True
    plant: PlantParams = field(default_factory=PlantParams)
    plant_mu_scale: float = 1.0            #: the simulated hand's mu_sf, mu_sr relative to the design's
    t_end_s: float = 10.0                  #: simulated time [s]

    def weights(self):
        """The paper's w for the diameter, as printed (its 180 mm w sums to 1.40: reported)."""
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", grasp.WeightSumWarning)
            return grasp.weights_for_diameter(self.diameter_mm, self.design)

    def force(self):
        """The push [N] as a function of t [s]: the ramp, or the disturbance file's profile."""
        if self.disturbance is None:
            return ramp(self.push_n, self.push_at_s, self.push_rise_s)
        from softhand.studies.io.control_files import read_disturbance

        return read_disturbance(self.disturbance, t_end=self.t_end_s)

    def gains(self, w) -> Gains:
        """kp, ki as given, the missing ones from the plant (:func:`softhand.reduced.dynamics.controllers.default_gains`)."""
        g = default_gains(HandTables(self.design, w), self.plant)
        return Gains(g.kp if self.kp is None else self.kp, g.ki if self.ki is None else self.ki,
                     anti_windup=self.anti_windup)

    def push_source(self) -> str:
        return self.disturbance or f"{self.push_n:g} N at {self.push_at_s:g} s, rise {self.push_rise_s:g} s"


@dataclass(frozen=True)
class ControlResult:
    study: ControlStudy
    flex: FlexibilityResult = field(repr=False)  #: both simulations, their summaries, Table II
    gains: Gains
    w: tuple  #: the weight vector used

    @property
    def rows(self) -> list:
        """Table II's three states (empty without a push), with the paper's numbers."""
        return self.flex.rows

    def summary(self, mode: str = "angle") -> dict:
        """The ``mode`` run's summary first, the other's, Table II, gains, plant, push, w, design
        (``softhand control --json``; summary.json)."""
        chosen, other = (self.flex.angle_summary, self.flex.pressure_summary) if mode == "angle" \
            else (self.flex.pressure_summary, self.flex.angle_summary)
        s = self.study
        return {"mode": mode, "summary": summary_dict(chosen), "other_mode": summary_dict(other),
                "table2": self.rows,
                "gains": {"kp_MPa_per_deg": math.radians(self.gains.kp),
                          "ki_MPa_per_deg_s": math.radians(self.gains.ki), "anti_windup": self.gains.anti_windup},
                "plant": {k: getattr(s.plant, k) for k in PlantParams.__dataclass_fields__},
                "push": {"azimuth_deg": math.degrees(s.push.azimuth), "elevation_deg": math.degrees(s.push.elevation),
                         "source": s.push_source()},
                "w": [float(x) for x in self.w], "design": s.design.to_dict()}

    def series(self, mode: str = "angle") -> list[dict]:
        """The ``mode`` run's time series at the sensor rate (one dict per sample)."""
        from softhand.studies.io.control_files import series_rows

        return series_rows(self.flex.angle if mode == "angle" else self.flex.pressure,
                           self.study.plant.steps_per_sample)

    def write(self, out, mode: str = "angle") -> list[str]:
        """control_angle.csv, control_pressure.csv (:meth:`series`) and summary.json
        (:meth:`summary`) into the folder ``out``; the names written."""
        from softhand.studies.io.files import write_csv, write_json

        out = Path(out)
        write_csv(out / FILES[0], self.series("angle"))
        write_csv(out / FILES[1], self.series("pressure"))
        write_json(out / FILES[2], self.summary(mode))
        return list(FILES)

    def plot(self, path, mode: str = "angle") -> None:
        """Fig. 10 (c), (d) analogue (:func:`softhand.studies.io.control_files.plot_fig10`)."""
        from softhand.studies.io.control_files import plot_fig10

        plot_fig10(path, self.flex, mode, math.degrees(self.study.theta_ref))


def summary_dict(s) -> dict:
    """A run's summary in edge units; nan (not applicable, e.g. no push) becomes None (JSON null)."""
    deg = math.degrees
    return {key: None if isinstance(value, float) and math.isnan(value) else value for key, value in {
        "mode": s.mode, "settling_time_s": s.settling_time, "theta_error_deg": deg(s.theta_error),
        "P_error_MPa": s.P_error, "P_before_MPa": s.P_before, "theta_before_deg": deg(s.theta_before),
        "P_during_MPa": s.P_during, "theta_during_deg": deg(s.theta_during),
        "fingers_during_deg": [deg(x) for x in s.fingers_during],
        "push_start_s": s.push_start, "push_end_s": s.push_end}.items()}


def run(study: ControlStudy) -> ControlResult:
    """Angle control with the push, then pressure control (:func:`softhand.reduced.dynamics.control.flexibility`)."""
    w = study.weights()
    gains = study.gains(w)
    plant_design = study.design.replace(mu_sf=study.plant_mu_scale * study.design.mu_sf,
                                        mu_sr=study.plant_mu_scale * study.design.mu_sr)
    flex = flexibility(study.design, study.theta_ref, study.mass_kg, w, study.force(), push=study.push,
                       gains=gains, plant=study.plant, plant_design=plant_design, t_end=study.t_end_s)
    return ControlResult(study, flex, gains, tuple(float(x) for x in w))
