r"""Axisymmetric (r–z) hyperelastic kernel on scikit-fem: Q2 elements with mean dilatation.

Coordinates are ordered (r, z, θ). A displacement field (u_r, u_z)(r, z) gives the
deformation gradient

.. math:: F = \begin{pmatrix} 1 + u_{r,r} & u_{r,z} & 0 \\ u_{z,r} & 1 + u_{z,z} & 0 \\
          0 & 0 & 1 + u_r / r \end{pmatrix},

the hoop stretch :math:`F_{θθ} = 1 + u_r/r` being the only term that is not a gradient.
Volumes carry the factor :math:`dV_0 = 2π r\,dr\,dz`, so energies are N·mm of the
whole solid of revolution and pressure × volume balances them exactly.

Locking: the rubber is nearly incompressible (κ ≫ μ). The element is the biquadratic
9-node quadrilateral (Q2) with a discontinuous **linear** dilatation/pressure per element
(Q2/P1disc, the generalised mean dilatation): the decoupled energy
:math:`ψ = ψ_{iso}(F) + U(J)` is integrated as

.. math:: Π = \int ψ_{iso}(F)\,dV_0 + \int U(Θ)\,dV_0, \qquad Θ = Π_h J,

:math:`Π_h` the element-wise L2 projection (weight :math:`dV_0`) onto span{1, r, z}. That is
the Hu–Washizu three-field functional with element-wise linear dilatation and pressure,
condensed (exact for :math:`U = κ/2 (J-1)^2`, whose U' is affine). Q2/P1disc satisfies the
inf–sup condition, so the answers converge to the incompressible limit independently of
κ/μ (``tests/fem/test_axisym.py``: κ/μ = 10²…10⁵ against the incompressible thick-sphere closed
form). ``pressure="P0"`` gives the classical mean dilatation (Q2/P0, Simo–Taylor–Pister
1985); it is stable too, but a piecewise-constant pressure cannot follow the linear
through-thickness pressure of a bending plate: with n layers it loses 1/n² of the
volumetric share of the bending stiffness (plate 19 % too soft with 2 layers), which P1
represents exactly with one. Both parts of ψ come from the 3D material of
:mod:`softhand.fem.materials` through its ``split()``.

Assembly: the 18 × 18 element matrices of all elements come from one ``einsum`` over
quadrature points and are scattered into a CSR pattern built once (:class:`softhand.fem.assembly.DofScatter`).

:class:`~softhand.fem.axisym.RevolvedVolume` is the volume enclosed between a boundary curve of the mesh,
revolved about the axis, and the plane z = 0: the oil volume of a reservoir sheet measured
from its clamp plane, or the cavity of a balloon modelled with a z = 0 symmetry plane.
"""
from __future__ import annotations

import numpy as np
from skfem import Basis, ElementQuad2, ElementVector

from softhand.fem import kinematics as kin
from softhand.fem.assembly import DofScatter

__all__ = ["AxisymSolid", "RevolvedVolume"]


