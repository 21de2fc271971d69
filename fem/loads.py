r"""Surface loads and cavity volume on the solid's boundary facets.

Sign convention: facets are boundary facets of the solid; N is the reference unit
normal pointing OUT of the solid (into the cavity for a cavity wall); by Nanson
:math:`n\,da = \operatorname{cof}F\,N\,dA`. Residuals follow R = f_int - f_ext, so
a load term adds :math:`-f_\text{ext}` to R and :math:`-\partial f_\text{ext}/\partial u` to K.

Follower pressure p > 0 pushes the wall away from the cavity (traction -p n):

.. math::
    f_\text{ext} = -p \int_{\Gamma_0} \operatorname{cof}F\,N\cdot\delta u\,dA,\qquad
    K_p[\delta u, \Delta u] = p\int_{\Gamma_0} \delta u\cdot
        \bigl(\partial\operatorname{cof}F[\nabla\Delta u]\,N\bigr)\,dA ,

with :math:`(\partial\operatorname{cof}F[G]N)_b = \varepsilon_{bjk}\varepsilon_{JKL}G_{jK}F_{kL}N_J`
(no inverse needed). K_p is unsymmetric on an open surface.

Cavity volume enclosed by the wall facets (x = X + u):

.. math::
    V = -\int_{\Gamma_0} x\cdot D\,\operatorname{cof}F\,N\,dA,\qquad
    D = \tfrac13 I \text{ (closed wall)}\ \text{or}\ D = e_k\otimes e_k ,

the minus because N points into the cavity. ``symmetry_normal=k`` gives
:math:`V = -\int x_k n_k\,da`: on a symmetry plane x_k = 0 (k its normal
component), so a half (or quarter) model needs only its wall facets, and a lid in
a plane x_k = 0 needs none either. The wall must close the cavity together with
such planes. Its gradient and Hessian are exact derivatives of this formula;
for a closed cavity :math:`\partial V/\partial u = f_\text{ext}/p`.

Volume control (Lagrangian :math:`\Pi(u) - p\,(V(u) - V^*)`, pressure p the
multiplier) gives the symmetric bordered system :func:`volume_control`.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from softhand.fem import kinematics as kin
from softhand.fem.compiled import cavity as cavity_kernels
from softhand.fem.kinematics import EPS
from softhand.fem.mapping import facet_basis


class _Facets:
    """Facet quadrature data of the solid's scalar basis on a set of boundary facets."""

    def __init__(self, solid, facets, intorder: int | None = None):
        self.solid = solid
        fb = facet_basis(solid.mesh, solid.element, facets=facets,
                         intorder=intorder if intorder is not None else 4)
        nloc = fb.Nbfun
        self.elements = np.asarray(fb.tind)
        self.N = np.asarray(fb.normals)  # (3, nf, nq), outward of the solid
        self.W = np.asarray(fb.dx)  # (nf, nq)
        self.phi = np.stack([np.asarray(fb.basis[i][0]) for i in range(nloc)], axis=-1)  # (nf, nq, nloc)
        self.G = np.stack([fb.basis[i][0].grad for i in range(nloc)]).transpose(2, 3, 0, 1).copy()
        self.X = np.asarray(fb.global_coordinates())  # (3, nf, nq)
        self.vdofs = solid.scatter.vector_dofs(self.elements)  # (nf, 3 nloc)
        self._positions = None  # see add_matrix_data

    def fields(self, u):
        """x (3, nf, nq) and F (3, 3, nf, nq) at the facet quadrature points."""
        ue = u[self.vdofs].reshape(len(self.elements), -1, 3)
        x = self.X + np.einsum("ena,eqn->aeq", ue, self.phi)
        F = kin.deformation_gradient(np.einsum("ena,eqnk->akeq", ue, self.G, optimize=True))
        return x, F

    def vector(self, fe):
        """Scatter (nf, nloc, 3) facet-element vectors into a full dof vector."""
        out = np.zeros(self.solid.ndofs)
        self.solid.scatter.add_vector(out, fe.reshape(len(self.elements), -1), self.elements)
        return out

    def matrix_data(self, Ke):
        """Scatter (nf, nloc, 3, nloc, 3) matrices into CSR data in the solid's pattern."""
        data = np.zeros(self.solid.scatter.nnz)
        self.add_matrix_data(data, Ke)
        return data

    def add_matrix_data(self, data, Ke, factor: float = 1.0) -> None:
        """data += factor * the scatter of (nf, nloc, 3, nloc, 3) matrices, touching only the
        positions these facets' elements reach (a few % of the solid's pattern: no pass over
        all of data, which costs more than the facet terms themselves)."""
        if self._positions is None:  # (the distinct CSR positions, each entry's index among them)
            pos = self.solid.scatter.positions(self.elements).ravel()
            self._positions = np.unique(pos, return_inverse=True)
        where, inverse = self._positions
        data[where] += factor * np.bincount(inverse, weights=Ke.ravel(), minlength=len(where))


