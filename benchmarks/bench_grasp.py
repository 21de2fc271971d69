"""Grasp FEM speed: one ``softhand weights`` case (two contact states), by mesh.

180 mm object, m = 0 (or ``--mass-kg``), P = 0.8 + 0.05 MPa, default placement. Prints, per
element size, the unknowns, wall and CPU time of building the finger model and of the two
contact solves, Newton iterations, tangent factorisations and augmented-Lagrangian updates. CPU time tells the cost when other jobs
share the cores. No assertions: speed is measured, not tested.

    python benchmarks/bench_grasp.py [--mesh-size-mm 10,6] [--mass-kg 2]
"""
from __future__ import annotations

import argparse
import time

from softhand.fem.hand.finger import FingerModel
from softhand.fem.hand.grasp import GraspModel, grasp_weights
from softhand.reduced.vocabulary.design import HandDesign
from softhand.studies.weights import finger_options


def timed(fn):
    """(result, wall [s], CPU [s]) of one call."""
    w0, c0 = time.perf_counter(), time.process_time()
    result = fn()
    return result, time.perf_counter() - w0, time.process_time() - c0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh-size-mm", default="6,4", help="finger element sizes [mm] (graded meshes, as softhand weights uses)")
    parser.add_argument("--mass-kg", type=float, default=0.0, help="object mass [kg]")
    args = parser.parse_args()
    design = HandDesign()
    for h in (float(x) for x in args.mesh_size_mm.split(",")):
        finger, w_build, c_build = timed(lambda: FingerModel(design, finger_options(h)))
        model = GraspModel(finger, 180.0, mass=args.mass_kg)
        r, wall, cpu = timed(lambda: grasp_weights(model, 0.8, 0.05))
        its = r.state.iterations + r.state_dP.iterations
        ups = r.state.updates + r.state_dP.updates
        facs = r.state.factorizations + r.state_dP.factorizations
        print(f"mesh {h:g} mm: {finger.ndofs} unknowns; build {w_build:.1f} s wall / {c_build:.1f} s CPU; "
              f"two contact states {wall:.1f} s wall / {cpu:.1f} s CPU, {its} Newton iterations, "
              f"{facs} factorisations, {ups} AL updates")


if __name__ == "__main__":
    main()
