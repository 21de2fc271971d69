"""The batch runner on a Dask cluster (an address, or 'local' for a LocalCluster)."""
from __future__ import annotations

import logging
import traceback

from softhand.reduced.errors import InputError
from softhand.studies.batch.cases import execute_case
from softhand.studies.batch.studyfile import Study


def open_cluster(scheduler: str, workers: int):
    """(client, cluster or None), before any case is claimed; InputError if unreachable."""
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise InputError("--scheduler", scheduler,
                         "needs dask: pip install 'softhand[cluster]'") from None
    if scheduler == "local":
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        return Client(cluster), cluster
    return _connect(Client, scheduler), None


def close_cluster(client, cluster) -> None:
    client.close()
    if cluster is not None:
        cluster.close()


def dask_outcomes(study: Study, todo, client):
    """Yield (case, output) as the cluster finishes the cases of ``todo``."""
    from dask.distributed import as_completed

    futures = {client.submit(execute_case, study.kind, c.params, c.design, pure=False): c
               for c in todo}
    for future in as_completed(futures):
        case = futures[future]
        try:
            yield case, future.result()
        except Exception as exc:  # e.g. KilledWorker: the case kills its workers
            yield case, {"status": "failed", "error": f"{type(exc).__name__}: {exc}",
                         "traceback": traceback.format_exc(), "wall_time_s": 0.0}


def _connect(Client, address: str):
    quiet = logging.getLogger("distributed")
    level, quiet.level = quiet.level, logging.CRITICAL  # the one error line says it all
    try:
        return Client(address, timeout="15s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError("--scheduler", address, f"cannot reach a Dask scheduler ({exc})") from None
    finally:
        quiet.setLevel(level)
