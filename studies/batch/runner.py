"""The batch runner: every case of a study, on a local process pool or a Dask cluster.

Resumable and safe by construction:

* a case is keyed by a hash of its inputs (kind, case parameters, design hash) and the
  package version, so a rerun finds what is already done and a new release recomputes.
  The hash of the package's sources is recorded in each result's provenance;
  ``status`` counts the results that other sources computed, and ``run(fresh=True)``
  recomputes everything (a working tree under development changes its sources often);
* a worker computes a case in its own temporary folder and returns the numbers and the
  files; this process writes them into ``results/<study>/.<key>.<random>.tmp/`` and
  renames that folder to ``results/<study>/<key>/`` in one step. A killed run leaves
  finished cases complete and nothing half-written (a leftover temporary folder of a case
  is removed by the next run that claims the case). The same path serves the process
  pool and Dask, and a Dask cluster needs no shared file system;
* several runs of one study may run at once: each case is claimed (:mod:`studies.claims`)
  before it is computed, a case another run holds is left to it and taken as reused once
  done, so every case is computed once;
* a case file that does not parse (truncated, empty, ``null``, edited) counts as not done:
  ``status`` reports it as corrupt and the next run recomputes it;
* a case that raises is recorded (``<key>/failed.json``, with the error and traceback)
  and the others go on; a rerun tries it again;
* pool workers die with this process (also on SIGKILL), and SIGTERM stops a run as
  Ctrl-C does: finished cases are kept and ``index.csv`` is written.

``results/<study>/index.csv`` lists every case of the sweep with its state and numbers.
"""
from __future__ import annotations

import hashlib
import itertools
import json
import os
import shutil
import signal
import sys
import tempfile
import time
import traceback
import uuid
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import closing
from dataclasses import dataclass, field
from datetime import datetime, timezone
from functools import lru_cache
from pathlib import Path

import numpy as np

from softhand.reduced.design import HandDesign
from softhand.reduced.errors import InputError
from softhand.studies.batch.claims import Claims
from softhand.studies.io.files import write_csv, write_json
from softhand.studies.batch.studyfile import Study, resolve_kind

RESULT, FAILED = "result.json", "failed.json"
_PACKAGES = ("fem", "meshes", "reduced", "studies")


@dataclass(frozen=True)
class Case:
    """One point of a study's sweep."""

    key: str  #: hash of the inputs and the code version; the case's folder name
    point: dict  #: the sweep axes' values at this point
    params: dict  #: what the kind function receives
    design: HandDesign


@dataclass
class RunSummary:
    """What a run did; ``failed`` maps case key -> one-line error."""

    total: int
    reused: int = 0
    computed: int = 0
    failed: dict = field(default_factory=dict)
    not_run: int = 0  #: cases left pending (a worker died, or interrupted)
    corrupt: int = 0  #: case files found unreadable at the start (recomputed)

    @property
    def ok(self) -> bool:
        return not self.failed and not self.not_run


# ---------------------------------------------------------------------- keys, plan, state
@lru_cache(maxsize=1)
def code_version() -> dict:
    """The package version and a hash of the package's Python sources."""
    root = Path(__file__).resolve().parent.parent
    sha = hashlib.sha256()
    for package in _PACKAGES:
        for path in sorted((root / package).rglob("*.py")):
            sha.update(path.relative_to(root).as_posix().encode())
            sha.update(path.read_bytes())
    return {"softhand": _version("softhand"), "source_sha256": sha.hexdigest()[:16]}


@lru_cache(maxsize=1)
def package_versions() -> dict:
    names = ("numpy", "scipy", "scikit-fem", "gmsh", "meshio", "pyvista")
    return {"python": sys.version.split()[0], **{n: _version(n) for n in names}}


def _version(name: str) -> str:
    from softhand.reduced.versions import package_version

    return package_version(name, "not installed")


