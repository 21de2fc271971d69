"""FEM speed benchmark: a compressible Neo-Hookean tube under dead loads.

Tube inner radius 4 mm, outer 9 mm, length 60 mm, clamped at z = 0; dead internal
pressure 0.3 MPa on the inner surface, dead traction (0.05, 0, 0) MPa on the end face;
W = mu/2 (I1 - 3) - mu ln J + lam/2 (ln J)^2, mu = 1.15 MPa, lam = 50 MPa; P2
displacements on straight-sided tetrahedra (gmsh), 5 equal load steps.

Prints DOFs, load steps, Newton iterations, assembly and solve seconds per iteration,
total, peak memory, and the tip displacement (mean over the end face). With
``ngsolve`` importable (the ``bench`` extra) it solves the same problem on the same
mesh with NGSolve (same quadrature, sparse Cholesky, plain Newton) and prints ratios.

    python benchmarks/bench_fem.py                 # ~20k DOFs
    python benchmarks/bench_fem.py --size medium   # ~80k DOFs
    python benchmarks/bench_fem.py --size large    # ~200k DOFs (heavy: run once)
    python benchmarks/bench_fem.py --size medium --steps 2   # time to the answer: the fewest
                                                             # load steps ours converges with

``--refactor adaptive`` (quasi-Newton on the last factorisation) and ``--precision double``
try the other solver settings (on this tube, 80k DOFs, 2 steps: quasi-Newton 14 factorisations,
14.0 s; Newton 22, 21.0 s; docs/fem-core.md).
"""
from __future__ import annotations

import argparse
import resource
import time
from dataclasses import replace

import numpy as np

from softhand.fem.assembly import Restriction
from softhand.fem.hand.finger_sweep import SWEEP_NEWTON
from softhand.fem.linsolve import make_solver
from softhand.fem.loads import dead_load
from softhand.fem.materials import CompressibleNeoHookean
from softhand.fem.newton import NewtonOptions
from softhand.fem.newton_path import PathOptions, solve_path
from softhand.fem.solid import Solid
from softhand.meshes.tube import Tube, tube_mesh

#: gmsh element size [mm] giving about 20k / 80k / 200k P2 DOFs on this tube
SIZES = {"small": 2.6, "medium": 1.6, "large": 1.15}
MU, LAM, P_IN, T_END = 1.15, 50.0, 0.3, (0.05, 0.0, 0.0)


