"""The coupled hinges held far below their free bends (softhand.reduced.calibrated.hinge_blocked and
its study): the correction's terms against central differences, the clamp, what it leaves at the free
state, the study's fit recovering known coefficients, and against the finger FEM held by hinge loads
on the paper's design (tests/data/blocked_hinges_paper.json: loads and states no coefficient was fitted to)."""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from softhand.reduced.calibrated import finger_hinges, hinge_blocked
from softhand.reduced.vocabulary.design import HandDesign
from softhand.studies.calibration import hinge_blocked as study

PAPER = finger_hinges.fem_finger(HandDesign())
BLOCKED = json.loads((Path(__file__).resolve().parents[1] / "data" / "blocked_hinges_paper.json").read_text())["states"]


def test_the_terms_gradients_and_curvatures_are_their_values_derivatives():
    rho, h = np.array([0.2, 0.55, 1.04, 0.9, -0.1]), 1e-6
    value, grad, hess = hinge_blocked.basis(rho)
    for j, e in enumerate(np.eye(5)):
        up, down = hinge_blocked.basis(rho + h * e), hinge_blocked.basis(rho - h * e)
        np.testing.assert_allclose(grad[j], (up[0] - down[0]) / (2 * h), rtol=1e-7, atol=1e-9)
        np.testing.assert_allclose(hess[j], (up[1][j] - down[1][j]) / (2 * h), rtol=1e-6, atol=1e-8)


def test_the_moments_weighted_gradient_is_the_terms_gradients():
    rho, c = np.array([[0.2, 0.55, 1.04, 0.9, -0.1], [1.0, 0.3, 0.3, 0.7, 1.2]]), np.array([-0.016, -0.006, 0.005])
    np.testing.assert_allclose(hinge_blocked._gradient(rho, c), hinge_blocked.basis(rho)[1] @ c, rtol=1e-13, atol=1e-16)


def test_the_pair_term_is_zero_for_hinges_held_alike_and_does_not_load_a_free_neighbour():
    value, grad, _ = hinge_blocked.basis(np.array([0.3, 0.3, 0.3, 0.3, 0.3]))
    assert value[0] == 0.0 and np.all(grad[:, 0] == 0.0)
    _, grad, _ = hinge_blocked.basis(np.array([1.0, 1.0, 0.25, 1.0, 1.0]))
    assert grad[2, 0] < -0.5
    assert grad[1, 0] == pytest.approx(0.0, abs=1e-15) and grad[3, 0] == pytest.approx(0.0, abs=1e-15)


def test_the_clamp_is_the_identity_inside_and_smooth_and_bounded_beyond():
    r = np.linspace(-3.0, 3.0, 6001)
    rho, d1, d2 = hinge_blocked._clamp(r)
    inside = (r >= hinge_blocked.LOW) & (r <= hinge_blocked.HIGH)
    np.testing.assert_array_equal(rho[inside], r[inside])
    assert rho.min() > hinge_blocked.LOW - hinge_blocked.WIDTH and rho.max() < hinge_blocked.HIGH + hinge_blocked.WIDTH
    np.testing.assert_allclose(np.gradient(rho, r)[1:-1], d1[1:-1], atol=1e-5)
    np.testing.assert_allclose(np.gradient(d1, r)[1:-1], d2[1:-1], atol=2e-2)  # O(h / WIDTH^2) at the edges
    assert np.max(np.abs(np.diff(d1))) < 1e-2                           # no kink at the edges


@pytest.mark.parametrize("P", [0.6, 1.3])
def test_the_free_state_keeps_its_moments_and_stiffness(P):
    q_f = finger_hinges.coupled_free_angles(P, PAPER)
    np.testing.assert_allclose(hinge_blocked.moments(q_f, q_f, P, PAPER), 0.0, atol=1e-12)
    np.testing.assert_allclose(hinge_blocked.stiffness(q_f, q_f, P, PAPER), 0.0, atol=1e-9)
    assert np.all(np.abs(hinge_blocked.moments(q_f * (1 - 1e-3), q_f, P, PAPER)) < 1e-4)  # second order


