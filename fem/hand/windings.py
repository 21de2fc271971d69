r"""The Kevlar windings of the finger: a tension-only hoop fiber family and its own quadrature.

:class:`WindingFibers` is the fiber law (a smooth onset of width ``toe``, or a jump);
:func:`hoop_directions` the winding direction e_phi around the tube axis; :class:`~softhand.fem.hand.windings.Windings`
the windings' energy, residual and tangent on a P2 tetrahedral mesh, integrated with a rule
of their own (see its docstring for why).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from skfem import Basis, ElementTetP2

from softhand.fem import kinematics as kin
from softhand.fem import threads
from softhand.fem.lowrank import write_matrices
from softhand.fem.materials import Fibers


@dataclass(frozen=True, eq=False)
class WindingFibers(Fibers):
    r"""The tension-only winding fibers with a smooth onset ("toe") of width ``toe``.

    .. math:: \psi = k\,G(\lambda_f - 1),\quad
        G(e) = \begin{cases} 0 & e \le 0\\ e^3/(6\delta) & 0 < e < \delta\\
        e^2/2 - \delta e/2 + \delta^2/6 & e \ge \delta \end{cases}

    so the fiber stiffness k G'' rises linearly from 0 to k over 0 < e < delta (the slack of
    wound threads) instead of jumping at lambda_f = 1. ``toe = 0`` is
    :class:`softhand.fem.materials.Fibers` (stiff already at lambda_f = 1). The jump makes Newton
    chatter where the hoop stretch is near 1, i.e. in much of the bent tube; docs/finger.md
    shows the effect of delta on theta.
    """

    toe: float = 0.0  #: width delta of the onset in fiber strain

    def take(self, elements):
        return self if self.a0.ndim == 1 else WindingFibers(self.k, self.a0[:, elements], self.toe)

    def _g(self, e):
        """(G, G', G'') of the fiber strain e (see the class docstring)."""
        d = self.toe
        if d == 0:
            on = e >= 0
            return (np.where(on, 0.5 * e * e, 0.0), np.where(on, e, 0.0), on * 1.0)
        ramp = np.clip(e, 0.0, d)
        G = np.where(e < d, ramp ** 3 / (6 * d), 0.5 * e * e - 0.5 * d * e + d * d / 6)
        G1 = np.where(e < d, ramp ** 2 / (2 * d), e - 0.5 * d)
        return G, G1, ramp / d

    def energy(self, F):
        return self.k * self._g(self.stretch(F) - 1.0)[0]

    def stress(self, F):
        a0, f, lam, _ = self._kinematics(F)
        return self.k * self._g(lam - 1.0)[1] / lam * np.einsum("a...,K...->aK...", f, a0)

    def tangent(self, F):
        a0, f, lam, _ = self._kinematics(F)
        _, G1, G2 = self._g(lam - 1.0)
        fa = np.einsum("a...,K...->aK...", f, a0)
        aa = np.einsum("ab,K...,L...->aKbL...", np.eye(3), a0, a0)
        return self.k * ((G2 / lam ** 2 - G1 / lam ** 3) * kin.outer(fa, fa) + G1 / lam * aa)



def hoop_directions(X: np.ndarray) -> np.ndarray:
    """Fiber directions e_phi = (0, -z, y)/r around the tube axis (the x axis), X (3, ...).

    On the axis itself (points of the end cap, r = 0) the hoop is undefined; e_z is used.
    """
    r = np.hypot(X[1], X[2])
    on_axis = r < 1e-12
    a0 = np.stack([np.zeros_like(X[0]), np.where(on_axis, 1.0, -X[2]), X[1]])
    return a0 / np.where(on_axis, 1.0, r)


class Windings:
    r"""The windings' energy :math:`\int k G(\lambda_f - 1)\,dV` (:class:`WindingFibers`),
    residual and tangent, integrated with their own quadrature rule of degree ``intorder``.

    Why a rule of its own: the fiber energy is a kinked function of the hoop strain, and
    the taut fibers sit in a thin layer at the cavity wall (bending contracts the hoop,
    the pressure expands it; at the optimum the hoop strain is largest at the inner
    radius). The rubber's 4-point rule samples it only at points inside each element, so
    the hoop strain at the cavity wall can go positive unseen, the more so the fewer
    elements the wall has; the 14-point degree-5 rule includes the edge midpoints.

    With f = F a0 = a0 + sum_n u_n g_n (g_n = grad N_n . a0) and c1 = k (G''/lam^2 -
    G'/lam^3), c2 = k G'/lam: r_na = sum_q w k G'/lam f_a g_n and
    K_(na)(mb) = sum_q w (c1 f_a g_n f_b g_m + c2 delta_ab g_n g_m): a rank-one term per point
    and a delta term, far cheaper than the general anisotropic tangent of :mod:`softhand.fem.solid`;
    :meth:`terms` hands them to the rubber's low-rank kernel (:mod:`softhand.fem.lowrank`), which adds
    them in its own batched product, so the two are computed and scattered together, once
    (:meth:`softhand.fem.assembly.ElementScatter.block_matrix_data`).
    """

    def __init__(self, mesh, fibers_k: float, toe: float, intorder: int, scatter, chunk=threads.CHUNK):
        basis = Basis(mesh, ElementTetP2(), intorder=intorder)
        self.law = WindingFibers(fibers_k, hoop_directions(np.asarray(basis.global_coordinates().value)), toe)
        a0 = self.law.a0                                                    # (3, nel, nq)
        grads = np.stack([basis.basis[i][0].grad for i in range(basis.Nbfun)])  # (nloc, 3, nel, nq)
        self.g = np.einsum("nkeq,keq->eqn", grads, a0)                      # (nel, nq, nloc)
        self.W = np.asarray(basis.dx)                                       # (nel, nq)
        #: the fiber directions at the rule's points, (nel, nq, 3)
        self.a0q = np.ascontiguousarray(a0.transpose(1, 2, 0))
        self.scatter = scatter
        nel = self.W.shape[0]
        self.chunks = [slice(i, min(i + chunk, nel)) for i in range(0, nel, chunk)]

    def stretch(self, u: np.ndarray, elements=slice(None)):
        """(f = F a0 (3, ne, nq), fiber stretch lam (ne, nq)) at the rule's points."""
        ue = u[self.scatter.vector_dofs(elements)].reshape(*self.g[elements].shape[::2], 3)
        f = self.law.a0[:, elements] + np.einsum("ena,eqn->aeq", ue, self.g[elements], optimize=True)
        return f, np.sqrt(np.einsum("aeq,aeq->eq", f, f))

    def energy(self, u: np.ndarray) -> float:
        """Stored energy of the windings [N mm]."""
        lam = self.stretch(u)[1]
        return float(np.sum(self.W * self.law.k * self.law._g(lam - 1.0)[0]))

    def _points(self, u, c):
        """(f = F a0 (ne, nq, 3), c1, c2 (ne, nq), the weighted coefficients of the class docstring)
        of chunk c."""
        g, W, k = self.g[c], self.W[c], self.law.k
        ne, nq, nloc = g.shape
        f = self.a0q[c] + np.matmul(g, u[self.scatter.vector_dofs(c)].reshape(ne, nloc, 3))
        lam = np.sqrt(np.einsum("eqa,eqa->eq", f, f))
        _, G1, G2 = self.law._g(lam - 1.0)
        return f, W * k * (G2 / lam ** 2 - G1 / lam ** 3), W * k * G1 / lam

    def add_residual(self, u: np.ndarray, R: np.ndarray) -> None:
        """R += the windings' internal force, r_(n a) = sum_q c2 f_a g_n."""
        def forces(c):
            f, _, c2 = self._points(u, c)
            return np.matmul(self.g[c].transpose(0, 2, 1), c2[:, :, None] * f).reshape(len(f), -1)

        self.scatter.add_chunk_vectors(R, threads.map_chunks(forces, self.chunks))

    def add_residual_tangent(self, u: np.ndarray, R: np.ndarray, Ke_all: np.ndarray) -> None:
        """R += the windings' internal force; Ke_all (element matrices of the whole mesh in the
        block layout of :func:`softhand.fem.solid_kernels.element_matrices`) += their tangent. (The finger passes
        :meth:`terms` to the rubber's kernel instead, which adds them in its own product.)"""
        def kernels(c):  # in a thread: adds only to its own chunk of Ke_all
            re, L, Rw, S = self.terms(u, c)
            write_matrices(Ke_all[c], L, Rw, S, add=True)
            return re

        self.scatter.add_chunk_vectors(R, threads.map_chunks(kernels, self.chunks))

    def terms(self, u: np.ndarray, c: slice):
        """The windings' (re, L, R, S) on the elements c, as :meth:`softhand.fem.solid.Solid.residual_element_matrices`
        takes them (``extra=``): element forces re (ne, 3 nloc) and the tangent
        sum_q c1 (f_a g_n)(f_b g_m) + delta_ab S_nm, S_nm = sum_q c2 g_n g_m (class docstring),
        L = v (ne, (n a), q), R = c1 v (ne, q, (b m))."""
        f, c1, c2 = self._points(u, c)
        g = self.g[c]
        ne, nq, nloc = g.shape
        v = (g[:, :, :, None] * f[:, :, None, :]).reshape(ne, nq, -1)     # v[e, q, (n a)] = f_a g_n
        re = np.matmul(g.transpose(0, 2, 1), c2[:, :, None] * f).reshape(ne, -1)
        L = v.transpose(0, 2, 1)                                            # (ne, (n a), q)
        R = ((c1[:, :, None] * f)[:, :, :, None] * g[:, :, None, :]).reshape(ne, nq, -1)  # (ne, q, (b m))
        S = np.matmul(g.transpose(0, 2, 1) * c2[:, None, :], g)            # (ne, nloc, nloc)
        return re, L, R, S
