r"""A simulated hydraulic hand: one pump, one reservoir, n fingers with their own loads.

The plant the angle controller of :mod:`softhand.reduced.dynamics.control` runs on. Its statics are the
reduced model's (eqs. (25), (27), (28)); its dynamics are the simplest ones consistent
with them. Nothing here is in the paper except the statics; every other number is a
documented parameter of :class:`PlantParams`.

Statics, finger by finger. Eq. (25) is the hand's virtual-work balance. With the
reservoir term written as its gauge pressure (``mu_sr zeta_r = -n a^2 pi d p_r(V)``,
:mod:`softhand.reduced.equations.hand`) it splits into one balance per finger j, all fingers sharing the
finger-side pressure p_f = P + p_r(V) behind the pump:

.. math:: a^2\pi d\,(P + p_r(V)) + F_{x,j} J_x\mathbf w + F_{y,j} J_y\mathbf w
          = \mu_{sf}\zeta_f(\theta_j),
          \qquad V = V_0 - a^2\pi d\sum_j\theta_j   \quad (15)

Summed over j with equal loads F_y = mg/n this is (25) again. Solved for the pressure,
finger j is in equilibrium when P + p_r(V) equals its *static pressure*

.. math:: p^s_j(\theta_j) = p_{28}(\theta_j) - \frac{F_{x,j}J_x\mathbf w + F_{y,j}J_y\mathbf w}{a^2\pi d},

with p_28 the no-reservoir pressure (28) of :func:`softhand.reduced.equations.hand.finger_pressure`.

Dynamics. The pump, with its own pressure regulation, sets the differential pressure P
between the finger line and the reservoir; the motor makes it a first-order lag
(time constant ``tau_m``) behind the command, clipped to [P_min, P_max]. Oil reaches
finger j through a linear flow resistance, so its angle is a first-order lag towards the
statics:

.. math:: \dot\theta_j = \frac{P + p_r(V) - p^s_j(\theta_j)}{\bar k\,\tau_f},
          \qquad q = a^2\pi d\sum_j\dot\theta_j, \qquad \dot V = -q,

with k_bar the mean slope of (28) over 0..90 deg, so ``tau_f`` is the fingers' time
constant at that stiffness. The pump cannot move more than ``q_max``: if the flow the
fingers ask for exceeds it, the line pressure is the one that passes exactly +-q_max
(``P + p_r = mean_j p^s_j +- q_max k_bar tau_f / (n a^2 pi d)``) and the motor's pressure
follows it. The oil volume V + Q(theta) is conserved (the same flow leaves the reservoir
and enters the fingers).

The push. An external force F(t) [N] on the object, of direction ``azimuth`` (measured
from finger 1's outward direction, about the hand's vertical axis) and ``elevation``
(below the horizontal; 90 deg = straight down, with gravity). The object rests in the
fingers without squeeze (F_x = 0, F_y = mg/n, eq. (24)) before the push. The vertical
part is shared equally, like the weight: F_y,j = (mg + F sin(elevation)) / n. The
horizontal part presses the object against the fingers it points to: it is split,
non-negatively, onto the outward directions of the two fingers that bracket its azimuth
(fingers sit at azimuths 2 pi j / n) and acts on them as an outward tip force F_x,j
(the sign convention of :mod:`softhand.reduced.equations.grasp`: the object pushes the pad outward). The
other fingers feel no horizontal force (frictionless contact, no adhesion). So a
horizontal push bends the fingers unequally.

Another finger model (``design.finger_model``, :mod:`softhand.reduced.equations.finger`) replaces a^2 pi d by
that finger's dQ/dtheta at theta_j and a^2 pi d theta_j by its Q(theta_j) - Q(0) throughout.

Sensors. Angles and pressure are sampled every ``1 / sample_hz`` s (zero-order hold to
the controller), with optional Gaussian noise.

Numerics. p_28, J_x w, J_y w (per angle) and p_r (per volume) are tabulated once per
(design, w) and linearly interpolated; explicit Euler at ``dt``, the lag being far slower
than dt for the defaults (dt / tau_f = 1/200).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from softhand.reduced.equations import finger, hand, reservoir
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.equations.grasp import PAPER_WEIGHTS, projected_jacobian

#: angles the tables cover [rad]; a loaded finger may open past 0
TABLE_RANGE = (math.radians(-45.0), math.radians(150.0))
TABLE_SIZE = 3901  #: 0.05 deg spacing: linear interpolation error ~ h^2/8 p'' < 1e-6 MPa


@dataclass(frozen=True)
class PlantParams:
    """Dynamics, limits and sensors of the simulated hand (none of these is in the paper)."""

    tau_f: float = 0.2  #: finger lag at the mean stiffness of (28) [s]
    tau_m: float = 0.05  #: pump motor (pressure) time constant [s]
    q_max: float = 2000.0  #: pump flow limit [mm^3/s]
    P_max: float = 2.0  #: largest differential pressure [MPa] (the fingers were tested to 2.0)
    P_min: float = -0.5  #: smallest (most negative) differential pressure [MPa]
    dt: float = 1e-3  #: integration step [s]
    sample_hz: float = 100.0  #: sensor and controller rate [1/s]
    noise_theta: float = 0.0  #: standard deviation of the angle sensors [rad]
    noise_P: float = 0.0  #: standard deviation of the pressure sensor [MPa]
    seed: int = 0  #: of the sensor noise

    def __post_init__(self):
        for name in ("tau_f", "tau_m", "q_max", "dt", "sample_hz"):
            if not getattr(self, name) > 0:
                raise InputError(name, getattr(self, name), "must be positive")
        if self.dt > 0.1 * self.tau_f:  # explicit Euler on the finger lag: keep dt/tau small
            raise InputError("tau_f", self.tau_f, f"must be at least 10 dt = {10 * self.dt:g} s")
        if not self.P_min < self.P_max:
            raise InputError("P_max", self.P_max, f"must exceed P_min = {self.P_min}")
        if self.noise_theta < 0 or self.noise_P < 0:
            raise InputError("noise", (self.noise_theta, self.noise_P), "must be >= 0")

    @property
    def steps_per_sample(self) -> int:
        """Integration steps between two sensor samples (at least 1)."""
        return max(1, round(1.0 / (self.sample_hz * self.dt)))


@dataclass(frozen=True)
class Push:
    """Direction of the external force on the object (its magnitude comes over time)."""

    azimuth: float = 0.0  #: from finger 1's outward direction about the vertical axis [rad]
    elevation: float = 0.0  #: below the horizontal [rad]; pi/2 = straight down

    def shares(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """(sx, sy), shape (n,): a push of F [N] adds F*sx_j to F_x,j and F*sy_j to F_y,j."""
        sy = np.full(n, math.sin(self.elevation) / n)
        horizontal = math.cos(self.elevation)
        sx = np.zeros(n)
        if abs(horizontal) < 1e-12:
            return sx, sy
        if n < 3:
            raise InputError("push_azimuth_deg", math.degrees(self.azimuth),
                             f"a horizontal push needs n >= 3 fingers around the object (n = {n})")
        spacing = 2.0 * math.pi / n
        alpha = self.azimuth % (2.0 * math.pi)
        k = int(alpha // spacing) % n
        beta = alpha - k * spacing  # in [0, spacing): between finger k and finger k+1
        # e_alpha = a e_k + b e_{k+1}, a, b >= 0 (sine rule)
        sx[k] = horizontal * math.sin(spacing - beta) / math.sin(spacing)
        sx[(k + 1) % n] += horizontal * math.sin(beta) / math.sin(spacing)
        return sx, sy


class HandTables:
    """The plant's statics tabulated once: p_28, J_x w, J_y w over theta; p_r over V."""

    def __init__(self, design: HandDesign, w=PAPER_WEIGHTS[180]):
        self.design = design
        self.w = np.asarray(w, dtype=float)
        self.theta = np.linspace(*TABLE_RANGE, TABLE_SIZE)
        self.p28 = hand.finger_pressure(self.theta, design)
        self.jxw, self.jyw = projected_jacobian(self.theta, self.w, design)
        self.area = design.a**2 * math.pi * design.d  #: a^2 pi d [mm^2]: dQ/dtheta of one finger (2)
        #: dQ/dtheta and Q - Q(0) of one finger on the table (the finger model's; eq. (2) for "paper")
        self.rate, self.taken = (finger.volume_rate(self.theta, design), finger.oil_taken(self.theta, design))
        self.uniform = design.finger_model == "paper"  #: dQ/dtheta = a^2 pi d for every angle
        span = self.area * design.n * np.array(TABLE_RANGE) if self.uniform else \
            design.n * finger.oil_taken(np.array(TABLE_RANGE), design)
        self.V = np.linspace(design.V0 - span[1], design.V0 - span[0], TABLE_SIZE)
        if self.V[0] <= 0:  # the fingers can take all the oil: keep the table where V > 0
            self.V = np.linspace(1e-3 * design.V0, self.V[-1], TABLE_SIZE)
        self.p_r = reservoir.pressure(self.V, design)
        quarter = np.interp([0.0, math.pi / 2], self.theta, self.p28)
        self.k_bar = float(quarter[1] - quarter[0]) / (math.pi / 2)  #: mean slope of (28) [MPa/rad]

    def static_pressure(self, theta, F_x, F_y):
        """p^s_j [MPa]: finger-side pressure holding angle theta_j [rad] under tip load (F_x, F_y) [N]."""
        p = np.interp(theta, self.theta, self.p28)
        jx = np.interp(theta, self.theta, self.jxw)
        jy = np.interp(theta, self.theta, self.jyw)
        return p - (F_x * jx + F_y * jy) / self.volume_rate(theta)

    def reservoir_pressure(self, V):
        """p_r(V) [MPa] from the table."""
        return np.interp(V, self.V, self.p_r)

    def volume_rate(self, theta):
        """dQ/dtheta of each finger at its angle [mm^3/rad]; the scalar a^2 pi d for the paper's model."""
        return self.area if self.uniform else np.interp(theta, self.theta, self.rate)

    def volume(self, theta):
        """Eq. (15) with unequal fingers (n,) [rad]: V = V0 - a^2 pi d sum_j theta_j [mm^3];
        V0 - sum_j (Q(theta_j) - Q(0)) for another finger model."""
        if self.uniform:
            return self.design.V0 - self.area * np.sum(theta)
        return self.design.V0 - np.sum(np.interp(theta, self.theta, self.taken))

    @cached_property
    def slopes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """d/dtheta of p28, jxw, jyw and d p_r / dV on the tables (central differences)."""
        return (np.gradient(self.p28, self.theta), np.gradient(self.jxw, self.theta),
                np.gradient(self.jyw, self.theta), np.gradient(self.p_r, self.V))

    def check(self, theta) -> None:
        """InputError if an angle left the tabulated range (the plant left the model)."""
        lo, hi = TABLE_RANGE
        if np.any(theta < lo) or np.any(theta > hi) or not np.all(np.isfinite(theta)):
            raise InputError("theta_deg", np.degrees(theta).round(1).tolist(),
                             f"a finger left the modelled range [{math.degrees(lo):.0f}, "
                             f"{math.degrees(hi):.0f}] deg; lower the load or the push")