def case_key(kind: str, params: dict, design: HandDesign) -> str:
    """16 hex digits of the hash of (kind, params, design hash, package version)."""
    canon = {k: float(v) if isinstance(v, int) and not isinstance(v, bool) else v
             for k, v in params.items()}
    text = json.dumps({"kind": kind, "params": canon, "design": design.hash(),
                       "softhand": code_version()["softhand"]}, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def plan(study: Study) -> list[Case]:
    """Every case of the sweep, in sweep order."""
    names = [name for name, _ in study.axes]
    cases = []
    for params, design in study.cases():
        point = {n: params.get(n, design.to_dict().get(n)) for n in names}
        cases.append(Case(case_key(study.kind, params, design), point, params, design))
    return cases


def study_dir(study: Study, results_root: str | Path = "results") -> Path:
    return Path(results_root) / study.name


def case_state(sdir: Path, case: Case) -> str:
    """'done', 'failed', 'pending' or 'corrupt' (a case file that does not parse)."""
    folder = sdir / case.key
    for name, state in ((RESULT, "done"), (FAILED, "failed")):
        if (folder / name).exists():
            return state if _record(folder / name) is not None else "corrupt"
    return "corrupt" if folder.exists() else "pending"


def read_case(sdir: Path, case: Case) -> dict | None:
    """The stored result.json or failed.json of a case; None if pending or corrupt."""
    for name in (RESULT, FAILED):
        path = sdir / case.key / name
        if path.exists():
            return _record(path)
    return None


def _record(path: Path) -> dict | None:
    """A case file's record if it parses and has the record's shape, else None."""
    try:
        record = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    ok = (isinstance(record, dict) and record.get("status") == ("done" if path.name == RESULT else "failed")
          and isinstance(record.get("numbers"), dict) and isinstance(record.get("provenance"), dict))
    return record if ok else None


# ---------------------------------------------------------------------- one case
def execute_case(kind, params: dict, design: HandDesign) -> dict:
    """Compute one case in a private temporary folder; return numbers, files, timing.

    ``kind``: a registered kind's name, or (for callers inside softhand) the case function.

    Never raises for a failing kind: the error comes back as ``status = 'failed'``.
    """
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="softhand-case-") as tmp:
        try:
            out = (kind if callable(kind) else resolve_kind(kind))(dict(params), design, Path(tmp))
            numbers, extra = _split_output(out)
        except Exception as exc:  # a failing case is data, not a crash
            return {"status": "failed", "error": f"{type(exc).__name__}: {exc}",
                    "traceback": traceback.format_exc(),
                    "wall_time_s": time.perf_counter() - start}
        files = {p.relative_to(tmp).as_posix(): p.read_bytes()
                 for p in sorted(Path(tmp).rglob("*")) if p.is_file()}
    return {"status": "done", "numbers": numbers, **extra, "files": files,
            "wall_time_s": time.perf_counter() - start}


def _split_output(out) -> tuple[dict, dict]:
    """Check a kind's return value: numbers, plus optional 'mesh' and 'solver' dicts."""
    if not isinstance(out, dict):
        raise TypeError(f"a kind must return a dict of numbers, got {type(out).__name__}")
    extra = {k: out[k] for k in ("mesh", "solver") if isinstance(out.get(k), dict)}
    numbers = {}
    for key, value in out.items():
        if key in extra:
            continue
        array = np.asarray(value)
        if array.dtype.kind not in "biuf":
            raise TypeError(f"a kind's result {key!r} must be a number or list of numbers")
        numbers[key] = array.tolist()
    return numbers, extra


def commit_case(sdir: Path, study: Study, case: Case, output: dict) -> Path:
    """Store a case's outcome as ``<sdir>/<key>/result.json`` (or ``failed.json``) + files."""
    record = {"study": study.name, "case": case.key, "kind": study.kind, "point": case.point,
              **outcome_record(case.params, case.design, output)}
    return commit(sdir / case.key, record, output.get("files", {}))


