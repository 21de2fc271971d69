"""The sparse direct solver backends behind :func:`softhand.fem.linsolve.make_solver`.

The symbolic analysis (ordering + symbolic factorisation) is done once per sparsity
pattern and reused for every later matrix with the same pattern (PARDISO phase 11
once, then phase 22 per factorisation, phase 33 per solve). ``solver.name`` says which backend runs.

Mixed precision (PARDISO, ``precision="mixed"``, the default): the matrix is factorised
in single precision (half the factor's memory, ~1.8x faster on the 80k-DOF benchmark
tangent: 0.68 s against 1.27 s) and the solution is refined in double precision,
x <- x + LU^-1 (b - K x) with the residual in double, until
``||b - K x|| <= REFINE_RTOL ||b||`` -- the accuracy of the double-precision solve (2e-11
there). Each step gains a factor ~cond(K) eps_single (60x on that tangent, 4-5 steps).
When the refinement stalls or is too slow to reach it in REFINE_MAX steps (an
ill-conditioned K, e.g. kappa/mu = 1000 rubber with fibers) the solver falls back to double precision for good and says so in ``describe()``.
"""
from __future__ import annotations

import os
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

REFINE_RTOL = 1e-10  #: mixed precision: relative residual the refinement must reach
REFINE_MAX = 8  #: mixed precision: refinement steps before falling back to double


def pardiso_handle(**kwargs):
    """A new pypardiso solver. pypardiso looks for MKL by a recursive glob of the environment
    (0.2-0.3 s, 80 000 entries here) unless PYPARDISO_MKL_RT names the library: it is looked
    for first where the MKL wheels put it (``_wheel_mkl_rt()``), and the first handle's
    library is put there. MKL's OpenMP threads sleep as soon as a parallel region ends
    (``KMP_BLOCKTIME=0``, read when MKL starts its threads; see :mod:`softhand.fem.threads`) unless the
    environment sets it."""
    os.environ.setdefault("KMP_BLOCKTIME", "0")
    if "PYPARDISO_MKL_RT" not in os.environ and (found := _wheel_mkl_rt()):
        os.environ["PYPARDISO_MKL_RT"] = found
    import pypardiso
    ps = pypardiso.PyPardisoSolver(**kwargs)
    os.environ.setdefault("PYPARDISO_MKL_RT", ps.libmkl._name)
    return ps


def _wheel_mkl_rt() -> str | None:
    """MKL's runtime library where the ``mkl`` wheel installs it (the environment's ``lib``,
    or ``Library/bin`` on Windows), shortest name first; None when it is not there."""
    import glob
    import sys

    for pattern in ("lib/libmkl_rt.so*", "lib/libmkl_rt*.dylib", "Library/bin/mkl_rt*.dll"):
        found = sorted(glob.glob(os.path.join(sys.prefix, pattern)), key=len)
        if found:
            return found[0]
    return None


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


