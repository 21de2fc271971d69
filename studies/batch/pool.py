"""The local process pool of the batch runner; its workers die with the parent process.

Each worker gets an equal share of the cores for its own threads (MKL PARDISO, OpenBLAS,
OpenMP): N workers on C cores run ``max(1, C // N)`` threads each. Left alone, every
worker's PARDISO starts a thread per core, so two workers on two cores ran four threads each
(``benchmarks/bench_batch.py`` measures the speed-up of 2 workers over 1).
"""
from __future__ import annotations

import itertools
import os
import shutil
import signal
import sys
import threading
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool

from softhand.studies.batch.cases import CASE_FOLDERS, Case, execute_case
from softhand.studies.batch.studyfile import Study


def pool_outcomes(study: Study, todo, workers: int, restarts: int = 2):
    """A process pool; if a worker dies, a new pool takes the cases not finished (twice at most)."""
    remaining = todo
    for attempt in range(restarts + 1):
        lost: list[Case] = []
        yield from _one_pool(study, remaining, workers, lost)
        if not lost:
            return
        remaining = itertools.chain(lost, remaining)
        again = "; a new pool takes them" if attempt < restarts else "; rerun to finish them"
        print(f"softhand study: a worker died; {len(lost)} cases not finished{again}",
              file=sys.stderr)
        if attempt == restarts:
            return


def _one_pool(study: Study, todo, workers: int, lost: list[Case]):
    """At most ``workers`` cases in flight; the next one read from ``todo`` as one finishes."""
    first = next(todo, None)
    if first is None:
        return
    pool = ProcessPoolExecutor(max_workers=workers, initializer=_worker_init,
                               initargs=(os.getpid(), thread_share(workers)))
    futures, broken = {}, False

    def submit(case):
        """In flight, or lost if the pool is broken: a worker can die after wait() returned."""
        nonlocal broken
        try:
            if not broken:
                futures[pool.submit(execute_case, study.kind, case.params, case.design)] = case
                return
        except BrokenProcessPool:
            broken = True
        lost.append(case)

    try:
        submit(first)
        for case in itertools.islice(todo, workers - 1):
            submit(case)
        while futures:
            finished, _ = wait(futures, return_when=FIRST_COMPLETED)
            for future in finished:
                case = futures.pop(future)
                try:
                    output = future.result()
                except BrokenProcessPool:
                    lost.append(case)
                    broken = True
                    continue
                yield case, output
                if not broken:
                    case = next(todo, None)
                    if case is not None:
                        submit(case)
    except BaseException:  # Ctrl-C, SIGTERM, an error here: the workers go with us
        for process in list((getattr(pool, "_processes", None) or {}).values()):
            process.terminate()
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def thread_share(workers: int) -> int:
    """Threads of each of ``workers`` processes: an equal share of the cores, at least one."""
    return max(1, (os.cpu_count() or 1) // workers)


def limit_threads(threads: int) -> None:
    """At most ``threads`` threads in this process's numerical libraries: those loaded later
    read the environment, those already loaded (a forked worker inherits them) are told."""
    for name in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
        os.environ[name] = str(threads)
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=threads)


def stop_worker(signum, frame=None) -> None:
    """A pool worker's SIGTERM (the parent stopping the pool, or dying): the private folder of the
    case it is computing removed, then exit at once (nothing of the case reaches the results)."""
    for folder in list(CASE_FOLDERS):
        shutil.rmtree(folder, ignore_errors=True)
    os._exit(128 + signum)


def _await_sigterm() -> None:
    """A worker's thread that takes its SIGTERM (blocked in every other thread) and stops it."""
    stop_worker(signal.sigwait({signal.SIGTERM}))


def _worker_init(parent: int, threads: int) -> None:
    """In each pool worker: its share of the cores' threads; die with the parent (Linux:
    PR_SET_PDEATHSIG, as SIGTERM); SIGTERM ends it at once, without the case's temporary folder; Ctrl-C
    (SIGINT to the whole process group) is the parent's to handle: it stops the workers.

    SIGTERM is taken by a thread of its own (:func:`_await_sigterm`), blocked in every other: a
    process's signal goes to any thread that does not block it, and the worker's libraries start
    threads (three in a worker here); Python runs a handler only in its main thread, which, waiting
    for the next case in a read() of the pool's pipe that another thread's signal does not
    interrupt, slept on (about one killed parent in 60 left a worker alive, measured)."""
    signal.signal(signal.SIGTERM, stop_worker)  # where a thread that does not block it takes it
    if hasattr(signal, "pthread_sigmask"):  # first: every thread started later inherits the block
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM})
        threading.Thread(target=_await_sigterm, name="softhand-sigterm", daemon=True).start()
    limit_threads(threads)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        import ctypes

        # 1 = PR_SET_PDEATHSIG; SIGTERM, not SIGKILL: stop_worker removes the case's folder first
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)
    except (OSError, AttributeError):
        pass  # not Linux: workers exit when they find the pool's pipe closed
    if os.getppid() != parent:  # the parent died before the death signal was armed
        os._exit(1)
