r"""Forward kinematics and Jacobians of the n_s-hinge finger, eqs. (19)-(22).

Convention (the project's; the paper gives none -- see docs/conventions.md and its figure):

* The finger moves in the vertical plane through the hand's axis. The origin is on the
  hand's axis at the height of the finger bases. **x** is horizontal and points **outward**,
  away from the hand's axis; **y** is vertical and points **down**, along gravity. With this
  choice F_y = m g / n (24) is positive and the printed eqs. (24), (25), (29) hold as they are.
* The finger is a chain of n_s + 1 rigid links along the (inextensible) hinge plate, with
  hinge i at arc length ``design.hinge_s[i]`` from the finger base; the tip is the end of the
  plate at arc length l0. The base sits at (``design.base_offset``, 0).
* Link directions are measured from the downward vertical, positive **inward** (towards the
  axis): the base link is inclined outward, alpha_0 = -theta0_hat (Table I: 20 deg), and link k
  has alpha_k = -theta0_hat + theta_hat_1 + ... + theta_hat_k. Its unit direction is
  t = (-sin alpha, cos alpha). A positive hinge angle closes the finger (the tube lies on the
  outer side of the plate, eq. (8)); the tip link has alpha = theta - theta0_hat when
  sum(theta_hat) = theta, the angle in eq. (29).
* The tip force (F_x, F_y) is the force of the object **on** the finger tip. The finger pad
  (the plate side) faces the object; the object pushes it outward, along the outward normal
  of the tip link n_out = (cos alpha, sin alpha), and F_v = F . n_out (29) is that normal
  force: positive while the finger squeezes the object.
* The configuration at which Jacobians are taken is theta_hat = w theta
  (:func:`hinge_angles`), the integral of the virtual displacement (21) from the open hand.

Jacobians (20): rotating hinge i by d theta_hat_i turns everything beyond it, so
J_x[i] = -(y_tip - y_i), J_y[i] = x_tip - x_i (mm/rad).
"""
from __future__ import annotations

import numpy as np

from softhand.reduced.vocabulary.design import HandDesign


def hinge_angles(theta, w):
    """Eq. (21) integrated from theta = 0: theta_hat = w theta [rad], shape theta.shape + (n_s,)."""
    return np.multiply.outer(np.asarray(theta, float), np.asarray(w, float))


def link_angles(theta_hat, design: HandDesign):
    """Direction alpha_k of links 0..n_s from the downward vertical, inward positive [rad], (..., n_s+1)."""
    theta_hat = np.asarray(theta_hat, float)
    alpha = np.empty(theta_hat.shape[:-1] + (theta_hat.shape[-1] + 1,))
    alpha[..., 0] = 0.0
    np.cumsum(theta_hat, axis=-1, out=alpha[..., 1:])
    return -design.theta0 + alpha


def joint_positions(theta_hat, design: HandDesign):
    """Base, hinges 1..n_s and tip as (x, y) [mm] (x outward, y down), shape (..., n_s + 2, 2)."""
    return positions_at(link_angles(theta_hat, design), design)


def positions_at(alpha, design: HandDesign):
    """:func:`joint_positions` from the links' directions alpha (..., n_s + 1) [rad]
    (:func:`link_angles`), for a caller that has them already."""
    lengths = np.asarray(design.link_lengths)
    steps = np.empty(alpha.shape + (2,))  # (..., n_s+1, 2): each link's vector
    steps[..., 0] = -np.sin(alpha) * lengths
    steps[..., 1] = np.cos(alpha) * lengths
    out = np.empty(alpha.shape[:-1] + (alpha.shape[-1] + 1, 2))
    out[..., 0, :] = (design.base_offset, 0.0)
    out[..., 1:, :] = out[..., :1, :] + np.cumsum(steps, axis=-2)
    return out


def tip_position(theta_hat, design: HandDesign):
    """Finger tip (x, y) [mm] at hinge angles theta_hat [rad] (..., n_s) -> (..., 2)."""
    return joint_positions(theta_hat, design)[..., -1, :]


def jacobian(theta_hat, design: HandDesign):
    """Eq. (20): (J_x, J_y), each (..., n_s) [mm/rad], d(tip)/d(theta_hat) at theta_hat [rad]."""
    p = joint_positions(theta_hat, design)
    arm = p[..., -1:, :] - p[..., 1:-1, :]        # tip minus hinge i, (..., n_s, 2)
    return -arm[..., 1], arm[..., 0]
