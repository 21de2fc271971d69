r"""Where the closing finger meets an object: placement, contact angle, rolling weight vector.

The object is a circle of diameter D in the bending plane, centred on the hand's axis at
depth ``depth`` below the palm (the hand frame of :mod:`softhand.reduced.equations.kinematics`: x outward,
y down). Link k grasps with its *pad*, the segment of the hinge plate between its two
joints, facing the hand's axis (the inward normal -n_out = -(cos alpha_k, sin alpha_k)).
Its gap is the distance from the centre C to the closest pad point minus D/2; a pad whose
line has the centre behind it cannot touch (gap +inf). This is the geometry of the grasp
FEM (``fem.contact``), written here with NumPy alone so that the reduced model can use it.

* :func:`object_depth` -- the placement of the grasp FEM: the object's top ``palm_gap``
  below the palm, lowered until the open fingers' pads clear it by ``clearance``.
* :func:`contact_angle` -- the bend theta at which the freely closing finger (hinge angles
  theta_hat = w theta, uniform w by default: the free finger FEM bends its hinges equally)
  first touches the object, and the pad that touches.
* :func:`rolling_weights` -- the virtual displacement (21) of a finger in contact: the
  smallest hinge motion (sum of squares) with sum(w) = 1 (23) that keeps the touching pad
  on the rigid object, d g_k/d q . w = 0. The hinges beyond the touching link share equally;
  those before it roll the pad on the object.

The gap's gradient is analytic: hinge j turns every point beyond it, so the closest pad
point x* of link k moves by dx*/dq_j = Omega (x* - x_j) (j <= k, Omega the rotation by
+90 deg in the hand frame) and dg/dq_j = -nu . dx*/dq_j, nu = (C - x*)/``|C - x*|``.
Units: mm, rad.
"""
from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import math

import numpy as np
from scipy.optimize import brentq

from softhand.reduced.equations import kinematics
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError

#: placement of the object, as in the grasp FEM (fem.grasp.GraspOptions) [mm]
PALM_GAP, CLEARANCE = 10.0, 2.0
#: rotation by +90 deg in the hand frame: d(direction)/d(alpha) = OMEGA direction
OMEGA = np.array([[0.0, -1.0], [1.0, 0.0]])
#: bend angles scanned for the first contact [rad], their number, and the refinements' number
_SCAN, _SCAN_POINTS, _REFINE_POINTS = (0.0, np.pi), 181, 101


def _closest(theta_hat, centre, design: HandDesign):
    """Closest point x* (..., n_s+1, 2) of every pad to ``centre`` and whether the pad faces it."""
    alpha = kinematics.link_angles(theta_hat, design)
    p = kinematics.positions_at(alpha, design)
    A, AB = p[..., :-1, :], p[..., 1:, :] - p[..., :-1, :]
    C = np.asarray(centre, dtype=float)
    tau = np.minimum(np.maximum(np.einsum("...i,...i", C - A, AB) / np.einsum("...i,...i", AB, AB), 0.0), 1.0)
    x = A + tau[..., None] * AB
    inward = np.empty(alpha.shape + (2,))
    inward[..., 0], inward[..., 1] = -np.cos(alpha), -np.sin(alpha)
    return x, np.einsum("...i,...i", inward, C - x) > 0.0, p


def pad_gaps(theta_hat, centre, radius: float, design: HandDesign):
    """Gap [mm] of every pad (links 0..n_s) to the circle (centre (2,), radius) at hinge
    angles theta_hat (..., n_s) [rad] -> (..., n_s + 1); +inf where the pad faces away."""
    x, facing, _ = _closest(theta_hat, centre, design)
    rho = np.linalg.norm(np.asarray(centre, float) - x, axis=-1)
    return np.where(facing, rho - radius, np.inf)


def pad_motion(theta_hat, centre, link: int, design: HandDesign, *, end: bool = False):
    """(x*, nu, dx): the closest point x* (2,) [mm] of pad ``link`` to ``centre`` (``end``: the
    pad's far end, the next joint), the unit vector nu (2,) from x* to the centre, and
    dx*/d theta_hat (n_s, 2) [mm/rad] (zero beyond the link) at hinge angles theta_hat (n_s,) [rad]."""
    x, _, p = _closest(np.asarray(theta_hat, float), centre, design)
    xs = p[link + 1] if end else x[link]
    nu = (np.asarray(centre, float) - xs) / np.linalg.norm(np.asarray(centre, float) - xs)
    turns = np.arange(1, design.n_s + 1) <= link      # hinge j turns link k when j <= k
    dx = np.where(turns[:, None], (xs - p[1:-1]) @ OMEGA.T, 0.0)  # hinge j turns x* about x_j
    return xs, nu, dx


def pad_gap_gradient(theta_hat, centre, link: int, design: HandDesign) -> np.ndarray:
    """d g_link / d theta_hat (n_s,) [mm/rad] at hinge angles theta_hat (n_s,), analytic."""
    _, nu, dx = pad_motion(theta_hat, centre, link, design)
    return -dx @ nu


def _uniform(design: HandDesign) -> np.ndarray:
    return np.full(design.n_s, 1.0 / design.n_s)


def object_depth(diameter: float, design: HandDesign, *, palm_gap: float = PALM_GAP,
                 clearance: float = CLEARANCE) -> float:
    """Depth [mm] of the object's centre below the palm: its top ``palm_gap`` below it, lowered
    until the open fingers (theta_hat = 0) clear it by ``clearance`` (fem.grasp.default_depth)."""
    return _depth(float(diameter), _kinematic_key(design), palm_gap, clearance)


