"""Finger kinematics (19)-(22): closed-form poses and Jacobians against finite differences."""
import math

import numpy as np
import pytest

from softhand.reduced.equations import kinematics as kin
from softhand.reduced.vocabulary.design import HandDesign

D = HandDesign()


def test_open_finger_points_down_and_outward_at_theta0():
    tip = kin.tip_position(np.zeros(D.n_s), D)
    s, c = math.sin(D.theta0), math.cos(D.theta0)
    assert tip == pytest.approx([D.base_offset + D.l0 * s, D.l0 * c], rel=1e-14)


def test_tip_link_turned_by_the_total_bend():
    # bend all at the last hinge by 90 deg + theta0: the tip link points horizontally inward
    theta_hat = np.zeros(D.n_s)
    theta_hat[-1] = math.pi / 2 + D.theta0
    p = kin.joint_positions(theta_hat, D)
    last = D.link_lengths[-1]
    assert p[-1] - p[-2] == pytest.approx([-last, 0.0], abs=1e-12)
    assert kin.link_angles(theta_hat, D)[-1] == pytest.approx(math.pi / 2)


def test_link_lengths_are_kept():
    theta_hat = np.random.default_rng(1).uniform(-0.5, 1.0, (7, D.n_s))
    p = kin.joint_positions(theta_hat, D)
    lengths = np.linalg.norm(np.diff(p, axis=-2), axis=-1)
    assert lengths == pytest.approx(np.broadcast_to(D.link_lengths, lengths.shape), rel=1e-13)


def test_jacobians_against_finite_differences():
    rng = np.random.default_rng(2)
    h = 1e-6  # central differences: error ~ h^2 l0 / 6 ~ 1e-11 mm/rad
    for theta_hat in rng.uniform(-0.3, 0.8, (5, D.n_s)):
        J_x, J_y = kin.jacobian(theta_hat, D)
        for i in range(D.n_s):
            e = np.zeros(D.n_s)
            e[i] = h
            fd = (kin.tip_position(theta_hat + e, D) - kin.tip_position(theta_hat - e, D)) / (2 * h)
            assert [J_x[i], J_y[i]] == pytest.approx(fd, abs=1e-7)


def test_jacobian_vectorised_and_hinge_angles():
    w = np.array([0.1, 0.2, 0.3, 0.2, 0.2])
    theta = np.array([0.2, 0.9])
    theta_hat = kin.hinge_angles(theta, w)
    assert theta_hat.shape == (2, D.n_s) and theta_hat.sum(axis=-1) == pytest.approx(theta)
    J_x, J_y = kin.jacobian(theta_hat, D)
    assert J_x.shape == (2, D.n_s)
    assert J_x[1] == pytest.approx(kin.jacobian(theta_hat[1], D)[0], rel=1e-14)
