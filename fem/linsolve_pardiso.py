"""MKL PARDISO behind :func:`softhand.fem.linsolve.make_solver`: its handle (the MKL runtime found
fast) and its solver, in double or mixed precision.

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

import numpy as np
import scipy.sparse as sp

from softhand.fem.linsolve_backends import LinearSolver

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
