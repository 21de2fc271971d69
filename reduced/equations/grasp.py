r"""Grasping: weight vectors (21)-(23), the grasp relation (25), F_y (24) and F_v (29).

With the virtual displacement theta_hat = w theta (21) and the tip Jacobians (20), the
virtual-work balance (1) becomes eq. (25):

.. math:: P n a^2 \pi d + n F_x J_x w + m g J_y w = n \mu_{sf}\zeta_f(\theta) + \mu_{sr}\zeta_r(\theta),

i.e. n a^2 pi d (f(theta) - P) = n F_x J_x w + m g J_y w with f the free-hand pressure (27)
(:func:`softhand.reduced.equations.hand.pressure`). Given (P, theta, m, w) it is solved for F_x; F_y = m g / n
(24); the normal force on the finger pad is F_v = F_x cos(theta - theta0) + F_y sin(theta - theta0)
(29). Signs and axes: :mod:`softhand.reduced.equations.kinematics` (x outward, y down; F is the object's force
on the finger; F_v > 0 while the finger squeezes the object).

The inverses users need, both at a prescribed normal force F_v (default 0, the limit where
the finger just stops pressing on the object):

* :func:`pressure_to_hold`: the pump pressure at which the finger, bent to theta and carrying
  its share of the mass m, presses on the object with F_v (eq. (25) is linear in P and F_x);
* :func:`angle_at`: the bend angle reached at pump pressure P under the same load -- the
  inverse of :func:`pressure_to_hold` in theta.

The paper's two weight vectors ship as :data:`softhand.reduced.vocabulary.paper.WEIGHTS`; the 180 mm one sums to 1.40,
violating (23): :func:`check_weights` warns and can normalise.
"""
from __future__ import annotations

import math
import warnings
from typing import NamedTuple

import numpy as np

from softhand.reduced.equations import finger, hand
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.vocabulary.paper import WEIGHTS as PAPER_WEIGHTS

#: newtons per kilogram-force (standard gravity, by definition of the kgf)
KGF = 9.80665
#: ``|sum(w) - 1|`` above which check_weights warns (the paper prints w to two decimals)
SUM_TOLERANCE = 5e-3


class WeightSumWarning(UserWarning):
    """A weight vector w whose entries do not sum to 1 (eq. (23))."""


class GraspForces(NamedTuple):
    F_x: np.ndarray  #: horizontal tip force of the object on the finger, outward positive [N]
    F_y: np.ndarray  #: vertical tip force, downward positive, m g / n (24) [N]
    F_v: np.ndarray  #: normal force on the finger pad (29) [N]


def weights_for_diameter(diameter_mm: float, design: HandDesign) -> np.ndarray:
    """The weight vector w (n_s,) for an object of the given diameter [mm], as stored (unchecked).

    For now the paper's presets (:data:`~softhand.reduced.vocabulary.paper.WEIGHTS`); the one place to extend (FEM-derived w).
    """
    w = PAPER_WEIGHTS.get(float(diameter_mm))
    if w is None:
        raise InputError("diameter_mm", diameter_mm, "no weight vector for this diameter; "
                         f"available: {', '.join(f'{D:g}' for D in PAPER_WEIGHTS)}")
    if len(w) != design.n_s:
        raise InputError("n_s", design.n_s, f"the paper's w for {float(diameter_mm):g} mm has "
                         f"{len(w)} hinges; give a design with n_s = {len(w)}, or w itself")
    return np.array(w, dtype=float)


#: largest ``|w_i|``: a hinge turning more than ten times the mean bend is no grasp (the paper's
#: w lie in [-0.2, 0.8]; the studies' grasp kind has the same bound)
MAX_WEIGHT = 10.0


def check_weights(w, design: HandDesign, normalise: bool = False) -> np.ndarray:
    """w as an (n_s,) array: InputError unless n_s numbers within +-MAX_WEIGHT; warns when
    sum(w) != 1 (23)."""
    try:
        w = np.asarray(w, dtype=float)
    except (TypeError, ValueError):
        raise InputError("weights", w, f"must be {design.n_s} numbers") from None
    if w.shape != (design.n_s,) or not np.all(np.abs(w) <= MAX_WEIGHT):
        raise InputError("weights", w.tolist() if w.ndim else w.item(),
                         f"must be n_s = {design.n_s} numbers in [-{MAX_WEIGHT:g}, {MAX_WEIGHT:g}]")
    total = float(w.sum())
    if normalise:
        if abs(total) < 1e-12 or not np.all(np.abs(w / total) <= MAX_WEIGHT):
            raise InputError("weights", w.tolist(), f"sum to {total:.3g}; normalised, each must still be in "
                                                    f"[-{MAX_WEIGHT:g}, {MAX_WEIGHT:g}]")
        return w / total
    if abs(total - 1.0) > SUM_TOLERANCE:
        warnings.warn(f"weights sum to {total:.4g}, not 1 as eq. (23) requires; "
                      "use normalise (--normalise) to scale them", WeightSumWarning, stacklevel=2)
    return w


