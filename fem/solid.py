r"""Hyperelastic solid on quadratic tetrahedra: energy, residual, tangent; vectorised kernels.

Unknown: the displacement u, a vector P2 field numbered like scikit-fem's
``ElementVector(ElementTetP2())`` (dof ``3 s + a`` = component a of scalar dof s).

Formulations
------------
``"displacement"``: :math:`\Pi(u) = \int_{\Omega_0} \psi(F)\,dV`.

``"mean_dilatation"`` (default when the law has a volumetric part, e.g. NeoHookean):
the P2-P0 three-field (u, p, theta) Hu-Washizu formulation with the element-wise
constant pressure p and dilatation theta condensed out on each element,

.. math::
    \Pi(u) = \int_{\Omega_0} \psi_\text{dev}(F)\,dV + \sum_e V_e\,U(\bar J_e),\qquad
    \bar J_e = \frac{1}{V_e}\int_{\Omega_e} J\,dV,

with element pressure :math:`p_e = U'(\bar J_e)`. The volume constraint is
enforced once per element instead of once per quadrature point, which removes
volumetric locking (P2-P0 is inf-sup stable); as kappa -> inf it converges to the
incompressible solution (tests/fem/test_solid.py: the plane-strain tube gives the
same answer for kappa/mu = 1e2..1e5). Its exact tangent is

.. math::
    K_e = \int (A_\text{dev} + p_e \partial^2 J/\partial F^2)\,{:}\,\nabla\delta u\,\nabla\Delta u
        + \frac{U''(\bar J_e)}{V_e}\,b_e b_e^T,\qquad
    b_e = \int_{\Omega_e} \operatorname{cof}F : \nabla\delta u\,dV .

Newton for nearly incompressible rubber: the residual above is a penalty-like
function of u; after a Newton step its element pressures U'(Jbar) are off by
kappa times the second-order volume error, which poisons the next tangent's
geometric term. The mixed (u, p) iteration keeps the P0 pressure linearised at the
previous iterate instead (:class:`~softhand.fem.mixed.PressureAnchor`, :class:`~softhand.fem.mixed.MixedNewton`, passed as
``anchor=``); it is the Newton method of the uncondensed three-field problem and
converges in ~4-5 full steps for kappa/mu = 1e2..1e5 alike (tests/fem/test_solid.py),
where the displacement iteration needs cut-backs or diverges (kappa/mu >= 1e4).

Kernels: F, P and A are evaluated once per iterate at all quadrature points; the
element matrices come from two batched matrix products over all basis pairs,
written in a block layout that needs no transposed copy into one buffer for the
whole mesh (kept between iterates: nel (3 nloc)^2 doubles, 117 MB at 80k DOFs), and
scattered by :class:`softhand.fem.assembly.ElementScatter` into a CSR pattern built once, in
one pass (the kernels: :mod:`softhand.fem.solid_kernels`). Elements are processed in chunks
(memory of the intermediates), never one by one, the chunks side by side in threads
(:mod:`softhand.fem.threads`).
"""
from __future__ import annotations

import copy

import numpy as np
import scipy.sparse as sp
from skfem import Basis, ElementTetP2

from softhand.fem import kinematics as kin
from softhand.fem import threads
from softhand.fem.assembly import ElementScatter, Restriction
from softhand.fem.materials import Volumetric
from softhand.fem.mixed import PressureAnchor
from softhand.fem.solid_kernels import ElementKernels

__all__ = ["FORMULATIONS", "Solid"]

FORMULATIONS = ("mean_dilatation", "displacement")


