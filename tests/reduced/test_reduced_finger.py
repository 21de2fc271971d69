"""Finger tube, eqs. (2), (5), (8), (10): closed forms, an independent quadrature route, rates."""
import numpy as np
import pytest
from scipy.integrate import quad

from softhand.reduced.equations import finger
from softhand.reduced.vocabulary.design import HandDesign

D = HandDesign()
ANGLES = np.array([0.05, 0.3, 0.8, np.pi / 2, np.pi, -0.4, -np.pi / 2])


def moment(k, design=D):
    """M_k = integral of c^k over the tube section [mm^2], c = (d + rho sin phi)/l0, closed form."""
    a, ro, d, l0 = design.a, design.a + design.b, design.d, design.l0
    ring = {1: np.pi * d * (ro**2 - a**2),
            2: np.pi * (d**2 * (ro**2 - a**2) + (ro**4 - a**4) / 4),
            3: np.pi * (d**3 * (ro**2 - a**2) + 3 * d * (ro**4 - a**4) / 4)}[k]
    return ring / l0**k


def zeta_f_by_exact_phi(theta, design=D):
    """Eq. (10) with the phi-integral in closed form and r by adaptive quad (independent route).

    lambda = A + B sin phi; (lambda - lambda^-3) c = (lambda^2 - lambda - lambda^-2 + lambda^-3)/theta.
    """
    a, b, d, l0 = design.a, design.b, design.d, design.l0
    A = 1 + d * theta / l0

    def ring(rho):
        B = rho * theta / l0
        e = A**2 - B**2
        lam1, lam2 = 2 * np.pi * A, 2 * np.pi * (A**2 + B**2 / 2)
        inv2, inv3 = 2 * np.pi * A / e**1.5, np.pi * (2 * A**2 + B**2) / e**2.5
        return (lam2 - lam1 - inv2 + inv3) / theta * l0 * rho

    return quad(ring, a, a + b, epsabs=0, epsrel=1e-13)[0]


def test_zeta_f_against_exact_phi_integration():
    # rtol 1e-11: the default Gauss-Legendre orders converge to ~1e-14 (next test); quad to 1e-13
    expected = [zeta_f_by_exact_phi(t) for t in ANGLES]
    assert finger.zeta_f(ANGLES, D) == pytest.approx(expected, rel=1e-11)


def test_quadrature_converges_geometrically_to_1e10():
    reference = finger.zeta_f(ANGLES, D, orders=(30, 60))
    orders = [(2, 4), (3, 6), (4, 8), (5, 10)]
    errors = [np.max(np.abs(finger.zeta_f(ANGLES, D, orders=o) / reference - 1)) for o in orders]
    assert all(e1 < 0.05 * e0 for e0, e1 in zip(errors, errors[1:])), errors  # geometric
    assert np.max(np.abs(finger.zeta_f(ANGLES, D) / reference - 1)) < 1e-10


def test_small_angle_closed_form_and_second_order_term():
    # zeta_f = 4 l0 M2 theta - 6 l0 M3 theta^2 + O(theta^3)  (lambda - lambda^-3 = 4x - 6x^2 + 10x^3 ..)
    assert finger.zeta_f_small_angle(1.0, D) == pytest.approx(4 * D.l0 * moment(2), rel=1e-14)
    theta = np.array([1e-3, 2e-3, 4e-3, 8e-3])
    second = (finger.zeta_f(theta, D) - finger.zeta_f_small_angle(theta, D)) / theta**2
    # deviation from -6 l0 M3 is the theta^3 term: 10 l0 M4 theta / (6 l0 M3) < 1e-3 here
    assert second == pytest.approx(-6 * D.l0 * moment(3), rel=2e-3)
    rate = np.polyfit(np.log(theta), np.log(np.abs(second + 6 * D.l0 * moment(3))), 1)[0]
    assert rate == pytest.approx(1.0, abs=0.05)


def test_zeta_f_is_the_derivative_of_the_strain_energy():
    # eq. (9): dW_f/dtheta = mu_sf zeta_f; central differences, error ~ h^2 W'''/6 < 1e-9 relative
    h = 1e-4
    dW = (finger.strain_energy(ANGLES + h, D) - finger.strain_energy(ANGLES - h, D)) / (2 * h)
    assert dW == pytest.approx(D.mu_sf * finger.zeta_f(ANGLES, D), rel=1e-8)


def test_strain_energy_small_angle():
    # W_f = mu/2 (lambda - 1/lambda)^2 ~ 2 mu x^2 -> 2 mu l0 M2 theta^2 (relative error O(theta))
    theta = 1e-4
    assert finger.strain_energy(theta, D) == pytest.approx(2 * D.mu_sf * D.l0 * moment(2) * theta**2,
                                                           rel=1e-3)
    assert finger.strain_energy(0.0, D) == 0.0


def test_Q_is_the_cavity_volume_of_the_bent_tube():
    # integrate lambda_f (8) over the cavity disc (r in [-a, 0], i.e. rho in [0, a]): Q/n
    x, wx = np.polynomial.legendre.leggauss(8)
    r = -D.a * (x + 1) / 2
    phi = np.pi * (x + 1)
    R, PHI = np.meshgrid(r, phi, indexing="ij")
    W = np.outer(D.a / 2 * wx * (D.a + r), np.pi * wx)
    for theta in (0.0, 0.7, 1.5):
        volume = np.sum(finger.axial_stretch(theta, R, PHI, D) * D.l0 * W)
        assert finger.Q(theta, D) == pytest.approx(D.n * volume, rel=1e-12)


def test_vectorised_over_any_shape():
    theta = np.linspace(0, 1, 12).reshape(3, 4)
    z = finger.zeta_f(theta, D)
    assert z.shape == (3, 4)
    assert z[1, 2] == pytest.approx(float(finger.zeta_f(theta[1, 2], D)), rel=1e-14)
