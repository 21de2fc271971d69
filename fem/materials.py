r"""Hyperelastic material laws: pure NumPy functions of the deformation gradient.

Every law takes ``F`` of shape ``(3, 3, *batch)`` and returns

- ``energy(F)``: strain energy density psi [MPa = N mm/mm^3], shape ``batch``;
- ``stress(F)``: first Piola-Kirchhoff stress P = dpsi/dF [MPa], shape ``(3, 3, *batch)``;
- ``tangent(F)``: A = dP/dF [MPa], shape ``(3, 3, 3, 3, *batch)`` indexed [a, K, b, L].

They know nothing of meshes, so the same laws serve the 3D solid and the
axisymmetric (r-z) kernel (which passes F with its hoop stretch in F[2, 2]).

Laws (J = det F, I1 = tr C, C = F^T F, F^{-T} = cof F / J):

.. math::
    \psi_\text{NH} &= \tfrac{\mu}{2}(J^{-2/3} I_1 - 3) + \tfrac{\kappa}{2}(J-1)^2
        \quad\text{(nearly incompressible, isochoric/volumetric split)}\\
    \psi_\text{cNH} &= \tfrac{\mu}{2}(I_1 - 3) - \mu\ln J + \tfrac{\lambda}{2}(\ln J)^2
        \quad\text{(compressible, the benchmark's)}\\
    \psi_\text{f} &= \tfrac{k}{2}(\lambda_f - 1)^2\,[\lambda_f > 1],\quad
        \lambda_f = |F a_0| \quad\text{(tension-only fiber family)}

Laws add up (``NeoHookean(...) + Fibers(...)``). A law with a volumetric part
offers ``split() -> (deviatoric_law, volumetric)``; the solid uses it for the
locking-free mean-dilatation (P2-P0) formulation, see :mod:`softhand.fem.solid`. A sum splits
into the sum of its parts' deviatoric laws and its one volumetric part, so
``NeoHookeanIsochoric(mu) + Volumetric(kappa)`` is split like ``NeoHookean(mu, kappa)``
(two volumetric parts are refused). Other rubber models: :mod:`softhand.fem.hyperelastic`.
Small-strain limits: NH -> Hooke with shear modulus mu and bulk modulus kappa;
cNH -> Hooke with Lame constants lambda, mu.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from softhand.fem import kinematics as kin


class Law:
    """Base: laws add up; an isotropic law needs no per-point data (``take`` is identity)."""

    def __add__(self, other: "Law") -> "Sum":
        return Sum(_parts(self) + _parts(other))

    def take(self, elements) -> "Law":
        """This law restricted to a subset of elements (per-element data sliced)."""
        return self

    def split(self):
        """(deviatoric law, volumetric part or None) for the mean-dilatation formulation."""
        return self, None


def _parts(law) -> tuple:
    return law.parts if isinstance(law, Sum) else (law,)


@dataclass(frozen=True)
class Volumetric(Law):
    r"""Volumetric energy U(J) = kappa/2 (J - 1)^2, used alone or by the mean-dilatation solid."""

    kappa: float  #: bulk modulus [MPa]

    def split(self):
        """All volumetric: ``law + Volumetric(kappa)`` then splits into (law, this)."""
        return None, self

    def U(self, J):
        """U(J) [MPa]."""
        return 0.5 * self.kappa * (J - 1.0) ** 2

    def dU(self, J):
        """U'(J): the pressure-like quantity [MPa]."""
        return self.kappa * (J - 1.0)

    def ddU(self, J):
        """U''(J) [MPa]."""
        return self.kappa * np.ones_like(J)

    def energy(self, F):
        return self.U(kin.det(F))

    def stress(self, F):
        return self.dU(kin.det(F)) * kin.cofactor(F)

    def tangent(self, F):
        J, cof = kin.det(F), kin.cofactor(F)
        return self.ddU(J) * kin.outer(cof, cof) + self.dU(J) * kin.d2det(F)


@dataclass(frozen=True)
class NeoHookeanIsochoric(Law):
    r"""Isochoric Neo-Hookean part mu/2 (J^{-2/3} I1 - 3)."""

    mu: float  #: shear modulus [MPa]

    def energy(self, F):
        J = kin.det(F)
        return 0.5 * self.mu * (J ** (-2.0 / 3.0) * np.einsum("aK...,aK...->...", F, F) - 3.0)

    def stress(self, F):
        J = kin.det(F)
        I1 = np.einsum("aK...,aK...->...", F, F)
        return self.mu * J ** (-2.0 / 3.0) * (F - I1 / 3.0 * kin.inv_transpose(F))

    def tangent(self, F):
        J = kin.det(F)
        I1 = np.einsum("aK...,aK...->...", F, F)
        Fi = kin.inv_transpose(F)
        delta = np.einsum("ab,KL->aKbL", np.eye(3), np.eye(3))
        delta = delta.reshape(delta.shape + (1,) * (F.ndim - 2))
        A = (delta - 2.0 / 3.0 * (kin.outer(F, Fi) + kin.outer(Fi, F))
             + 2.0 / 9.0 * I1 * kin.outer(Fi, Fi) + I1 / 3.0 * kin.outer_swap(Fi, Fi))
        return self.mu * J ** (-2.0 / 3.0) * A


