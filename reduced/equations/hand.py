r"""The hand without load: pump pressure P(theta) (27), (28) and its inverse theta(P).

Eq. (25) with F_x = F_y = 0 gives, for n fingers sharing one pump and one reservoir,

.. math:: P(\theta) = \frac{n\mu_{sf}\zeta_f(\theta) + \mu_{sr}\zeta_r(\theta)}{n a^2\pi d}
                    = \frac{\mu_{sf}\zeta_f(\theta)}{a^2\pi d} - p_r(V(\theta))   \quad (27)

since mu_sr zeta_r / (n a^2 pi d) = -p_r(V(theta)) (dV/dtheta = -n a^2 pi d); the second form
works for every reservoir model of :mod:`softhand.reduced.equations.reservoir`. Without reservoir (28) the last
term is absent. For any finger model of :mod:`softhand.reduced.equations.finger` (W_f, Q of one finger) the
same balance P n dQ/dtheta = d(n W_f + W_r)/dtheta reads P = (dW_f/dtheta)/(dQ/dtheta) -
p_r(V0 - n (Q(theta) - Q(0))); the paper's model gives (27), (28) as printed. P is the pump's differential pressure: with the reservoir P(0) < 0, i.e. at
zero pump pressure the charged sheet already bends the fingers a little (reported, not clipped).

The inverse theta(P) is found on the monotone branch of P(theta) through theta = 0 inside
:data:`THETA_RANGE`: a table of 1025 angles, cubic Hermite interpolation of the inverse
function (error ~1e-13 rad for the ellipse model), and vectorised chord-Newton steps on the
exact P until converged -- one step for a smooth P; a kinked reservoir model p_r(V) takes a
few more for the values near its kinks (no per-value root finder).
"""
from __future__ import annotations

import math

import numpy as np

from softhand.reduced.equations import finger
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.equations.reservoir import oil_volume, pump_pressure

#: bend angles the reduced model accepts [rad]: a finger bent back by 90 deg up to curled by 180 deg
THETA_RANGE = (-0.5 * math.pi, math.pi)
_TABLE_SIZE = 1025


def check_theta(theta) -> np.ndarray:
    """theta [rad] as a float array; InputError (in degrees) unless finite and in THETA_RANGE."""
    theta = np.asarray(theta, dtype=float)
    lo, hi = THETA_RANGE
    bad = ~np.isfinite(theta) | (theta < lo - 1e-12) | (theta > hi + 1e-12)
    if np.any(bad):
        raise InputError("theta_deg", float(np.degrees(theta[bad].flat[0])),
                         f"must be a number in [{math.degrees(lo):.0f}, {math.degrees(hi):.0f}] deg")
    return theta


def finger_pressure(theta, design: HandDesign):
    """Eq. (28): P = mu_sf zeta_f / (a^2 pi d) [MPa], the hand without reservoir, theta [rad];
    for another rubber mu_sf zeta_f is dW_f/dtheta (:func:`softhand.reduced.equations.finger.finger_force`); for any
    finger model P = (dW_f/dtheta) / (dQ/dtheta)."""
    if design.finger_model == "paper":  # as printed, bit for bit
        return finger.finger_force(theta, design) / (design.a**2 * math.pi * design.d)
    return finger.energy_rate(theta, design) / finger.volume_rate(theta, design)


def pressure(theta, design: HandDesign, reservoir: bool = True):
    """Eq. (27) (reservoir=True) or (28): pump pressure [MPa] holding bend theta [rad], free fingers."""
    theta = check_theta(theta)
    P = finger_pressure(theta, design)
    if reservoir:
        if theta.size:
            finger.check_volume(design, float(np.max(theta)))
        P = pump_pressure_at_bend(P, theta, design)
    return P


def pump_pressure_at_bend(P_cavity, theta, design: HandDesign, reservoir: bool = True):
    """The pump pressure [MPa] of the cavity pressure P_cavity [MPa] with the fingers at bend
    theta [rad]: :func:`softhand.reduced.equations.reservoir.pump_pressure` at the oil left (15); P_cavity itself
    without the reservoir."""
    if not reservoir:
        return P_cavity
    return pump_pressure(P_cavity, oil_volume(theta, design), design)


