"""Material laws: stress = d(energy)/dF, tangent = d(stress)/dF (central finite
differences), the small-strain limit vs Hooke's law (observed order 2), and
homogeneous uniaxial tension vs the closed form."""
import numpy as np
import pytest
from scipy.optimize import brentq

from softhand.fem.materials import CompressibleNeoHookean, Fibers, NeoHookean, Volumetric

RNG = np.random.default_rng(0)
#: a batch (4, 2) of deformation gradients with J in about [0.7, 1.4]
F_BATCH = np.eye(3)[:, :, None, None] + 0.25 * RNG.standard_normal((3, 3, 4, 2))


def laws():
    a0 = RNG.standard_normal((3, 4))  # per-element fiber directions for the batch (4, 2)
    return {
        "neo-hookean": NeoHookean(mu=1.15, kappa=115.0),
        "compressible": CompressibleNeoHookean(mu=1.15, lam=50.0),
        "fibers": Fibers(k=100.0, a0=a0),
        "nh+fibers": NeoHookean(mu=1.15, kappa=50.0) + Fibers(k=100.0, a0=a0),
        "volumetric": Volumetric(kappa=10.0),
    }


def fd_derivative(f, F, h=1e-6):
    """Central differences of f w.r.t. every F[b, L]: shape f(F).shape[:-2] + (3, 3) + batch."""
    cols = []
    for b in range(3):
        for L in range(3):
            dF = np.zeros_like(F)
            dF[b, L] = h
            cols.append((f(F + dF) - f(F - dF)) / (2 * h))
    D = np.stack(cols)  # (9, ..., batch)
    return D.reshape((3, 3) + D.shape[1:])


@pytest.mark.parametrize("name", list(laws()))
def test_stress_is_energy_gradient(name):
    law = laws()[name]
    P_fd = fd_derivative(law.energy, F_BATCH)
    # central differences with h = 1e-6: truncation O(h^2 * psi''') ~ 1e-10, round-off ~ 1e-10 * psi / h
    np.testing.assert_allclose(law.stress(F_BATCH), P_fd, atol=2e-7 * law.stress(F_BATCH).std())


@pytest.mark.parametrize("name", list(laws()))
def test_tangent_is_stress_gradient(name):
    law = laws()[name]
    A_fd = np.moveaxis(fd_derivative(law.stress, F_BATCH), (0, 1), (2, 3))
    A = law.tangent(F_BATCH)
    np.testing.assert_allclose(A, A_fd, atol=2e-7 * np.abs(A).max())
    np.testing.assert_allclose(A, np.swapaxes(np.swapaxes(A, 0, 2), 1, 3), atol=1e-12 * np.abs(A).max())


@pytest.mark.parametrize("law, lam, mu", [
    (NeoHookean(mu=1.15, kappa=40.0), 40.0 - 2.0 / 3.0 * 1.15, 1.15),
    (CompressibleNeoHookean(mu=1.15, lam=50.0), 50.0, 1.15),
])
def test_small_strain_limit_is_hooke_with_order_two(law, lam, mu):
    H = RNG.standard_normal((3, 3))
    eps_values = np.array([1e-2, 5e-3, 2.5e-3, 1.25e-3])
    errors = []
    for e in eps_values:
        strain = 0.5 * e * (H + H.T)
        hooke = lam * np.trace(strain) * np.eye(3) + 2 * mu * strain
        P = law.stress(np.eye(3) + e * H)
        # P ~ sigma + (grad u) sigma - ... : the symmetric part differs by O(e^2)
        errors.append(np.abs(0.5 * (P + P.T) - hooke).max())
    order = np.polyfit(np.log(eps_values), np.log(errors), 1)[0]
    assert 1.9 < order < 2.1, f"observed order {order:.3f}"


def test_uniaxial_tension_closed_form():
    """Incompressible-limit check: for NH with kappa, free lateral stretch l2 from P22 = 0;
    with kappa -> inf, l2 -> l^{-1/2} and P11 -> mu (l - l^{-2})."""
    lam = 1.6
    law = NeoHookean(mu=1.15, kappa=1.15e5)

    def lateral(l2):
        F = np.diag([lam, l2, l2])
        return law.stress(F)[1, 1]

    l2 = brentq(lateral, 0.5, 1.0, xtol=1e-15)
    P11 = law.stress(np.diag([lam, l2, l2]))[0, 0]
    # relative deviation from incompressibility is O(mu/kappa) = 1e-5
    assert l2 == pytest.approx(lam ** -0.5, rel=3e-5)
    assert P11 == pytest.approx(1.15 * (lam - lam ** -2), rel=3e-5)


def test_fibers_are_tension_only():
    f = Fibers(k=1000.0, a0=np.array([1.0, 0.0, 0.0]))
    compressed = np.diag([0.9, 1.1, 1.0])[:, :, None]
    stretched = np.diag([1.1, 0.95, 1.0])[:, :, None]
    assert f.energy(compressed)[0] == 0.0 and np.all(f.stress(compressed) == 0.0)
    assert f.energy(stretched)[0] == pytest.approx(0.5 * 1000.0 * 0.1 ** 2)
    assert f.stress(stretched)[0, 0, 0] == pytest.approx(1000.0 * 0.1)
