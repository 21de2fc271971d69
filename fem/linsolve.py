"""Sparse direct solvers for Newton tangents, chosen automatically and reported.

Order of preference for ``method="auto"``: MKL PARDISO (``pypardiso``, a dependency
wherever Intel ships MKL wheels: x86-64 Linux, Windows, macOS) -- symmetric indefinite
mode (mtype -2, 2x2 Bunch-Kaufman pivoting, upper triangle only) when the caller
declares the matrix symmetric, real unsymmetric mode (mtype 11) otherwise (follower
pressure on an open surface makes the tangent unsymmetric); then UMFPACK
(``scikit-umfpack``) if installed; then, for symmetric matrices, QDLDL (``qdldl``, the
dependency where MKL is missing: LDL^T with an AMD ordering and no pivoting, for the
quasi-definite tangents here; a zero pivot falls back to SuperLU); then SciPy's SuperLU
with a minimum-degree ordering on A^T + A. On the finger FEM's 38k-unknown tangent
(loaded 2-core machine) one factorisation took 2.9 s with PARDISO, 35 s with QDLDL,
27 s with cholespy (SPD only), > 60 s with SuperLU (MMD on A^T + A) and > 400 s with
SuperLU's default COLAMD; the one python-mumps wheel does not import with NumPy 2. A
fallback is announced once (a :class:`RuntimeWarning`) with its expected slowdown.

The backends, their bookkeeping and the reuse of the symbolic analysis are in
:mod:`softhand.fem.linsolve_backends`, PARDISO and its mixed precision in
:mod:`softhand.fem.linsolve_pardiso`.
"""
from __future__ import annotations

import warnings

from softhand.fem import threads
from softhand.fem.linsolve_backends import LinearSolver, QdldlSolver, SuperLUSolver, UmfpackSolver
from softhand.fem.linsolve_pardiso import REFINE_MAX, REFINE_RTOL, PardisoSolver, pardiso_handle

__all__ = ["METHODS", "PRECISIONS", "available", "make_solver", "LinearSolver", "PardisoSolver",
           "UmfpackSolver", "QdldlSolver", "SuperLUSolver", "REFINE_RTOL", "REFINE_MAX"]

METHODS = ("auto", "pardiso", "umfpack", "qdldl", "superlu")
#: factorisation time over PARDISO's on the finger FEM's tangent (module docstring)
SLOWDOWN = {"umfpack": 3, "qdldl": 12, "superlu": 30}
_announced = set()
PRECISIONS = ("mixed", "double")


def available() -> list[str]:
    """Backends importable here, fastest first."""
    out = []
    try:
        pardiso_handle()  # raises ImportError when the MKL runtime is missing
        out.append("pardiso")
    except (ImportError, OSError):
        pass
    for name, module in (("umfpack", "scikits.umfpack"), ("qdldl", "qdldl")):
        try:
            __import__(module)
            out.append(name)
        except ImportError:
            pass
    return out + ["superlu"]


def make_solver(method: str = "auto", *, symmetric: bool = False, precision: str = "mixed") -> "LinearSolver":
    """A solver object with ``solve(K, b) -> x``; ``symmetric``: K is symmetric (any sign);
    ``precision``: "mixed" (PARDISO only; see the module docstring) or "double"."""
    if method not in METHODS:
        raise ValueError(f"linear solver {method!r} not in {METHODS}")
    if precision not in PRECISIONS:
        raise ValueError(f"precision {precision!r} not in {PRECISIONS}")
    threads.quiet_blas()  # OpenBLAS's spinning threads would slow the factorisations (fem.threads)
    if method == "auto":
        method = next(m for m in available() if symmetric or m != "qdldl")
        _announce(method)
    if method == "qdldl" and not symmetric:
        raise ValueError("linear solver 'qdldl' needs a symmetric matrix (symmetric=True)")
    if method == "pardiso":
        return PardisoSolver(symmetric, precision)
    return {"umfpack": UmfpackSolver, "qdldl": QdldlSolver, "superlu": SuperLUSolver}[method](symmetric)


def _announce(method: str) -> None:
    """Warn once per backend that the automatic choice is not PARDISO, and by how much it is slower."""
    if method == "pardiso" or method in _announced:
        return
    _announced.add(method)
    warnings.warn(f"MKL PARDISO (pypardiso) is not available here: the FEM's sparse factorisations "
                  f"use {method}, about {SLOWDOWN[method]}x slower (pypardiso needs MKL, which "
                  f"Intel ships for x86-64 only)", RuntimeWarning, stacklevel=3)
