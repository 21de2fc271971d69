"""The element kernels of :class:`softhand.fem.solid.Solid`: a chunk's element residuals and, with a
buffer, its element matrices in the block layout of :func:`~softhand.fem.solid_kernels.element_matrices`,
by the low-rank Neo-Hookean kernel (:mod:`softhand.fem.lowrank`) or the general one for any law.
"""
from __future__ import annotations

import numpy as np

from softhand.fem import kinematics as kin
from softhand.fem.lowrank import neo_hookean_terms, write_matrices
from softhand.fem.materials import NeoHookeanIsochoric


class ElementKernels:
    """The element kernels, a base of :class:`softhand.fem.solid.Solid`, which provides what they
    read: ``F(u, elements)``, the reference gradients ``G`` (nel, nqp, nloc, 3), the weights ``W``
    (nel, nqp), the deviatoric law ``_dev`` and the volumetric part ``_vol`` (None: the
    displacement formulation)."""

    def _element_kernels(self, u, c, Ke=None, p_geo=None, extra=None):
        """Element residuals (ne, 3nloc) of chunk c; with Ke (its slice of the element matrix
        buffer), the element matrices are written into it; extra: (re, L, R, S) of another
        energy's terms on these elements
        (:meth:`softhand.fem.solid.Solid.residual_element_matrices`), added.

        The Neo-Hookean isochoric law takes the low-rank kernel of :mod:`softhand.fem.lowrank` (no
        fourth-order tangent per point); any other law the general :func:`element_matrices`."""
        if Ke is not None and type(self._dev) is NeoHookeanIsochoric:
            return self._neo_hookean_kernels(u, c, Ke, p_geo, extra)
        re = self._general_kernels(u, c, Ke, p_geo)
        if extra is not None:
            re = re + extra[0]
            if Ke is not None:
                write_matrices(Ke, extra[1], extra[2], extra[3], add=True)
        return re

    def _stress_and_volume(self, F, c):
        """(P of the formulation, cof F, Ve, Jbar, p_e) of chunk c; the last four None
        without a volumetric part."""
        P = self._dev.take(c).stress(F)
        if self._vol is None:
            return P, None, None, None, None
        W = self.W[c]
        cof = kin.cofactor(F)
        Ve = W.sum(axis=1)
        Jbar = (W * kin.det(F)).sum(axis=1) / Ve
        p = self._vol.dU(Jbar)
        return P + p[:, None] * cof, cof, Ve, Jbar, p

    def _neo_hookean_kernels(self, u, c, Ke, p_geo, extra):
        """Residuals and element matrices of chunk c by the low-rank kernel (:mod:`softhand.fem.lowrank`)."""
        F = self.F(u, c)
        G, W = self.G[c], self.W[c]
        P, cof, Ve, Jbar, p = self._stress_and_volume(F, c)
        GW = G * W[:, :, None, None]
        re = np.einsum("akeq,eqnk->ena", P, GW, optimize=True).reshape(len(W), -1)
        p_geo = p if p_geo is None else p_geo
        L, R, S, X = neo_hookean_terms(F, G, W, self._dev.mu, p_geo)
        Ls, Rs = [L], [R]
        if self._vol is not None:  # + U''/V_e b_e b_e^T, b[e, (n a)]
            b = np.einsum("akeq,eqnk->ena", cof, GW, optimize=True)
            Ls.append(b.reshape(len(W), -1, 1))
            Rs.append(((self._vol.ddU(Jbar) / Ve)[:, None, None] * b.transpose(0, 2, 1)).reshape(len(W), 1, -1))
        if extra is not None:
            re = re + extra[0]
            Ls.append(extra[1])
            Rs.append(extra[2])
            S = S + extra[3]
        write_matrices(Ke, np.concatenate(Ls, axis=2), np.concatenate(Rs, axis=1), S, X)
        return re

    def _general_kernels(self, u, c, Ke=None, p_geo=None):
        """Element residuals of chunk c and (with Ke) its element matrices, for any law."""
        F = self.F(u, c)
        dev = self._dev.take(c)
        G, W = self.G[c], self.W[c]
        P = dev.stress(F)
        tangent = Ke is not None
        A = dev.tangent(F) if tangent else None
        if self._vol is not None:
            cof = kin.cofactor(F)
            Ve = W.sum(axis=1)
            Jbar = (W * kin.det(F)).sum(axis=1) / Ve
            p = self._vol.dU(Jbar)[:, None]
            P = P + p * cof
            if tangent:
                A = A + (p if p_geo is None else p_geo[:, None]) * kin.d2det(F)
        GW = G * W[:, :, None, None]
        re = np.einsum("akeq,eqnk->ena", P, GW, optimize=True).reshape(len(W), -1)
        if not tangent:
            return re
        element_matrices(A, G, GW, out=Ke)
        if self._vol is not None:  # + U''/V_e b_e b_e^T, b[e, n, a]
            b = np.einsum("akeq,eqnk->ena", cof, GW, optimize=True)
            cb = (self._vol.ddU(Jbar) / Ve)[:, None, None] * b
            Ke += cb[:, :, :, None, None] * b.transpose(0, 2, 1)[:, None, None, :, :]
        return re


def element_matrices(A: np.ndarray, G: np.ndarray, GW: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """K[e, n, a, b, m] = sum_q sum_kl GW[e,q,n,k] A[a,k,b,l,e,q] G[e,q,m,l]: the stiffness between
    row dof (node n, component a) and column dof (node m, component b), shape (ne, nloc, 3, 3, nloc).

    Two batched matrix products over all basis pairs (no loop over elements or points), in an
    order whose results need no transposed copy: D[eq, (k a b), m] = A[eq, (k a b), l] G[eq, m, l],
    then K[e, n, (a b m)] = GW[e, n, (q k)] D[e, (q k), (a b m)]. ``out``: where to write K.
    """
    ne, nq, nloc, _ = G.shape
    Ab = np.ascontiguousarray(A.transpose(4, 5, 1, 0, 2, 3)).reshape(ne * nq, 27, 3)  # [eq, (k a b), l]
    D = np.matmul(Ab, G.reshape(ne * nq, nloc, 3).transpose(0, 2, 1))  # [eq, (k a b), m]
    GWt = np.ascontiguousarray(GW.transpose(0, 2, 1, 3)).reshape(ne, nloc, nq * 3)  # [e, n, (q k)]
    K = np.empty((ne, nloc, 3, 3, nloc)) if out is None else out
    np.matmul(GWt, D.reshape(ne, nq * 3, 9 * nloc), out=K.reshape(ne, nloc, 9 * nloc))
    return K
