r"""Verification: a thick Neo-Hookean sphere inflated under volume control past its pressure maximum.

Closed form (incompressible, exact for any wall thickness). A shell A <= R <= B deforms to
a <= r <= b with :math:`r^3 - R^3 = a^3 - A^3`; with λ = r/R the radial equilibrium
:math:`dσ_r/dr = 2(σ_θ - σ_r)/r`, :math:`σ_θ - σ_r = μ(λ^2 - λ^{-4})` and
:math:`dr/r = -dλ / (λ(λ^3 - 1))` integrate to

.. math:: p = 2μ\Big[\frac{1}{λ_b} + \frac{1}{4λ_b^4} - \frac{1}{λ_a} - \frac{1}{4λ_a^4}\Big],
          \qquad λ_b^3 = 1 + (λ_a^3 - 1)\frac{A^3}{B^3},

whose thin-wall limit is :math:`p = 2μ (H/R)(λ^{-1} - λ^{-7})`, maximal at λ = 7^{1/6}.

FEM: a quarter annulus in r–z (:mod:`softhand.meshes.shell`), u_r = 0 on the axis, u_z = 0 on the
equator plane, the cavity volume V = (2/3)π a³ prescribed (its half above the equator) and
p its Lagrange multiplier. λ_a is taken from the prescribed volume over the *discrete*
reference cavity volume, so the O(h³) geometry error of the circle does not enter p.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softhand.fem.axisym import AxisymSolid, RevolvedVolume
from softhand.fem.hyperelastic import rubber_law
from softhand.fem.materials import NeoHookean
from softhand.fem.volume_path import follow_volume, volume_path_options
from softhand.meshes.shell import shell_mesh

__all__ = ["ThickSphere", "closed_form_pressure", "inflate_sphere"]


@dataclass(frozen=True)
class ThickSphere:
    """A thick spherical balloon and its discretisation."""

    A: float = 10.0  #: inner radius [mm]
    B: float = 11.0  #: outer radius [mm]
    mu: float = 1.15  #: shear modulus [MPa]
    kappa_ratio: float = 1000.0  #: bulk modulus / μ [-]
    n_radial: int = 1  #: Q2 elements through the wall
    n_polar: int = 8  #: Q2 elements from the pole to the equator
    pressure_space: str = "P1"  #: dilatation/pressure space per element, "P1" or "P0"
    #: a :mod:`softhand.reduced.materials.rubber` model (its initial shear modulus replaces mu); None: Neo-Hookean
    material: object = None

    @property
    def shear_modulus(self) -> float:
        return self.mu if self.material is None else self.material.mu0


def closed_form_pressure(lambda_a, A: float, B: float, mu: float):
    """Exact p [MPa] of the incompressible Neo-Hookean thick sphere at inner stretch λ_a = a/A."""
    lam_a = np.asarray(lambda_a, dtype=float)
    lam_b = np.cbrt(1.0 + (lam_a**3 - 1.0) * (A / B) ** 3)
    f = lambda lam: 1.0 / lam + 0.25 / lam**4  # noqa: E731
    return 2.0 * mu * (f(lam_b) - f(lam_a))


def closed_form_pressure_general(lambda_a, A: float, B: float, material):
    r"""Exact p [MPa] of an incompressible thick sphere of any :mod:`softhand.reduced.materials.rubber` model:

    .. math:: p = \int_{\lambda_b}^{\lambda_a} \frac{\hat W'(\lambda)}{\lambda^3 - 1}\,d\lambda,
              \qquad \hat W(\lambda) = W(\lambda, \lambda, \lambda^{-2}),

    (radial equilibrium with the equibiaxial hoop state at every radius; for Neo-Hookean it
    is :func:`closed_form_pressure`), by adaptive quadrature. Thin wall (B - A = H << A):
    p -> (H / A) W'(lambda) / lambda^2."""
    from scipy.integrate import quad

    dW = lambda lam: 2.0 * float(material.nominal_stress("equibiaxial", lam))  # noqa: E731
    out = []
    for lam_a in np.atleast_1d(np.asarray(lambda_a, dtype=float)):
        lam_b = np.cbrt(1.0 + (lam_a**3 - 1.0) * (A / B) ** 3)
        out.append(quad(lambda lam: dW(lam) / (lam**3 - 1.0), lam_b, lam_a, epsabs=0, epsrel=1e-12)[0])
    return np.array(out)


def inflate_sphere(sphere: ThickSphere, lambda_a):
    """FEM pressure [MPa] at the inner stretches ``lambda_a`` (increasing, > 1), and the solver path."""
    mesh = shell_mesh(sphere.A, sphere.B, n_radial=sphere.n_radial, n_polar=sphere.n_polar)
    mu = sphere.shear_modulus
    law = (NeoHookean(mu, sphere.kappa_ratio * mu) if sphere.material is None
           else rubber_law(sphere.material, sphere.kappa_ratio * mu))
    solid = AxisymSolid(mesh, law, pressure=sphere.pressure_space)
    cavity = RevolvedVolume(solid, mesh.boundaries["inner"])
    b = solid.basis
    fixed = np.concatenate([b.get_dofs("axis").all("u^1"), b.get_dofs("equator").all("u^2")])
    V_ref = cavity.value(np.zeros(solid.ndofs))
    targets = V_ref * np.asarray(lambda_a, dtype=float) ** 3
    opts = volume_path_options(first_step=0.01 * V_ref, max_step=0.3 * V_ref,
                       atol=1e-12 * sphere.kappa_ratio * mu * sphere.B**2)
    hits, path = follow_volume(solid, cavity, fixed, targets, options=opts, volume_scale=V_ref)
    return np.array([s.pressure for s in hits]), path