class AxisymSolid:
    """Nearly incompressible hyperelastic solid of revolution on a quadrilateral r–z mesh.

    ``material`` is a :mod:`softhand.fem.materials` law whose ``split()`` gives (isochoric law,
    volumetric part with ``U, dU, ddU``); the volumetric part enters through the mean
    dilatation. ``intorder`` 4 integrates the Q2 stiffness (and the 1/r terms) well.
    """

    def __init__(self, mesh, material, *, intorder: int = 4, pressure: str = "P1"):
        self.mesh = mesh
        self.iso, self.vol = material.split()
        if self.vol is None:
            raise ValueError("the axisymmetric kernel needs a material with a volumetric part")
        self.basis = Basis(mesh, ElementVector(ElementQuad2()), intorder=intorder)
        x = self.basis.mapping.F(self.basis.X)  # (2, nel, nqp) reference r, z [mm]
        self.r0 = x[0]
        self.wdV = 2.0 * np.pi * self.r0 * self.basis.dx  # (nel, nqp) [mm^3]
        self.proj = _projection(x, self.wdV, pressure)  # (nel, nqp, nqp)
        self.G = self._gradient_operators()  # (18, 3, 3, nel, nqp)
        self.G5 = self.G[:, _I5, _J5]  # (18, 5, nel, nqp): its non-zero components
        self.dofs = self.basis.element_dofs  # (18, nel)
        self.scatter = DofScatter(self.dofs, self.basis.N)

    @property
    def ndofs(self) -> int:
        return self.basis.N

    def _gradient_operators(self):
        """Per local basis function a: dF/du_a, (3, 3) per quadrature point."""
        nb = self.basis.Nbfun
        G = np.zeros((nb, 3, 3, *self.r0.shape))
        for a in range(nb):  # 18 local basis functions, not elements
            phi = self.basis.basis[a][0]
            G[a, :2, :2] = phi.grad
            G[a, 2, 2] = np.asarray(phi)[0] / self.r0
        return G

    def deformation_gradient(self, u):
        """F (3, 3, nel, nqp) of the nodal displacement vector u (ndofs,) [mm]."""
        H = np.einsum("ae,aijeq->ijeq", u[self.dofs], self.G)
        return H + np.eye(3)[:, :, None, None]

    def _dilatation(self, J):
        """Θ = Π_h J at the quadrature points (nel, nqp)."""
        return np.einsum("eqk,ek->eq", self.proj, J)

    def energy(self, u) -> float:
        """Stored strain energy Π [N·mm] of the solid of revolution."""
        F = self.deformation_gradient(u)
        U = self.vol.U(self._dilatation(kin.det(F)))
        return float(((self.iso.energy(F) + U) * self.wdV).sum())

    def _pressure(self, F):
        """Θ and the projected pressure Π_h U'(Θ) at the quadrature points."""
        theta = self._dilatation(kin.det(F))
        return theta, self._dilatation(self.vol.dU(theta))

    def residual(self, u):
        """Internal force vector dΠ/du (ndofs,) [N]."""
        F = self.deformation_gradient(u)
        _, p = self._pressure(F)
        S = self.iso.stress(F) + p * kin.cofactor(F)
        fe = np.einsum("ijeq,aijeq,eq->ae", S, self.G, self.wdV)
        return self.scatter.vector(fe)

    def tangent(self, u):
        """Tangent stiffness d²Π/du² (CSR, pattern reused) [N/mm].

        Per quadrature point everything acts on the five non-zero components of dF
        (rr, rz, zr, zz, θθ): K_ab = ∫ G_a · [A_iso + p J (F^-T ⊗ F^-T - F^-T ⊠ F^-1)] · G_b
        + ∫ U''(Θ) dΘ_a dΘ_b, with dΘ_a = Π_h(J F^-T : G_a).
        """
        F = self.deformation_gradient(u)
        theta, p = self._pressure(F)
        J = kin.det(F)
        FiT = kin.inv_transpose(F)[_I5, _J5]  # (5, nel, nqp)
        Finv = np.swapaxes(kin.inv_transpose(F), 0, 1)
        D = Finv[_J5[:, None], _I5[None, :]] * Finv[_J5[None, :], _I5[:, None]]  # F^-1_Jk F^-1_Li
        C = self.iso.tangent(F)[_I5[:, None], _J5[:, None], _I5[None, :], _J5[None, :]]
        C += (J * p) * (FiT[:, None] * FiT[None, :] - D)
        Ke = np.einsum("aIeq,IJeq,bJeq,eq->abe", self.G5, C, self.G5, self.wdV, optimize=True)
        dtheta = np.einsum("eqk,aek->aeq", self.proj, J * np.einsum("Ieq,aIeq->aeq", FiT, self.G5))
        Ke += np.einsum("aeq,beq,eq->abe", dtheta, dtheta, self.vol.ddU(theta) * self.wdV,
                        optimize=True)
        return self.scatter.matrix(Ke)

    def stretches(self, u):
        """Principal stretches at quadrature points: (in-plane max, in-plane min, hoop), each (nel, nqp)."""
        F = self.deformation_gradient(u)
        C = np.einsum("kieq,kjeq->ijeq", F[:2, :2], F[:2, :2])
        mean, diff = (C[0, 0] + C[1, 1]) / 2, np.hypot((C[0, 0] - C[1, 1]) / 2, C[0, 1])
        return np.sqrt(mean + diff), np.sqrt(np.maximum(mean - diff, 0.0)), F[2, 2]


#: the components of an axisymmetric dF that can be non-zero: rr, rz, zr, zz, θθ
_I5, _J5 = np.array([0, 0, 1, 1, 2]), np.array([0, 1, 0, 1, 2])


