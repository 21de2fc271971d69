"""Sparse direct solvers for Newton tangents, chosen automatically and reported.

Order of preference for ``method="auto"`` (measured on the 85k-DOF benchmark tangent,
issue 3): MKL PARDISO (``pypardiso``, the ``fast`` extra) -- symmetric indefinite
mode (mtype -2, 2x2 Bunch-Kaufman pivoting, upper triangle only) when the caller
declares the matrix symmetric, real unsymmetric mode (mtype 11) otherwise (follower
pressure on an open surface makes the tangent unsymmetric); then UMFPACK
(``scikit-umfpack``) if installed; then SciPy's SuperLU with a minimum-degree
ordering on A^T + A (the default COLAMD ordering is ~10x slower on these meshes).

The symbolic analysis (ordering + symbolic factorisation) is done once per sparsity
pattern and reused for every later matrix with the same pattern (PARDISO phase 11
once, then phase 23 per solve). ``solver.name`` says which backend runs.
"""
from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

METHODS = ("auto", "pardiso", "umfpack", "superlu")


def available() -> list[str]:
    """Backends importable here, fastest first."""
    out = []
    try:
        import pypardiso
        pypardiso.PyPardisoSolver()  # raises ImportError when the MKL runtime is missing
        out.append("pardiso")
    except (ImportError, OSError):
        pass
    try:
        import scikits.umfpack  # noqa: F401
        out.append("umfpack")
    except ImportError:
        pass
    return out + ["superlu"]


def make_solver(method: str = "auto", *, symmetric: bool = False) -> "LinearSolver":
    """A solver object with ``solve(K, b) -> x``; ``symmetric``: K is symmetric (any sign)."""
    if method not in METHODS:
        raise ValueError(f"linear solver {method!r} not in {METHODS}")
    if method == "auto":
        method = available()[0]
    return {"pardiso": PardisoSolver, "umfpack": UmfpackSolver, "superlu": SuperLUSolver}[method](symmetric)


class LinearSolver:
    """Common bookkeeping: times and counts of analyses and factorisations."""

    name = "?"

    def __init__(self, symmetric: bool):
        self.symmetric = symmetric
        self.n_analyses = 0
        self.n_solves = 0
        self.seconds = 0.0
        self._pattern = None

    def _same_pattern(self, K) -> bool:
        p = self._pattern
        same = p is not None and np.array_equal(p[0], K.indptr) and np.array_equal(p[1], K.indices)
        if not same:
            self._pattern = (K.indptr.copy(), K.indices.copy())
            self.n_analyses += 1
        return same

    def solve(self, K: sp.spmatrix, b: np.ndarray) -> np.ndarray:
        """x with K x = b (K square sparse, b of shape (n,))."""
        t0 = time.perf_counter()
        K = K.tocsr()
        if not K.has_sorted_indices:
            K.sort_indices()
        x = self._solve(K, np.asarray(b, dtype=float))
        self.n_solves += 1
        self.seconds += time.perf_counter() - t0
        if not np.all(np.isfinite(x)):
            raise np.linalg.LinAlgError(f"{self.name}: non-finite solution (singular tangent?)")
        return x

    def describe(self) -> str:
        """One line for reports."""
        kind = "symmetric" if self.symmetric else "unsymmetric"
        return f"{self.name} ({kind}), {self.n_analyses} analyses, {self.n_solves} solves, {self.seconds:.2f} s"


class PardisoSolver(LinearSolver):
    """MKL PARDISO through pypardiso; symbolic analysis once per pattern."""

    name = "pardiso"

    def __init__(self, symmetric):
        super().__init__(symmetric)
        import pypardiso
        self._ps = pypardiso.PyPardisoSolver(mtype=-2 if symmetric else 11)
        self._upper = None

    def _solve(self, K, b):
        same = self._same_pattern(K)
        if self.symmetric:
            if not same:  # positions of the upper triangle in K.data, once per pattern
                rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
                sel = np.flatnonzero(K.indices >= rows)
                indptr = np.zeros(K.shape[0] + 1, dtype=K.indptr.dtype)
                np.cumsum(np.bincount(rows[sel], minlength=K.shape[0]), out=indptr[1:])
                self._upper = (sel, K.indices[sel], indptr)
            sel, ind, ptr = self._upper
            K = sp.csr_matrix((K.data[sel], ind, ptr), shape=K.shape, copy=False)
            K.has_sorted_indices = True
        b2 = np.asfortranarray(b.reshape(-1, 1))
        self._ps.set_iparm(12, 0)  # CSR, not transposed
        if not same:
            self._ps.set_phase(11)  # reordering + symbolic factorisation
            self._ps._call_pardiso(K, b2)
        self._ps.set_phase(23)  # numerical factorisation + solve
        return self._ps._call_pardiso(K, b2).ravel()


class UmfpackSolver(LinearSolver):
    """UMFPACK (scikit-umfpack); symbolic analysis once per pattern."""

    name = "umfpack"

    def __init__(self, symmetric):
        super().__init__(symmetric)
        import scikits.umfpack as um
        self._ctx = um.UmfpackContext("di")
        self._um = um

    def _solve(self, K, b):
        Kc = K.tocsc()
        Kc.sort_indices()
        Kc.indptr, Kc.indices = Kc.indptr.astype(np.int32), Kc.indices.astype(np.int32)
        if not self._same_pattern(Kc):
            self._ctx.symbolic(Kc)
        self._ctx.numeric(Kc)
        return self._ctx.solve(self._um.UMFPACK_A, Kc, b, autoTranspose=True)


class SuperLUSolver(LinearSolver):
    """SciPy SuperLU (portable fallback; no reuse of the analysis)."""

    name = "superlu"

    def _solve(self, K, b):
        self._same_pattern(K)
        lu = spla.splu(K.tocsc(), permc_spec="MMD_AT_PLUS_A")
        return lu.solve(b)
