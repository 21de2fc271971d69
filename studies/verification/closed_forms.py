r"""Closed-form solutions the FEM is verified against (``softhand verify``, tests).

Pure NumPy/SciPy; stresses in MPa, lengths in mm.

**Uniaxial tension** of the nearly incompressible Neo-Hookean law of :mod:`softhand.fem.materials`,
:math:`\psi = \tfrac{\mu}{2}(J^{-2/3}I_1 - 3) + \tfrac{\kappa}{2}(J-1)^2`, stretched by λ
along :math:`e_1` with free lateral faces: the lateral stretch t solves
:math:`\sigma_{22} = \mu J^{-5/3}\big(t^2 - \tfrac{λ^2 + 2t^2}{3}\big) + κ(J-1) = 0`,
:math:`J = λt^2`, and the nominal stress is :math:`P_{11} = Jσ_{11}/λ`.

**Thick-walled tube in plane strain**, incompressible Neo-Hookean (:math:`σ = -q I + μ b`),
reference radii :math:`R_i < R_o`, inner pressure p, outer surface free. A material circle
of radius R moves to r with :math:`λ = λ_θ = r/R`, :math:`λ_r = 1/λ`, and incompressibility
gives :math:`r^2 = r_i^2 - R_i^2 + R^2 = R^2 + c`. Radial equilibrium
:math:`dσ_{rr}/dr + (σ_{rr} - σ_{θθ})/r = 0` with :math:`σ_{rr}(r_i) = -p`,
:math:`σ_{rr}(r_o) = 0`:

.. math::
    p = \int_{r_i}^{r_o} \frac{σ_{θθ} - σ_{rr}}{r}\,dr
      = μ\int_{R_i}^{R_o}\Big(\frac{r^2}{R^2} - \frac{R^2}{r^2}\Big)\frac{R\,dR}{r^2}
      = μ\int_{R_i}^{R_o}\Big(\frac1R - \frac{R^3}{(R^2 + c)^2}\Big)dR
      = μ\Big[\ln\frac{λ_i}{λ_o} + \frac c2\Big(\frac1{r_i^2} - \frac1{r_o^2}\Big)\Big],

using :math:`r\,dr = R\,dR` and :math:`\int R^3/(R^2+c)^2\,dR = \tfrac12\ln(R^2+c) + c/(2(R^2+c))`.
Small strain: :math:`p ≈ 2με(1 - R_i^2/R_o^2)`, Lamé's incompressible result.

**Closed-end tube wound with an inextensible hoop fiber ring on its outer surface**
(the Kevlar winding as a zero-thickness ring: :math:`r_o = R_o`), incompressible
Neo-Hookean, inner pressure p also acting on the end cap. Far from the ends the
deformation is a uniform axial stretch :math:`λ_z` with
:math:`r^2 = R_o^2 - (R_o^2 - R^2)/λ_z`, :math:`λ_θ = r/R`, :math:`λ_r = 1/(λ_θλ_z)`.
With T the ring's tension per unit length (:math:`σ_{rr}(r_o) = -T/r_o`), radial
equilibrium gives :math:`p - T/r_o = μI_p`, and the axial balance with the cap,
:math:`\int 2πσ_{zz}r\,dr = pπr_i^2`, rewritten with
:math:`d(r^2σ_{rr})/dr = r(σ_{rr} + σ_{θθ})`, gives :math:`T r_o = μI_N`:

.. math::
    p = μ\Big(I_p + \frac{I_N}{R_o^2}\Big),\quad
    I_p = \int_{r_i}^{r_o} \frac{λ_θ^2 - λ_r^2}{r}dr,\quad
    I_N = \int_{r_i}^{r_o} (2λ_z^2 - λ_r^2 - λ_θ^2)\,r\,dr,

integrated over R (:math:`r\,dr = R\,dR/λ_z`) by adaptive quadrature.
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq


def uniaxial_lateral_stretch(lam: float, mu: float, kappa: float) -> float:
    """Lateral stretch t of the free faces in uniaxial tension by ``lam`` (σ22 = 0)."""
    def sigma_22(t):
        J = lam * t * t
        return mu * J ** (-5.0 / 3.0) * (t * t - (lam * lam + 2 * t * t) / 3.0) + kappa * (J - 1.0)

    return brentq(sigma_22, 0.2 / np.sqrt(lam), 5.0 / np.sqrt(lam), xtol=1e-15, rtol=1e-15)


def uniaxial_nominal_stress(lam: float, mu: float, kappa: float) -> float:
    """Nominal (first Piola-Kirchhoff) stress P11 [MPa] in uniaxial tension by ``lam``."""
    t = uniaxial_lateral_stretch(lam, mu, kappa)
    J = lam * t * t
    sigma_11 = mu * J ** (-5.0 / 3.0) * (lam * lam - (lam * lam + 2 * t * t) / 3.0) + kappa * (J - 1.0)
    return J * sigma_11 / lam


def tube_pressure_plane_strain(lam_i: float, R_i: float, R_o: float, mu: float) -> float:
    """Inner pressure [MPa] holding an incompressible NH tube at inner hoop stretch ``lam_i``."""
    c = (lam_i ** 2 - 1.0) * R_i ** 2
    r_i2, r_o2 = R_i ** 2 + c, R_o ** 2 + c
    lam_o = np.sqrt(r_o2) / R_o
    return mu * (np.log(lam_i / lam_o) + 0.5 * c * (1.0 / r_i2 - 1.0 / r_o2))


def ring_tube_pressure(lam_z: float, R_i: float, R_o: float, mu: float) -> float:
    """Inner pressure [MPa] of a closed-end NH tube with an inextensible outer hoop ring at
    axial stretch ``lam_z`` (see the module docstring)."""
    def stretches(R):
        r = np.sqrt(R_o ** 2 - (R_o ** 2 - R ** 2) / lam_z)
        lam_t = r / R
        return r, lam_t, 1.0 / (lam_t * lam_z)

    def dI_p(R):
        r, lt, lr = stretches(R)
        return (lt ** 2 - lr ** 2) * R / (lam_z * r ** 2)

    def dI_N(R):
        _, lt, lr = stretches(R)
        return (2 * lam_z ** 2 - lr ** 2 - lt ** 2) * R / lam_z

    I_p = quad(dI_p, R_i, R_o, epsabs=1e-14, epsrel=1e-12, limit=200)[0]
    I_N = quad(dI_N, R_i, R_o, epsabs=1e-14, epsrel=1e-12, limit=200)[0]
    return mu * (I_p + I_N / R_o ** 2)


def ring_tube_axial_stretch(p: float, R_i: float, R_o: float, mu: float) -> float:
    """Inverse of :func:`ring_tube_pressure`: λz at inner pressure ``p`` [MPa]."""
    return brentq(lambda lz: ring_tube_pressure(lz, R_i, R_o, mu) - p, 1.0, 20.0, xtol=1e-14)
