"""Sparse assembly for vector fields: a CSR pattern built once, element matrices scattered into it.

Vector dofs are interleaved as scikit-fem's ``ElementVector`` numbers them:
dof ``3 * s + a`` is component ``a`` of scalar dof ``s``. The pattern is built at
the scalar level (100 node pairs per P2 tetrahedron instead of 900) and expanded
to 3x3 blocks by index arithmetic, so building it is cheap. The CSR positions of
all elements' matrices are computed once (:meth:`ElementScatter.block_matrix_data`,
or per restriction, :meth:`Restriction.block_matrix`); assembling a matrix is then
one ``np.bincount`` over the whole mesh into the CSR data array: no Python loop
over elements, no COO-to-CSR conversion per Newton iterate.
"""
from __future__ import annotations

import weakref

import numpy as np
import scipy.sparse as sp


class DofScatter:
    """Scatter element vectors and matrices over any element DOF numbering into a CSR pattern
    built once (duplicates summed); the scatter of the axisymmetric kernel and its volume.

    ``dofs``: (nloc, nel) global DOF of each element's local DOF; ``n``: the system's size.
    """

    def __init__(self, dofs: np.ndarray, n: int):
        self.dofs, self.n = np.asarray(dofs), n
        nloc, nel = self.dofs.shape
        rows = np.broadcast_to(self.dofs[:, None, :], (nloc, nloc, nel)).ravel().astype(np.int64)
        cols = np.broadcast_to(self.dofs[None, :, :], (nloc, nloc, nel)).ravel().astype(np.int64)
        pattern = sp.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(n, n))
        pattern.sum_duplicates()
        pattern.sort_indices()
        keys = np.repeat(np.arange(n, dtype=np.int64), np.diff(pattern.indptr)) * n + pattern.indices
        self.pattern = pattern
        self.slots = np.searchsorted(keys, rows * n + cols)  # per (a, b, e): its slot in the CSR data

    def vector(self, fe: np.ndarray) -> np.ndarray:
        """Sum of the element vectors fe (nloc, nel) as a full vector (n,)."""
        return np.bincount(self.dofs.ravel(), weights=fe.ravel(), minlength=self.n)

    def matrix(self, Ke: np.ndarray) -> sp.csr_matrix:
        """Sum of the element matrices Ke (nloc, nloc, nel) as CSR in the pattern."""
        data = np.bincount(self.slots, weights=Ke.ravel(), minlength=self.pattern.nnz)
        return sp.csr_matrix((data, self.pattern.indices, self.pattern.indptr), shape=self.pattern.shape)