def outcome_record(params: dict, design: HandDesign, output: dict) -> dict:
    """The JSON record of an :func:`execute_case` output: numbers, error, provenance."""
    return {"status": output["status"], "numbers": output.get("numbers", {}),
            "files": sorted(output.get("files", {})),
            "error": output.get("error"), "traceback": output.get("traceback"),
            "provenance": _provenance(params, design, output)}


def commit(final: Path, record: dict, files: dict) -> Path:
    """Write ``files`` and the record into a temporary folder, then rename it to ``final``.

    The record is ``result.json`` if its status is 'done', else ``failed.json``.
    """
    tmp = final.parent / f".{final.name}.{uuid.uuid4().hex[:8]}.tmp"
    tmp.mkdir(parents=True)
    for rel, data in files.items():
        (tmp / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp / rel).write_bytes(data)
    write_json(tmp / (RESULT if record["status"] == "done" else FAILED), record)
    if final.exists():
        shutil.rmtree(final)  # an earlier failure, a corrupt file, or a result of other inputs
    os.rename(tmp, final)
    return final


def _remove_leftovers(sdir: Path, key: str) -> None:
    """Temporary folders of case ``key`` a killed run left (only its claim holder calls this)."""
    for tmp in sdir.glob(f".{key}.*.tmp"):
        shutil.rmtree(tmp, ignore_errors=True)


def _provenance(params: dict, design: HandDesign, output: dict) -> dict:
    return {"inputs": params, "design": design.to_dict(), "design_hash": design.hash(), "code": code_version(),
            "versions": package_versions(), "mesh": output.get("mesh"),
            "solver": output.get("solver"), "wall_time_s": output["wall_time_s"],
            "finished_utc": datetime.now(timezone.utc).isoformat(timespec="seconds")}


# ---------------------------------------------------------------------- the run
def run_study(study: Study, *, results_root: str | Path = "results", workers: int | None = None,
              scheduler: str | None = None, progress: bool = True,
              fresh: bool = False) -> RunSummary:
    """Run every case of ``study`` not yet done (``fresh``: every case); write results and index.csv.

    ``workers``: processes (default: the CPU count); 1 runs in this process.
    ``scheduler``: a Dask scheduler address, or 'local' for a LocalCluster.
    """
    sdir = study_dir(study, results_root)
    cases = plan(study)
    states = {c.key: case_state(sdir, c) for c in cases}
    todo = [c for c in cases if fresh or states[c.key] != "done"]
    summary = RunSummary(total=len(cases), reused=len(cases) - len(todo), not_run=len(todo),
                         corrupt=sum(state == "corrupt" for state in states.values()))
    if summary.corrupt:
        print(f"softhand study: {summary.corrupt} case files do not parse; recomputing them",
              file=sys.stderr)
    workers = max(1, workers or os.cpu_count() or 1)
    bar = _progress_bar(study, summary, progress)
    claims = Claims(sdir)
    try:
        while todo:
            deferred: list[Case] = []
            mine = _claimed(sdir, todo, claims, fresh, deferred, summary, bar)
            with closing(_outcomes(study, mine, workers, scheduler)) as outcomes:
                for case, output in outcomes:
                    commit_case(sdir, study, case, output)
                    claims.release(case.key)
                    summary.not_run -= 1
                    if output["status"] == "done":
                        summary.computed += 1
                    else:
                        summary.failed[case.key] = output["error"]
                    bar.update(1)
                    bar.set_postfix(running=min(workers, summary.not_run), failed=len(summary.failed))
            if deferred and len(deferred) == len(todo):
                time.sleep(0.2)  # every case left is another run's: wait for it
            todo, fresh = deferred, False
    finally:
        claims.release_all()
        bar.close()
        write_index(study, results_root)
    return summary


