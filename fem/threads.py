"""Threads for the element kernels: chunks of elements evaluated side by side.

NumPy's batched products release the GIL, so the chunks of an assembly run in parallel
in threads of one process. What decides the speed-up is the chunk's size, not the
thread count alone: on the finger's 8664 P2 tetrahedra (2 cores) the rubber's residual
and tangent took 68 ms in chunks of 2048 elements on one thread, 71 ms on two (the two
chunks' intermediates, ~20 MB, evict each other from the cache), and 40 ms in chunks of
512 on two (:data:`CHUNK`).

Threads: ``OMP_NUM_THREADS`` when it is set (a batch worker's share of the cores, see
:mod:`softhand.studies.batch.pool`), else the cores this process may run on.

Threads that wait by spinning: OpenBLAS's threads (NumPy's and SciPy's BLAS) and MKL's
OpenMP threads (PARDISO) keep a core busy for a while after each call. The FEM's BLAS
calls are small (vector products, n x 5 blocks), but every one of them woke OpenBLAS's
threads, which then spun beside PARDISO's factorisation and the element kernels: the
finger curve (default mesh, 2 cores) took 19.8 s with them, 15.9 s with OpenBLAS on one
thread (PARDISO's time 9.6 -> 6.8 s) and 15.0 s with MKL's threads also asleep right after
a parallel region (``KMP_BLOCKTIME=0``: the tangent 133 -> 114 ms). :func:`quiet_blas`
does the first when a FEM solver is made (:func:`softhand.fem.linsolve.make_solver`); the second is
set before MKL is loaded (:mod:`softhand.fem.linsolve_pardiso`), unless the environment says otherwise.
"""
from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

CHUNK = 512  #: elements per chunk of an element kernel (see the module docstring)

_pools: dict = {}  # (process id, threads) -> executor: a forked child must not reuse its parent's
_quiet: set = set()  # processes whose OpenBLAS runs on one thread


def count() -> int:
    """Threads the element kernels may use (see the module docstring)."""
    try:
        return max(1, int(os.environ["OMP_NUM_THREADS"].split(",")[0]))
    except (KeyError, ValueError):
        return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def map_chunks(fn, chunks) -> list:
    """[fn(c) for c in chunks], evaluated in up to :func:`count` threads (in order), each under
    the caller's floating-point error handling (NumPy's ``errstate`` is per thread: a line
    search's trial point that inverts an element must stay as quiet in a worker thread)."""
    n = min(count(), len(chunks))
    if n <= 1:
        return [fn(c) for c in chunks]
    key = (os.getpid(), n)
    pool = _pools.get(key)
    if pool is None:
        pool = _pools[key] = ThreadPoolExecutor(n, thread_name_prefix="softhand-kernels")
    errors = np.geterr()

    def task(c):
        with np.errstate(**errors):
            return fn(c)

    return list(pool.map(task, chunks))


def quiet_blas() -> None:
    """OpenBLAS (NumPy's and SciPy's BLAS, as loaded now) on one thread in this process,
    once (see the module docstring); MKL, and so PARDISO, keeps its threads."""
    if os.getpid() in _quiet:
        return
    from threadpoolctl import ThreadpoolController

    ThreadpoolController().select(internal_api="openblas").limit(limits=1)
    _quiet.add(os.getpid())


def slabs(centroids: np.ndarray, dofs: np.ndarray, parts: int) -> list[np.ndarray]:
    """Element lists [slab 0, ..., slab parts-1, the rest]: the elements cut into ``parts`` slabs of
    equal count along the axis of the centroids' (nel, 3) largest extent; a slab keeps only the
    elements whose nodes (``dofs`` (nel, nloc)) no other slab's elements touch; the rest is last."""
    nel = len(centroids)
    if parts <= 1:
        return [np.arange(nel), np.arange(0)]
    axis = int(np.argmax(np.ptp(centroids, axis=0)))
    slab = np.empty(nel, dtype=np.int64)
    slab[np.argsort(centroids[:, axis], kind="stable")] = np.arange(nel) * parts // nel
    lo = np.full(dofs.max() + 1, parts, dtype=np.int64)
    hi = np.full(dofs.max() + 1, -1, dtype=np.int64)
    np.minimum.at(lo, dofs, slab[:, None])
    np.maximum.at(hi, dofs, slab[:, None])
    own = np.all((lo[dofs] == slab[:, None]) & (hi[dofs] == slab[:, None]), axis=1)
    return [np.flatnonzero(own & (slab == k)) for k in range(parts)] + [np.flatnonzero(~own)]