def bend_angle(P, design: HandDesign, reservoir: bool = True):
    """Inverse of :func:`pressure`: free bend theta [rad] at pump pressure P [MPa], vectorised."""
    return _invert_pressure(P, design, reservoir, _pressure_branch(design, reservoir))


def bend_angles(P, design: HandDesign) -> tuple[np.ndarray, np.ndarray]:
    """(theta with the reservoir, eq. (27); theta without, eq. (28)) [rad] at pump pressures P
    [MPa]; one InputError naming the pressures both answer for if P is outside them."""
    branches = [_pressure_branch(design, r) for r in (True, False)]
    lo, hi = max(b[1][0] for b in branches), min(b[1][-1] for b in branches)
    values = np.asarray(P, dtype=float)
    bad = ~np.isfinite(values) | (values < lo) | (values > hi)
    if np.any(bad):
        raise InputError("pressure_MPa", float(values[bad].flat[0]),
                         f"must be in [{lo:.4g}, {hi:.4g}] MPa (the pressures the hand reaches both "
                         f"with its reservoir, eq. (27), and without, eq. (28))")
    return tuple(_invert_pressure(P, design, r, b) for r, b in zip((True, False), branches))


def pressure_span(design: HandDesign, reservoir: bool = True) -> tuple[float, float]:
    """The pump pressures [MPa] :func:`bend_angle` answers for: the ends of the increasing
    branch of P(theta) through theta = 0."""
    _, fx, _ = _pressure_branch(design, reservoir)
    return float(fx[0]), float(fx[-1])


def _pressure_branch(design: HandDesign, reservoir: bool):
    """(theta, P, dP/dtheta) tabulated on the increasing branch of P(theta) through 0."""
    return monotone_branch(lambda th: pressure(th, design, reservoir), _bend_bracket(design, reservoir))


def _invert_pressure(P, design: HandDesign, reservoir: bool, branch):
    return invert_monotone(lambda th: pressure(th, design, reservoir), P, _bend_bracket(design, reservoir),
                           field="pressure_MPa", unit="MPa", branch=branch)


def _bend_bracket(design: HandDesign, reservoir: bool) -> tuple[float, float]:
    lo, hi = THETA_RANGE
    if reservoir:  # the fingers cannot take more oil than the reservoir holds
        hi = min(hi, volume_limit(design))
    return lo, hi


def volume_limit(design: HandDesign) -> float:
    """The bend [rad] at which the n fingers have taken 99.9 % of the reservoir's oil V0."""
    if design.finger_model == "paper":
        return 0.999 * design.V0 / (design.n * design.a**2 * math.pi * design.d)
    theta = np.linspace(0.0, THETA_RANGE[1], 4097)
    taken = design.n * finger.oil_taken(theta, design)  # increasing: dQ/dtheta > 0
    return float(np.interp(0.999 * design.V0, taken, theta)) if taken[-1] > 0.999 * design.V0 \
        else THETA_RANGE[1]


def monotone_branch(fn, bracket: tuple[float, float], anchor: float = 0.0, size: int = _TABLE_SIZE):
    """(x, fn(x), fn'(x)) on ``size`` points of ``bracket``, kept where fn increases around
    ``anchor`` (:func:`invert_monotone`'s table)."""
    return _increasing_run(*_table(fn, bracket, size), anchor)


