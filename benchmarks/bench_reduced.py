"""Speed of the reduced model: P(theta), theta(P), F_v for 1e5 values; `softhand curve` wall time;
the same P(theta), theta(P) with the FEM-calibrated finger model (finger_model = "fem").

Run: python benchmarks/bench_reduced.py   (prints the best of a few repeats, in seconds; the
`softhand curve` rows' CPU time is the child process's, start-up included)
"""
from __future__ import annotations

import math
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from softhand.reduced.equations import grasp, hand
from softhand.reduced.vocabulary.design import HandDesign

N = 100_000


def best_of(fn, repeats: int = 5) -> tuple[float, float]:
    """Best wall and CPU time of ``repeats`` calls [s] (after one warm-up call).

    The CPU time of this process says what the code costs when other jobs share the cores.
    """
    fn()
    walls, cpus = [], []
    for _ in range(repeats):
        wall, cpu = time.perf_counter(), _cpu()
        fn()
        walls.append(time.perf_counter() - wall)
        cpus.append(_cpu() - cpu)
    return min(walls), min(cpus)


def _cpu() -> float:
    """CPU seconds of this process and of its finished children (the `softhand curve` runs)."""
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + children.ru_utime + children.ru_stime


def main() -> None:
    design = HandDesign()
    rng = np.random.default_rng(0)
    theta = rng.uniform(0.0, math.pi / 2, N)
    P = hand.pressure(theta, design)
    w = np.array(grasp.PAPER_WEIGHTS[240.0])
    mass = rng.uniform(0.0, 6.0, N)
    P_grasp = P + rng.uniform(0.0, 0.5, N)
    rows = [
        ("P(theta), eq. (27), 1e5 angles", lambda: hand.pressure(theta, design)),
        ("P(theta), eq. (28), 1e5 angles", lambda: hand.pressure(theta, design, reservoir=False)),
        ("theta(P), eq. (27) inverted, 1e5 pressures", lambda: hand.bend_angle(P, design)),
        ("F_v, eqs. (25), (29), 1e5 states",
         lambda: grasp.grasp_forces(P_grasp, theta, mass, w, design).F_v),
    ]
    fem = design.replace(finger_model="fem")
    P_fem = hand.pressure(theta, fem)
    rows += [
        ("P(theta), finger_model fem, 1e5 angles", lambda: hand.pressure(theta, fem)),
        ("theta(P), finger_model fem, 1e5 pressures", lambda: hand.bend_angle(P_fem, fem)),
    ]
    print(f"{'':<45} {'wall [s]':>9} {'cpu [s]':>9}   (load average {os.getloadavg()[0]:.1f})")
    for label, fn in rows:
        print(f"{label:<45} {'%9.4f %9.4f' % best_of(fn)}")
    command = [sys.executable, "-m", "softhand.studies.cli.main", "curve", "--theta-deg", "0:90:10"]
    times = best_of(lambda: subprocess.run(command, check=True, capture_output=True), repeats=3)
    print(f"{'softhand curve --theta-deg 0:90:10, start-up incl.':<45} {'%9.4f %9.4f' % times}")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "softhand.fem.toml"
        path.write_text(fem.to_toml())
        times = best_of(lambda: subprocess.run(command[:-2] + ["--pressure-mpa", "0.2,0.5,0.8",
                                                              "--design", str(path)],
                                               check=True, capture_output=True), repeats=3)
    print(f"{'softhand curve, finger_model fem, start-up incl.':<45} {'%9.4f %9.4f' % times}")


if __name__ == "__main__":
    main()
