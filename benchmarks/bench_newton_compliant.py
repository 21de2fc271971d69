"""A compliant finger's Newton: the pressure sweep as shipped against a continuation in the
rubber's bulk modulus (measured here, not yet the sweep's own path).

The design an optimiser proposed (a 6, b 3, d 10.14, l0 180 mm, 10 mm ring ties) bent by one
pressure of 0.6 MPa to about 70 deg. As shipped (:func:`softhand.fem.hand.finger.solve_pressures`)
its line search cuts Newton's steps to a few per cent and the step is cut back several times:
along the (accurate) predictor the nearly incompressible rubber's volume energy rises 500-fold,
most of it in a few elements of the tip's end cap. With the bulk modulus kappa lowered to
``--kappa-ratio`` mu the same path converges in full steps; one quasi-Newton solve at the real
kappa (1000 mu) from that state then lands on the same answer (theta within the Newton
tolerance) with one or two factorisations.

Run: ``python benchmarks/bench_newton_compliant.py [--pressure-mpa 0.6] [--steps 6]
[--kappa-ratio 100] [--axial-size-mm 2.5]``. Prints, per method, the factorisations, cut-backs,
Newton iterations, wall time and theta.
"""
from __future__ import annotations

import argparse
import math
import time
from dataclasses import replace

import numpy as np

from softhand.fem.hand.finger import FingerModel, FingerOptions, solve_pressures
from softhand.fem.hand.finger_sweep import SWEEP_NEWTON
from softhand.fem.linsolve import make_solver
from softhand.fem.newton import newton
from softhand.fem.newton_path import PathOptions, solve_path
from softhand.reduced.vocabulary.design import HandDesign

COMPLIANT = dict(a=6.0, b=3.0, d=10.14, l0=180.0)


def continuation(design, options, P, steps, kappa_ratio):
    """(factorisations, cut-backs, iterations, theta [deg]): the path at kappa_ratio mu in
    ``steps`` load steps, then one quasi-Newton solve at the options' kappa."""
    soft = FingerModel(design, replace(options, kappa_ratio=kappa_ratio))
    real = FingerModel(design, options)
    solver = make_solver(symmetric=True, precision="mixed")
    scale = design.mu_sf * design.a ** 2 * design.l0
    path = solve_path(lambda y, t: soft.residual_tangent(y, t * P), soft.constraint.zero(),
                      PathOptions(steps=steps, newton=SWEEP_NEWTON), solver=solver, scale_t=lambda t: scale,
                      residual_t=lambda y, t: soft.residual(y, t * P))
    last = newton(lambda y: real.residual_tangent(y, P), path.x[-1], SWEEP_NEWTON, solver=solver, scale=scale,
                  residual=lambda y: real.residual(y, P))
    theta = math.degrees(float(np.sum(real.constraint.q(last.x))))
    return solver.n_factorizations, path.cutbacks, path.total_iterations + last.iterations, theta


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pressure-mpa", type=float, default=0.6)
    parser.add_argument("--steps", type=int, default=6, help="load steps of the continuation's soft path")
    parser.add_argument("--kappa-ratio", type=float, default=100.0, help="the soft path's kappa / mu")
    parser.add_argument("--axial-size-mm", type=float, default=2.5, help="the layered mesh's slices (default mesh)")
    args = parser.parse_args()
    design = HandDesign().replace(**COMPLIANT)
    options = FingerOptions(axial_size=args.axial_size_mm)
    print("method                         factorisations  cut-backs  iterations  wall_s  theta_deg")
    t0 = time.perf_counter()
    model = FingerModel(design, options)
    states, stats = solve_pressures(model, [args.pressure_mpa])
    print(f"{'sweep as shipped':30s} {stats.factorizations:14d}  {stats.cutbacks:9d}  {stats.newton_iterations:10d}  "
          f"{time.perf_counter() - t0:6.1f}  {math.degrees(states[-1].theta):9.6f}", flush=True)
    t0 = time.perf_counter()
    n, cut, its, theta = continuation(design, options, args.pressure_mpa, args.steps, args.kappa_ratio)
    name = f"kappa {args.kappa_ratio:g} mu, {args.steps} steps"
    print(f"{name:30s} {n:14d}  {cut:9d}  {its:10d}  {time.perf_counter() - t0:6.1f}  {theta:9.6f}")


if __name__ == "__main__":
    main()
