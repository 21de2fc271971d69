"""The reduced model with a general rubber W: finger (pure-shear kinematics), reservoir
(equibiaxial membrane), design files with [finger.material] / [reservoir.material]."""
import json
import math
import warnings

import numpy as np
import pytest
from scipy import integrate

from softhand.reduced.equations import finger, hand, reservoir
from softhand.reduced.materials import rubber
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.design_files import design_from_dict, load_design
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.cli.main import main

MR = rubber.MooneyRivlin(0.5, 0.075)
YEOH = rubber.Yeoh(0.575, -0.02, 0.004)


def test_neo_hookean_written_as_another_model_gives_the_papers_numbers():
    """Ogden (mu, alpha = 2) and MR with C01 = 0 are NH: the general path vs eqs. (10), (18)."""
    theta = np.radians([-30.0, 0.0, 10.0, 45.0, 90.0, 150.0])
    nh = HandDesign()
    for same in (rubber.Ogden((1.15,), (2.0,)), rubber.MooneyRivlin(0.575, 0.0)):
        d = nh.replace(finger_material=same, reservoir_material=same)
        assert not d.finger_is_neo_hookean
        np.testing.assert_allclose(finger.finger_force(theta, d), nh.mu_sf * finger.zeta_f(theta, nh),
                                   rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(hand.pressure(theta, d), hand.pressure(theta, nh), rtol=1e-12, atol=1e-12)
        V = reservoir.oil_volume(theta, nh)
        np.testing.assert_allclose(reservoir.strain_energy(V, d), reservoir.strain_energy(V, nh), rtol=1e-12)


def test_neo_hookean_table_is_the_default():
    d = design_from_dict({"finger": {"material": {"model": "neo-hookean", "mu_MPa": 1.15}}})
    assert d.finger_is_neo_hookean and d.mu_sf == 1.15
    theta = np.radians([10.0, 60.0])
    assert np.array_equal(hand.pressure(theta, d), hand.pressure(theta, HandDesign()))


def _finger_force_dblquad(theta, design, material):
    """dW_f/dtheta by adaptive quadrature over the whole annulus (no symmetry, no Gauss rule)."""
    g = design

    def integrand(phi, rho):
        c = (g.d + rho * math.sin(phi)) / g.l0
        return float(material.nominal_stress("pure-shear", 1.0 + c * theta)) * c * g.l0 * rho

    return integrate.dblquad(integrand, g.a, g.a + g.b, 0.0, 2 * math.pi, epsabs=1e-10, epsrel=1e-11)[0]


@pytest.mark.parametrize("material", [MR, YEOH, rubber.Gent(1.15, 30.0),
                                      rubber.Ogden((1.1, 0.01, -0.05), (1.3, 5.0, -2.0))],
                         ids=lambda m: m.model)
def test_finger_force_against_adaptive_quadrature(material):
    d = HandDesign().replace(finger_material=material, mu_sf=material.mu0)
    for theta_deg in (25.0, 120.0):
        theta = math.radians(theta_deg)
        assert finger.finger_force(theta, d) == pytest.approx(_finger_force_dblquad(theta, d, material), rel=1e-9)


def test_finger_force_is_the_derivative_of_the_strain_energy():
    d = HandDesign().replace(finger_material=YEOH, mu_sf=YEOH.mu0)
    theta, h = np.radians([20.0, 80.0]), 1e-6
    fd = (finger.strain_energy(theta + h, d) - finger.strain_energy(theta - h, d)) / (2 * h)
    np.testing.assert_allclose(finger.finger_force(theta, d), fd, rtol=1e-7)


def test_reservoir_pressure_mooney_rivlin_closed_form_and_energy():
    d = HandDesign().replace(reservoir_material=MR, mu_sr=MR.mu0)
    V = np.array([9000.0, 17800.0, 20000.0])
    lam = reservoir.stretch(V, d)
    # membrane: dW/dlam = 4 (lam - lam^-5)(C10 + C01 lam^2) for MR
    closed = 4 * (lam - lam**-5) * (0.5 + 0.075 * lam**2) * reservoir.dstretch_dV(V, d) * math.pi * 24.0**2
    np.testing.assert_allclose(reservoir.pressure(V, d), closed, rtol=1e-13)
    h = 1e-2
    fd = (reservoir.strain_energy(V + h, d) - reservoir.strain_energy(V - h, d)) / (2 * h)
    np.testing.assert_allclose(reservoir.pressure(V, d), fd, rtol=1e-7)


def test_material_tables_in_a_design_file(tmp_path):
    path = tmp_path / "d.toml"
    path.write_text('V0_mm3 = 17800.0\n[finger.material]\nmodel = "yeoh"\nC10_MPa = 0.575\n'
                    'C20_MPa = -0.02\nC30_MPa = 0.004\n[reservoir.material]\nmodel = "mooney-rivlin"\n'
                    'C10_MPa = 0.5\nC01_MPa = 0.075\n')
    d = load_design(path)
    assert d.finger_rubber == YEOH and d.reservoir_rubber == MR
    assert d.mu_sf == pytest.approx(1.15) and d.mu_sr == pytest.approx(1.15)
    assert not d.finger_is_neo_hookean and not d.reservoir_is_neo_hookean
    again = tmp_path / "again.toml"
    again.write_text(d.to_toml())
    assert load_design(again) == d and load_design(again).hash() == d.hash()
    # mu_sf_MPa on such a design scales the material (softhand fit, sweeps)
    stiffer = design_from_dict({"mu_sf_MPa": 2.3}, d)
    assert stiffer.finger_rubber.parameters() == pytest.approx({k: 2 * v for k, v in YEOH.parameters().items()})


def test_design_material_errors():
    # the calibrated models take any rubber (tests/reduced/test_calibrated_rubber.py)
    assert not design_from_dict({"reservoir_model": "fem",
                                 "reservoir": {"material": {"model": "yeoh", "C10_MPa": 0.5}}}).reservoir_is_neo_hookean
    assert design_from_dict({"reservoir_model": "fem"}).reservoir_is_neo_hookean
    with pytest.raises(InputError, match="finger.material.C01_MPa"):
        design_from_dict({"finger": {"material": {"model": "yeoh", "C10_MPa": 0.5, "C01_MPa": 1}}})
    with pytest.raises(InputError, match="model"):
        design_from_dict({"finger": {"material": {"C10_MPa": 0.5}}})
    with pytest.raises(InputError, match=r"\[finger.material\]"):
        design_from_dict({"finger": {"mu": 1}})
    with pytest.warns(UserWarning, match="overridden"):
        d = design_from_dict({"mu_sf_MPa": 1.15, "finger": {"material": {"model": "yeoh", "C10_MPa": 0.4}}})
    assert d.mu_sf == 0.8
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        design_from_dict({"mu_sf_MPa": 0.8, "finger": {"material": {"model": "yeoh", "C10_MPa": 0.4}}})


def test_curve_honours_the_materials(tmp_path, capsys):
    path = tmp_path / "mr.toml"
    path.write_text('[finger.material]\nmodel = "mooney-rivlin"\nC10_MPa = 0.5\nC01_MPa = 0.075\n'
                    '[reservoir.material]\nmodel = "mooney-rivlin"\nC10_MPa = 0.5\nC01_MPa = 0.075\n')
    assert main(["curve", "--theta-deg", "60", "--design", str(path), "--json"]) == 0
    row = json.loads(capsys.readouterr().out)["rows"][0]
    d, theta = HandDesign(), math.radians(60.0)
    free = _finger_force_dblquad(theta, d, MR) / (d.a**2 * math.pi * d.d)
    V = d.V0 - d.n * d.a**2 * math.pi * d.d * theta
    lam = float(reservoir.stretch(V, d))
    p_r = 4 * (lam - lam**-5) * (0.5 + 0.075 * lam**2) * float(reservoir.dstretch_dV(V, d)) * math.pi * 24.0**2
    assert row["P_cavity_MPa"] == pytest.approx(free, rel=1e-9)
    assert row["P_pump_MPa"] == pytest.approx(free - p_r, rel=1e-9)
    assert row["p_reservoir_MPa"] == pytest.approx(p_r, rel=1e-12)
    assert main(["curve", "--pressure-mpa", str(row["P_pump_MPa"]), "--design", str(path), "--json"]) == 0
    back = json.loads(capsys.readouterr().out)["rows"][0]
    assert back["theta_deg"] == pytest.approx(60.0, abs=1e-8)
