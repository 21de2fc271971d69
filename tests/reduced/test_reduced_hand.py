"""The free hand, eqs. (27), (28): P(0), the virtual-work identity, the inverse theta(P)."""
import math

import numpy as np
import pytest

from softhand.reduced.equations import finger, hand, reservoir
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError

D = HandDesign()
THETA = np.radians([-80.0, -10.0, 0.0, 5.0, 30.0, 50.0, 90.0, 170.0])


def test_no_reservoir_pressure_is_zero_at_zero_bend():
    assert hand.pressure(0.0, D, reservoir=False) == 0.0


def test_with_reservoir_the_pump_pressure_at_zero_bend_is_minus_the_charge():
    assert hand.pressure(0.0, D) == pytest.approx(-reservoir.pressure(D.V0, D), rel=1e-15)
    assert hand.pressure(0.0, D) < 0


def test_virtual_work_identity_from_strain_energies():
    # P dQ/dtheta = d(n W_f + W_r)/dtheta, W_f from (5) and W_r from (11) directly;
    # central differences with h = 1e-4 rad: truncation ~ h^2 W'''/6, < 1e-8 of the largest term
    h = 1e-4
    energy = lambda t: D.n * finger.strain_energy(t, D) + \
        reservoir.strain_energy(reservoir.oil_volume(t, D), D)
    dW = (energy(THETA + h) - energy(THETA - h)) / (2 * h)
    dQ = (finger.Q(THETA + h, D) - finger.Q(THETA - h, D)) / (2 * h)
    tol = 1e-8 * np.max(np.abs(dW))
    assert hand.pressure(THETA, D) * dQ == pytest.approx(dW, rel=1e-7, abs=tol)
    dW_free = D.n * (finger.strain_energy(THETA + h, D) - finger.strain_energy(THETA - h, D)) / (2 * h)
    assert hand.pressure(THETA, D, reservoir=False) * dQ == pytest.approx(dW_free, rel=1e-7, abs=tol)


def test_eq_27_as_printed():
    P = (D.n * D.mu_sf * finger.zeta_f(THETA, D) + D.mu_sr * reservoir.zeta_r(THETA, D)) \
        / (D.n * D.a**2 * math.pi * D.d)
    assert hand.pressure(THETA, D) == pytest.approx(P, rel=1e-13, abs=1e-15)


@pytest.mark.parametrize("with_reservoir", [True, False])
def test_bend_angle_inverts_pressure(with_reservoir):
    theta = np.random.default_rng(0).uniform(-math.pi / 2, math.pi, 2000)
    back = hand.bend_angle(hand.pressure(theta, D, with_reservoir), D, with_reservoir)
    # Hermite table error ~1e-12 rad before the Newton step, round-off after it
    assert np.max(np.abs(back - theta)) < 1e-11
    assert hand.bend_angle(0.0, D, reservoir=False) == pytest.approx(0.0, abs=1e-15)


def test_reservoir_lowers_the_pressure_by_about_0p1_MPa():
    # the paper, Fig. 7: "bent at 0.1 MPa lower pressure" with the reservoir, 0..90 deg
    theta = np.radians(np.linspace(0, 90, 91))
    drop = hand.pressure(theta, D, reservoir=False) - hand.pressure(theta, D)
    assert np.all(drop > 0.05) and np.all(drop < 0.12)
    assert np.all(np.diff(drop) < 0)  # the sheet's pressure falls as it empties


@pytest.mark.parametrize("call, field", [
    (lambda: hand.pressure(math.radians(200), D), "theta_deg"),
    (lambda: hand.pressure(np.nan, D), "theta_deg"),
    (lambda: hand.bend_angle(50.0, D), "pressure_MPa"),
    (lambda: hand.bend_angle([0.1, np.inf], D), "pressure_MPa"),
    (lambda: hand.pressure(math.radians(90), D.replace(V0=3000.0)), "V0_mm3"),
])
def test_bad_input_names_the_field(call, field):
    with pytest.raises(InputError, match=field):
        call()


def test_inverse_converges_for_a_kinked_reservoir_model(monkeypatch):
    # a piecewise-linear p_r(V), as a tabulated calibration could be: P(theta) has slope jumps
    kinked = lambda V, design: np.interp(V, [0.0, 1.2e4, 1.6e4, 2e4, 4e4], [0.0, 0.05, 0.12, 0.1, 0.2])
    monkeypatch.setitem(reservoir._MODELS, "fem", kinked)
    design = D.replace(reservoir_model="fem")
    theta = np.random.default_rng(3).uniform(-math.pi / 2, math.pi, 3000)
    theta[:3] = [0.0, (D.V0 - 1.6e4) / (D.n * D.a**2 * math.pi * D.d), -0.5]  # one on a kink
    back = hand.bend_angle(hand.pressure(theta, design), design)
    assert np.max(np.abs(back - theta)) < 1e-10  # converged to the 5e-12 rad step tolerance