def invert_monotone(fn, y, bracket: tuple[float, float], *, field: str, unit: str = "",
                    anchor: float = 0.0, size: int = _TABLE_SIZE, branch=None):
    """x with fn(x) = y on the increasing branch of the vectorised fn through ``anchor``.

    Tabulates fn on ``size`` points of ``bracket``, keeps the increasing run that holds
    ``anchor`` (or takes ``branch``, :func:`monotone_branch`'s table of the same), interpolates
    the inverse with cubic Hermite polynomials (slopes 1/fn' by central differences), then
    takes chord-Newton steps on fn until each step is below 1e-12 of the bracket (one step for
    a smooth fn). InputError for y off the branch.
    """
    y = np.asarray(y, dtype=float)
    shape = y.shape
    x, fx, slope = monotone_branch(fn, bracket, anchor, size) if branch is None else branch
    bad = ~np.isfinite(y) | (y < fx[0]) | (y > fx[-1])
    if np.any(bad):
        raise InputError(field, float(y[bad].flat[0]),
                         f"must be in [{fx[0]:.4g}, {fx[-1]:.4g}] {unit} "
                         f"(reached at {math.degrees(x[0]):.0f}..{math.degrees(x[-1]):.0f} deg)")
    y = y.ravel()
    guess, dxdy_at_y = _hermite_inverse(x, fx, slope, y)
    step = (fn(guess) - y) * dxdy_at_y                 # first step: every value at once
    root = np.clip(guess - step, x[0], x[-1])
    xtol = 1e-12 * (bracket[1] - bracket[0])
    todo = np.abs(step) > xtol
    if todo.any():                                      # kinked fn: iterate the few left
        dxdy = lambda value: _hermite_inverse(x, fx, slope, value)[1]  # noqa: E731
        root[todo] = _chord_newton(fn, y[todo], root[todo], dxdy, (x[0], x[-1]), xtol)
    return root.reshape(shape)


def _chord_newton(fn, y, x, dxdy, bounds, xtol, max_iter: int = 30):
    """Solve fn(x) = y (1-d) from x with the table's dx/dy; only unconverged values iterate."""
    todo = np.ones(y.shape, dtype=bool)
    for _ in range(max_iter):
        value = fn(x[todo])
        step = (value - y[todo]) * dxdy(value)
        x[todo] = np.clip(x[todo] - step, *bounds)
        todo[todo] = np.abs(step) > xtol
        if not todo.any():
            return x
    raise RuntimeError(f"inverse not converged for {todo.sum()} values after {max_iter} steps "
                       f"(first: {y[todo][0]!r})")


def _table(fn, bracket, size):
    """x, fn(x), fn'(x) on ``size`` points; slopes by central differences (one-sided at the ends)."""
    x = np.linspace(bracket[0], bracket[1], size)
    step = 1e-6 * (bracket[1] - bracket[0])
    points = x[:, None] + step * np.array([-1.0, 1.0])
    points[0], points[-1] = x[0] + step * np.array([1.0, 2.0]), x[-1] - step * np.array([1.0, 2.0])
    fx, near = fn(x), fn(points)
    slope = (near[:, 1] - near[:, 0]) / (2.0 * step)
    slope[0] = (4.0 * near[0, 0] - near[0, 1] - 3.0 * fx[0]) / (2.0 * step)
    slope[-1] = (3.0 * fx[-1] - 4.0 * near[-1, 0] + near[-1, 1]) / (2.0 * step)
    return x, fx, slope


def _increasing_run(x, fx, slope, anchor):
    """The longest stretch of the table around ``anchor`` where fx increases strictly."""
    rising = (np.diff(fx) > 0) & (slope[:-1] > 0) & (slope[1:] > 0)
    k = int(np.clip(np.searchsorted(x, anchor) - 1, 0, rising.size - 1))
    if not rising[k]:
        raise InputError("design", "P(theta)", f"is not increasing at {math.degrees(anchor):.0f} deg; "
                         "the bend angle is not unique")
    falls = np.flatnonzero(~rising)
    first = falls[falls < k].max() + 1 if np.any(falls < k) else 0
    last = falls[falls > k].min() if np.any(falls > k) else rising.size
    keep = slice(first, last + 1)
    return x[keep], fx[keep], slope[keep]


def _hermite_inverse(x, fx, slope, y):
    """Cubic Hermite interpolant of x(y) through (fx, x) with dx/dy = 1/slope, and its dx/dy."""
    k = np.clip(np.searchsorted(fx, y) - 1, 0, fx.size - 2)
    dy = fx[k + 1] - fx[k]
    s = (y - fx[k]) / dy
    m0, m1 = dy / slope[k], dy / slope[k + 1]
    s2, s3 = s * s, s * s * s
    x_y = ((2 * s3 - 3 * s2 + 1) * x[k] + (s3 - 2 * s2 + s) * m0
           + (-2 * s3 + 3 * s2) * x[k + 1] + (s3 - s2) * m1)
    dxds = ((6 * s2 - 6 * s) * (x[k] - x[k + 1]) + (3 * s2 - 4 * s + 1) * m0 + (3 * s2 - 2 * s) * m1)
    return x_y, dxds / dy
