"""The benchmark tube of bench_fem.py in NGSolve, on the same mesh (optional ``bench`` extra).

NGSolve's best practice for this problem: the energy as a ``Variation`` (symbolic
linearisation), sparse Cholesky on the free dofs, plain Newton, the same load steps
and quadrature degree as ours. Times are measured the same way: assembly (energy
linearisation + residual) and solve (factorisation + solve) per Newton iteration.
Threads: all cores, or ``OMP_NUM_THREADS`` when set (MKL, i.e. PARDISO, reads it too).
"""
from __future__ import annotations

import os
import time

import numpy as np

MU, LAM, P_IN, T_END = 1.15, 50.0, 0.3, (0.05, 0.0, 0.0)


def ngsolve_mesh(mesh):
    """The skfem MeshTet as an NGSolve mesh with the same vertices, tets and named boundaries."""
    import netgen.meshing as nm
    import ngsolve
    ngm = nm.Mesh(dim=3)
    ngm.AddPoints(np.ascontiguousarray(mesh.p.T, dtype=float))
    ngm.AddElements(dim=3, index=ngm.AddRegion("wall", dim=3),
                    data=np.ascontiguousarray(mesh.t.T, dtype=np.int32), base=0)
    for name, facets in mesh.boundaries.items():
        tris = _outward(mesh, facets)
        ngm.AddElements(dim=2, index=ngm.AddRegion(name, dim=2), data=tris, base=0)
    return ngsolve.Mesh(ngm)


def _outward(mesh, facets):
    """Facet vertex triples ordered so that (p1 - p0) x (p2 - p0) points out of the solid."""
    tri = mesh.facets[:, facets].T.copy()
    p = mesh.p
    n = np.cross(p[:, tri[:, 1]] - p[:, tri[:, 0]], p[:, tri[:, 2]] - p[:, tri[:, 0]], axis=0)
    inside = p[:, mesh.t[:, mesh.f2t[0, facets]]].mean(axis=1)  # centroid of the adjacent tet
    flip = np.einsum("ij,ij->j", n, inside - p[:, tri[:, 0]]) > 0
    tri[flip, 1], tri[flip, 2] = tri[flip, 2], tri[flip, 1].copy()
    return np.ascontiguousarray(tri, dtype=np.int32)


def run_ngsolve(mesh, steps: int, intorder: int, *, tol: float = 1e-10, max_iter: int = 40,
                budget: int | None = None):
    """Plain Newton over ``steps`` equal load steps; halves the step on divergence (as ours).

    budget: stop after this many Newton iterations (per-iteration times only; tip is None).
    """
    import ngsolve as ng
    threads = int(os.environ.get("OMP_NUM_THREADS", "0"))  # as MKL (PARDISO) does for ours
    if threads > 0:
        ng.SetNumThreads(threads)
    with ng.TaskManager():
        return _run(ng, mesh, steps, intorder, tol, max_iter, budget)


class _Budget(Exception):
    pass


def _run(ng, mesh, steps, intorder, tol, max_iter, budget):
    t_start = time.perf_counter()
    m = ngsolve_mesh(mesh)
    fes = ng.VectorH1(m, order=2, dirichlet="base")
    u, v = fes.TnT()
    rule = {ng.ET.TET: ng.IntegrationRule(ng.ET.TET, intorder)}
    F = ng.Id(3) + ng.Grad(u)
    J = ng.Det(F)
    W = MU / 2 * (ng.Trace(F.trans * F) - 3) - MU * ng.log(J) + LAM / 2 * ng.log(J) ** 2
    a = ng.BilinearForm(fes, symmetric=True)
    a += ng.Variation(W.Compile() * ng.dx(intrules=rule))
    n = ng.specialcf.normal(3)
    f = ng.LinearForm(fes)
    f += -P_IN * n * v * ng.ds("inner", bonus_intorder=2)
    f += ng.CoefficientFunction(T_END) * v * ng.ds("tip", bonus_intorder=2)
    f.Assemble()
    gfu = ng.GridFunction(fes)
    res, work = gfu.vec.CreateVector(), gfu.vec.CreateVector()
    free = fes.FreeDofs()
    scale = np.linalg.norm(np.asarray(f.vec)[np.asarray(list(free), dtype=bool)])
    stats = dict(assembly=0.0, solve=0.0, iterations=0, per_step=[], budget=budget)
    t, dt = 0.0, 1.0 / steps
    while t < 1.0 - 1e-12:
        tn = min(1.0, t + dt)
        backup = gfu.vec.CreateVector()
        backup.data = gfu.vec
        try:
            its = _newton(a, f, gfu, res, work, free, tn, tol * tn * scale, max_iter, stats)
        except _Budget:
            return dict(steps=len(stats["per_step"]), iterations=stats["iterations"],
                        per_step=stats["per_step"], assembly=stats["assembly"], solve=stats["solve"],
                        total=time.perf_counter() - t_start, tip=None)
        if its is None:
            gfu.vec.data = backup
            dt *= 0.5
            continue
        t = tn
        stats["per_step"].append(its)
    tip = _tip_mean(ng, m, gfu)
    return dict(steps=len(stats["per_step"]), iterations=stats["iterations"], per_step=stats["per_step"],
                assembly=stats["assembly"], solve=stats["solve"], total=time.perf_counter() - t_start, tip=tip)


def _newton(a, f, gfu, res, work, free, t, tol, max_iter, stats):
    """Plain Newton at load factor t; iterations, or None on divergence."""
    mask = np.asarray(list(free), dtype=bool)
    for it in range(max_iter + 1):
        t0 = time.perf_counter()
        a.Apply(gfu.vec, res)
        res.data -= t * f.vec
        r = np.asarray(res)
        norm = np.linalg.norm(r[mask])
        if not np.isfinite(norm):
            return None
        if norm <= tol:
            stats["assembly"] += time.perf_counter() - t0
            return it
        if it == max_iter:
            return None
        a.AssembleLinearization(gfu.vec)
        t1 = time.perf_counter()
        inv = a.mat.Inverse(free, inverse="sparsecholesky")
        work.data = inv * res
        gfu.vec.data -= work
        stats["assembly"] += t1 - t0
        stats["solve"] += time.perf_counter() - t1
        stats["iterations"] += 1
        if stats["budget"] is not None and stats["iterations"] >= stats["budget"]:
            raise _Budget
    return None


def _tip_mean(ng, m, gfu):
    area = ng.Integrate(ng.CoefficientFunction(1.0), m, ng.BND, definedon=m.Boundaries("tip"), order=4)
    vals = ng.Integrate(gfu, m, ng.BND, definedon=m.Boundaries("tip"), order=4)
    return np.asarray(vals) / area
