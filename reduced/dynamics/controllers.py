"""The controllers of the hand's pump (see :mod:`softhand.reduced.dynamics.control`, which runs them on the plant).

:class:`AngleController` is the 2-DOF angle controller of eqs. (30), (31): feedforward
f(theta_ref) (eq. (27) of the nominal design) + PI on the mean finger angle, with anti-windup
by conditional integration; :class:`PressureController` holds a constant pressure; their
call ``controller(theta_meas, P_meas, flow_limit) -> P_ref`` is what the simulation samples.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softhand.reduced.equations import hand
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.dynamics.plant import HandTables, PlantParams

__all__ = ["Gains", "default_gains", "AngleController", "PressureController"]


@dataclass(frozen=True)
class Gains:
    """PI gains of eq. (30) on the mean angle."""

    kp: float  #: proportional gain [MPa/rad]
    ki: float  #: integral gain [MPa/(rad s)]
    anti_windup: bool = True  #: conditional integration while the pump saturates


def default_gains(tables: HandTables, plant: PlantParams, closed_loop_time: float = 0.5) -> Gains:
    """PI by pole-zero cancellation on the plant's lag: T_i = tau_f, closed-loop time constant T.

    The loop P -> mean theta is, linearised, a gain 1/k_bar with the lag tau_f; PI with
    ki/kp = 1/tau_f cancels the lag and leaves a first-order loop of time constant
    k_bar tau_f / kp = T. A design rule from the plant, not a fit to any measurement.
    """
    kp = tables.k_bar * plant.tau_f / closed_loop_time
    return Gains(kp=kp, ki=kp / plant.tau_f)


class AngleController:
    """Eqs. (30), (31): P_ref from the measured angles; call it once per sample."""

    def __init__(self, theta_ref: float, gains: Gains, design: HandDesign, plant: PlantParams,
                 *, feedforward: bool = True):
        self.theta_ref = float(theta_ref)
        self.gains = gains
        self.P_ff = float(hand.pressure(theta_ref, design)) if feedforward else 0.0
        self.limits = (plant.P_min, plant.P_max)
        self.Ts = plant.steps_per_sample * plant.dt
        self.integral = 0.0  #: K_i * int theta_e dt [MPa]

    def __call__(self, theta_meas: np.ndarray, P_meas: float, flow_limit: int) -> float:
        """P_ref [MPa]; ``flow_limit`` is +1/-1 while the pump is at +-q_max, else 0."""
        e = self.theta_ref - float(np.mean(theta_meas))
        raw = self.P_ff + self.gains.kp * e + self.integral
        P_ref = min(max(raw, self.limits[0]), self.limits[1])
        pushing = (raw > self.limits[1] and e > 0) or (raw < self.limits[0] and e < 0) \
            or flow_limit * e > 0
        if not (self.gains.anti_windup and pushing):
            self.integral += self.gains.ki * e * self.Ts
        return P_ref


class PressureController:
    """Pressure control: a constant P_ref [MPa], clipped to the pump's range."""

    def __init__(self, P_ref: float, plant: PlantParams):
        self.P_ref = min(max(float(P_ref), plant.P_min), plant.P_max)

    def __call__(self, theta_meas, P_meas, flow_limit) -> float:
        return self.P_ref
