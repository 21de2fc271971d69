"""One design's calibrated finger as curves of theta: cubic Hermite P(theta) and Delta Q(theta)
on 0.5 deg knots, and W_f(theta) = int P dQ exactly (so P dQ/dtheta = dW_f/dtheta to rounding).

dW_f/dtheta is defined as P dQ/dtheta, a quintic per piece, and W_f as its integral by the
3-point Gauss rule per piece, which is exact for it. Units: MPa, mm^3, N mm, rad.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["KNOTS", "Hermite", "Curves", "energy_curves"]

#: the knots: 0.5 deg over the hand's THETA_RANGE
KNOTS = np.linspace(-0.5 * math.pi, math.pi, 541)
_KNOTS = KNOTS


class Hermite:
    """Cubic Hermite interpolant on the uniform knots ``_KNOTS`` of values f and slopes m
    (the end pieces continue as polynomials); NumPy only, so ``softhand curve`` starts fast."""

    def __init__(self, f: np.ndarray, m: np.ndarray):
        self.f, self.m = f, m
        self.x0, self.h = float(_KNOTS[0]), float(_KNOTS[1] - _KNOTS[0])

    def _locate(self, t):
        t = np.asarray(t, float)
        i = np.minimum(np.maximum(np.floor((t - self.x0) / self.h).astype(int), 0), self.f.size - 2)
        return i, (t - self.x0) / self.h - i

    def __call__(self, t):
        i, s = self._locate(t)
        s2, s3 = s**2, s**3
        h00, h10, h01, h11 = 2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s, 3 * s2 - 2 * s3, s3 - s2
        return h00 * self.f[i] + self.h * (h10 * self.m[i] + h11 * self.m[i + 1]) + h01 * self.f[i + 1]

    def derivative(self, t):
        i, s = self._locate(t)
        s2 = s**2
        d00, d10, d11 = 6 * s2 - 6 * s, 3 * s2 - 4 * s + 1, 3 * s2 - 2 * s
        return d00 * (self.f[i] - self.f[i + 1]) / self.h + d10 * self.m[i] + d11 * self.m[i + 1]


#: 3-point Gauss-Legendre rule on [0, 1]: exact for the quintic P dQ/dtheta of one piece
_GAUSS_X = 0.5 + 0.5 * np.sqrt(0.6) * np.array([-1.0, 0.0, 1.0])
_GAUSS_W = np.array([5.0, 8.0, 5.0]) / 18.0


@dataclass(frozen=True, eq=False)
class Curves:
    """One design's calibrated finger: Hermite cubics of P and Delta Q; W_f = int P dQ exactly."""

    P: Hermite  #: pressure of the free finger [MPa]
    dQ: Hermite  #: Delta Q = Q - Q(0) of one finger [mm^3]
    W_knots: np.ndarray  #: W_f at the knots [N mm], W_f(0) = 0
    Q0: float  #: Q(0) = a^2 pi l0 [mm^3]

    def energy_rate(self, t):
        """dW_f/dtheta = P dQ/dtheta [N mm/rad] (a quintic per piece)."""
        return self.P(t) * self.dQ.derivative(t)

    def energy(self, t):
        """W_f [N mm]: the knot value plus the 3-point Gauss integral from the piece's start."""
        t = np.asarray(t, float)
        i, _ = self.P._locate(t)
        start = _KNOTS[i]
        span = t - start
        tau = start[..., None] + span[..., None] * _GAUSS_X
        return self.W_knots[i] + span * (self.energy_rate(tau) @ _GAUSS_W)


def _with_slopes(fn) -> tuple[Hermite, ...]:
    """Hermite interpolants of each output of fn at the knots (fn evaluated three times), slopes
    by central differences (h = 1e-6 rad)."""
    h = 1e-6
    at, up, down = fn(_KNOTS), fn(_KNOTS + h), fn(_KNOTS - h)
    return tuple(Hermite(f, (u - d) / (2 * h)) for f, u, d in zip(at, up, down))


def energy_curves(pressure_and_oil, Q0: float) -> Curves:
    """Curves of (P [MPa], Delta Q [mm^3]) = pressure_and_oil(theta) (a vectorised callable),
    W_f(0) = 0; Q0 = Q(0) [mm^3]."""
    P, dQ = _with_slopes(pressure_and_oil)
    pieces = np.empty(_KNOTS.size)
    pieces[0] = 0.0
    tau = _KNOTS[:-1, None] + (_KNOTS[1] - _KNOTS[0]) * _GAUSS_X
    pieces[1:] = (_KNOTS[1] - _KNOTS[0]) * (P(tau) * dQ.derivative(tau)) @ _GAUSS_W
    W = np.cumsum(pieces)
    W -= W[np.argmin(np.abs(_KNOTS))]  # theta = 0 is a knot
    return Curves(P, dQ, W, Q0)