def equilibrium(P, F_x, F_y, tables: HandTables, theta0=None, *, tol=1e-10, max_iter=50):
    """Static angles theta_j [rad] (n,) at pump pressure P [MPa] under tip loads F_x, F_y (n,) [N].

    Newton on the n per-finger balances coupled through the reservoir volume; raises
    InputError when it does not converge (a load the fingers cannot hold).
    """
    d = tables.design
    F_x, F_y = np.broadcast_to(F_x, (d.n,)), np.broadcast_to(F_y, (d.n,))
    theta = np.full(d.n, 0.5) if theta0 is None else np.array(theta0, float)
    dp28, djx, djy, dpr = tables.slopes
    for _ in range(max_iter):
        V = tables.volume(theta)
        r = P - reservoir.pump_pressure(tables.static_pressure(theta, F_x, F_y), V, d, tables.reservoir_pressure)
        if np.max(np.abs(r)) < tol:
            return theta
        ks = (np.interp(theta, tables.theta, dp28)
              - (F_x * np.interp(theta, tables.theta, djx)
                 + F_y * np.interp(theta, tables.theta, djy)) / tables.volume_rate(theta))
        J = -np.diag(ks) - np.interp(V, tables.V, dpr) * tables.volume_rate(theta)
        theta = theta - np.linalg.solve(J, r)
        tables.check(theta)
    raise InputError("equilibrium", float(P), f"no static state found (residual {np.max(np.abs(r)):.2e} MPa)")