def peak_mb() -> float:
    """Peak resident memory of this process so far [MB] (Linux ru_maxrss is in kB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def tip_mean(solid, u) -> np.ndarray:
    """Mean displacement over the end face (area-weighted) [mm]."""
    from skfem import FacetBasis
    fb = FacetBasis(solid.mesh, solid.element, facets="tip", intorder=4)
    uu = solid.nodal(u)
    vals = [np.asarray(fb.interpolate(uu[a])) for a in range(3)]
    area = fb.dx.sum()
    return np.array([(v * fb.dx).sum() / area for v in vals])


def run_ours(mesh, steps: int, solver_name: str, intorder: int, predictor: str, refactor: str = "always",
             precision: str = "mixed"):
    t0 = time.perf_counter()
    solid = Solid(mesh, CompressibleNeoHookean(MU, LAM), intorder=intorder)
    fixed = solid.dofs("base")
    red = Restriction(solid.ndofs, solid.free_dofs(fixed))
    f_ext = dead_load(solid, "inner", pressure=P_IN) + dead_load(solid, "tip", traction=T_END)
    f_free = red.vector(f_ext)
    setup = time.perf_counter() - t0
    solver = make_solver(solver_name, symmetric=True, precision=precision)

    calls = [0]

    def fun_t(x, t):
        calls[0] += 1
        R, K = solid.residual_tangent(red.expand(x), restriction=red)  # straight into the free-dof pattern
        return R - t * f_free, K

    def residual_t(x, t):  # the line search's trial points need no tangent
        return red.vector(solid.residual(red.expand(x))) - t * f_free

    scale = np.linalg.norm(red.vector(f_ext))
    newton = NewtonOptions(rtol=1e-10, atol=0.0) if refactor == "always" else \
        replace(SWEEP_NEWTON, rtol=1e-10, atol=0.0)  # the finger sweep's quasi-Newton
    opts = PathOptions(steps=steps, grow=1.0, predictor=predictor, newton=newton)
    res = solve_path(fun_t, np.zeros(len(red.keep)), opts, solver=solver, scale_t=lambda t: t * scale,
                     residual_t=residual_t)
    total = time.perf_counter() - t0
    u = red.expand(res.x[-1])
    return dict(dofs=solid.ndofs, steps=len(res.t) - 1, iterations=res.total_iterations,
                cutbacks=res.cutbacks, setup=setup, total=total,
                assembly=res.assembly_seconds, solve=res.solve_seconds,
                tip=tip_mean(solid, u), solver=solver.describe(), per_step=res.iterations,
                assemblies=calls[0], factorizations=res.factorizations)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", choices=list(SIZES), default="small")
    ap.add_argument("--h", type=float, help="gmsh element size [mm] (overrides --size)")
    ap.add_argument("--steps", type=int, default=5)
    ap.add_argument("--predictor", default="none", choices=["none", "tangent", "secant"],
                    help="load-step predictor (pure load control: none)")
    ap.add_argument("--solver", default="auto")
    ap.add_argument("--refactor", default="always", choices=["always", "adaptive"],
                    help="Newton (always: the per-iteration comparison) or quasi-Newton on the last factorisation")
    ap.add_argument("--precision", default="mixed", choices=["mixed", "double"],
                    help="PARDISO's factorisation (mixed: single precision refined to double)")
    ap.add_argument("--intorder", type=int, default=2, help="quadrature degree (both codes)")
    ap.add_argument("--no-ngsolve", action="store_true")
    ap.add_argument("--ngsolve-iterations", type=int, help="time only this many NGSolve iterations")
    ap.add_argument("--ngsolve-only", action="store_true", help="skip ours (NGSolve's own peak memory)")
    args = ap.parse_args(argv)
    h = args.h or SIZES[args.size]
    mesh = tube_mesh(Tube(4.0, 9.0, 60.0), size=h, order=1)
    if args.ngsolve_only:
        ng = _ngsolve_in_child(h, args)
        nit = max(ng["iterations"], 1)
        print(f"ngsolve: {ng['iterations']} Newton iterations, assembly {ng['assembly'] / nit:.3f} s/it, "
              f"solve {ng['solve'] / nit:.3f} s/it, peak RSS {ng['peak_mb']:.0f} MB")
        return
    base_mb = peak_mb()
    ours = run_ours(mesh, args.steps, args.solver, args.intorder, args.predictor, args.refactor,
                    args.precision)
    ours["peak_mb"] = peak_mb()
    it = max(ours["iterations"], 1)
    print(f"mesh h = {h} mm: {mesh.t.shape[1]} tets, {ours['dofs']} DOFs (P2); "
          f"peak RSS before solving {base_mb:.0f} MB")
    print(f"solver: {ours['solver']}")
    print(f"ours   : {ours['steps']} load steps, {ours['iterations']} Newton iterations "
          f"{ours['per_step']}, {ours['cutbacks']} cut-backs, {ours['assemblies']} assemblies, "
          f"{ours['factorizations']} factorisations")
    print(f"ours   : assembly {ours['assembly'] / it:.3f} s/it, solve {ours['solve'] / it:.3f} s/it, "
          f"setup {ours['setup']:.2f} s, total {ours['total']:.2f} s, peak RSS {ours['peak_mb']:.0f} MB")
    print(f"ours   : tip displacement (mean over end face) {np.array2string(ours['tip'], precision=10)} mm")
    if args.no_ngsolve:
        return
    try:
        import ngsolve  # noqa: F401
    except ImportError:
        print("ngsolve not importable: no comparison (pip install softhand[bench])")
        return
    ng = _ngsolve_in_child(h, args)
    nit = max(ng["iterations"], 1)
    print(f"ngsolve: {ng['steps']} load steps, {ng['iterations']} Newton iterations {ng['per_step']}")
    print(f"ngsolve: assembly {ng['assembly'] / nit:.3f} s/it, solve {ng['solve'] / nit:.3f} s/it, "
          f"total {ng['total']:.2f} s, peak RSS {ng['peak_mb']:.0f} MB (own process)")
    if ng["tip"] is not None:
        print(f"ngsolve: tip displacement {np.array2string(ng['tip'], precision=10)} mm; "
              f"max |difference| {np.abs(ng['tip'] - ours['tip']).max():.2e} mm")
    per_it = (ours["assembly"] + ours["solve"]) / it / ((ng["assembly"] + ng["solve"]) / nit)
    print(f"ratio ours/ngsolve: time per iteration {per_it:.2f}, "
          f"assembly {ours['assembly'] / it / (ng['assembly'] / nit):.2f}, "
          f"solve {ours['solve'] / it / (ng['solve'] / nit):.2f}, total {ours['total'] / ng['total']:.2f}, "
          f"peak memory {ours['peak_mb'] / ng['peak_mb']:.2f}")


def _ngsolve_in_child(h, args):
    """NGSolve on the same (cached) mesh in a fresh process, so its peak memory is its own."""
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor
    with ProcessPoolExecutor(1, mp_context=mp.get_context("spawn")) as pool:
        return pool.submit(_ngsolve_child, h, args.steps, args.intorder, args.ngsolve_iterations).result()


def _ngsolve_child(h, steps, intorder, budget):
    from bench_ngsolve import run_ngsolve
    out = run_ngsolve(tube_mesh(Tube(4.0, 9.0, 60.0), size=h, order=1), steps, intorder, budget=budget)
    out["peak_mb"] = peak_mb()
    return out


if __name__ == "__main__":
    main()