class Solid(ElementKernels):
    """A hyperelastic body: ``Solid(mesh, law)``; see the module docstring for the formulations.

    mesh: skfem MeshTet or MeshTet2 (quadratic geometry); law: a :mod:`softhand.fem.materials` law
    (fiber directions per element, shape (3, nel), or per quadrature point, (3, nel, nqp));
    intorder: quadrature degree (default 2: 4 points, exact for linear P2 stiffness);
    chunk: elements per vectorised batch (bounds the memory of element matrices).
    """

    def __init__(self, mesh, law, *, element=None, intorder: int = 2,
                 formulation: str | None = None, chunk: int = threads.CHUNK):
        self.mesh, self.law = mesh, law
        self.element = element or ElementTetP2()
        self.sbasis = Basis(mesh, self.element, intorder=intorder)
        dev, vol = law.split()
        formulation = formulation or ("mean_dilatation" if vol is not None else "displacement")
        if formulation not in FORMULATIONS:
            raise ValueError(f"formulation {formulation!r} not in {FORMULATIONS}")
        self.formulation = formulation
        self._dev, self._vol = (dev, vol) if formulation == "mean_dilatation" else (law, None)
        nloc = self.sbasis.Nbfun
        #: (nel, nqp, nloc, 3) reference gradients of the scalar shape functions
        self.G = np.stack([self.sbasis.basis[i][0].grad for i in range(nloc)]).transpose(2, 3, 0, 1).copy()
        self.W = np.asarray(self.sbasis.dx)  # (nel, nqp) quadrature weights x |det J|
        self.scatter = ElementScatter(self.sbasis.element_dofs, self.sbasis.N)
        self.ndofs = self.scatter.n
        nel = self.G.shape[0]
        self._chunks = [slice(i, min(i + chunk, nel)) for i in range(0, nel, chunk)]
        self._ke = None  # the element matrix buffer, allocated at the first tangent

    def with_bulk_modulus(self, kappa: float) -> "Solid":
        """The same body (mesh, quadrature, scatter shared) with its mean-dilatation volume energy
        U(J) = kappa/2 (J - 1)^2 at another bulk modulus [MPa], e.g. a softer rubber to follow a
        load path in full Newton steps (:mod:`softhand.fem.hand.finger_sweep`)."""
        if self._vol is None:
            raise ValueError("with_bulk_modulus needs the mean-dilatation formulation")
        soft = copy.copy(self)
        soft._vol, soft._ke = Volumetric(float(kappa)), None
        soft.law = None  # no single law: the deviatoric part's and this volume energy
        return soft

    @property
    def parts(self) -> tuple:
        """(the law's isochoric part, its volumetric part or None): what the formulation
        integrates (the displacement formulation: (the whole law, None))."""
        return self._dev, self._vol

    # -- dofs ---------------------------------------------------------------------------
    def dofs(self, facets=None, components=(0, 1, 2)) -> np.ndarray:
        """Vector dofs of the given components on a boundary (name, facet indices, or all if None)."""
        s = self.sbasis.get_dofs(facets).all() if facets is not None else np.arange(self.sbasis.N)
        return np.sort((3 * s[:, None] + np.asarray(components)[None, :]).ravel())

    def free_dofs(self, fixed) -> np.ndarray:
        """The complement of ``fixed`` (sorted)."""
        return np.setdiff1d(np.arange(self.ndofs), fixed)

    def nodal(self, u: np.ndarray) -> np.ndarray:
        """u as (3, n_scalar) at the scalar dofs (first the mesh vertices, then P2 edge dofs)."""
        return u.reshape(-1, 3).T

    @property
    def dof_locations(self) -> np.ndarray:
        """Reference coordinates (3, n_scalar) of the scalar dofs."""
        return self.sbasis.doflocs

    def reaction(self, u: np.ndarray, facets, *, about=None, external=None):
        """Resultant force [N] (3,) that the supports on ``facets`` exert on the body, and its
        moment [N mm] (3,) about the point ``about`` (None: no moment), at equilibrium state u.

        The support's force on a dof is the residual of the body without it, f_int - f_ext
        (``external``: the external force vector f_ext, e.g. a follower pressure's, if any acts
        on those dofs), summed per component; the moment uses the deformed positions X + u
        of the facets' dofs.
        """
        dofs = self.dofs(facets)
        f = self.residual(u) if external is None else self.residual(u) - external
        forces = f[dofs].reshape(-1, 3)
        resultant = forces.sum(axis=0)
        if about is None:
            return resultant, None
        scalar = dofs.reshape(-1, 3)[:, 0] // 3
        x = self.dof_locations[:, scalar].T + self.nodal(u)[:, scalar].T - np.asarray(about, float)
        return resultant, np.cross(x, forces).sum(axis=0)

    # -- kinematics -------------------------------------------------------------------
    def F(self, u: np.ndarray, elements=slice(None)) -> np.ndarray:
        """Deformation gradient (3, 3, ne, nqp) at the quadrature points of the elements."""
        ue = u[self.scatter.vector_dofs(elements)].reshape(-1, self.G.shape[2], 3)
        grad_u = np.einsum("ena,eqnk->akeq", ue, self.G[elements], optimize=True)
        return kin.deformation_gradient(grad_u)

    def element_pressure(self, u: np.ndarray) -> np.ndarray:
        """Mean-dilatation pressure p_e = U'(Jbar_e) [MPa] per element (zeros if displacement)."""
        if self._vol is None:
            return np.zeros(self.G.shape[0])
        return self._vol.dU(self._jbar(kin.det(self.F(u)), slice(None)))

    def first_piola(self, u: np.ndarray) -> np.ndarray:
        """First Piola-Kirchhoff stress (3, 3, nel, nqp) of the formulation (incl. p_e cof F)."""
        F = self.F(u)
        P = self._dev.stress(F)
        if self._vol is not None:
            P = P + self.element_pressure(u)[:, None] * kin.cofactor(F)
        return P

    def _jbar(self, J, elements):
        W = self.W[elements]
        return (W * J).sum(axis=1) / W.sum(axis=1)

    # -- energy, residual, tangent ----------------------------------------------------
    def energy(self, u: np.ndarray) -> float:
        """Stored energy Pi(u) [N mm]."""
        total = 0.0
        for c in self._chunks:
            F = self.F(u, c)
            total += np.sum(self.W[c] * self._dev.take(c).energy(F))
            if self._vol is not None:
                Jbar = self._jbar(kin.det(F), c)
                total += np.sum(self.W[c].sum(axis=1) * self._vol.U(Jbar))
        return float(total)

    def residual(self, u: np.ndarray) -> np.ndarray:
        """Internal force dPi/du [N], shape (ndofs,)."""
        return self._assemble(u, tangent=False)[0]

    def tangent(self, u: np.ndarray, anchor: "PressureAnchor | None" = None) -> sp.csr_matrix:
        """Stiffness d^2 Pi/du^2, CSR with the fixed pattern (symmetric); see ``anchor`` below."""
        return self.scatter.csr(self._assemble(u, tangent=True, anchor=anchor)[1])

    def residual_tangent(self, u: np.ndarray, anchor: "PressureAnchor | None" = None,
                         restriction: "Restriction | None" = None):
        """(residual, tangent CSR) in one pass over the elements.

        restriction: a :class:`softhand.fem.assembly.Restriction` (e.g. to the free dofs): returns
        (R[keep], K[keep][:, keep]), the tangent scattered straight into the restricted
        pattern (no full matrix and no gather per Newton iterate).

        anchor: for the mean-dilatation formulation, the mixed (u, p) Newton iteration:
        the element pressure in the geometric stiffness p_e d^2J/dF^2 is the pressure
        linearised at the last accepted Newton iterate (``self.anchor(u_k)``) instead of
        U'(Jbar(u)). The residual is unchanged (so is the solution); Newton then
        converges in a number of iterations independent of kappa/mu (see
        :class:`~softhand.fem.mixed.MixedNewton`), where the plain displacement iteration needs many more
        and diverges for kappa/mu >~ 1e4.
        """
        if restriction is not None:
            R, Ke = self._assemble(u, tangent=True, anchor=anchor, scatter=False)
            return restriction.vector(R), restriction.block_matrix(self.scatter, Ke)
        R, data = self._assemble(u, tangent=True, anchor=anchor)
        return R, self.scatter.csr(data)

    def residual_tangent_data(self, u: np.ndarray, anchor: "PressureAnchor | None" = None):
        """(residual, CSR data array) for callers that add terms in the same pattern."""
        return self._assemble(u, tangent=True, anchor=anchor)

    def residual_element_matrices(self, u: np.ndarray, anchor: "PressureAnchor | None" = None, extra=None):
        """(residual, element matrices in the block layout of
        :func:`softhand.fem.solid_kernels.element_matrices`, not yet
        scattered) for callers that add element terms of their own before the one scatter
        (:meth:`softhand.fem.assembly.ElementScatter.block_matrix_data`); the buffer is reused by the
        next call.

        extra(c) -> (re, L, R, S): terms of another energy on the same elements (e.g. the
        finger's windings), per chunk c of elements: element residuals re (ne, 3 nloc) and the
        element matrices sum_k L[e, (n a), k] R[e, k, (b m)] + delta_ab S[e, n, m]
        (:func:`softhand.fem.lowrank.write_matrices`), computed in the same pass and the same product."""
        return self._assemble(u, tangent=True, anchor=anchor, scatter=False, extra=extra)

    def anchor(self, u: np.ndarray) -> "PressureAnchor | None":
        """The element pressures linearised at u (None for the displacement formulation)."""
        if self._vol is None:
            return None
        p0, c0, b = [], [], []
        for c in self._chunks:
            F, W, GW = self.F(u, c), self.W[c], self.G[c] * self.W[c][:, :, None, None]
            Ve = W.sum(axis=1)
            Jbar = (W * kin.det(F)).sum(axis=1) / Ve
            p0.append(self._vol.dU(Jbar))
            c0.append(self._vol.ddU(Jbar) / Ve)
            b.append(np.einsum("akeq,eqnk->ena", kin.cofactor(F), GW, optimize=True).reshape(len(W), -1))
        return PressureAnchor(u.copy(), np.concatenate(p0), np.concatenate(c0), np.concatenate(b))

    def _assemble(self, u, tangent, anchor=None, scatter=True, extra=None):
        """(R, CSR data of the tangent or None); scatter=False: (R, the element matrix buffer)."""
        R = np.zeros(self.ndofs)
        Ke = self._element_matrix_buffer() if tangent else None

        def kernels(c):  # in a thread: writes only its own chunk of Ke
            p_geo = None if anchor is None else anchor.pressure(u, c, self.scatter.vector_dofs(c))
            return self._element_kernels(u, c, None if Ke is None else Ke[c], p_geo,
                                         None if extra is None else extra(c))

        self.scatter.add_chunk_vectors(R, threads.map_chunks(kernels, self._chunks))
        if not tangent or not scatter:
            return R, Ke
        return R, self.scatter.block_matrix_data(Ke)

    def _element_matrix_buffer(self) -> np.ndarray:
        """The element matrices of the whole mesh, block layout (see
        :func:`softhand.fem.solid_kernels.element_matrices`)."""
        if self._ke is None:
            nel, _, nloc, _ = self.G.shape
            self._ke = np.empty((nel, nloc, 3, 3, nloc))
        return self._ke
