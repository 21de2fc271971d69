"""Calibration speed: ``softhand fit`` on the shipped synthetic examples.

Prints the best wall / CPU time of the least-squares fit itself (reading, fitting, the
Jacobian and its SVD; no plotting) for the bending example (36 points) with one and two
parameters and for the grasp example (12 points), with the model evaluations each took.
No assertions: speed is measured, not tested.

    python benchmarks/bench_fit.py
"""
from __future__ import annotations

import argparse
import warnings
from pathlib import Path

from bench_reduced import best_of  # the sibling script: best wall time after a warm-up
from softhand.reduced.fitting.csvdata import read_measurements
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.fitting.fit import fit, make_predictor

DATA = Path(__file__).resolve().parent.parent / "studies" / "data"
CASES = (("example_bending.csv", "V0_mm3"), ("example_bending.csv", "V0_mm3,mu_sf_MPa"),
         ("example_grasp.csv", "V0_mm3,mu_sf_MPa"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    warnings.simplefilter("ignore")  # the paper's 180 mm w sums to 1.40
    for name, params in CASES:
        data = read_measurements(DATA / name)
        predictor = make_predictor(data)
        result = fit(data, params, predictor, HandDesign())
        wall, cpu = best_of(lambda: fit(data, params, predictor, HandDesign()), args.repeat)
        print(f"{name:22s} {params:18s} {len(data):3d} points: {result.nfev:3d} evaluations, "
              f"wall {1e3 * wall:7.1f} ms, cpu {1e3 * cpu:7.1f} ms")


if __name__ == "__main__":
    main()