def _dcofN(F, N):
    """C[b, j, K] = d(cof F N)_b / dF_jK = eps_bjk eps_JKL F_kL N_J, shape (3, 3, 3, nf, nq)."""
    return np.einsum("bjk,JKL,kLeq,Jeq->bjKeq", EPS, EPS, F, N, optimize=True)


class FollowerPressure:
    """Follower (hydrostatic) pressure on boundary facets; see the module docstring for signs."""

    def __init__(self, solid, facets, *, intorder: int | None = None):
        self.f = _Facets(solid, facets, intorder)

    def residual(self, u, p: float) -> np.ndarray:
        """-f_ext = p int cof(F) N . phi dA [N], shape (ndofs,)."""
        _, F = self.f.fields(u)
        cofN = np.einsum("aKeq,Keq->aeq", kin.cofactor(F), self.f.N)
        return self.f.vector(p * np.einsum("aeq,eq,eqn->ena", cofN, self.f.W, self.f.phi))

    def tangent_data(self, u, p: float) -> np.ndarray:
        """Load stiffness -d f_ext/du as CSR data in the solid's pattern."""
        _, F = self.f.fields(u)
        C = _dcofN(F, self.f.N)
        Ke = p * np.einsum("eqn,bjKeq,eqmK,eq->enbmj", self.f.phi, C, self.f.G, self.f.W, optimize=True)
        return self.f.matrix_data(Ke)

    def tangent(self, u, p: float) -> sp.csr_matrix:
        """Load stiffness as CSR (unsymmetric in general)."""
        return self.f.solid.scatter.csr(self.tangent_data(u, p))


def dead_load(solid, facets, traction=None, *, pressure=None, intorder: int | None = None) -> np.ndarray:
    """External force vector f_ext [N] of a dead traction t [MPa] (3,) or a dead pressure p
    [MPa] (traction -p N on the reference configuration) on boundary facets."""
    f = _Facets(solid, facets, intorder)
    if pressure is not None:
        t = -pressure * f.N
    else:
        t = np.asarray(traction, dtype=float)[:, None, None] * np.ones_like(f.N)
    return f.vector(np.einsum("aeq,eq,eqn->ena", t, f.W, f.phi))


