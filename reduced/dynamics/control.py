r"""Running the hand under control: the 2-DOF angle controller (eqs. (30), (31)) or pressure
control (:mod:`softhand.reduced.dynamics.controllers`) on the plant, the runs' numbers, and the flexibility test.

Angle control (Fig. 9). All fingers hang on one pump, so the controlled variable is the
mean finger angle; the pump pressure command is

.. math:: P_{ref} = f(\theta_{ref}) + K_p\theta_e + K_i\int\theta_e\,dt, \qquad
          \theta_e = \theta_{ref} - \frac1n\sum_{j=1}^n\theta_j   \quad (30), (31)

with the feedforward f = eq. (27) of the *nominal* design (:func:`softhand.reduced.equations.hand.pressure`),
evaluated once. It runs at the sensor rate with the integral as a forward-Euler sum. Anti-
windup by conditional integration (clamping): the integral is frozen while P_ref is clipped
to the pump's range [P_min, P_max], or while the pump is at its flow limit, whenever the
error would drive the output further into that limit.

Pressure control holds a constant P_ref: the pump's own regulation does the rest.

Flexibility (Table II). Three states, the grasping force F_v estimated in each as the paper
does, from a pressure and the mean angle by (25) with F_y = mg/n and (29)
(:func:`softhand.reduced.equations.grasp.grasp_forces`):

* (a) angle control, no push: P_a, theta_a, the mean over the last ``window`` s before it;
* (b) pressure control holding P_a, push: P_b, theta_b, the last ``window`` s of the push;
* (c) angle control, push: P_c, theta_c, the same window.

Unlike the paper, which assumed theta in (b) equal to the one it measured in (c), state (b)
is simulated with its own run. The plant's actual tip loads are reported next to the
estimate (the estimate attributes every load to F_x).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from softhand.reduced.dynamics.controllers import AngleController, Gains, PressureController, default_gains
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.equations.grasp import grasp_forces
from softhand.reduced.vocabulary.paper import TABLE_II as PAPER_TABLE_II
from softhand.reduced.dynamics.plant import HandTables, PlantParams, Push, equilibrium
from softhand.reduced.equations.reservoir import pump_pressure

__all__ = ["Gains", "default_gains", "AngleController", "PressureController", "Simulation",
           "initial_state", "simulate", "Summary", "ramp", "push_interval", "summarize",
           "pad_force", "FlexibilityResult", "flexibility"]



@dataclass(frozen=True)
class Simulation:
    """Time series of one run; row k is the state at t[k] and the pressure during the step."""

    t: np.ndarray  #: time [s], (N,)
    theta: np.ndarray  #: finger angles [rad], (N, n)
    P: np.ndarray  #: pump differential pressure [MPa], (N,)
    P_ref: np.ndarray  #: controller output (held between samples) [MPa], (N,)
    V: np.ndarray  #: oil in the reservoir [mm^3], (N,)
    force: np.ndarray  #: push magnitude [N], (N,)
    F_x: np.ndarray  #: tip load of each finger, outward [N], (N, n)
    F_y: np.ndarray  #: tip load of each finger, weight and push [N], (N, n)
    flow_limit: np.ndarray  #: +1/-1 while the pump is at +-q_max, (N,)

    @property
    def theta_mean(self) -> np.ndarray:
        """Eq. (31)'s mean angle [rad], (N,)."""
        return self.theta.mean(axis=1)


def initial_state(tables: HandTables, mass: float) -> np.ndarray:
    """Static angles at P = 0 with the object resting in the fingers [rad], (n,)."""
    d = tables.design
    return equilibrium(0.0, 0.0, mass * d.g / d.n, tables, theta0=np.zeros(d.n))


def simulate(controller, tables: HandTables, plant: PlantParams, *, mass: float,
             force: np.ndarray, push: Push = Push(), t_end: float = 10.0) -> Simulation:
    """Run ``controller`` on the plant for ``t_end`` s; ``force`` [N] per step, (N,) or callable of t.

    The push magnitude is shared among the fingers by ``push.shares(n) -> (sx, sy)``; any
    object with that method gives other per-finger loads. Explicit Euler at plant.dt; sensors
    and controller every plant.steps_per_sample steps.
    """
    d, dt = tables.design, plant.dt
    N = int(round(t_end / dt))
    t = np.arange(N) * dt
    force = np.asarray(force(t) if callable(force) else force, dtype=float)
    if force.shape != (N,):
        raise InputError("force", force.shape, f"must have one value per step ({N})")
    sx, sy = push.shares(d.n)
    F_x = np.multiply.outer(force, sx)
    F_y = mass * d.g / d.n + np.multiply.outer(force, sy)
    theta, P, P_ref, V, limit = _integrate(controller, tables, plant,
                                           initial_state(tables, mass), F_x, F_y)
    return Simulation(t=t, theta=theta, P=P, P_ref=P_ref, V=V, force=force,
                      F_x=F_x, F_y=F_y, flow_limit=limit)


