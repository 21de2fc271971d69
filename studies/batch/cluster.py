"""The batch runner on a Dask cluster (an address, or 'local' for a LocalCluster)."""
from __future__ import annotations

import traceback

from softhand.reduced.errors import InputError
from softhand.studies.batch.cases import Case, execute_case
from softhand.studies.batch.studyfile import Study


def dask_outcomes(study: Study, todo: list[Case], workers: int, scheduler: str):
    try:
        from dask.distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise InputError("--scheduler", scheduler,
                         "needs dask: pip install 'softhand[cluster]'") from None
    if scheduler == "local":
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    else:
        cluster, client = None, _connect(Client, scheduler)
    try:
        futures = {client.submit(execute_case, study.kind, c.params, c.design, pure=False): c
                   for c in todo}
        for future in as_completed(futures):
            case = futures[future]
            try:
                yield case, future.result()
            except Exception as exc:  # e.g. KilledWorker: the case kills its workers
                yield case, {"status": "failed", "error": f"{type(exc).__name__}: {exc}",
                             "traceback": traceback.format_exc(), "wall_time_s": 0.0}
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _connect(Client, address: str):
    try:
        return Client(address, timeout="15s")
    except (OSError, TimeoutError) as exc:
        raise InputError("--scheduler", address, f"cannot reach a Dask scheduler ({exc})") from None
