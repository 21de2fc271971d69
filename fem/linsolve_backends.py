"""The sparse direct solver backends behind :func:`softhand.fem.linsolve.make_solver`: their common
bookkeeping, and UMFPACK, QDLDL and SuperLU (PARDISO is :mod:`softhand.fem.linsolve_pardiso`).

The symbolic analysis (ordering + symbolic factorisation) is done once per sparsity
pattern and reused for every later matrix with the same pattern (PARDISO phase 11
once, then phase 22 per factorisation, phase 33 per solve). ``solver.name`` says which backend runs.
"""
from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


class LinearSolver:
    """Common bookkeeping: times and counts of analyses, factorisations and solves.

    ``solve(K, b)`` factorises K and solves; ``factorize(K)`` then ``apply(b)`` keep the
    factor for later right-hand sides (a modified Newton step reuses an old tangent's).
    """

    name = "?"

    def __init__(self, symmetric: bool):
        self.symmetric = symmetric
        self.n_analyses = 0
        self.n_factorizations = 0
        self.n_solves = 0
        self.seconds = 0.0
        self._pattern = None
        self._K = None  #: the matrix of the current factor

    def _same_pattern(self, K) -> bool:
        p = self._pattern
        same = p is not None and np.array_equal(p[0], K.indptr) and np.array_equal(p[1], K.indices)
        if not same:
            self._pattern = (K.indptr.copy(), K.indices.copy())
            self.n_analyses += 1
        return same

    @property
    def factored_size(self) -> int | None:
        """Order of the matrix of the current factor (None: nothing factorised yet)."""
        return None if self._K is None else self._K.shape[0]

    def forget(self) -> None:
        """Drop the current factor (the analysis is kept): a caller that knows it belongs to a
        state of no further use (a failed solve's last iterate) keeps it from being applied."""
        self._K = None

    def factorize(self, K: sp.spmatrix) -> None:
        """Factorise K (square sparse) for :meth:`apply`; the analysis is reused for the same pattern."""
        t0 = time.perf_counter()
        K = K.tocsr(copy=True)  # the factor's own copy: the caller may reuse K's arrays
        if not K.has_sorted_indices:
            K.sort_indices()
        self._K = K
        self._factorize(K)
        self.n_factorizations += 1
        self.seconds += time.perf_counter() - t0

    def apply(self, b: np.ndarray, rtol: float | None = None) -> np.ndarray:
        """x with K x = b for the last factorised K; ``rtol``: a relative residual
        ||b - K x|| / ||b|| that is enough (an inexact Newton step): a solver that refines its
        solution (PARDISO in mixed precision) stops there instead of at ``REFINE_RTOL``;
        the direct solvers' one solve is more accurate anyway."""
        if self._K is None:
            raise RuntimeError(f"{self.name}: apply() before factorize()")
        t0 = time.perf_counter()
        x = self._apply(np.asarray(b, dtype=float), rtol)
        self.n_solves += 1
        self.seconds += time.perf_counter() - t0
        if not np.all(np.isfinite(x)):
            raise np.linalg.LinAlgError(f"{self.name}: non-finite solution (singular tangent?)")
        return x

    def solve(self, K: sp.spmatrix, b: np.ndarray, rtol: float | None = None) -> np.ndarray:
        """x with K x = b (K square sparse, b of shape (n,)); K's factor is kept; ``rtol`` as
        in :meth:`apply`."""
        self.factorize(K)
        return self.apply(b, rtol)

    def describe(self) -> str:
        """One line for reports."""
        kind = "symmetric" if self.symmetric else "unsymmetric"
        return (f"{self.name} ({kind}), {self.n_analyses} analyses, {self.n_factorizations} "
                f"factorisations, {self.n_solves} solves, {self.seconds:.2f} s")


class UmfpackSolver(LinearSolver):
    """UMFPACK (scikit-umfpack); symbolic analysis once per pattern."""

    name = "umfpack"

    def __init__(self, symmetric):
        super().__init__(symmetric)
        import scikits.umfpack as um
        self._ctx = um.UmfpackContext("di")
        self._um = um

    def _factorize(self, K):
        Kc = K.tocsc()
        Kc.sort_indices()
        Kc.indptr, Kc.indices = Kc.indptr.astype(np.int32), Kc.indices.astype(np.int32)
        if not self._same_pattern(Kc):
            self._ctx.symbolic(Kc)
        self._ctx.numeric(Kc)
        self._Kc = Kc

    def _apply(self, b, rtol=None):
        return self._ctx.solve(self._um.UMFPACK_A, self._Kc, b, autoTranspose=True)


class QdldlSolver(LinearSolver):
    """QDLDL on the upper triangle (symmetric K); the symbolic analysis (AMD ordering,
    elimination tree) once per pattern. A zero pivot (no LDL^T without pivoting in that
    ordering) or a tiny one (a solution with a relative residual above 1e-6) falls back to
    SuperLU for that matrix."""

    name = "qdldl"

    def __init__(self, symmetric):
        super().__init__(symmetric)
        import qdldl
        self._qdldl, self._f, self._lu = qdldl, None, None

    def _factorize(self, K):
        U = sp.triu(K, format="csc")
        self._lu = None
        try:
            if self._same_pattern(K) and self._f is not None:
                self._f.update(U, upper=True)
            else:
                self._f = self._qdldl.Solver(U, upper=True)
        except (ValueError, RuntimeError):
            self._f, self._pattern = None, None
            self._lu = spla.splu(K.tocsc(), permc_spec="MMD_AT_PLUS_A")

    def _apply(self, b, rtol=None):
        if self._lu is None:
            x = self._f.solve(b)
            with np.errstate(over="ignore", invalid="ignore"):  # a tiny pivot's huge x
                if np.linalg.norm(self._K @ x - b) <= 1e-6 * np.linalg.norm(b):
                    return x
            self._lu = spla.splu(self._K.tocsc(), permc_spec="MMD_AT_PLUS_A")  # a tiny pivot
        return self._lu.solve(b)


class SuperLUSolver(LinearSolver):
    """SciPy SuperLU (portable fallback; no reuse of the analysis)."""

    name = "superlu"

    def _factorize(self, K):
        self._same_pattern(K)
        self._lu = spla.splu(K.tocsc(), permc_spec="MMD_AT_PLUS_A")

    def _apply(self, b, rtol=None):
        return self._lu.solve(b)
