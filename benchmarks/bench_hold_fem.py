"""Whole-hand FEM hold speed: a hold to its holding limit, off-axis (every finger solved) and
on-axis (symmetric: one finger solved).

Sphere (default the paper's 180 mm object, 2 kg, mu 0.8, at a cavity pressure of 0.9 MPa, which
the hand holds) at ``--pressure-mpa``; the off-axis case shifts it by
``--offset-mm`` along x. Prints wall and CPU time, fingers solved, load steps, the answer. CPU
time tells the cost when other jobs share the cores. No assertions: speed is measured, not tested.

    python benchmarks/bench_hold_fem.py [--mesh default|ci] [--cases offaxis,symmetric]
"""
from __future__ import annotations

import argparse
import time
from dataclasses import replace

from softhand.fem.hand.finger import FingerOptions
from softhand.fem.hand.hold import solve_hold
from softhand.fem.hand.hold_options import HoldOptions
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.holding.objects import parse_object


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", default="default", choices=("default", "ci"))
    parser.add_argument("--cases", default="offaxis,symmetric")
    parser.add_argument("--object", default="sphere:180")
    parser.add_argument("--mass-kg", type=float, default=2.0)
    parser.add_argument("--friction", type=float, default=0.8)
    parser.add_argument("--pressure-mpa", type=float, default=0.9)
    parser.add_argument("--offset-mm", type=float, default=1.5)
    args = parser.parse_args()
    finger = FingerOptions() if args.mesh == "default" else FingerOptions(mesher="gmsh", mesh_size=10.0)
    design = HandDesign()
    obj = replace(parse_object(args.object), mass_kg=args.mass_kg, friction=args.friction)
    for case in args.cases.split(","):
        o = replace(obj, offset_mm=(args.offset_mm, 0.0, 0.0)) if case == "offaxis" else obj
        w0, c0 = time.perf_counter(), time.process_time()
        r = solve_hold(design, o, P_cavity_MPa=args.pressure_mpa, options=HoldOptions(finger=finger))
        wall, cpu = time.perf_counter() - w0, time.process_time() - c0
        print(f"{case:10s} mesh {args.mesh}: {r.extra['fingers_solved']} fingers solved, "
              f"{len(r.steps)} load steps, held {r.held}, limit {r.holding_limit_N:.4g} N; "
              f"wall {wall:.1f} s, CPU {cpu:.1f} s", flush=True)


if __name__ == "__main__":
    main()