class ElementScatter:
    """Scatter element vectors/matrices of a 3-component field into a fixed CSR pattern.

    ``scalar_dofs``: (nloc, nel) scalar dofs of each element (``basis.element_dofs``),
    ``n_scalar``: number of scalar dofs. The vector system has ``3 * n_scalar`` dofs.
    """

    def __init__(self, scalar_dofs: np.ndarray, n_scalar: int):
        dofs = np.ascontiguousarray(scalar_dofs.T)  # (nel, nloc)
        nel, nloc = dofs.shape
        rows = np.repeat(dofs, nloc, axis=1)
        cols = np.tile(dofs, (1, nloc))
        keys, inverse = np.unique(rows.astype(np.int64) * n_scalar + cols, return_inverse=True)
        s_rows, s_cols = np.divmod(keys, n_scalar)
        ip = np.zeros(n_scalar + 1, dtype=np.int64)
        np.cumsum(np.bincount(s_rows, minlength=n_scalar), out=ip[1:])
        deg = np.diff(ip)
        self.n = 3 * n_scalar
        self.nnz = 9 * len(keys)
        self.dofs = dofs
        self._spos = inverse.reshape(nel, nloc, nloc).astype(np.int64)
        self._ip, self._deg = ip, deg
        self.indptr, self.indices = self._vector_pattern(ip, deg, s_cols)
        self._cache = {}

    @staticmethod
    def _vector_pattern(ip, deg, s_cols):
        n_scalar = len(deg)
        # vector row 3i+a holds 3*deg_i entries, starting at 9 ip_i + 3 a deg_i
        starts = 9 * ip[:-1, None] + 3 * np.arange(3)[None, :] * deg[:, None]
        indptr = np.append(starts.ravel(), 9 * ip[-1])
        row_cols = (3 * s_cols[:, None] + np.arange(3)).ravel()  # per scalar row: 3*deg columns
        indices = np.empty(9 * len(s_cols), dtype=np.int32 if 9 * len(s_cols) < 2 ** 31 else np.int64)
        for a in range(3):  # three interleaved copies of each scalar row's column list
            seg = np.repeat(np.arange(n_scalar), 3 * deg)
            offs = np.arange(3 * ip[-1]) - 3 * ip[:-1][seg]
            indices[starts[seg, a] + offs] = row_cols
        return indptr.astype(indices.dtype), indices

    def positions(self, elements) -> np.ndarray:
        """CSR data positions of the (3 nloc)^2 entries of the given elements, (len, 3nloc, 3nloc)."""
        s = self._spos[elements]  # (ne, nloc, nloc)
        rows = self.dofs[elements]  # (ne, nloc)
        ip, deg = self._ip[rows], self._deg[rows]
        base = 6 * ip[:, :, None] + 3 * s  # = 9 ip + 3 (s - ip)
        a = np.arange(3)
        pos = (base[:, :, None, :, None] + 3 * a[None, None, :, None, None] * deg[:, :, None, None, None]
               + a[None, None, None, None, :])
        ne, nloc = rows.shape
        return pos.reshape(ne, 3 * nloc, 3 * nloc)

    def vector_dofs(self, elements=slice(None)) -> np.ndarray:
        """Vector dofs (ne, 3 nloc) of the elements, ordered (node, component)."""
        return (3 * self.dofs[elements][:, :, None] + np.arange(3)).reshape(
            self.dofs[elements].shape[0], -1)

    def block_matrix_data(self, Ke: np.ndarray) -> np.ndarray:
        """CSR data of the sum of ALL elements' matrices given in the block layout
        Ke[e, n, a, b, m] (row dof: node n, component a; column dof: node m, component b;
        shape (nel, nloc, 3, 3, nloc), as :func:`softhand.fem.solid_kernels.element_matrices` writes them).

        One bincount over the whole mesh (a chunk-wise scatter re-reads the nnz-long data
        array once per chunk); the positions in that layout are computed once and kept as
        np.intp, bincount's own index type (an int32 copy would be converted on every call,
        which doubles its time), nel (3 nloc)^2 of them.
        """
        pos = self._cache.get("blocks")
        if pos is None:
            pos = self._cache["blocks"] = self.block_positions()
        return np.bincount(pos.ravel(), weights=Ke.ravel(), minlength=self.nnz)

    def block_positions(self, mapping: np.ndarray | None = None) -> np.ndarray:
        """CSR data positions (nel, nloc, 3, 3, nloc) of the block layout of :meth:`block_matrix_data`;
        with ``mapping`` (an array over this pattern's positions), mapping[position] instead."""
        nel, nloc = self.dofs.shape
        pos = np.empty((nel, nloc, 3, 3, nloc), dtype=np.intp)
        for i in range(0, nel, 2048):  # in batches: int64 positions of all elements at once are big
            c = slice(i, min(i + 2048, nel))
            p = self.positions(c).reshape(-1, nloc, 3, nloc, 3).transpose(0, 1, 2, 4, 3)
            pos[c] = p if mapping is None else mapping[p]
        return pos

    def add_vector(self, out: np.ndarray, re: np.ndarray, elements) -> None:
        """out += scatter of element vectors re (ne, 3nloc)."""
        out += np.bincount(self.vector_dofs(elements).ravel(), weights=re.ravel(), minlength=self.n)

    def add_chunk_vectors(self, out: np.ndarray, parts: list) -> None:
        """out += scatter of the element vectors of ALL elements, given chunk by chunk in order
        (the parts of :func:`softhand.fem.threads.map_chunks`): one bincount, the dofs kept."""
        dofs = self._cache.get("vector_dofs")
        if dofs is None:
            dofs = self._cache["vector_dofs"] = self.vector_dofs().ravel()
        out += np.bincount(dofs, weights=np.concatenate(parts).ravel(), minlength=self.n)

    def csr(self, data: np.ndarray) -> sp.csr_matrix:
        """The CSR matrix with this pattern and the given data (index arrays shared, not copied)."""
        K = sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n, self.n), copy=False)
        K.has_sorted_indices = True
        return K


