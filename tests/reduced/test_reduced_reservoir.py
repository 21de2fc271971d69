"""Reservoir sheet, eqs. (11)-(18): geometry closed forms, analytic derivatives vs differences."""
import numpy as np
import pytest
from scipy.special import ellipe

from softhand.reduced.equations import reservoir
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError

D = HandDesign()
THETA = np.radians([-60.0, 0.0, 20.0, 45.0, 90.0, 150.0])


def test_height_of_half_spheroid():
    # a hemisphere of radius R holds 2/3 pi R^3
    assert reservoir.height(2 / 3 * np.pi * D.R**3, D) == pytest.approx(D.R, rel=1e-15)
    assert reservoir.oil_volume(0.0, D) == D.V0


def test_half_perimeter_circle_and_ellipse():
    assert reservoir.half_perimeter(D.R, D) == pytest.approx(np.pi * D.R, rel=1e-15)  # exact for a circle
    # half perimeter 2 a E(m); Ramanujan's (13) error grows like x^10, x = (a-b)/(a+b):
    # 1.0e-5 at h = 10 mm (x = 0.41), far smaller closer to the circle
    for h in (10.0, 15.0, 30.0):
        a, b = max(D.R, h), min(D.R, h)
        assert reservoir.half_perimeter(h, D) == pytest.approx(2 * a * ellipe(1 - (b / a) ** 2), rel=2e-5)


def test_dstretch_dtheta_against_finite_differences():
    # central differences: error ~ h^2 lambda'''/6, ~1e-10 relative for h = 1e-4 rad
    h = 1e-4
    lam = lambda t: reservoir.stretch(reservoir.oil_volume(t, D), D)
    fd = (lam(THETA + h) - lam(THETA - h)) / (2 * h)
    assert reservoir.dstretch_dtheta(THETA, D) == pytest.approx(fd, rel=1e-8)


def test_zeta_r_is_the_derivative_of_the_strain_energy():
    # eq. (17): dW_r/dtheta = mu_sr zeta_r, W_r from eq. (11) directly
    h = 1e-4
    W = lambda t: reservoir.strain_energy(reservoir.oil_volume(t, D), D)
    fd = (W(THETA + h) - W(THETA - h)) / (2 * h)
    assert D.mu_sr * reservoir.zeta_r(THETA, D) == pytest.approx(fd, rel=1e-7)


def test_pressure_is_dW_dV_and_matches_zeta_r():
    V = reservoir.oil_volume(THETA, D)
    h = 1e-2  # mm^3; W_r'' ~ 1e-5, truncation error ~1e-10 relative
    fd = (reservoir.strain_energy(V + h, D) - reservoir.strain_energy(V - h, D)) / (2 * h)
    assert reservoir.pressure(V, D) == pytest.approx(fd, rel=1e-7)
    rhs = -D.mu_sr * reservoir.zeta_r(THETA, D) / (D.n * D.a**2 * np.pi * D.d)
    assert reservoir.pressure(V, D) == pytest.approx(rhs, rel=1e-13)


def test_charged_reservoir_pressure_is_about_a_tenth_of_a_MPa():
    # the paper (Fig. 7): the reservoir lowers the pressure by "about 0.1 MPa"
    assert 0.05 < reservoir.pressure(D.V0, D) < 0.15


def test_registry_dispatches_on_reservoir_model(monkeypatch):
    monkeypatch.setitem(reservoir._MODELS, "fem", lambda V, design: 0.5 + 0 * V)
    fem = D.replace(reservoir_model="fem")
    assert reservoir.pressure([1e4, 2e4], fem) == pytest.approx([0.5, 0.5])
    assert reservoir.pressure(1e4, D) != 0.5
    with pytest.raises(InputError, match="reservoir_model.*available: ellipse"):
        reservoir.model("balloon")  # not registered, no module reduced.reservoir_balloon


def test_empty_reservoir_is_bad_input():
    with pytest.raises(InputError, match="V_mm3"):
        reservoir.pressure(0.0, D)