def projected_jacobian(theta, w, design: HandDesign):
    """(J_x w, J_y w) [mm/rad] at theta_hat = w theta, vectorised over theta [rad].

    Summed link by link (hinge i moves links k >= i):
    J_x w = -sum_k L_k W_k cos(alpha_k), J_y w = -sum_k L_k W_k sin(alpha_k), where
    W_k = w_1 + .. + w_k and alpha_k = W_k theta - theta0 (links k = 1..n_s; the base link
    does not move). Equal to ``jacobian(hinge_angles(theta, w)) @ w`` (tested).
    """
    W = np.cumsum(np.asarray(w, dtype=float))
    arm = np.asarray(design.link_lengths[1:]) * W                 # L_k W_k, k = 1..n_s
    alpha = np.multiply.outer(np.asarray(theta, float), W) - design.theta0
    return -np.einsum("...k,k", np.cos(alpha), arm), -np.einsum("...k,k", np.sin(alpha), arm)


def _check_mass(mass) -> np.ndarray:
    mass = np.asarray(mass, dtype=float)
    if not np.all(np.isfinite(mass) & (mass >= 0)):
        raise InputError("mass_kg", float(mass[~(np.isfinite(mass) & (mass >= 0))].flat[0]),
                         "must be a number >= 0")
    return mass


def _pad_axis(theta, design: HandDesign):
    """(cos, sin) of alpha = theta - theta0, the tip link's angle from the downward vertical."""
    alpha = np.asarray(theta, float) - design.theta0
    return np.cos(alpha), np.sin(alpha)


def _pump_area(design: HandDesign, theta):
    """n dQ/dtheta [mm^3/rad]: oil per radian of bend, all fingers; eq. (4): n a^2 pi d."""
    if design.finger_model == "paper":
        return design.n * design.a**2 * math.pi * design.d
    return design.n * finger.volume_rate(theta, design)


def grasp_forces(P, theta, mass, w, design: HandDesign, *, reservoir: bool = True) -> GraspForces:
    """Eqs. (24), (25), (29): tip forces [N] at pump pressure P [MPa], bend theta [rad], mass [kg].

    Vectorised (P, theta, mass broadcast); w (n_s,) is used as given (see check_weights).
    """
    theta = hand.check_theta(theta)
    mass = _check_mass(mass)
    J_xw, J_yw = projected_jacobian(theta, w, design)
    if np.any(np.abs(J_xw) < 1e-9):
        raise InputError("weights", np.asarray(w).tolist(),
                         "make J_x w = 0: the tip does not move sideways, F_x is undetermined")
    mg = mass * design.g
    F_x = (_pump_area(design, theta) * (hand.pressure(theta, design, reservoir) - np.asarray(P, float))
           - mg * J_yw) / (design.n * J_xw)
    F_y = mg / design.n * np.ones_like(F_x)
    cos_a, sin_a = _pad_axis(theta, design)
    return GraspForces(F_x, F_y, F_x * cos_a + F_y * sin_a)


def pressure_to_hold(mass, theta, w, design: HandDesign, *, F_v=0.0, reservoir: bool = True):
    """Pump pressure [MPa] at which the finger, bent to theta [rad] and carrying mass [kg] with
    the others, presses on the object with the normal force F_v [N] (eqs. (25), (29) solved for P).
    """
    theta = hand.check_theta(theta)
    mg = _check_mass(mass) * design.g
    cos_a, sin_a = _pad_axis(theta, design)
    F_x = (np.asarray(F_v, float) - mg / design.n * sin_a) / cos_a
    J_xw, J_yw = projected_jacobian(theta, w, design)
    return hand.pressure(theta, design, reservoir) - (design.n * F_x * J_xw + mg * J_yw) / _pump_area(design, theta)


def angle_at(P, mass: float, w, design: HandDesign, *, F_v: float = 0.0, reservoir: bool = True):
    """Bend angle [rad] reached at pump pressure P [MPa] (vectorised) carrying mass [kg] (scalar)
    with normal force F_v [N]: the inverse of :func:`pressure_to_hold` on its rising branch.
    """
    if np.ndim(mass) or np.ndim(F_v):
        raise InputError("mass_kg", np.asarray(mass).tolist(), "angle_at takes one mass and one F_v")
    lo, hi = hand.THETA_RANGE
    lo = max(lo, design.theta0 - 0.45 * math.pi)  # cos(theta - theta0) > 0 in (29)
    hi = min(hi, design.theta0 + 0.45 * math.pi)
    return hand.invert_monotone(
        lambda th: pressure_to_hold(mass, th, w, design, F_v=F_v, reservoir=reservoir),
        P, (lo, hi), field="pressure_MPa", unit="MPa")
