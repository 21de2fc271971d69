"""Reservoir sheet FEM: cost and mesh convergence of the inflation to V0 (prints numbers).

    python benchmarks/bench_reservoir.py

Per mesh (radial x layers of Q2/P1disc): DOFs, load steps, Newton iterations, wall time of
the whole path, one tangent assembly and one bordered solve at V0, and p, h, W at V0.
"""
from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from softhand.fem.linsolve import make_solver
from softhand.fem.hand.reservoir import SheetModel, inflate
from softhand.reduced.vocabulary.design import HandDesign

MESHES = ((20, 1), (40, 2), (80, 2), (40, 4), (80, 4))


def _timed(fn, repeat=5):
    t0 = time.perf_counter()
    for _ in range(repeat):
        out = fn()
    return out, (time.perf_counter() - t0) / repeat


def bench(n_radial: int, n_thick: int, V: float) -> dict:
    model = SheetModel(n_radial=n_radial, n_thick=n_thick)
    result = inflate(model, [V])
    state = result.states[0]
    solid, volume, fixed = model.build()
    free = np.setdiff1d(np.arange(solid.ndofs), fixed)
    K, t_asm = _timed(lambda: solid.tangent(state.u) - state.pressure * volume.hessian(state.u))
    g = volume.gradient(state.u)[free][:, None]
    A = sp.bmat([[K[free][:, free], sp.csr_matrix(-g)], [sp.csr_matrix(-g.T), None]], format="csr")
    solver = make_solver(symmetric=True)
    _, t_solve = _timed(lambda: solver.solve(A, np.ones(A.shape[0])))
    return {"mesh": f"{n_radial}x{n_thick}", "dofs": solid.ndofs, "steps": len(result.path_volume) - 1,
            "newton": result.newton_iterations, "total_s": result.wall_time,
            "assembly_ms": 1e3 * t_asm, "solve_ms": 1e3 * t_solve, "solver": solver.name,
            "p_MPa": state.pressure, "h_mm": state.apex, "W_Nmm": state.energy}


def main() -> None:
    V0 = HandDesign().V0
    print(f"reservoir sheet R = 24 mm, t = 1 mm, inflated from flat to V0 = {V0:.0f} mm^3")
    print(f"{'mesh':>6} {'dofs':>5} {'steps':>5} {'newton':>6} {'total_s':>7} {'asm_ms':>7} "
          f"{'solve_ms':>8} {'solver':>8} {'p_MPa':>9} {'h_mm':>8} {'W_Nmm':>8}")
    for n_radial, n_thick in MESHES:
        r = bench(n_radial, n_thick, V0)
        print(f"{r['mesh']:>6} {r['dofs']:>5} {r['steps']:>5} {r['newton']:>6} {r['total_s']:7.2f} "
              f"{r['assembly_ms']:7.2f} {r['solve_ms']:8.2f} {r['solver']:>8} {r['p_MPa']:9.6f} "
              f"{r['h_mm']:8.4f} {r['W_Nmm']:8.3f}", flush=True)


if __name__ == "__main__":
    main()
