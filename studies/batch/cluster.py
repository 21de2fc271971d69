"""The batch runner on a Dask cluster (an address, or 'local' for a LocalCluster).

Memory: Dask's nanny starts its workers with ``MALLOC_TRIM_THRESHOLD_=65536``, which turns off
glibc's adaptive thresholds: every freed block above 128 KiB goes back to the operating system
and the next allocation faults its pages in again. The FEM allocates and frees megabytes of
element-kernel temporaries per assembly, and a CI-mesh finger case took 8.9 s in a Dask worker
against 3.6 s in a plain process (one thread each). The local cluster's workers start without
that variable; on any other cluster ``_case_on_worker()`` raises the thresholds in the worker
itself (4.1 s), once per process.
"""
from __future__ import annotations

import ctypes
import logging
import os
import socket
import traceback

from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.batch.cases import execute_case
from softhand.studies.batch.pool import thread_share
from softhand.studies.batch.studyfile import Study

#: glibc's mallopt parameters (malloc.h) and the values set in a worker started with a small
#: trim threshold: the adaptive mmap threshold's own ceiling on 64-bit (32 MiB), and twice it
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
_ROOMY = {_M_MMAP_THRESHOLD: 32 << 20, _M_TRIM_THRESHOLD: 64 << 20}
_roomy_pids: set = set()


def open_cluster(scheduler: str, workers: int):
    """(client, cluster or None), before any case is claimed; InputError if unreachable."""
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise InputError("--scheduler", scheduler,
                         "needs dask: pip install 'softhand[cluster]'") from None
    if scheduler == "local":
        import dask

        threads = str(thread_share(workers))  # each worker's share of the cores, as in the pool
        environ = {"MALLOC_TRIM_THRESHOLD_": None, "OMP_NUM_THREADS": threads,
                   "MKL_NUM_THREADS": threads, "OPENBLAS_NUM_THREADS": threads}
        before = dict(os.environ)  # the nannies write their workers' variables into ours
        try:
            with dask.config.set({"distributed.nanny.pre-spawn-environ": environ}):
                cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
        finally:
            for key in set(os.environ) - set(before):
                del os.environ[key]
            os.environ.update(before)
        return Client(cluster), cluster
    return _connect(Client, scheduler), None


def close_cluster(client, cluster) -> None:
    client.close()
    if cluster is not None:
        cluster.close()


def dask_outcomes(study: Study, todo, client):
    """Yield (case, output) as the cluster finishes the cases of ``todo``."""
    from dask.distributed import as_completed

    futures = {client.submit(_case_on_worker, study.kind, c.params, c.design, pure=False): c
               for c in todo}
    for future in as_completed(futures):
        case = futures[future]
        try:
            yield case, future.result()
        except Exception as exc:  # e.g. KilledWorker: the case kills its workers
            yield case, {"status": "failed", "error": f"{type(exc).__name__}: {exc}",
                         "traceback": traceback.format_exc(), "wall_time_s": 0.0}


def _case_on_worker(kind: str, params: dict, design: dict) -> dict:
    """:func:`execute_case` in a Dask worker, with glibc's memory thresholds raised first when
    the worker was started with a trim threshold (see the module docstring)."""
    if "MALLOC_TRIM_THRESHOLD_" in os.environ:
        roomy_malloc()
    return execute_case(kind, params, design)


def roomy_malloc() -> bool:
    """glibc's mmap and trim thresholds raised to ``_ROOMY`` in this process, once; False
    where the C library has no ``mallopt`` (not glibc)."""
    if os.getpid() in _roomy_pids:
        return True
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    if not all(mallopt(param, value) == 1 for param, value in _ROOMY.items()):
        return False
    _roomy_pids.add(os.getpid())
    return True


def _probe(address: str) -> None:
    """Refuse at once a TCP address whose host does not resolve or whose port refuses the
    connection: Dask retries both until its 15 s timeout. Other schemes (tls, ucx, ...), and a
    host that does not answer at all, are left to Dask's own connection."""
    from distributed.comm.addressing import parse_address, parse_host_port

    try:
        scheme, location = parse_address(address)
        if scheme != "tcp":
            return
        host, port = parse_host_port(location, default_port=8786)
        socket.create_connection((host, port), timeout=5.0).close()
    except socket.gaierror as exc:
        raise InputError("--scheduler", address, f"cannot reach a Dask scheduler: no host {host!r} "
                         f"({exc.strerror})") from None
    except ConnectionRefusedError:
        raise InputError("--scheduler", address, f"cannot reach a Dask scheduler: nothing listens on "
                         f"port {port} of {host}") from None
    except (OSError, ValueError):  # a timeout, an address Dask may still read: Dask says
        return


def _connect(Client, address: str):
    _probe(address)
    quiet = logging.getLogger("distributed")
    level, quiet.level = quiet.level, logging.CRITICAL  # the one error line says it all
    try:
        return Client(address, timeout="15s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError("--scheduler", address, f"cannot reach a Dask scheduler ({exc})") from None
    finally:
        quiet.setLevel(level)