def _integrate(controller, tables: HandTables, plant: PlantParams, theta, F_x, F_y):
    """The time loop (the only Python loop: the plant is sequential in time)."""
    d, dt, N = tables.design, plant.dt, F_x.shape[0]
    rng = np.random.default_rng(plant.seed)
    every = plant.steps_per_sample
    alpha = 1.0 - math.exp(-dt / plant.tau_m)
    ktau = tables.k_bar * plant.tau_f
    q_max = plant.q_max
    theta = np.array(theta, float)
    V = float(tables.volume(theta))
    Pm, P_cmd, limit = 0.0, 0.0, 0
    rec_theta, rec = np.empty((N, d.n)), np.empty((N, 4))
    lo, hi = tables.theta[0], tables.theta[-1]
    for k in range(N):
        if k % every == 0:
            if theta.min() < lo or theta.max() > hi:
                tables.check(theta)
            noise_t = rng.normal(0.0, plant.noise_theta, d.n) if plant.noise_theta else 0.0
            noise_P = rng.normal(0.0, plant.noise_P) if plant.noise_P else 0.0
            P_cmd = controller(theta + noise_t, Pm + noise_P, limit)
        Pm += alpha * (min(max(P_cmd, plant.P_min), plant.P_max) - Pm)
        p_r = float(tables.reservoir_pressure(V))
        ps = tables.static_pressure(theta, F_x[k], F_y[k])
        drive = Pm + p_r - ps
        rate = tables.volume_rate(theta)  # dQ/dtheta per finger: a scalar for the paper's model
        q = (rate * drive.sum() if np.ndim(rate) == 0 else rate @ drive) / ktau
        limit = 1 if q > q_max else (-1 if q < -q_max else 0)
        if limit:  # the line pressure p_f that passes exactly +-q_max
            p_f = (ps.mean() + limit * q_max * ktau / (d.n * rate) if np.ndim(rate) == 0
                   else (rate @ ps + limit * q_max * ktau) / rate.sum())
            Pm, drive, q = pump_pressure(p_f, V, d, tables.reservoir_pressure), p_f - ps, limit * q_max
        rec_theta[k] = theta
        rec[k] = Pm, P_cmd, V, limit
        theta = theta + (dt / ktau) * drive
        V -= dt * q
    tables.check(rec_theta[-1])
    return rec_theta, rec[:, 0], rec[:, 1], rec[:, 2], rec[:, 3].astype(int)


@dataclass(frozen=True)
class Summary:
    """Numbers of one run. Windows: the last ``window`` s before the push and of the push."""

    mode: str  #: "angle" or "pressure"
    settling_time: float  #: first time after which the controlled variable stays in its band [s]; nan: never
    theta_error: float  #: theta_ref - mean angle before the push [rad]
    P_error: float  #: P_ref - P before the push [MPa] (pressure control; nan for angle control)
    P_before: float  #: mean pressure before the push [MPa]
    theta_before: float  #: mean finger angle before the push [rad]
    P_during: float  #: mean pressure at the end of the full push [MPa]; nan without a push
    theta_during: float  #: mean finger angle at the end of the full push [rad]; nan without a push
    fingers_during: tuple  #: each finger's angle at the end of the full push [rad]
    push_start: float  #: first time the push is non-zero [s]; nan without a push
    push_end: float  #: end of the last stretch at the push's full magnitude [s]


def ramp(F: float, at: float, rise: float = 0.5, until: float = math.inf):
    """A push profile [N] of t [s]: 0 before ``at``, rising linearly to F over ``rise`` s, held
    until ``until``; rise = 0 is a step."""
    def profile(t):
        t = np.asarray(t, float)
        up = np.clip((t - at) / rise, 0.0, 1.0) if rise > 0 else (t >= at).astype(float)
        return np.where(t < until, F * up, 0.0)
    return profile


def push_interval(sim: Simulation) -> tuple[float, float]:
    """(start, end) [s]: the first non-zero push, and the end of the last stretch at its full
    magnitude (within 1 %), where "during the push" windows end; (nan, nan) without a push."""
    size = np.abs(sim.force)
    on = np.flatnonzero(size > 0.0)
    if on.size == 0:
        return math.nan, math.nan
    full = np.flatnonzero(size >= 0.99 * size.max())
    return float(sim.t[on[0]]), float(sim.t[full[-1]] + (sim.t[1] - sim.t[0]))


def _window(sim: Simulation, end: float, window: float) -> np.ndarray:
    """Boolean mask of the samples in [end - window, end)."""
    return (sim.t >= end - window) & (sim.t < end)


def _settling(t, y, target, band) -> float:
    outside = np.flatnonzero(np.abs(y - target) > band)
    if outside.size == 0:
        return float(t[0])
    return math.nan if outside[-1] == t.size - 1 else float(t[outside[-1] + 1])


