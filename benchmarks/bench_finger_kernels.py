"""Milliseconds of the finger FEM's assembly, piece by piece: the compiled kernels against the NumPy ones.

Run: ``python benchmarks/bench_finger_kernels.py [--repeat N]``. On the default finger at its
0.8 MPa state (solved first, about 10 s), each piece alone N times in a row (the best time):
the rubber and windings' forces and stiffness, their forces alone, the cavity's gradient and
Hessian, the reduction to the free unknowns and hinge angles, and the whole reduced tangent
and residual of ``FingerModel``; then the first call of each compiled kernel in a fresh process
(compiling, or loading the on-disk cache).
"""
from __future__ import annotations

import argparse
import contextlib
import subprocess
import sys
import time

import numpy as np

from softhand.fem.compiled import cavity, chain, rubber
from softhand.fem.hand.finger import FingerModel, FingerOptions, solve_pressures
from softhand.fem.loads import CavityVolume
from softhand.reduced.vocabulary.design import HandDesign

FIRST_CALL = """
import time, numpy as np
from softhand.fem.hand.finger import FingerModel
from softhand.reduced.vocabulary.design import HandDesign
m = FingerModel(HandDesign())
y = m.constraint.zero()
t0 = time.perf_counter(); m.residual_tangent(y, 0.1); t1 = time.perf_counter(); m.residual_tangent(y, 0.1)
print(f"{t1 - t0:.2f} {time.perf_counter() - t1:.3f}")
"""


def best_ms(fn, repeat: int) -> float:
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * min(times)


@contextlib.contextmanager
def numpy_only():
    """The compiled kernels switched off (a model built, or a reduction run, inside uses NumPy)."""
    saved = [(m, m.available) for m in (rubber, cavity, chain)]
    for module, _ in saved:
        module.available = lambda: False
    try:
        yield
    finally:
        for module, was in saved:
            module.available = was


def on_numpy(fn):
    def run():
        with numpy_only():
            return fn()
    return run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=10, help="runs of each piece (default 10; the best is printed)")
    args = parser.parse_args()
    design, P = HandDesign(), 0.8
    fast = FingerModel(design, FingerOptions())
    y = solve_pressures(fast, [0.4, 0.8])[0][-1].y
    with numpy_only():
        slow = FingerModel(design, FingerOptions())
    u = fast.constraint.expand(y)
    s, w = slow.solid, slow.windings
    wall = fast.mesh.boundaries["cavity"]
    cav_np = CavityVolume(s, wall, symmetry_normal=0, compiled=False)
    R, data = fast.kernels.residual_tangent_data(u, fast.solid)
    K = fast.solid.scatter.csr(data)

    def numpy_tangent():
        R, Ke = s.residual_element_matrices(u, extra=lambda c: w.terms(u, c))
        return s.scatter.block_matrix_data(Ke)

    def numpy_residual():
        R = s.residual(u)
        w.add_residual(u, R)

    def numpy_cavity():
        cav_np.add_hessian_data(np.zeros(s.scatter.nnz), u, -P)
        return cav_np.gradient(u)

    rows = [
        ("rubber + windings: forces and stiffness, scattered", numpy_tangent,
         lambda: fast.kernels.residual_tangent_data(u, fast.solid)),
        ("rubber + windings: forces alone", numpy_residual, lambda: fast.kernels.residual(u, fast.solid)),
        ("cavity: gradient and Hessian", numpy_cavity, lambda: fast.cavity.gradient(u, np.zeros(s.scatter.nnz), -P)),
        ("reduction to free unknowns and hinge angles", on_numpy(lambda: slow.constraint.reduce(y, R, K, None, symmetric=True)),
         lambda: fast.constraint.reduce(y, R, K, None, symmetric=True)),
        ("FingerModel.residual_tangent (all of it)", on_numpy(lambda: slow.residual_tangent(y, P)),
         lambda: fast.residual_tangent(y, P)),
        ("FingerModel.residual (all of it)", on_numpy(lambda: slow.residual(y, P)), lambda: fast.residual(y, P)),
    ]
    print(f"{'piece':52s} {'numpy_ms':>9s} {'compiled_ms':>12s} {'speed-up':>9s}")
    for name, a, b in rows:
        ta, tb = best_ms(a, args.repeat), best_ms(b, args.repeat)
        print(f"{name:52s} {ta:9.1f} {tb:12.1f} {ta / tb:8.1f}x", flush=True)
    first, second = subprocess.run([sys.executable, "-c", FIRST_CALL], capture_output=True, text=True,
                                   check=True).stdout.split()
    print(f"# a fresh process's first tangent {first} s (compiled kernels loaded from the disk cache, or "
          f"compiled if none), its second {float(second) * 1e3:.0f} ms")


if __name__ == "__main__":
    main()