def _kinematic_key(design: HandDesign):
    """What the kinematics depend on (the cache key): theta0, l0, hinge_s, base_offset."""
    return (design.theta0, design.l0, design.hinge_s, design.base_offset)


def _from_key(key) -> HandDesign:
    theta0, l0, hinge_s, base_offset = key
    return HandDesign(theta0=theta0, l0=l0, hinge_s=hinge_s, n_s=len(hinge_s), base_offset=base_offset)


@lru_cache(maxsize=256)
def _depth(diameter, key, palm_gap, clearance) -> float:
    design, l0 = _from_key(key), key[1]
    if not diameter > 0:
        raise InputError("diameter_mm", diameter, "must be a positive number")
    open_hand = np.zeros(design.n_s)
    fun = lambda y: np.min(pad_gaps(open_hand, (0.0, y), 0.5 * diameter, design)) - clearance  # noqa: E731
    depth = 0.5 * diameter + palm_gap
    if fun(depth) >= 0.0:
        return depth
    hi = depth + diameter + 2.0 * l0
    if fun(hi) < 0.0:
        raise InputError("diameter_mm", diameter, "the object does not clear the open fingers")
    return float(brentq(fun, depth, hi, xtol=1e-9))


def contact_angle(diameter: float, design: HandDesign, *, depth: float | None = None,
                  w=None) -> tuple[float, int]:
    """(theta [rad], link) at which the finger closing with theta_hat = w theta (default:
    uniform hinges) first touches the object at ``depth`` (default :func:`object_depth`).

    The gap is scanned on 181 angles of [0, pi], the first bracket of a zero twice more on 101
    angles each (all vectorised), and the zero interpolated linearly in a bracket of ~2e-6 rad
    (the gap is smooth there: error ~1e-12 rad). InputError if the finger does not reach it.
    """
    depth = object_depth(diameter, design) if depth is None else float(depth)
    w = _uniform(design) if w is None else np.asarray(w, dtype=float)
    centre, radius = (0.0, depth), 0.5 * diameter
    gaps = lambda th: pad_gaps(kinematics.hinge_angles(th, w), centre, radius, design)  # noqa: E731
    theta = np.linspace(*_SCAN, _SCAN_POINTS)
    for _ in range(3):
        g = np.min(gaps(theta), axis=-1)
        if g[0] <= 0.0:
            raise InputError("diameter_mm", diameter, "the object overlaps the open finger")
        closed = np.flatnonzero(g <= 0.0)
        if closed.size == 0:
            raise InputError("diameter_mm", diameter,
                             f"the finger does not reach the object within {np.degrees(_SCAN[1]):.0f} deg")
        k = closed[0]
        lo, hi, g_lo, g_hi = theta[k - 1], theta[k], g[k - 1], g[k]
        theta = np.linspace(lo, hi, _REFINE_POINTS)
    root = lo + (hi - lo) * g_lo / (g_lo - g_hi)
    return float(root), int(np.argmin(gaps(root)))


def rolling_weights(theta_hat, diameter: float, link: int, design: HandDesign, *,
                    depth: float | None = None) -> np.ndarray:
    """The least-squares hinge motion w (n_s,) with sum(w) = 1 that keeps pad ``link`` on
    the object at hinge angles theta_hat [rad]: w = A^T (A A^T)^-1 (1, 0), A = [1; dg/dq]."""
    depth = object_depth(diameter, design) if depth is None else float(depth)
    grad = pad_gap_gradient(theta_hat, (0.0, depth), link, design)
    if not np.any(grad):  # the base link cannot roll: nothing constrains the hinges
        return _uniform(design)
    A = np.vstack([np.ones(design.n_s), grad])
    return A.T @ np.linalg.solve(A @ A.T, np.array([1.0, 0.0]))


class Geometry(NamedTuple):
    depth: float        #: object centre below the palm [mm]
    theta: float        #: grasp angle [rad]
    link: int           #: touching pad
    w: np.ndarray       #: rolling weight vector
    theta_open: float   #: bend at which the open tips span the opening [rad]; nan: never wide enough


def grasp_geometry(diameter: float, opening: float, design: HandDesign) -> Geometry:
    """The kinematics of a grasp task (cached by what they depend on): placement, grasp angle
    and touching pad, rolling w there, and the bend at which the tips of the fingers closing
    with equal hinge angles span ``opening`` [mm] (1025 angles, linear interpolation)."""
    return _grasp_geometry(float(diameter), float(opening), _kinematic_key(design))


@lru_cache(maxsize=1024)
def _grasp_geometry(diameter: float, opening: float, key: tuple) -> Geometry:
    d = _from_key(key)
    depth = object_depth(diameter, d)
    theta, link = contact_angle(diameter, d, depth=depth)
    uniform = np.full(d.n_s, 1.0 / d.n_s)
    w = rolling_weights(kinematics.hinge_angles(theta, uniform), diameter, link, d, depth=depth)
    th = np.linspace(0.0, 0.5 * math.pi, 1025)
    span = 2.0 * kinematics.tip_position(kinematics.hinge_angles(th, uniform), d)[:, 0]
    narrow = np.flatnonzero(span < opening)
    if not narrow.size:
        theta_open = 0.5 * math.pi
    elif narrow[0] == 0:
        theta_open = math.nan
    else:
        k = narrow[0]
        theta_open = float(th[k - 1] + (th[k] - th[k - 1]) * (span[k - 1] - opening) / (span[k - 1] - span[k]))
    return Geometry(depth, theta, link, w, theta_open)
