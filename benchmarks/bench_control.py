"""Control simulation speed: 10 s of simulated time at 1 kHz, target < 1 s.

Angle control to 50 deg holding 2 kg on the paper's design, a 5 N push at 5 s; the
controller runs at 100 Hz (default) and at 1 kHz (every step). Prints the best of
``--repeat`` wall and CPU times for: building the statics tables, one 10 s run, and the whole
Table II comparison (two runs). No assertions: speed is measured, not tested.

    python benchmarks/bench_control.py
"""
from __future__ import annotations

import argparse
import math
import time
import timeit
import warnings

from softhand.reduced.equations import grasp
from softhand.reduced.dynamics.control import AngleController, default_gains, flexibility, ramp, simulate
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.dynamics.plant import HandTables, PlantParams


def best(fn, repeat: int) -> tuple[float, float]:
    """(wall, CPU) [s]: the smallest of ``repeat`` single calls each; CPU time tells the cost
    when other jobs share the cores."""
    return (min(timeit.repeat(fn, number=1, repeat=repeat)),
            min(timeit.repeat(fn, timer=time.process_time, number=1, repeat=repeat)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    warnings.simplefilter("ignore", grasp.WeightSumWarning)
    design, w = HandDesign(), grasp.PAPER_WEIGHTS[180.0]
    theta_ref, push = math.radians(50.0), ramp(5.0, 5.0)
    wall, cpu = best(lambda: HandTables(design, w), args.repeat)
    print(f"tables (p28, J w on {HandTables(design, w).theta.size} angles): "
          f"{wall * 1e3:.1f} ms wall, {cpu * 1e3:.1f} ms CPU")
    tables = HandTables(design, w)
    for hz in (100.0, 1000.0):
        plant = PlantParams(sample_hz=hz)
        ctrl = lambda: AngleController(theta_ref, default_gains(tables, plant), design, plant)  # noqa: E731
        wall, cpu = best(lambda: simulate(ctrl(), tables, plant, mass=2.0, force=push), args.repeat)
        print(f"10 s at 1 kHz, controller at {hz:g} Hz: {wall:.3f} s wall, {cpu:.3f} s CPU "
              f"({cpu / 1e4 * 1e6:.1f} us/step; target < 1 s)")
    wall, cpu = best(lambda: flexibility(design, theta_ref, 2.0, w, push), args.repeat)
    print(f"Table II comparison (tables + angle run + pressure run): {wall:.3f} s wall, {cpu:.3f} s CPU")


if __name__ == "__main__":
    main()