class Restriction:
    """Rows and columns ``keep`` (sorted, unique) of square CSR matrices; index map built once per pattern.

    ``restrict(K)`` is a gather of K.data (no sparse slicing per Newton iterate);
    :meth:`block_matrix` scatters element matrices straight into the restricted
    pattern (no full matrix, no gather: what :meth:`softhand.fem.solid.Solid.residual_tangent`
    does with ``restriction=``); ``expand(x, fill)`` puts a reduced vector back into a full one.
    """

    def __init__(self, n: int, keep: np.ndarray, values: np.ndarray | float = 0.0):
        self.n = n
        self.keep = np.unique(np.asarray(keep, dtype=np.int64))
        #: the full vector's entries outside ``keep`` (prescribed displacements), filled by expand
        self.values = np.array(np.broadcast_to(values, (n,)), dtype=float)
        self._new = np.full(n, -1, dtype=np.int64)
        self._new[self.keep] = np.arange(len(self.keep))
        self._pattern = None
        self._blocks = weakref.WeakKeyDictionary()  # ElementScatter -> its block positions, restricted

    def _use_pattern(self, indptr, indices):
        """The index map of the full pattern (indptr, indices), built when it changes."""
        p = self._pattern
        if p is not None and np.array_equal(p[0], indptr) and np.array_equal(p[1], indices):
            return p
        rows = np.repeat(np.arange(self.n), np.diff(indptr))
        sel = np.flatnonzero((self._new[rows] >= 0) & (self._new[indices] >= 0))
        new_rows = self._new[rows[sel]]  # nondecreasing, and columns stay sorted: keep is sorted
        new_indptr = np.zeros(len(self.keep) + 1, dtype=np.int64)
        np.cumsum(np.bincount(new_rows, minlength=len(self.keep)), out=new_indptr[1:])
        new_indices = self._new[indices[sel]]
        # the index type scipy would choose anyway: it would otherwise convert both arrays on every call
        itype = np.int32 if len(sel) < 2 ** 31 else np.int64
        self._pattern = (indptr.copy(), indices.copy(), sel, new_indptr.astype(itype), new_indices.astype(itype))
        return self._pattern

    def _csr(self, data, p) -> sp.csr_matrix:
        Kr = sp.csr_matrix((data, p[4], p[3]), shape=(len(self.keep),) * 2, copy=False)
        Kr.has_sorted_indices = True
        return Kr

    def restrict(self, K: sp.spmatrix) -> sp.csr_matrix:
        """K[keep][:, keep] as CSR."""
        K = K.tocsr()
        p = self._use_pattern(K.indptr, K.indices)
        return self._csr(K.data[p[2]], p)

    def block_matrix(self, scatter: ElementScatter, Ke: np.ndarray) -> sp.csr_matrix:
        """K[keep][:, keep] of the matrix ``scatter.block_matrix_data(Ke)`` would assemble, scattered
        directly into the restricted pattern (entries of removed rows/columns go to a dropped bin)."""
        cached = self._blocks.get(scatter)  # a scatter's pattern never changes: no comparison per call
        if cached is None:
            p = self._use_pattern(scatter.indptr, scatter.indices)
            mapping = np.full(scatter.nnz, len(p[2]), dtype=np.intp)  # the dropped bin
            mapping[p[2]] = np.arange(len(p[2]))
            cached = self._blocks[scatter] = (scatter.block_positions(mapping), p)
        pos, p = cached
        return self._csr(np.bincount(pos.ravel(), weights=Ke.ravel(), minlength=len(p[2]) + 1)[:-1], p)

    def vector(self, R: np.ndarray) -> np.ndarray:
        """R[keep]."""
        return R[self.keep]

    def expand(self, x: np.ndarray, fill: np.ndarray | float | None = None) -> np.ndarray:
        """Full vector equal to ``fill`` (default: the prescribed ``values``) outside ``keep``
        and to ``x`` on it."""
        out = np.array(np.broadcast_to(self.values if fill is None else fill, (self.n,)), dtype=float)
        out[self.keep] = x
        return out
