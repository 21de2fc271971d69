"""The reduction of a symmetric tangent to a chain's unknowns (:meth:`softhand.fem.constraints.ChainConstraint.reduce`), compiled.

One pass over the full tangent K's rows: each entry between two free unknowns goes to its place in
the reduced pattern, and each entry in a column of a node the links carry adds its share of
:math:`K J_m` (J_m = dx/dq of the moving nodes); the rows are split between the threads (each
writes its own rows of K J_m and its own entries). The NumPy path gathers K's columns, multiplies
and then gathers the reduced data from a concatenation: four passes over K's entries.
"""
from __future__ import annotations

import numpy as np

from softhand.fem import threads
from softhand.fem.compiled import available, compiled

__all__ = ["SymmetricReduction", "available"]


@compiled
def _kernel(indptr, indices, data, dest, jrow, Jm, out, KJ, start, stop):
    n_s = Jm.shape[1]
    for i in range(start, stop):
        for k in range(indptr[i], indptr[i + 1]):
            v = data[k]
            d = dest[k]
            if d >= 0:
                out[d] = v
            r = jrow[indices[k]]
            if r >= 0:
                for j in range(n_s):
                    KJ[i, j] += v * Jm[r, j]


class SymmetricReduction:
    """T'^T K T' of a symmetric K in the reduced pattern ``pattern`` (the dict of
    ``ChainConstraint._reduced_pattern``): built once per pattern.

    ``K``: a CSR matrix of the pattern to reduce; ``pattern``: where each reduced entry comes
    from (``ids``: an index into K.data, or past its end into the (f, q), (q, f), (q, q) blocks);
    ``rows_m``: K's rows of the moving nodes' x, y unknowns, in J_m's order.
    """

    def __init__(self, K, pattern: dict, rows_m: np.ndarray):
        nnz, ids = K.nnz, pattern["ids"]
        self.dest = np.full(nnz, -1, dtype=np.int64)
        from_K = ids < nnz
        self.dest[ids[from_K]] = np.flatnonzero(from_K)
        self.rest_pos, self.rest_src = np.flatnonzero(~from_K), ids[~from_K] - nnz
        self.jrow = np.full(K.shape[0], -1, dtype=np.int64)
        self.jrow[rows_m] = np.arange(len(rows_m))
        self.size = len(ids)
        n, parts = K.shape[0], threads.count()
        cuts = np.searchsorted(K.indptr, np.arange(1, parts) * nnz // parts)  # equal entries a thread
        self.ranges = list(zip(np.r_[0, cuts], np.r_[cuts, n]))

    def __call__(self, K, Jm: np.ndarray):
        """(reduced data with the (f, q) blocks left to fill, K J_m (n, n_s)): the caller writes
        the rest with :meth:`fill`."""
        out = np.empty(self.size)
        KJ = np.zeros((K.shape[0], Jm.shape[1]))
        Jm = np.ascontiguousarray(Jm)

        def run(r):
            _kernel(K.indptr, K.indices, K.data, self.dest, self.jrow, Jm, out, KJ, int(r[0]), int(r[1]))

        threads.map_chunks(run, self.ranges)
        return out, KJ

    def fill(self, out: np.ndarray, rest: np.ndarray) -> np.ndarray:
        """out with the entries that are not K's (the (f, q), (q, f) and (q, q) blocks) from
        ``rest``, the concatenation the NumPy path appends to K.data."""
        out[self.rest_pos] = rest[self.rest_src]
        return out