def _projection(x, wdV, space: str):
    """Element-wise L2 projection onto P0 or P1 = span{1, r, z}: (nel, nqp, nqp), weights wdV."""
    if space == "P0":
        Q = np.ones((1, *wdV.shape))
    elif space == "P1":
        c = (x * wdV).sum(axis=2, keepdims=True) / wdV.sum(axis=1)[:, None]
        scale = np.ptp(x, axis=2, keepdims=True)
        Q = np.concatenate([np.ones((1, *wdV.shape)), (x - c) / scale])
    else:
        raise ValueError(f"pressure space {space!r}: allowed 'P0', 'P1'")
    Mass = np.einsum("keq,leq,eq->ekl", Q, Q, wdV)
    return np.einsum("keq,ekl,lep,ep->eqp", Q, np.linalg.inv(Mass), Q, wdV)


# Quadratic Lagrange shape functions on a facet, ξ in [0, 1]: start, middle, end nodes
_XI, _W = np.polynomial.legendre.leggauss(4)
_XI, _W = (_XI + 1) / 2, _W / 2
_N = np.array([(1 - _XI) * (1 - 2 * _XI), 4 * _XI * (1 - _XI), _XI * (2 * _XI - 1)])  # (3, nq)
_DN = np.array([4 * _XI - 3, 4 - 8 * _XI, 4 * _XI - 1])  # d/dξ


class RevolvedVolume:
    r"""Volume between the boundary ``facets`` (revolved) and the plane z = 0.

    .. math:: V = -π \int r^2\,dz

    along the curve traversed with the solid on its left (for a sheet's underside: from the
    axis outwards). Exact for Q2 displacements on straight or quadratic (``MeshQuad2``)
    facets: 4-point Gauss on a degree-5 integrand.
    ``value``, ``gradient`` and ``hessian`` are those of V(u) [mm³, mm², mm].
    """

    def __init__(self, solid: AxisymSolid, facets):
        basis, mesh = solid.basis, solid.mesh
        facets = np.asarray(facets)
        v0, v1 = mesh.facets[:, facets]
        mid = mesh.p[:, mesh.t[:4, mesh.f2t[0, facets]]].mean(axis=1)
        tang = mesh.p[:, v1] - mesh.p[:, v0]
        into_solid = mid - (mesh.p[:, v0] + mesh.p[:, v1]) / 2
        flip = (-tang[1] * into_solid[0] + tang[0] * into_solid[1]) < 0  # solid on the right
        v0, v1 = np.where(flip, v1, v0), np.where(flip, v0, v1)
        nd, fd = basis.nodal_dofs, basis.facet_dofs
        self.r_dofs = np.array([nd[0, v0], fd[0, facets], nd[0, v1]])  # (3, nf)
        self.z_dofs = np.array([nd[1, v0], fd[1, facets], nd[1, v1]])
        self.X = np.array([basis.doflocs[0, self.r_dofs], basis.doflocs[1, self.z_dofs]])  # (2, 3, nf)
        self.ndofs = basis.N
        self.scatter = DofScatter(np.concatenate([self.r_dofs, self.z_dofs]), self.ndofs)  # (6, nf)

    def _geometry(self, u):
        r = self.X[0] + u[self.r_dofs]
        z = self.X[1] + u[self.z_dofs]
        return np.einsum("iq,if->qf", _N, r), np.einsum("iq,if->qf", _DN, z)  # r, dz/dξ

    def value(self, u) -> float:
        r, dz = self._geometry(u)
        return float(-np.pi * np.einsum("q,qf->", _W, r**2 * dz))

    def gradient(self, u):
        r, dz = self._geometry(u)
        g_r = -2 * np.pi * np.einsum("q,iq,qf->if", _W, _N, r * dz)
        g_z = -np.pi * np.einsum("q,iq,qf->if", _W, _DN, r**2)
        return self.scatter.vector(np.concatenate([g_r, g_z]))

    def hessian(self, u):
        r, dz = self._geometry(u)
        nf = r.shape[1]
        H = np.zeros((6, 6, nf))
        H[:3, :3] = -2 * np.pi * np.einsum("q,iq,jq,qf->ijf", _W, _N, _N, dz)
        H[:3, 3:] = -2 * np.pi * np.einsum("q,iq,jq,qf->ijf", _W, _N, _DN, r)
        H[3:, :3] = np.swapaxes(H[:3, 3:], 0, 1)
        return self.scatter.matrix(H)