class SplitLaw(Law):
    """A law defined by its ``split()`` (isochoric part, volumetric part): energy, stress and
    tangent are the sums of the parts'."""

    def energy(self, F):
        dev, vol = self.split()
        return dev.energy(F) + vol.energy(F)

    def stress(self, F):
        dev, vol = self.split()
        return dev.stress(F) + vol.stress(F)

    def tangent(self, F):
        dev, vol = self.split()
        return dev.tangent(F) + vol.tangent(F)


@dataclass(frozen=True)
class NeoHookean(SplitLaw):
    r"""Nearly incompressible Neo-Hookean rubber: mu/2 (J^{-2/3} I1 - 3) + kappa/2 (J - 1)^2.

    The default kappa = 1000 mu (Poisson's ratio 0.4995) makes the rubber nearly incompressible.
    """

    mu: float = 1.15  #: initial shear modulus [MPa]
    kappa: float | None = None  #: bulk modulus [MPa]; None -> 1000 mu

    def __post_init__(self):
        if self.kappa is None:
            object.__setattr__(self, "kappa", 1000.0 * self.mu)

    def split(self):
        return NeoHookeanIsochoric(self.mu), Volumetric(self.kappa)



@dataclass(frozen=True)
class CompressibleNeoHookean(Law):
    r"""mu/2 (I1 - 3) - mu ln J + lam/2 (ln J)^2 (the FEM benchmark's material)."""

    mu: float = 1.15  #: shear modulus [MPa]
    lam: float = 50.0  #: first Lame constant [MPa]

    def energy(self, F):
        lnJ = np.log(kin.det(F))
        I1 = np.einsum("aK...,aK...->...", F, F)
        return 0.5 * self.mu * (I1 - 3.0) - self.mu * lnJ + 0.5 * self.lam * lnJ ** 2

    def stress(self, F):
        lnJ = np.log(kin.det(F))
        return self.mu * F + (self.lam * lnJ - self.mu) * kin.inv_transpose(F)

    def tangent(self, F):
        lnJ = np.log(kin.det(F))
        Fi = kin.inv_transpose(F)
        delta = np.einsum("ab,KL->aKbL", np.eye(3), np.eye(3))
        delta = delta.reshape(delta.shape + (1,) * (F.ndim - 2))
        return (self.mu * delta + self.lam * kin.outer(Fi, Fi)
                + (self.mu - self.lam * lnJ) * kin.outer_swap(Fi, Fi))


@dataclass(frozen=True, eq=False)
class Fibers(Law):
    r"""Tension-only fiber family psi = k/2 (lam_f - 1)^2 for lam_f = ``|F a0|`` > 1, else 0.

    ``a0``: reference fiber direction(s), shape ``(3,)`` or ``(3, *b)`` with b aligned with the
    LEADING batch axes of F (e.g. (3, nel) per element or (3, nel, nqp) per quadrature
    point for the solid's batch (nel, nqp)); normalised here.
    """

    k: float  #: fiber stiffness [MPa], >> mu for the nearly inextensible Kevlar windings
    a0: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))

    def __post_init__(self):
        a0 = np.asarray(self.a0, dtype=float)
        object.__setattr__(self, "a0", a0 / np.linalg.norm(a0, axis=0))

    def take(self, elements):
        return self if self.a0.ndim == 1 else Fibers(self.k, self.a0[:, elements])

    def _kinematics(self, F):
        a0 = self.a0.reshape(self.a0.shape + (1,) * (F.ndim - 1 - self.a0.ndim))
        f = np.einsum("aK...,K...->a...", F, a0)
        lam = np.sqrt(np.einsum("a...,a...->...", f, f))
        return a0, f, lam, lam > 1.0

    def stretch(self, F):
        """Fiber stretch ``|F a0|``, shape batch."""
        return self._kinematics(F)[2]

    def energy(self, F):
        _, _, lam, on = self._kinematics(F)
        return np.where(on, 0.5 * self.k * (lam - 1.0) ** 2, 0.0)

    def stress(self, F):
        a0, f, lam, on = self._kinematics(F)
        return np.where(on, self.k * (1.0 - 1.0 / lam), 0.0) * np.einsum("a...,K...->aK...", f, a0)

    def tangent(self, F):
        a0, f, lam, on = self._kinematics(F)
        fa = np.einsum("a...,K...->aK...", f, a0)
        aa = np.einsum("ab,K...,L...->aKbL...", np.eye(3), a0, a0)
        A = kin.outer(fa, fa) / lam ** 3 + (1.0 - 1.0 / lam) * aa
        return np.where(on, self.k, 0.0) * A


@dataclass(frozen=True)
class Sum(Law):
    """A sum of laws (e.g. rubber matrix + fiber family)."""

    parts: tuple

    def take(self, elements):
        return Sum(tuple(p.take(elements) for p in self.parts))

    def split(self):
        devs, vols = zip(*(p.split() for p in self.parts))
        vols = [v for v in vols if v is not None]
        devs = tuple(d for d in devs if d is not None)
        if len(vols) > 1:
            raise ValueError("at most one volumetric part per material")
        if not devs:
            raise ValueError("a material needs a deviatoric (isochoric) part besides its volumetric one")
        return Sum(devs), (vols[0] if vols else None)

    def energy(self, F):
        return sum(p.energy(F) for p in self.parts)

    def stress(self, F):
        return sum(p.stress(F) for p in self.parts)

    def tangent(self, F):
        return sum(p.tangent(F) for p in self.parts)
