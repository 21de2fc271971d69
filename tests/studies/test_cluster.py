"""The Dask cluster's workers: their environment, their C library's memory thresholds."""
import os
import subprocess
import sys

import pytest

from softhand.studies.batch.pool import thread_share

ENV_KEYS = ("MALLOC_TRIM_THRESHOLD_", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS")


def _worker_environ():
    return {k: os.environ.get(k) for k in ENV_KEYS}


def test_local_cluster_workers_get_their_core_share_and_glibcs_own_malloc(monkeypatch):
    """Dask's nanny would start them with a 64 KiB trim threshold (2.5x slower FEM) and one
    thread each; they get the pool's share of the cores, and our own environment is left as
    it was (the nannies write theirs into the parent's before they spawn)."""
    pytest.importorskip("dask.distributed")
    from softhand.studies.batch.cluster import close_cluster, open_cluster

    for key in ENV_KEYS:
        monkeypatch.delenv(key, raising=False)
    before = dict(os.environ)
    client, cluster = open_cluster("local", 1)
    try:
        assert dict(os.environ) == before
        seen = list(client.run(_worker_environ).values())
    finally:
        close_cluster(client, cluster)
    threads = str(thread_share(1))
    assert seen == [{"MALLOC_TRIM_THRESHOLD_": None, "OMP_NUM_THREADS": threads,
                     "MKL_NUM_THREADS": threads, "OPENBLAS_NUM_THREADS": threads}]


PROBE = """
import ctypes
libc = ctypes.CDLL(None)
try:
    class Info(ctypes.Structure):
        _fields_ = [(n, ctypes.c_size_t) for n in
                    "arena ordblks smblks hblks hblkhd usmblks fsmblks uordblks fordblks keepcost".split()]
    libc.mallinfo2.restype = Info
except AttributeError:
    raise SystemExit(3)  # not glibc >= 2.33
libc.malloc.restype, libc.malloc.argtypes = ctypes.c_void_p, [ctypes.c_size_t]
libc.free.argtypes = [ctypes.c_void_p]

def mapped(size):
    before = libc.mallinfo2().hblks
    block = libc.malloc(size)
    n = libc.mallinfo2().hblks - before
    libc.free(block)
    return n

first = mapped(1 << 20)
from softhand.studies.batch.cluster import roomy_malloc
raised = roomy_malloc()
print(first, raised, mapped(1 << 20), mapped(64 << 20))
"""


def test_roomy_malloc_keeps_megabyte_blocks_off_mmap():
    """With Dask's MALLOC_TRIM_THRESHOLD_ a 1 MiB block is a fresh mmap every time (its pages
    faulted in anew); after roomy_malloc it comes from the heap, and 64 MiB still maps."""
    env = dict(os.environ, MALLOC_TRIM_THRESHOLD_="65536")
    run = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True, text=True)
    if run.returncode == 3:
        pytest.skip("the C library has no mallinfo2 (not glibc >= 2.33)")
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["1", "True", "0", "1"]


def test_an_unreachable_scheduler_is_told_at_once_and_a_live_one_is_joined():
    """An unknown host and a port nobody listens on are one line without Dask's 15 s of retries;
    the probe does not stand in the way of a scheduler that is there."""
    pytest.importorskip("distributed")
    import socket

    from dask.distributed import LocalCluster

    from softhand.reduced.vocabulary.errors import InputError
    from softhand.studies.batch.cluster import close_cluster, open_cluster

    with pytest.raises(InputError, match="no host 'nowhere.invalid'"):
        open_cluster("tcp://nowhere.invalid:8786", 1)
    with socket.socket() as s:  # a port that was free a moment ago
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    with pytest.raises(InputError, match=f"nothing listens on port {port} of 127.0.0.1"):
        open_cluster(f"127.0.0.1:{port}", 1)
    with LocalCluster(n_workers=1, processes=False, dashboard_address=None) as cluster:
        client, own = open_cluster(cluster.scheduler_address, 1)
        assert own is None and client.submit(lambda x: x + 1, 1).result() == 2
        close_cluster(client, own)