@pytest.mark.parametrize("P", [0.0, 0.02])
def test_a_finger_not_yet_bending_meets_a_finite_vanishing_correction(P):
    q_f = np.maximum(finger_hinges.coupled_free_angles(P, PAPER), 0.0) if P else np.zeros(5)
    q = np.radians([-3.0, 2.0, 5.0, 0.0, 1.0])
    for f in (hinge_blocked.moments, hinge_blocked.energy):
        v = f(q, q_f, P, PAPER)
        assert np.all(np.isfinite(v)) and np.all(np.abs(v) < 0.1)        # N mm: nothing against ~100 N mm moments
    K = hinge_blocked.stiffness(q, q_f, P, PAPER)
    assert np.all(np.isfinite(K)) and np.all(np.abs(K) < 0.01 * finger_hinges.coupled_stiffness(q, max(P, 0.01), PAPER))


def test_the_stiffness_is_the_moments_derivative_at_a_held_state():
    P, h = 1.2, 1e-6
    q = finger_hinges.coupled_free_angles(P, PAPER) * np.array([0.15, 0.5, 1.02, 1.0, 0.9])
    fd = [(finger_hinges.coupled_moments(q + h * e, P, PAPER) - finger_hinges.coupled_moments(q - h * e, P, PAPER))[j]
          / (2 * h) for j, e in enumerate(np.eye(5))]
    np.testing.assert_allclose(finger_hinges.coupled_stiffness(q, P, PAPER), fd, rtol=1e-5)


def test_the_study_fit_recovers_the_coefficients_that_made_the_states():
    """States whose loads are the uncorrected coupled moments plus a known correction: the fit returns it."""
    known = np.array([-0.012, 0.004, -0.002])
    rng = np.random.default_rng(3)
    states = []
    for P in study.PRESSURES[:2]:
        q_f = finger_hinges.coupled_free_angles(P, PAPER)
        states.append({"P": P, "Q": [0.0] * 5, "q": q_f.tolist()})
        for k in range(6):
            q = q_f * rng.uniform(0.1, 1.05, 5)
            rho = q / q_f
            extra = P * hinge_blocked.unit_of(PAPER) * q_f.mean() * (hinge_blocked.basis(rho)[1] @ known) / q_f
            Q = finger_hinges.coupled_moments(q, P, PAPER, blocked=False) + extra
            states.append({"P": P, "pattern": "x", "target": 0.0, "Q": Q.tolist(), "q": q.tolist()})
    c = study.fit(study.misses(PAPER, states), study.PRESSURES[:2])
    np.testing.assert_allclose(c, [known, known], rtol=1e-8, atol=1e-12)


def _errors(states, blocked):
    out = []
    for s in states:
        Q, held = np.array(s["Q"]), np.array(s["Q"]) != 0
        M = finger_hinges.coupled_moments(np.array(s["q"]), s["P"], PAPER, blocked=blocked)
        out += list((M[held] - Q[held]) / np.abs(Q[held]))
    return np.array(out)


def test_the_shipped_coefficients_bring_the_paper_designs_blocked_fem_closer():
    """The paper's design under loads of none of the fit's states: its 16 load patterns at 1.5 MPa, the
    held hinges' moments within 0.64 % rms, worst 1.5 % (uncorrected 1.61 %, 5.0 %); the 9 at 0.9 MPa
    with no held hinge within 1 deg of straight, 0.54 %, worst 1.0 % (1.58 %, 2.7 %)."""
    high = [s for s in BLOCKED if s["P"] == 1.5 and any(s["Q"])]
    low = [s for s in BLOCKED if s["P"] == 0.9 and any(s["Q"])
           and min(q for q, Q in zip(s["q"], s["Q"]) if Q) > math.radians(1.0)]
    assert len(high) == 16 and len(low) == 9
    for states in (high, low):
        e, e0 = _errors(states, True), _errors(states, False)
        assert np.sqrt(np.mean(e ** 2)) < 0.01 and np.max(np.abs(e)) < 0.025
        assert np.sqrt(np.mean(e0 ** 2)) > 2 * np.sqrt(np.mean(e ** 2))   # the test tells the two apart
