r"""Rigid planar serial chains as nonlinear multi-point constraints (the finger's shell).

The shell of a finger is a chain of ``n_s + 1`` rigid links joined by ``n_s`` revolute
hinges whose axes are normal to the bending plane (x-y). Link 0 (the base) is fixed.
The chain's configuration is its vector of hinge angles :math:`q` (the paper's
:math:`\hat\theta_1 \dots \hat\theta_{n_s}`); link :math:`k` is rotated by

.. math:: \varphi_k = \sum_{i \le k} q_i ,\qquad \theta = \sum_i q_i = \varphi_{n_s}.

With :math:`H_i` the reference position of hinge :math:`i` and :math:`p_i(q)` its current
one (:math:`p_1 = H_1`, :math:`p_{i+1} = p_i + R(\varphi_i)(H_{i+1} - H_i)`), a material
point :math:`X` of link :math:`k` is at

.. math:: x = p_k + R(\varphi_k)(X - H_k) = c_k + R(\varphi_k) X .

Hinge :math:`j` turns every link :math:`k \ge j` about :math:`p_j`, so with
:math:`\Omega` the in-plane rotation by +90 degrees

.. math::
    \frac{\partial x}{\partial q_j} = \Omega (x - p_j) \quad (j \le k), \qquad
    \frac{\partial^2 x}{\partial q_j \partial q_l} = -(x - p_{\max(j, l)})
    \quad (\max(j, l) \le k),

and zero otherwise. Out of plane (z) a link does not move.

A finite-element vector :math:`u` is tied to the chain by :class:`ChainConstraint`: the
displacement DOFs of the tied nodes follow the links, :math:`u = T(y)` with
:math:`y = (u_\mathrm{free}, q)`. Stationarity of the potential gives the reduced residual
:math:`r = T'^T R` and tangent :math:`K_r = T'^T K T' + \sum_n R_n \cdot T''_n`, the last
term from the rotation (the constraint's geometric stiffness).

Loads on the links (contact, a grasped object's weight) enter as generalised forces on
:math:`q`: :meth:`~softhand.fem.constraints.PlanarChain.point_load` turns point forces on link points into
:math:`Q = J^T f` and its derivative.

Angles are positive counter-clockwise about +z (radians).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from softhand.fem.compiled import chain as chain_kernels

#: rotation of an in-plane vector by +90 degrees
OMEGA = np.array([[0.0, -1.0], [1.0, 0.0]])


def rotation(phi) -> np.ndarray:
    """In-plane rotation matrices R(phi), shape ``(2, 2, *phi.shape)``."""
    c, s = np.cos(phi), np.sin(phi)
    return np.array([[c, -s], [s, c]])


@dataclass(frozen=True)
class PlanarChain:
    """A planar serial chain of rigid links; link 0 fixed, hinge i between links i-1 and i."""

    hinges: np.ndarray  #: (n_s, 2) reference hinge positions in the x-y plane [mm]

    def __post_init__(self):
        object.__setattr__(self, "hinges", np.asarray(self.hinges, dtype=float).reshape(-1, 2))

    @property
    def n_s(self) -> int:
        return len(self.hinges)

    def link_angles(self, q) -> np.ndarray:
        """Rotation of each link, phi_k = sum_{i<=k} q_i, shape (n_s + 1,) [rad]."""
        return np.concatenate(([0.0], np.cumsum(q)))

    def hinge_positions(self, q) -> np.ndarray:
        """Current hinge positions p_i, shape (n_s, 2) [mm]."""
        q = np.asarray(q, dtype=float)
        R = rotation(self.link_angles(q)[1:-1])            # links 1..n_s-1 span the hinges
        steps = np.einsum("ijk,kj->ki", R, np.diff(self.hinges, axis=0))
        return self.hinges[0] + np.concatenate((np.zeros((1, 2)), np.cumsum(steps, axis=0)))

    def link_poses(self, q) -> tuple[np.ndarray, np.ndarray]:
        """Poses (c_k, phi_k) of all links: a point X of link k is at c_k + R(phi_k) X.

        Returns ``origins`` (n_s + 1, 2) [mm] and ``angles`` (n_s + 1,) [rad].
        """
        phi = self.link_angles(q)
        p = self.hinge_positions(q)
        H = np.concatenate((np.zeros((1, 2)), self.hinges))
        P = np.concatenate((np.zeros((1, 2)), p))
        return P - np.einsum("ijk,kj->ki", rotation(phi), H), phi

    def point_map(self, q, links, X, order: int = 2):
        """Current position of points X (m, 2) on links (m,), with derivatives in q.

        Returns x (m, 2), J = dx/dq (m, 2, n_s) and H = d2x/dq2 (m, 2, n_s, n_s); with
        ``order`` 0 or 1, the derivatives above that order are None.
        """
        links = np.asarray(links, dtype=int)
        X = np.asarray(X, dtype=float).reshape(-1, 2)
        c, phi = self.link_poses(q)
        x = c[links] + np.einsum("ijm,mj->mi", rotation(phi[links]), X)
        if order == 0:
            return x, None, None
        p = self.hinge_positions(q)
        j = np.arange(self.n_s)
        moved = j[None, :] < links[:, None]                      # hinge j+1 moves link k
        arm = x[:, None, :] - p[None, :, :]                      # (m, n_s, 2)
        J = np.einsum("ab,mjb->maj", OMEGA, arm) * moved[:, None, :]
        if order == 1:
            return x, J, None
        jl = np.maximum(j[:, None], j[None, :])                  # (n_s, n_s)
        H = -np.moveaxis(arm[:, jl, :], -1, 1) * (jl[None, None] < links[:, None, None, None])
        return x, J, H

    def generalised_force(self, q, links, x, f) -> np.ndarray:
        """Q = sum_m J_m^T f_m (n_s,) [N mm] of forces f (m, 2) at the current points x (m, 2) of
        links (m,), without forming J: entry j is the moment about p_j of the forces on links
        > j, sum (x_m - p_j) x f_m, a suffix sum over the links (as in :meth:`force_hessian`)."""
        links = np.asarray(links, dtype=int)
        n = self.n_s + 1
        xf = np.bincount(links, weights=x[:, 0] * f[:, 1] - x[:, 1] * f[:, 0], minlength=n)
        fs = np.stack([np.bincount(links, weights=f[:, a], minlength=n) for a in range(2)], axis=1)
        beyond = lambda v: np.cumsum(v[::-1], axis=0)[::-1][1:]  # noqa: E731  sum over links > j
        p, F = self.hinge_positions(q), beyond(fs)
        return beyond(xf) - (p[:, 0] * F[:, 1] - p[:, 1] * F[:, 0])

    def force_hessian(self, q, links, x, f) -> np.ndarray:
        """sum_m f_m . d2x_m/dq2 (n_s, n_s) for forces f (m, 2) at the current points x (m, 2)
        of links (m,), without forming d2x/dq2: entry (j, l) is -sum over the points of
        links > max(j, l) of f_m . (x_m - p_max(j, l)), a suffix sum over the links."""
        links = np.asarray(links, dtype=int)
        n = self.n_s + 1
        fx = np.bincount(links, weights=np.einsum("ma,ma->m", f, x), minlength=n)
        fs = np.stack([np.bincount(links, weights=f[:, a], minlength=n) for a in range(2)], axis=1)
        beyond = lambda v: np.cumsum(v[::-1], axis=0)[::-1][1:]  # noqa: E731  sum over links > k
        A = beyond(fx) - np.einsum("ka,ka->k", self.hinge_positions(q), beyond(fs))
        j = np.arange(self.n_s)
        return -A[np.maximum(j[:, None], j[None, :])]

    def point_load(self, q, links, X, f, dfdx=None):
        """Generalised force Q = sum J^T f of point forces f (m, 2) on link points X.

        ``dfdx`` (m, 2, 2), optional: the forces' derivative with respect to the point's
        position (a penalty contact). Returns Q (n_s,) [N mm] and dQ/dq (n_s, n_s).
        """
        f = np.asarray(f, dtype=float).reshape(-1, 2)
        x, J, _ = self.point_map(q, links, X, order=1)
        Q = np.einsum("maj,ma->j", J, f)
        dQ = self.force_hessian(q, links, x, f)
        if dfdx is not None:
            dQ = dQ + np.einsum("maj,mab,mbl->jl", J, dfdx, J)
        return Q, dQ

    def moment_load(self, links, M):
        """Generalised force of moments M (m,) about +z on links (m,): Q_j = sum_{k>j} M_k."""
        links = np.asarray(links, dtype=int)
        moved = np.arange(self.n_s)[None, :] < links[:, None]
        return np.asarray(M, dtype=float) @ moved


@dataclass
class ChainConstraint:
    """Nodes of a finite-element vector carried by the links of a :class:`PlanarChain`.

    The full vector u (size ``n_dofs``; any layout, e.g. displacements then pressures)
    is parametrised by y = (w, q) with w = the entries that are neither tied nor fixed.
    Every node listed in ``nodes`` follows a link: its displacement is the link's rigid
    motion plus its own unknowns (co-rotated parametrisation),

        u_n = (x_k(q; X_n) - X_n, 0) + w_n,

    and a ``tied`` node has no w_n: it moves rigidly with its link. Entries in ``fixed``
    are zero; they must not move with the chain (z components, or nodes on link 0).
    Carrying the free nodes along keeps a large rotation of the distal links from
    shearing the elements next to the tied ones in a Newton update (an update of q then
    moves a whole segment rigidly, not by the linearised rotation).
    """

    chain: PlanarChain
    n_dofs: int               #: size of the full vector
    nodes: np.ndarray         #: (m, 3) indices of the x, y, z displacement DOFs of each node
    links: np.ndarray         #: (m,) the link each node follows
    X: np.ndarray             #: (m, 2) reference x-y position of each node [mm]
    tied: np.ndarray          #: (m,) True: the node moves rigidly with its link
    fixed: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))  #: zero DOFs

    def __post_init__(self):
        self.nodes = np.asarray(self.nodes, dtype=int).reshape(-1, 3)
        self.links = np.asarray(self.links, dtype=int)
        self.X = np.asarray(self.X, dtype=float).reshape(-1, 2)
        self.tied = np.asarray(self.tied, dtype=bool)
        slaved = np.zeros(self.n_dofs, dtype=bool)
        slaved[self.nodes[self.tied].ravel()] = True
        slaved[np.asarray(self.fixed, dtype=int)] = True
        self.free = np.flatnonzero(~slaved)
        self._pattern = None  # the reduced tangent's pattern (see _reduced_pattern), built at first use

    @property
    def n_reduced(self) -> int:
        return len(self.free) + self.chain.n_s

    def zero(self) -> np.ndarray:
        return np.zeros(self.n_reduced)

    def q(self, y) -> np.ndarray:
        """The hinge angles in y [rad]."""
        return np.asarray(y)[len(self.free):]

    def expand(self, y) -> np.ndarray:
        """The full vector u = T(y)."""
        u = np.zeros(self.n_dofs)
        u[self.free] = y[:len(self.free)]
        x, _, _ = self.chain.point_map(self.q(y), self.links, self.X, order=0)
        u[self.nodes[:, :2]] += x - self.X
        return u

    def operator(self, y) -> sp.csr_matrix:
        """T' = du/dy at y, shape (n_dofs, n_reduced); its pattern does not depend on y."""
        n_f, n_s = len(self.free), self.chain.n_s
        _, J, _ = self.chain.point_map(self.q(y), self.links, self.X, order=1)
        moving = self.links > 0                       # link-0 nodes have J = 0
        rows_t = np.repeat(self.nodes[moving, :2], n_s, axis=1).ravel()
        cols_t = np.tile(n_f + np.arange(n_s), 2 * int(moving.sum()))
        rows = np.concatenate((self.free, rows_t))
        cols = np.concatenate((np.arange(n_f), cols_t))
        vals = np.concatenate((np.ones(n_f), J[moving].ravel()))
        return sp.csr_matrix((vals, (rows, cols)), shape=(self.n_dofs, self.n_reduced))

    def reduce(self, y, R, K=None, K_qq=None, *, symmetric: bool = False):
        """Reduced residual T'^T R and, with K (CSR), tangent T'^T K T' + sum_n R_n . T''_n
        (+ K_qq, an (n_s, n_s) term of loads on the hinge angles); ``symmetric``: K is
        symmetric, so K^T J_m is K J_m and is not formed a second time.

        With T' = [S_f | J_m] (S_f selects the free entries; J_m, nonzero on the x, y rows of
        the moving nodes, is dx/dq): K_ff is a gather of K.data, K_fq = (K J_m)_f and
        K_qf = (K^T J_m)_f^T are sparse-times-dense products with n_s columns, K_qq =
        J_m^T K J_m. All four go into a pattern built once per pattern of K (a full n_s
        coupling for every entry that couples to a moving node), so the tangent's pattern,
        and with it the direct solver's symbolic analysis, never changes (a sparse
        triple product drops entries that happen to be zero).
        """
        if K is None:  # the residual alone: J^T R as moments about the hinges, J not formed
            x, _, _ = self.chain.point_map(self.q(y), self.links, self.X, order=0)
            return np.concatenate((R[self.free], self.chain.generalised_force(
                self.q(y), self.links, x, R[self.nodes[:, :2]])))
        x, J, _ = self.chain.point_map(self.q(y), self.links, self.X, order=1)
        moving = self.links > 0                       # link-0 nodes have J = 0
        n_s = self.chain.n_s
        rows_m = self.nodes[moving, :2].ravel()
        Jm = J[moving].reshape(-1, n_s)               # rows ordered like rows_m
        r = np.concatenate((R[self.free], R[rows_m] @ Jm))
        K = K.tocsr()  # K.data below must be in CSR order
        pat = self._reduced_pattern(K, rows_m)
        compiled = symmetric and chain_kernels.available()  # then one pass over K (fem.compiled.chain)
        if compiled and "compiled" not in pat:
            pat["compiled"] = chain_kernels.SymmetricReduction(K, pat, rows_m)
        data, KJ = pat["compiled"](K, Jm) if compiled else (None, pat["cols"](K.data) @ Jm)  # KJ = K J_m
        KtJ = KJ if symmetric else pat["rows"](K.data).T @ Jm  # (n_dofs, n_s) = K^T J_m
        Kqq = Jm.T @ KJ[rows_m] + self.chain.force_hessian(self.q(y), self.links, x, R[self.nodes[:, :2]])
        if K_qq is not None:
            Kqq = Kqq + K_qq
        rest = (KJ[pat["fq"]].ravel(), KtJ[pat["qf"]].ravel(), Kqq.ravel())
        data = (pat["compiled"].fill(data, np.concatenate(rest)) if compiled
                else np.concatenate((K.data,) + rest)[pat["ids"]])
        Kr = sp.csr_matrix((data, pat["indices"], pat["indptr"]),
                           shape=(self.n_reduced, self.n_reduced))
        Kr.has_sorted_indices = True
        return r, Kr

    def _reduced_pattern(self, K: sp.csr_matrix, rows_m: np.ndarray) -> dict:
        """The reduced tangent's fixed pattern and where each entry comes from (cached per K pattern)."""
        cached = self._pattern
        if cached is not None and (cached["key"][0] is K.indices or (
                np.array_equal(cached["key"][0], K.indices) and np.array_equal(cached["key"][1], K.indptr))):
            return cached
        n_f, n_s = len(self.free), self.chain.n_s
        marker = sp.csr_matrix((np.arange(1.0, K.nnz + 1), K.indices, K.indptr), shape=K.shape)

        def gather(sub):  # a function K.data -> sub-matrix of K with sub's (fixed) pattern
            sub = sub.tocsr()
            pos, ind, ptr, shape = sub.data.astype(np.intp) - 1, sub.indices, sub.indptr, sub.shape
            return lambda data: sp.csr_matrix((data[pos], ind, ptr), shape=shape)

        cols, rows = marker[:, rows_m], marker[rows_m, :]
        ff = marker[self.free][:, self.free].tocoo()
        fq = np.flatnonzero(np.diff(cols.tocsr()[self.free].indptr))         # free rows coupled to q
        qf = np.flatnonzero(np.diff(rows.tocsc()[:, self.free].indptr))      # free columns coupled to q
        j = np.arange(n_s)
        off = [K.nnz, K.nnz + len(fq) * n_s, K.nnz + (len(fq) + len(qf)) * n_s]
        i_idx = np.concatenate((ff.row, np.repeat(fq, n_s), n_f + np.tile(j, len(qf)), n_f + np.repeat(j, n_s)))
        j_idx = np.concatenate((ff.col, n_f + np.tile(j, len(fq)), np.repeat(qf, n_s), n_f + np.tile(j, n_s)))
        ids = np.concatenate((ff.data - 1, off[0] + np.arange(len(fq) * n_s),
                              off[1] + np.arange(len(qf) * n_s), off[2] + np.arange(n_s * n_s)))
        template = sp.csr_matrix((ids + 1.0, (i_idx, j_idx)), shape=(self.n_reduced,) * 2)
        template.sort_indices()
        self._pattern = {
            "key": (K.indices, K.indptr), "cols": gather(cols), "rows": gather(rows),
            "fq": self.free[fq], "qf": self.free[qf], "ids": template.data.astype(np.intp) - 1,
            "indices": template.indices, "indptr": template.indptr}
        return self._pattern