class CavityVolume:
    """Enclosed volume V(u) of a cavity from its wall facets, with gradient and Hessian.

    symmetry_normal: None for a wall that closes the cavity, or k in {0, 1, 2} when the
    cavity is closed by planes x_k = 0 (symmetry planes, or a lid lying in such a plane).
    """

    def __init__(self, solid, facets, *, symmetry_normal: int | None = None, intorder: int | None = None,
                 compiled: bool = True):
        self.f = _Facets(solid, facets, intorder)
        self.D = np.eye(3) / 3.0 if symmetry_normal is None else np.diag(np.eye(3)[symmetry_normal])
        #: the compiled gradient and Hessian (fem.compiled.cavity), or None: the NumPy forms below
        self.kernels = (cavity_kernels.CompiledCavity(self.f, np.diag(self.D))
                        if compiled and cavity_kernels.available() else None)

    def volume(self, u) -> float:
        """V [mm^3]."""
        x, F = self.f.fields(u)
        cofN = np.einsum("aKeq,Keq->aeq", kin.cofactor(F), self.f.N)
        return float(-np.einsum("aeq,ab,beq,eq->", x, self.D, cofN, self.f.W))

    value = volume  #: V(u), the name of every volume functional (:func:`volume_control`)

    def gradient(self, u, data=None, factor: float = 1.0) -> np.ndarray:
        """dV/du [mm^2], shape (ndofs,); with ``data`` (CSR data in the solid's pattern), also
        data += factor * d^2V/du^2 (:meth:`add_hessian_data`), in one pass where compiled."""
        if self.kernels is not None:
            return self.kernels.gradient(u, data, factor)
        if data is not None:
            self.add_hessian_data(data, u, factor)
        x, F = self.f.fields(u)
        cofN = np.einsum("aKeq,Keq->aeq", kin.cofactor(F), self.f.N)
        y = np.einsum("ab,beq->aeq", self.D, x)  # D x (D symmetric)
        W = self.f.W
        g = (np.einsum("ab,beq,eq,eqn->ena", self.D, cofN, W, self.f.phi, optimize=True)
             + np.einsum("beq,bjKeq,eq,eqnK->enj", y, _dcofN(F, self.f.N), W, self.f.G, optimize=True))
        return -self.f.vector(g)

    def hessian_data(self, u) -> np.ndarray:
        """d^2V/du^2 as CSR data in the solid's pattern (symmetric)."""
        data = np.zeros(self.f.solid.scatter.nnz)
        self.add_hessian_data(data, u)
        return data

    def _hessian_blocks(self, u) -> np.ndarray:
        """-d^2V/du^2 per wall facet, (nf, nloc, 3, nloc, 3) (minus: V carries a minus sign).

        The second-derivative term factorises: y_b eps_bac eps_JKL N_J = Y_ac M_KL with the
        skew matrices Y = [y]_x (y = D x) and M = [N]_x, so per point it is Y_ac s_nm with
        s_nm = grad phi_n . M grad phi_m (no 3^4 tensor per point and node pair).
        """
        x, F = self.f.fields(u)
        W, phi, G, N = self.f.W, self.f.phi, self.f.G, self.f.N
        y = np.einsum("ab,beq->aeq", self.D, x)
        DC = np.einsum("ab,bjKeq->eqajK", self.D, _dcofN(F, N))  # D dcofN, points first
        # phi_i . D dcof[grad phi_j] N  (i = (n, a), j = (m, c))
        H1 = np.einsum("eqn,eqacm->enamc", phi * W[:, :, None], np.matmul(DC, G.transpose(0, 1, 3, 2)[:, :, None]))
        # x . D d2cof[grad phi_i, grad phi_j] N = Y_ac (grad phi_n . M grad phi_m)
        Y = np.einsum("bac,beq->eqac", EPS, y)
        M = np.einsum("JKL,Jeq->eqKL", EPS, N)
        S = np.matmul(G, np.matmul(M, G.transpose(0, 1, 3, 2)))             # (e, q, n, m)
        H2 = np.einsum("eqac,eqnm->enamc", Y * W[:, :, None, None], S, optimize=True)
        return H1 + H1.transpose(0, 3, 4, 1, 2) + H2

    def add_hessian_data(self, data, u, factor: float = 1.0) -> None:
        """data += factor * d^2V/du^2, data: CSR data in the solid's pattern (only the
        positions of the wall's elements are touched)."""
        if self.kernels is not None:
            self.kernels.gradient(u, data, factor)
            return
        self.f.add_matrix_data(data, self._hessian_blocks(u), -factor)

    def hessian(self, u) -> sp.csr_matrix:
        return self.f.solid.scatter.csr(self.hessian_data(u))


def volume_control(R: np.ndarray, K: sp.spmatrix | None, p: float, cavity, u, V_target: float):
    """Bordered residual and Jacobian of Pi(u) - p (V(u) - V*), unknowns (u, p).

    R, K: residual and tangent of everything else at u (solid + other loads; K None: the
    residual alone); cavity: its volume functional (``value``, ``gradient``, ``hessian``:
    :class:`CavityVolume`, :class:`softhand.fem.axisym.RevolvedVolume`);
    returns (R_b (ndofs+1,), K_b CSR (ndofs+1)^2 or None, symmetric if K is):

        [ R - p dV/du ]      [ K - p d2V/du2   -dV/du ]
        [ -(V - V*)   ],     [ -dV/du^T          0    ]

    Restrict rows/columns to the free dofs plus the last (pressure) index.
    """
    g = cavity.gradient(u)
    Rb = np.append(R - p * g, -(cavity.value(u) - V_target))
    if K is None:
        return Rb, None
    gcol = sp.csr_matrix(-g[:, None])
    return Rb, sp.bmat([[K - p * cavity.hessian(u), gcol], [gcol.T, sp.csr_matrix((1, 1))]], format="csr")