def _claimed(sdir: Path, todo: list[Case], claims: Claims, fresh: bool, deferred: list,
             summary: RunSummary, bar):
    """Yield the cases of ``todo`` this run claims and must compute, one at a time (claimed
    when taken); a case another run holds goes to ``deferred``, one it finished is reused."""
    for case in todo:
        if not claims.try_claim(case.key):
            deferred.append(case)
            continue
        if not fresh and case_state(sdir, case) == "done":  # another run has just finished it
            claims.release(case.key)
            summary.reused += 1
            summary.not_run -= 1
            bar.update(1)
            continue
        _remove_leftovers(sdir, case.key)
        yield case


def _progress_bar(study: Study, summary: RunSummary, enabled: bool):
    from tqdm import tqdm

    return tqdm(total=summary.total, initial=summary.reused, desc=study.name, unit="case",
                file=sys.stderr, disable=not enabled, dynamic_ncols=True)


def _outcomes(study: Study, todo, workers: int, scheduler: str | None):
    """Yield (case, output) as cases finish, on the chosen executor; ``todo`` is an iterator,
    read only as workers become free (each case is claimed when read)."""
    todo = iter(todo)
    if scheduler:
        cases = list(todo)
        if cases:
            yield from _dask_outcomes(study, cases, workers, scheduler)
    elif workers == 1:
        for case in todo:
            yield case, execute_case(study.kind, case.params, case.design)
    else:
        yield from _pool_outcomes(study, todo, workers)


def _pool_outcomes(study: Study, todo, workers: int, restarts: int = 2):
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
    pool = ProcessPoolExecutor(max_workers=workers, initializer=_worker_init, initargs=(os.getpid(),))
    futures, broken = {}, False

    def submit(case):
        futures[pool.submit(execute_case, study.kind, case.params, case.design)] = case

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


def _worker_init(parent: int) -> None:
    """In each pool worker: die with the parent (Linux: PR_SET_PDEATHSIG), default SIGTERM."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # 1 = PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass  # not Linux: workers exit when they find the pool's pipe closed
    if os.getppid() != parent:  # the parent died before the death signal was armed
        os._exit(1)


def _dask_outcomes(study: Study, todo: list[Case], workers: int, scheduler: str):
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


# ---------------------------------------------------------------------- index and status
def status(study: Study, results_root: str | Path = "results") -> dict[str, list[Case]]:
    """Cases grouped by state: {'done', 'failed', 'pending', 'corrupt' (recomputed by a run)}."""
    sdir = study_dir(study, results_root)
    groups = {"done": [], "failed": [], "pending": [], "corrupt": []}
    for case in plan(study):
        groups[case_state(sdir, case)].append(case)
    return groups


def other_sources(study: Study, done: list[Case], results_root: str | Path = "results") -> list[Case]:
    """The done cases whose result was computed by other package sources than these."""
    sdir, mine = study_dir(study, results_root), code_version()["source_sha256"]
    def source(case):
        code = ((read_case(sdir, case) or {}).get("provenance") or {}).get("code")
        return code.get("source_sha256") if isinstance(code, dict) else None

    return [c for c in done if source(c) != mine]


def index_rows(study: Study, results_root: str | Path = "results") -> list[dict]:
    """One row per case: key, state, axis values, scalar numbers, wall time, error."""
    sdir = study_dir(study, results_root)
    rows = []
    for case in plan(study):
        record = read_case(sdir, case) or {}
        state = record.get("status") or case_state(sdir, case)
        row = {"case": case.key, "status": state, **case.point}
        row.update(record.get("numbers", {}))
        row["wall_time_s"] = (record.get("provenance") or {}).get("wall_time_s")
        row["error"] = record.get("error")
        rows.append(row)
    return rows


def write_index(study: Study, results_root: str | Path = "results") -> Path:
    rows = index_rows(study, results_root)
    columns = list(dict.fromkeys(k for row in rows for k in row if k not in ("wall_time_s", "error")))
    return write_csv(study_dir(study, results_root) / "index.csv", rows,
                     columns + ["wall_time_s", "error"])