class PardisoSolver(LinearSolver):
    """MKL PARDISO through pypardiso; symbolic analysis once per pattern; mixed or double precision."""

    name = "pardiso"

    def __init__(self, symmetric, precision="mixed"):
        super().__init__(symmetric)
        self.precision = precision
        self.refinement_steps = 0  #: mixed precision: refinement solves so far
        self.fallback = None  #: why mixed precision was given up (None: it was not)
        self._ps = self._handle(precision)
        self._upper = None

    def _handle(self, precision):
        ps = pardiso_handle(mtype=-2 if self.symmetric else 11)
        if precision == "mixed":  # explicit iparm (iparm[0] = 1) for the single-precision factor
            settings = {1: 2, 9: 8, 10: 0, 12: 0} if self.symmetric else {1: 2, 9: 13, 10: 1, 12: 1}
            ps.iparm[0], ps.iparm[27] = 1, 1  # user settings; single precision (a, b, x float32)
            for i, v in settings.items():  # METIS ordering, pivot perturbation, scaling, matching
                ps.iparm[i] = v
        return ps

    def describe(self) -> str:
        line = super().describe()
        if self.precision == "mixed":
            return f"{line}, mixed precision ({self.refinement_steps} refinement steps)"
        if self.fallback:
            return f"{line}, double precision ({self.fallback})"
        return line

    def _factorize(self, K):
        same = self._same_pattern(K)
        A = self._stored(K, same)
        if self.precision == "mixed":
            A = sp.csr_matrix((A.data.astype(np.float32), A.indices, A.indptr), shape=A.shape, copy=False)
        self._A = A
        work = np.zeros((K.shape[0], 1), dtype=A.dtype, order="F")
        self._ps.set_iparm(12, 0)  # CSR, not transposed
        if not same:
            self._ps.set_phase(11)  # reordering + symbolic factorisation
            self._ps._call_pardiso(A, work)
        self._ps.set_phase(22)  # numerical factorisation
        self._ps._call_pardiso(A, work)

    def _apply(self, b, rtol=None):
        if self.precision == "mixed":
            x = self._refine(self._K, b, rtol)
            if x is not None:
                return x
            self.precision, self._ps, self._pattern = "double", self._handle("double"), None
            self._factorize(self._K)  # a new analysis, in double precision
            self.n_factorizations += 1
        self._ps.set_phase(33)  # solve with the stored factor
        # PARDISO's default (iparm[7] = 2) refines every solution twice, three solves for one; it
        # gains nothing on a factor without perturbed pivots (the finger's tangent: relative residual
        # 6.3e-11 with and without). 0: refine (twice) only when pivots were perturbed
        self._ps.iparm[7] = 0
        return self._ps._call_pardiso(self._A, np.asfortranarray(b.reshape(-1, 1))).ravel()

    def _stored(self, K, same):
        """The matrix PARDISO gets: K, or its upper triangle in symmetric mode."""
        if not self.symmetric:
            return K
        if not same or self._upper is None:  # positions of the upper triangle in K.data, once per pattern
            rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
            sel = np.flatnonzero(K.indices >= rows)
            indptr = np.zeros(K.shape[0] + 1, dtype=K.indptr.dtype)
            np.cumsum(np.bincount(rows[sel], minlength=K.shape[0]), out=indptr[1:])
            self._upper = (sel, K.indices[sel], indptr)
        sel, ind, ptr = self._upper
        A = sp.csr_matrix((K.data[sel], ind, ptr), shape=K.shape, copy=False)
        A.has_sorted_indices = True
        return A

    def _refine(self, K, b, rtol=None):
        """Single-precision factor + double-precision refinement to max(REFINE_RTOL, rtol);
        None when it stalls."""
        target = REFINE_RTOL if rtol is None else max(REFINE_RTOL, rtol)
        A32 = self._A
        work = np.zeros((len(b), 1), dtype=np.float32, order="F")
        self._ps.set_phase(33)  # solves with the stored factor
        bnorm = float(np.linalg.norm(b))
        x, r, last = np.zeros_like(b), b, bnorm
        for step in range(REFINE_MAX):
            if last <= target * bnorm:
                return x
            work[:, 0] = r
            x = x + self._ps._call_pardiso(A32, work).ravel()
            self.refinement_steps += 1
            r = b - K @ x
            norm = float(np.linalg.norm(r))
            if not norm < 0.5 * last:  # stalled or diverging: single precision is not enough for K
                self.fallback = f"mixed precision stalled at relative residual {norm / bnorm:.1e}"
                return None
            left = REFINE_MAX - (step + 1)
            if norm * (norm / last) ** left > target * bnorm:  # too slow to get there in time
                self.fallback = (f"mixed precision too slow (relative residual {norm / bnorm:.1e}, "
                                 f"{norm / last:.2f} per step)")
                return None
            last = norm
        if last <= target * bnorm:
            return x
        self.fallback = f"mixed precision reached only {last / bnorm:.1e} in {REFINE_MAX} steps"
        return None


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
