"""A compliant finger's Newton: the pressure sweep's path through a softer rubber against the
direct load step cut back until it converges.

The design an optimiser proposed (a 6, b 3, d 10.14, l0 180 mm, 10 mm ring ties) bent by one
pressure of 0.6 MPa to about 70 deg. Directly (``continuation=False``) the line search cuts
Newton's steps to a few per cent and the step is cut back several times: along the (accurate)
predictor the nearly incompressible rubber's volume energy rises 500-fold, most of it in a few
elements of the tip's end cap. The sweep (:func:`softhand.fem.hand.finger.solve_pressures`)
sees the predictor bend the finger by more than ``BEND_STEP`` and follows the path on the rubber
with its bulk modulus at ``PATH_KAPPA_RATIO`` mu, then lands on the real rubber's equilibrium
with one quasi-Newton solve (:mod:`softhand.fem.hand.finger_sweep`).

Run: ``python benchmarks/bench_newton_compliant.py [--pressure-mpa 0.6] [--axial-size-mm 2.5]``.
Prints, per path, the factorisations, cut-backs, Newton iterations, wall time and theta.
"""
from __future__ import annotations

import argparse
import math
import time

from softhand.fem.hand.finger import FingerModel, FingerOptions, solve_pressures
from softhand.reduced.vocabulary.design import HandDesign

COMPLIANT = dict(a=6.0, b=3.0, d=10.14, l0=180.0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pressure-mpa", type=float, default=0.6)
    parser.add_argument("--axial-size-mm", type=float, default=2.5, help="the layered mesh's slices (default mesh)")
    args = parser.parse_args()
    model = FingerModel(HandDesign().replace(**COMPLIANT), FingerOptions(axial_size=args.axial_size_mm))
    print(f"# {model.ndofs} unknowns, 0 -> {args.pressure_mpa:g} MPa in one sweep step")
    print("path                                   factorisations  cut-backs  iterations  wall_s  theta_deg")
    for name, continuation in (("sweep (softer rubber where needed)", True), ("direct, cut back", False)):
        t0 = time.perf_counter()
        states, stats = solve_pressures(model, [args.pressure_mpa], continuation=continuation)
        print(f"{name:38s} {stats.factorizations:14d}  {stats.cutbacks:9d}  {stats.newton_iterations:10d}  "
              f"{time.perf_counter() - t0:6.1f}  {math.degrees(states[-1].theta):9.6f}", flush=True)


if __name__ == "__main__":
    main()
