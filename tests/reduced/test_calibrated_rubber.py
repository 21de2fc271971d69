"""The FEM-calibrated finger and reservoir with a design's own rubber: the Neo-Hookean tables
carry the geometry, the rubber enters through the physics they correct (eq. (10)'s pure-shear
stress for the tube, the equibiaxial stress for the sheet). Checked here against closed forms
and the Neo-Hookean limit; against the FEM in tests/fem/test_calibrated_rubber_fem.py."""
import math

import numpy as np
import pytest

from softhand.reduced.calibrated import finger_fem, reservoir_fem
from softhand.reduced.equations import finger, hand
from softhand.reduced.materials import rubber
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.design_files import design_from_dict

FEM = HandDesign(finger_model="fem", reservoir_model="fem")
THETA = np.radians([-20.0, 0.0, 5.0, 30.0, 60.0, 95.0])


def test_neo_hookean_written_as_another_model_gives_the_calibrated_curves_unchanged():
    """Yeoh with C20 = C30 = 0 is Neo-Hookean with mu = 2 C10: the general pure-shear integral
    of eq. (10) against the paper's closed form (to round-off of its quadrature: 1.9e-10 measured at
    the largest angle's energy), and the sheet's factor 1."""
    as_yeoh = FEM.replace(finger_material=rubber.Yeoh(0.575, 0.0, 0.0),
                          reservoir_material=rubber.MooneyRivlin(0.575, 0.0))
    assert not as_yeoh.finger_is_neo_hookean and not as_yeoh.reservoir_is_neo_hookean
    for f in (finger.energy_rate, finger.energy, finger.volume):
        np.testing.assert_allclose(f(THETA, as_yeoh), f(THETA, FEM), rtol=1e-9, atol=1e-9)
    V = np.array([3000.0, FEM.V0, 25000.0])
    np.testing.assert_allclose(reservoir_fem.pressure(V, as_yeoh), reservoir_fem.pressure(V, FEM), rtol=1e-12)
    np.testing.assert_allclose(reservoir_fem.strain_energy(V, as_yeoh), reservoir_fem.strain_energy(V, FEM),
                               rtol=1e-7)  # the composite Gauss panels straddle the table's knots


def test_the_tube_prior_is_the_pure_shear_integral_of_the_rubber():
    """P / mu_sf of the prior with a Yeoh rubber against an independent quadrature of
    int W'(lambda) c dV / (pi d) over the untied tube (scipy's adaptive dblquad)."""
    from scipy import integrate

    shape = rubber.Yeoh(0.5, -0.02, 0.004)  # mu0 = 1
    g = finger_fem.groups_of(FEM)
    l0 = 6 * g["link_a"] * (1.0 - g["tie_link"])
    b, d = g["b_a"], g["d_a"]
    for theta in (0.3, 1.2):
        def integrand(phi, rho):
            c = (d + rho * math.sin(phi)) / l0
            return float(shape.nominal_stress("pure-shear", 1.0 + c * theta)) * c * l0 * rho

        exact = integrate.dblquad(integrand, 1.0, 1.0 + b, 0.0, 2 * math.pi, epsabs=1e-12, epsrel=1e-11)[0]
        got = finger_fem.prior_pressure(theta, g, "rings", shape)
        assert got == pytest.approx(exact / (math.pi * d), rel=1e-8)


def test_the_sheet_factor_is_the_mooney_rivlin_closed_form():
    """Equibiaxial nominal stress 2 (lam - lam^-5)(C10 + C01 lam^2) over mu0 (lam - lam^-5):
    (C10 + C01 lam^2) / (C10 + C01) at the ellipse model's stretch lambda_r(V)."""
    from softhand.reduced.equations import reservoir

    mr = FEM.replace(reservoir_material=rubber.MooneyRivlin(0.46, 0.115))
    V = np.array([5000.0, mr.V0, 24000.0])
    lam = reservoir.stretch(V, mr)
    np.testing.assert_allclose(reservoir_fem.rubber_factor(V, mr), (0.46 + 0.115 * lam**2) / 0.575, rtol=1e-12)
    neo = mr.replace(reservoir_material=None)
    np.testing.assert_allclose(reservoir_fem.pressure(V, mr),
                               reservoir_fem.pressure(V, neo) * (0.46 + 0.115 * lam**2) / 0.575, rtol=1e-12)
    # the energy stays the pressure's integral (p = dW/dV to the central difference's error)
    h = 0.1
    dW = (reservoir_fem.strain_energy(V + h, mr) - reservoir_fem.strain_energy(V - h, mr)) / (2 * h)
    np.testing.assert_allclose(dW, reservoir_fem.pressure(V, mr), rtol=1e-6)


def test_a_design_file_with_its_own_rubber_runs_on_the_calibrated_models():
    """Refused before: a Yeoh tube and a Mooney-Rivlin sheet with finger_model and
    reservoir_model "fem"; a rubber that stiffens in pure shear bends the finger less at the
    same pump pressure and initial modulus, one that softens bends it more."""
    d = design_from_dict({"finger_model": "fem", "reservoir_model": "fem",
                          "finger": {"material": {"model": "yeoh", "C10_MPa": 0.575, "C20_MPa": 0.02,
                                                  "C30_MPa": 0.0}},
                          "reservoir": {"material": {"model": "mooney-rivlin", "C10_MPa": 0.5,
                                                     "C01_MPa": 0.075}}})
    assert d.finger_rubber.model == "yeoh" and d.reservoir_rubber.model == "mooney-rivlin"
    P = np.array([0.5, 1.0, 2.0])
    stiff = hand.bend_angle(P, d, reservoir=False)
    soft = hand.bend_angle(P, d.replace(finger_material=rubber.Yeoh(0.575, -0.02, 0.0)), reservoir=False)
    neo = hand.bend_angle(P, FEM, reservoir=False)
    assert np.all(stiff < neo) and np.all(soft > neo)
    # the stretch is the tube's kinematics: the same at the same bend
    np.testing.assert_allclose(finger_fem.rubber_stretch(stiff, d), finger_fem.rubber_stretch(stiff, FEM))
