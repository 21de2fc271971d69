"""Factorisation time of the sparse direct solvers on the finger FEM's tangent (38k unknowns).

The tangent of the default finger mesh after half a Newton step at 0.3 MPa, evaluated at
0.4 MPa, factorised by each backend of :mod:`softhand.fem.linsolve` that is installed (PARDISO,
UMFPACK, QDLDL, SuperLU) and by cholespy if importable, each in its own process with a
time limit. Prints seconds per factorisation and the relative residual of one solve.

    python benchmarks/bench_solvers.py [--timeout-s 400]
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp


def tangent(path: Path) -> None:
    """Write the benchmark tangent K and right-hand side b to ``path`` (npz)."""
    from softhand.fem.hand.finger import FingerModel, FingerOptions
    from softhand.fem.linsolve import make_solver
    from softhand.reduced.vocabulary.design import HandDesign

    model = FingerModel(HandDesign(), FingerOptions())
    y = model.constraint.zero()
    R, K = model.residual_tangent(y, 0.3)
    y = y + 0.5 * make_solver(symmetric=True, precision="double").solve(K, -R)
    R, K = model.residual_tangent(y, 0.4)
    K = K.tocsr()
    np.savez(path, data=K.data, indices=K.indices, indptr=K.indptr, b=-R)


def factorise(path: str, method: str) -> None:
    """Child process: time one factorisation + solve of the saved tangent by ``method``."""
    z = np.load(path)
    K = sp.csr_matrix((z["data"], z["indices"], z["indptr"]))
    b = z["b"]
    t0 = time.perf_counter()
    if method == "cholespy":
        from cholespy import CholeskySolverD, MatrixType
        C = K.tocoo()
        chol = CholeskySolverD(K.shape[0], C.row.astype(np.int32), C.col.astype(np.int32), C.data,
                               MatrixType.COO)
        x = np.zeros_like(b)
        chol.solve(b.copy(), x)
    else:
        from softhand.fem.linsolve import make_solver
        x = make_solver(method, symmetric=True, precision="double").solve(K, b)
    seconds = time.perf_counter() - t0
    print(f"{method:9s} {seconds:8.2f} s   relative residual {np.linalg.norm(K @ x - b) / np.linalg.norm(b):.1e}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timeout-s", type=float, default=400.0, help="time limit per solver [s]")
    parser.add_argument("--child", nargs=2, metavar=("NPZ", "METHOD"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        return factorise(*args.child)
    from softhand.fem.linsolve import available

    methods = available() + (["cholespy"] if _importable("cholespy") else [])
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "tangent.npz"
        tangent(path)
        print(f"# {len(np.load(path)['b'])} unknowns; seconds for one factorisation + solve")
        for method in methods:
            try:
                subprocess.run([sys.executable, __file__, "--child", str(path), method],
                               timeout=args.timeout_s, check=False)
            except subprocess.TimeoutExpired:
                print(f"{method:9s} > {args.timeout_s:g} s (stopped)")


def _importable(module: str) -> bool:
    try:
        __import__(module)
        return True
    except ImportError:
        return False


if __name__ == "__main__":
    main()