def summarize(sim: Simulation, controller, *, window: float = 1.0,
              band_theta: float = math.radians(1.0), band_P: float = 0.01) -> Summary:
    """Settling time (band: +-1 deg or +-0.01 MPa), errors, pressure and angle before/during the push."""
    start, end = push_interval(sim)
    quiet_end = start if math.isfinite(start) else float(sim.t[-1] + sim.t[1] - sim.t[0])
    if quiet_end - window < sim.t[0] - 1e-12:
        raise InputError("push_start_s", start, f"must leave at least {window} s before the push")
    before, quiet = _window(sim, quiet_end, window), sim.t < quiet_end
    angle = isinstance(controller, AngleController)
    target = controller.theta_ref if angle else controller.P_ref
    y = sim.theta_mean if angle else sim.P
    settle = _settling(sim.t[quiet], y[quiet], target, band_theta if angle else band_P)
    during = _window(sim, end, min(window, end - start)) if math.isfinite(start) else None
    mean = lambda a, m: float(np.mean(a[m], axis=0)) if m is not None else math.nan  # noqa: E731
    return Summary(
        mode="angle" if angle else "pressure", settling_time=settle,
        theta_error=(controller.theta_ref if angle else math.nan) - mean(sim.theta_mean, before),
        P_error=math.nan if angle else controller.P_ref - mean(sim.P, before),
        P_before=mean(sim.P, before), theta_before=mean(sim.theta_mean, before),
        P_during=mean(sim.P, during), theta_during=mean(sim.theta_mean, during),
        fingers_during=tuple(np.mean(sim.theta[during], axis=0)) if during is not None else (),
        push_start=start, push_end=end)


def pad_force(F_x, F_y, theta, design: HandDesign):
    """Eq. (29) finger by finger: F_v = F_x cos(theta - theta0) + F_y sin(theta - theta0) [N]."""
    alpha = np.asarray(theta) - design.theta0
    return F_x * np.cos(alpha) + F_y * np.sin(alpha)


@dataclass(frozen=True)
class FlexibilityResult:
    """Table II by simulation: the two runs and the three states."""

    angle: Simulation
    pressure: Simulation
    angle_summary: Summary
    pressure_summary: Summary
    rows: list = field(default_factory=list)  #: one dict per state, with the paper's numbers


def flexibility(design: HandDesign, theta_ref: float, mass: float, w, force, *,
                push: Push = Push(), gains: Gains | None = None, plant: PlantParams = PlantParams(),
                plant_design: HandDesign | None = None, t_end: float = 10.0,
                window: float = 1.0) -> FlexibilityResult:
    """Angle control with the push, then pressure control at the pressure it held before the push.

    ``design`` is the controller's (feedforward, estimator); ``plant_design`` the simulated
    hand's (default: the same). ``force`` [N]: per step or a callable of t [s].
    """
    tables = HandTables(plant_design or design, w)
    gains = gains or default_gains(tables, plant)
    ctrl_a = AngleController(theta_ref, gains, design, plant)
    angle = simulate(ctrl_a, tables, plant, mass=mass, force=force, push=push, t_end=t_end)
    sum_a = summarize(angle, ctrl_a, window=window)
    ctrl_p = PressureController(sum_a.P_before, plant)
    pressure = simulate(ctrl_p, tables, plant, mass=mass, force=force, push=push, t_end=t_end)
    sum_p = summarize(pressure, ctrl_p, window=window)
    start, end = push_interval(angle)
    states = {"a_no_push": (angle, _window(angle, start, window)),
              "b_push_pressure_control": (pressure, _window(pressure, end, window)),
              "c_push_angle_control": (angle, _window(angle, end, window))}
    rows = [_state_row(name, sim, mask, mass, w, design) for name, (sim, mask) in states.items()] \
        if math.isfinite(start) else []
    return FlexibilityResult(angle, pressure, sum_a, sum_p, rows)


def _state_row(name: str, sim: Simulation, mask: np.ndarray, mass: float, w, design: HandDesign) -> dict:
    """One Table II state: window means, the paper's estimate of F_v, the plant's actual pad forces."""
    P, theta = float(np.mean(sim.P[mask])), float(np.mean(sim.theta_mean[mask]))
    estimate = float(grasp_forces(P, theta, mass, w, design).F_v)
    actual = np.mean(pad_force(sim.F_x[mask], sim.F_y[mask], sim.theta[mask], design), axis=0)
    row = {"state": name, "P_pump_MPa": P, "theta_deg": math.degrees(theta),
           "F_v_estimated_N": estimate, "F_v_estimated_kgf": estimate / design.g,
           "F_v_actual_mean_N": float(np.mean(actual)), "F_v_actual_max_N": float(np.max(actual))}
    if design != HandDesign():  # the paper's numbers are of its own hand only
        return row
    paper = PAPER_TABLE_II[name]
    return row | {"paper_P_pump_MPa": paper[0], "paper_theta_deg": paper[1], "paper_F_v_kgf": paper[2]}
