"""Convergence of the FEM hold's holding limit with the finger mesh and the contact tolerance.

A case (default: two facing fingers pinching a 150 mm box, mu 0.5, 5 g, at 1.2 MPa -- the
closed-form check of tests/test_hold_fem.py -- or ``--object`` for the four-finger hand) on
two meshes (gmsh 10 mm, the CI mesh, and ``--fine-mm``), or with ``--axial-mm`` on nested
members of the default (layered) finger mesh family (axial slices of 5 / 2.5 / 1.25 mm: each
splits every slice of the one before; 2.5 mm is the default mesh), and two contact tolerances
(gap and stick slip, ``--tols``, default 1e-4 and 1e-6 mm). Prints the holding limit of each; a
long run (nice, background).

    nice python benchmarks/hold_convergence.py [--fine-mm 7] [--object sphere:150 --mass-kg 0.2]
    nice python benchmarks/hold_convergence.py --object sphere:180 --mass-kg 2 --friction 0.8 \
        --pressure-mpa 0.9 --axial-mm 5 2.5 1.25 --tols 1e-6 --resolution 0.002 --floor-n 0.002 \
        [--pull-control displacement]
"""
from __future__ import annotations

import argparse
import math
import time
from dataclasses import replace

from softhand.fem.hand.finger import FingerModel, FingerOptions
from softhand.fem.hand.hold import run_hold, solve_hold
from softhand.fem.hand.hold_model import HoldModel
from softhand.fem.hand.hold_options import HoldOptions
from softhand.fem.hand.hold_body import Body
from softhand.fem.hand.hold_options import ContactOptions
from softhand.fem.hand.hold_geometry import FingerFrame
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.holding.objects import parse_object


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fine-mm", type=float, default=7.0)
    parser.add_argument("--object", default="")
    parser.add_argument("--mass-kg", type=float, default=0.2)
    parser.add_argument("--friction", type=float, default=0.5)
    parser.add_argument("--pressure-mpa", type=float, default=1.2)
    parser.add_argument("--axial-mm", type=float, nargs="+", default=None,
                        help="layered finger meshes of these axial slice lengths instead of the gmsh pair")
    parser.add_argument("--tols", type=float, nargs="+", default=[1e-4, 1e-6])
    parser.add_argument("--resolution", type=float, default=0.02,
                        help="the holding limit's resolution, a share of the pull (default 0.02)")
    parser.add_argument("--floor-n", type=float, default=0.1,
                        help="... and at least this many newtons (default 0.1)")
    parser.add_argument("--pull-control", choices=("force", "displacement"), default="force",
                        help="the pull stepped as a force (default) or drawn by displacement")
    args = parser.parse_args()
    design = HandDesign()
    meshes = [("layered", h) for h in args.axial_mm] if args.axial_mm else [("gmsh", 10.0), ("gmsh", args.fine_mm)]
    for mesher, h in meshes:
        finger = FingerOptions(axial_size=h) if mesher == "layered" else FingerOptions(mesher="gmsh", mesh_size=h)
        model = FingerModel(design, finger)
        for tol in args.tols:
            contact = ContactOptions(gap_tol=tol, slip_tol=tol)
            t0 = time.perf_counter()
            if args.object:
                obj = replace(parse_object(args.object), mass_kg=args.mass_kg, friction=args.friction)
                r = solve_hold(design, obj, P_cavity_MPa=args.pressure_mpa,
                               options=HoldOptions(finger=finger, contact=contact, pull_resolution=args.resolution,
                                                   pull_floor=args.floor_n, pull_control=args.pull_control))
                held, limit = r.held, r.holding_limit_N
            else:
                box = Body("box", (0.0, 130.0, 0.0), (150.0, 140.0, 40.0), mass_kg=0.005, friction=args.friction)
                hold = HoldModel(design, box, layout=[FingerFrame(0.0), FingerFrame(math.pi)], finger_model=model,
                                 options=HoldOptions(finger=finger, contact=contact, close_steps=3,
                                                     pull_step=0.02, pull_floor=0.002, pull_control=args.pull_control))
                path = run_hold(hold, args.pressure_mpa)
                held, limit = path.held, path.holding_limit_N
            print(f"{mesher} mesh {h:g} mm ({model.ndofs} unknowns), tol {tol:g} mm: held {held}, "
                  f"limit {limit:.4g} N ({time.perf_counter() - t0:.0f} s)", flush=True)


if __name__ == "__main__":
    main()
