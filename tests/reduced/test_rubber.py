"""Strain energies of reduced/materials/rubber.py: derivatives vs finite differences, closed forms."""
import numpy as np
import pytest

from softhand.reduced.materials import rubber, rubber_base, rubber_parameters
from softhand.reduced.vocabulary.errors import InputError

MODELS = [
    rubber.NeoHookean(0.6),
    rubber.MooneyRivlin(0.4, 0.05),
    rubber.Yeoh(0.3, -0.01, 4e-4),
    rubber.Gent(0.55, 40.0),
    rubber.Ogden((0.62, 0.0012, -0.01), (1.3, 5.0, -2.0)),
]
L = np.array([[1.3, 0.9, 2.1, 1.0], [0.8, 1.1, 0.7, 1.0], [1.2, 0.95, 1.4, 1.0]])  # (3, 4), J free


@pytest.mark.parametrize("model", MODELS, ids=lambda m: m.model)
def test_derivatives_match_finite_differences(model):
    h = 1e-6
    g, H = model.dW(*L), model.d2W(*L)
    for i in range(3):
        e = np.zeros((3, 1))
        e[i] = h
        fd = (model.energy(*(L + e)) - model.energy(*(L - e))) / (2 * h)
        np.testing.assert_allclose(g[i], fd, rtol=1e-7, atol=1e-9)
        fd2 = (model.dW(*(L + e)) - model.dW(*(L - e))) / (2 * h)
        np.testing.assert_allclose(H[:, i], fd2, rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(H, H.transpose(1, 0, 2), rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize("model", MODELS, ids=lambda m: m.model)
@pytest.mark.parametrize("mode", rubber_base.MODES)
def test_nominal_stress_is_the_derivative_of_the_mode_energy(model, mode):
    lam, h = np.array([0.7, 1.0, 1.5, 2.5]), 1e-6
    share = 2.0 if mode == "equibiaxial" else 1.0
    fd = (model.mode_energy(mode, lam + h) - model.mode_energy(mode, lam - h)) / (2 * h) / share
    np.testing.assert_allclose(model.nominal_stress(mode, lam), fd, rtol=1e-7, atol=1e-9)


@pytest.mark.parametrize("model", MODELS, ids=lambda m: m.model)
def test_small_strain_shear_modulus(model):
    """Uniaxial: P ~ 3 mu0 (lam - 1) (Young's modulus 3 mu0), error O(eps^2)."""
    eps = np.array([1e-3, 5e-4])
    err = model.nominal_stress("uniaxial", 1 + eps) / eps - 3 * model.mu0
    assert np.all(np.abs(err) < 20 * model.mu0 * eps)
    assert abs(err[1] / err[0] - 0.5) < 0.05  # first order in eps: the slope's error


def test_neo_hookean_and_mooney_rivlin_closed_forms():
    lam = np.linspace(0.5, 4.0, 15)
    nh, mr = rubber.NeoHookean(1.15), rubber.MooneyRivlin(0.4, 0.07)
    np.testing.assert_allclose(nh.nominal_stress("uniaxial", lam), 1.15 * (lam - lam**-2), rtol=1e-14)
    np.testing.assert_allclose(nh.nominal_stress("equibiaxial", lam), 1.15 * (lam - lam**-5), rtol=1e-14)
    np.testing.assert_allclose(nh.nominal_stress("pure-shear", lam), 1.15 * (lam - lam**-3), rtol=1e-14)
    np.testing.assert_allclose(nh.mode_energy("pure-shear", lam), 0.575 * (lam**2 + lam**-2 - 2), rtol=1e-13)
    np.testing.assert_allclose(nh.mode_energy("equibiaxial", lam), 0.575 * (2 * lam**2 + lam**-4 - 3),
                               rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(mr.nominal_stress("uniaxial", lam),
                               2 * (lam - lam**-2) * (0.4 + 0.07 / lam), rtol=1e-13)
    np.testing.assert_allclose(mr.nominal_stress("equibiaxial", lam),
                               2 * (lam - lam**-5) * (0.4 + 0.07 * lam**2), rtol=1e-13)


def test_ogden_one_term_alpha_2_is_neo_hookean():
    lam = np.linspace(0.6, 3.0, 9)
    for mode in rubber_base.MODES:
        np.testing.assert_allclose(rubber.Ogden((1.15,), (2.0,)).nominal_stress(mode, lam),
                                   rubber.NeoHookean(1.15).nominal_stress(mode, lam), rtol=1e-13)


def test_drucker_hessian():
    l1 = np.linspace(0.3, 5, 30)
    stretches = rubber_base.stretches("uniaxial", l1)
    assert np.all(np.linalg.eigvalsh(np.moveaxis(rubber.NeoHookean(1).drucker_hessian(*stretches), -1, 0)) > 0)
    unstable = rubber.Yeoh(0.3, -0.05, 0.0)  # softens without bound: unstable at large I1
    smallest = np.linalg.eigvalsh(np.moveaxis(unstable.drucker_hessian(*stretches), -1, 0))[:, 0]
    I1 = sum(s**2 for s in stretches)
    # the softening C20 < 0 makes it unstable once I1 grows: stable near 1, unstable far
    assert np.all(smallest[I1 < 3.5] > 0) and np.all(smallest[I1 > 5] < 0)


@pytest.mark.parametrize("model", MODELS, ids=lambda m: m.model)
def test_drucker_hessian_is_the_log_strain_hessian(model):
    """Finite differences of w(e1, e2) = W(e^e1, e^e2, e^(-e1-e2))."""
    e, h = np.array([0.3, -0.1]), 1e-4
    w = lambda x: model.energy(np.exp(x[0]), np.exp(x[1]), np.exp(-x[0] - x[1]))  # noqa: E731
    fd = np.empty((2, 2))
    for a in range(2):
        for b in range(2):
            da, db = h * np.eye(2)[a], h * np.eye(2)[b]
            fd[a, b] = (w(e + da + db) - w(e + da - db) - w(e - da + db) + w(e - da - db)) / (4 * h * h)
    H = model.drucker_hessian(np.exp(e[0]), np.exp(e[1]), np.exp(-e.sum()))
    np.testing.assert_allclose(H, fd, rtol=1e-5, atol=1e-6)


def test_parameters_round_trip_and_validation():
    for m in MODELS:
        back = rubber_parameters.from_parameters(m.model, m.parameters())
        assert back == m and back.parameters() == m.parameters()
        assert back.scaled(2.0).mu0 == pytest.approx(2 * m.mu0)
    assert rubber_parameters.from_parameters("yeoh", {"C10_MPa": 0.5}) == rubber.Yeoh(0.5)
    assert rubber_parameters.from_parameters("Mooney_Rivlin", {"c10_mpa": 0.5, "C01_MPa": 0.1}) == rubber.MooneyRivlin(0.5, 0.1)
    assert rubber_parameters.from_parameters("Ogden", {"MU1_MPa": 1.0, "Alpha1": 2.0}) == rubber.Ogden((1.0,), (2.0,))
    with pytest.raises(InputError, match="unknown parameter"):
        rubber_parameters.from_parameters("mooney-rivlin", {"C10_MPa": 0.5, "C02_MPa": 1})
    with pytest.raises(InputError, match="missing"):
        rubber_parameters.from_parameters("gent", {"mu_MPa": 0.5})
    with pytest.raises(InputError, match="must be positive"):
        rubber_parameters.from_parameters("neo-hookean", {"mu_MPa": -1.0})
    with pytest.raises(InputError, match="must be one of"):
        rubber_parameters.from_parameters("arruda-boyce", {})
