"""The FEM-informed grasp posed by F_v or by the pump pressure (reduced/calibrated/grasp_hold.py): the
one-solve path against the bracketing root finder on grasp_fem.grasp_state, per call.

For the designs of the four example tasks' optima (the paper's, the small object's, the large
object's), after one warm-up call (the design's calibrated finger curves are built once per
design), prints the CPU and wall time per call and the batched evaluations of the equations.
CPU time tells the cost when other jobs share the cores. No assertions: speed is measured.

    PYTHONPATH=. python benchmarks/bench_grasp_hold.py [--repeat 20]
"""
from __future__ import annotations

import argparse
import time

from softhand.reduced.calibrated import finger_hinges, grasp_hold, grasp_hold_fast, grasp_hold_solve
from softhand.reduced.vocabulary.design import HandDesign

PAPER = finger_hinges.fem_finger(HandDesign(reservoir_model="fem"))
CASES = {
    "paper 180 mm, 2 kg": (PAPER.replace(a=4.5, b=4.5, d=18.0, V0=26312.0), 180.0, 2.0, 9.80665),
    "small 140 mm, 0.5 kg": (PAPER.replace(a=4.5, b=4.5, d=12.0, V0=16226.0, l0=185.7,
                                           hinge_s=tuple(s * 185.7 / PAPER.l0 for s in PAPER.hinge_s)),
                             140.0, 0.5, 2.4516625),
    "large 240 mm, 3 kg": (PAPER.replace(a=4.5, b=5.69, d=18.0, R=29.3, V0=30000.0), 240.0, 3.0, 14.709975),
}


def per_call(fn, repeat: int):
    """(wall [ms], CPU [ms]) per call, averaged over ``repeat`` calls."""
    w0, c0 = time.perf_counter(), time.process_time()
    for _ in range(repeat):
        fn()
    return 1e3 * (time.perf_counter() - w0) / repeat, 1e3 * (time.process_time() - c0) / repeat


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=20, help="calls per timing (the slow path: a quarter)")
    args = parser.parse_args()
    calls = [0]
    residuals = grasp_hold_solve._residuals

    def counted(*a):
        calls[0] += 1
        return residuals(*a)

    grasp_hold_solve._residuals = counted
    for name, (design, diameter, mass, F_v) in CASES.items():
        fast = lambda: grasp_hold_fast.fast_hold(design, diameter, mass, "F_v", F_v)  # noqa: E731
        slow = lambda: grasp_hold.slow_hold(design, diameter, mass, "F_v", F_v)  # noqa: E731
        fast()
        calls[0] = 0
        wf, cf = per_call(fast, args.repeat)
        n = calls[0] / args.repeat
        ws, cs = per_call(slow, max(1, args.repeat // 4))
        print(f"{name}: fast {cf:.1f} ms CPU ({wf:.1f} ms wall, {n:.1f} batched evaluations), "
              f"slow {cs:.0f} ms CPU ({ws:.0f} ms wall): {cs / cf:.0f} x")


if __name__ == "__main__":
    main()
