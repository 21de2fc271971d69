"""Element kernels in threads: the thread count, order of results, and an assembly that is the
same on one thread as on several (each chunk's arithmetic does not depend on the threads)."""
import os
import warnings

import numpy as np
import pytest
import skfem as fe

from softhand.fem import threads
from softhand.fem.materials import Fibers, NeoHookean
from softhand.fem.solid import Solid


def test_thread_count_follows_omp_num_threads(monkeypatch):
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    monkeypatch.setenv("OMP_NUM_THREADS", "3")
    assert threads.count() == 3
    monkeypatch.setenv("OMP_NUM_THREADS", "not a number")  # ignored: the cores
    assert threads.count() == cores
    monkeypatch.delenv("OMP_NUM_THREADS")
    assert threads.count() == cores


def test_map_chunks_keeps_the_order(monkeypatch):
    monkeypatch.setenv("OMP_NUM_THREADS", "2")
    chunks = [slice(i, i + 3) for i in range(0, 30, 3)]
    assert threads.map_chunks(lambda c: c.start, chunks) == list(range(0, 30, 3))


def test_assembly_on_two_threads_equals_one_thread(monkeypatch):
    mesh = fe.MeshTet.init_tensor(*(np.linspace(0, 1, 4),) * 3).with_defaults()
    rng = np.random.default_rng(5)
    law = NeoHookean(1.0, 40.0) + Fibers(30.0, rng.standard_normal((3, mesh.t.shape[1])))
    solid = Solid(mesh, law, chunk=23)  # several chunks
    u = 0.05 * solid.dof_locations.T.ravel() + 0.005 * rng.standard_normal(solid.ndofs)
    out = {}
    for n in ("1", "2"):
        monkeypatch.setenv("OMP_NUM_THREADS", n)
        R, K = solid.residual_tangent(u)
        out[n] = (R, K.toarray(), solid.residual(u))
    for a, b in zip(out["1"], out["2"]):
        np.testing.assert_array_equal(a, b)


def test_worker_threads_keep_the_callers_error_handling(monkeypatch):
    monkeypatch.setenv("OMP_NUM_THREADS", "2")
    chunks = [slice(0, 1), slice(1, 2), slice(2, 3)]
    with np.errstate(invalid="raise"):
        with pytest.raises(FloatingPointError):
            threads.map_chunks(lambda c: np.sqrt(-np.ones(2)), chunks)
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("error")
        out = threads.map_chunks(lambda c: np.sqrt(-np.ones(2)), chunks)
    assert all(np.isnan(o).all() for o in out)


def test_a_fem_solver_puts_openblas_on_one_thread_and_leaves_mkl_its_threads():
    threadpoolctl = pytest.importorskip("threadpoolctl")
    from softhand.fem.linsolve import make_solver

    make_solver(symmetric=True)  # loads MKL where it is installed
    mkl = {i["filepath"]: i["num_threads"] for i in threadpoolctl.threadpool_info() if i["internal_api"] == "mkl"}
    threads._quiet.clear()  # as in a new process
    make_solver(symmetric=True)
    info = threadpoolctl.threadpool_info()
    assert all(i["num_threads"] == 1 for i in info if i["internal_api"] == "openblas")
    assert {i["filepath"]: i["num_threads"] for i in info if i["internal_api"] == "mkl"} == mkl
