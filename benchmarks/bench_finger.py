"""Wall time and size of the finger FEM's default P-theta curve (0-0.8 MPa in 0.1 MPa steps).

Run: ``python benchmarks/bench_finger.py [--mesh-size-mm H ...] [--design FILE] [--numpy-kernels]``.
Prints, per mesh size, the unknowns, tetrahedra, Newton iterations, tangent factorisations,
assembly / linear-solve / total seconds and theta at the last pressure. ``--design``: another
design's finger (e.g. docs/tutorial/gripper.toml, a fitted Yeoh rubber); ``--numpy-kernels``:
with the compiled kernels switched off (the NumPy kernels alone), for comparison.
"""
from __future__ import annotations

import argparse

from softhand.fem.compiled import cavity, chain, rubber
from softhand.fem.hand.finger import FingerOptions
from softhand.reduced.vocabulary.design_files import load_design
from softhand.studies.bending import BendingStudy, run


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh-size-mm", type=float, nargs="+", default=[],
                        help="also gmsh meshes of these sizes (default: only the default layered mesh)")
    parser.add_argument("--design", default=None, help="design TOML (default: the paper's finger)")
    parser.add_argument("--numpy-kernels", action="store_true", help="switch the compiled kernels off")
    args = parser.parse_args()
    if args.numpy_kernels:
        for module in (rubber, cavity, chain):
            module.available = lambda: False
    design = load_design(args.design)
    print("mesh     unknowns  tets  newton  factorisations  assembly_s  solve_s  total_s  theta_0.8_deg")
    cases = [("default", FingerOptions())] + [(f"gmsh {h:g}", FingerOptions(mesher="gmsh", mesh_size=h))
                                              for h in args.mesh_size_mm]
    for name, options in cases:
        result = run(BendingStudy(design=design, options=options))
        s = result.stats
        print(f"{name:8s} {result.ndofs:8d}  {result.nelements:4d}  {s.newton_iterations:6d}  {s.factorizations:14d}  "
              f"{s.assembly_seconds:10.1f}  {s.solve_seconds:7.1f}  {s.wall_seconds:7.1f}  "
              f"{result.rows[-1]['theta_deg']:13.3f}", flush=True)
        print(f"# solver: {s.solver}; mesh and setup {result.build_seconds:.1f} s")


if __name__ == "__main__":
    main()
