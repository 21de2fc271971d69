"""The cases of a study: keys, plan, state on disk, computing one case and committing it.

A case is keyed by a hash of its inputs (kind, case parameters, design hash) and the
package version. :func:`execute_case` computes it in a private temporary folder and
returns the numbers and the files; :func:`commit` writes them into a temporary folder
next to the case's and renames it in one step, so nothing half-written is left.
"""
from __future__ import annotations

import hashlib
import json
import math
import os
import shutil
import sys
import tempfile
import time
import traceback
import uuid
from dataclasses import dataclass
from datetime import datetime, timezone
from functools import lru_cache
from pathlib import Path

import numpy as np

from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.versions import package_version
from softhand.studies.batch.studyfile import Study, resolve_kind
from softhand.studies.io.files import finite_or_none, read_bounded, write_json

RESULT, FAILED = "result.json", "failed.json"
_PACKAGES = ("fem", "meshes", "reduced", "studies")


@dataclass(frozen=True)
class Case:
    """One point of a study's sweep."""

    key: str  #: hash of the inputs and the code version; the case's folder name
    point: dict  #: the sweep axes' values at this point
    params: dict  #: what the kind function receives
    design: HandDesign


@lru_cache(maxsize=1)
def code_version() -> dict:
    """The package version and a hash of the package's Python sources."""
    root = Path(__file__).resolve().parents[2]  # the source tree: fem/, meshes/, reduced/, studies/
    sha = hashlib.sha256()
    for package in _PACKAGES:
        for path in sorted((root / package).rglob("*.py")):
            sha.update(path.relative_to(root).as_posix().encode())
            sha.update(path.read_bytes())
    return {"softhand": package_version("softhand", "not installed"), "source_sha256": sha.hexdigest()[:16]}


@lru_cache(maxsize=1)
def package_versions() -> dict:
    names = ("numpy", "scipy", "scikit-fem", "gmsh", "meshio", "pyvista")
    return {"python": sys.version.split()[0], **{n: package_version(n, "not installed") for n in names}}


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


#: the file in a study's folder that says which kind of study it holds
OWNER = "study.json"
#: the largest case file read (a case's numbers and provenance: kB; a kind's curves: MB)
MAX_RECORD_BYTES = 64 << 20


def own_study_dir(study: Study, results_root: str | Path = "results", *, write: bool, outputs=()) -> Path:
    """The study's folder, after checking it holds no study of another kind under the same
    name (whose index.csv and report this one would overwrite) and that every one of
    ``outputs`` (names in it the caller writes) already there was written by an earlier softhand
    run (:func:`~softhand.studies.io.outputs.check_owned`: never a file of the user's);
    ``write``: record this kind there and ``outputs`` as softhand's (a run, a report).
    InputError naming the study's name or the path."""
    from softhand.reduced.vocabulary.errors import InputError
    from softhand.studies.io.outputs import check_output_tree, check_owned, record_outputs

    sdir = study_dir(study, results_root)
    check_output_tree(sdir, "--results", files=(OWNER, "index.csv", "report.md"), folders=(".claims", "report"))
    try:
        held = json.loads(read_bounded(sdir / OWNER, MAX_RECORD_BYTES)).get("kind")
    except (OSError, ValueError, AttributeError, RecursionError):
        held = None  # none yet (or a folder from before this record): this study takes it
    if held is not None and held != study.kind:
        raise InputError("name", study.name, f"{sdir} holds a {held!r} study of that name; this one "
                         f"is {study.kind!r}: rename it or give another --results")
    check_owned(sdir, (OWNER, *outputs) if write else outputs, "--results")
    if write:
        sdir.mkdir(parents=True, exist_ok=True)
        record_outputs(sdir, (OWNER, *outputs), verb="study")
        if held is None:
            write_json(sdir / OWNER, {"study": study.name, "kind": study.kind})
    return sdir


def case_state(sdir: Path, case: Case) -> str:
    """'done', 'failed', 'pending' or 'corrupt' (a case file that does not parse, a case folder
    that is a symbolic link or no folder: recomputed by a run)."""
    folder = sdir / case.key
    if folder.is_symlink() or folder.exists() and not folder.is_dir():
        return "corrupt"
    for name, state in ((RESULT, "done"), (FAILED, "failed")):
        if (folder / name).exists():
            return state if _record(folder / name) is not None else "corrupt"
    return "corrupt" if folder.exists() else "pending"


def read_case(sdir: Path, case: Case) -> dict | None:
    """The stored result.json or failed.json of a case; None if pending or corrupt."""
    if (sdir / case.key).is_symlink():
        return None
    for name in (RESULT, FAILED):
        path = sdir / case.key / name
        if path.exists() or path.is_symlink():
            return _record(path)
    return None


def _record(path: Path) -> dict | None:
    """A case file's record if it parses and has the record's shape (its numbers finite numbers,
    null or lists of them, as :func:`execute_case` writes them), else None."""
    try:  # bounded, and never waiting on a FIFO; a file nested too deep does not parse
        record = json.loads(read_bounded(path, MAX_RECORD_BYTES))
    except (OSError, ValueError, RecursionError):
        return None
    ok = (isinstance(record, dict) and record.get("status") == ("done" if path.name == RESULT else "failed")
          and isinstance(record.get("numbers"), dict) and isinstance(record.get("provenance"), dict)
          and all(_stored_number(v) for v in record["numbers"].values()))
    return record if ok else None


def _stored_number(value) -> bool:
    """A finite number (or bool), null (a kind's nan: not applicable) or a list of these; NaN,
    Infinity or a string in a case file is an edited or damaged file."""
    if isinstance(value, list):
        return all(map(_stored_number, value))
    return value is None or (isinstance(value, (int, float)) and math.isfinite(value))


# ---------------------------------------------------------------------- one case
#: the private folders of the cases this process is computing (a pool worker told to stop
#: removes them before it exits: :func:`softhand.studies.batch.pool.stop_worker`)
CASE_FOLDERS: set[str] = set()


def execute_case(kind, params: dict, design: HandDesign) -> dict:
    """Compute one case in a private temporary folder; return numbers, files, timing.

    ``kind``: a registered kind's name, or (for callers inside softhand) the case function.

    Never raises for a failing kind: the error comes back as ``status = 'failed'``.
    """
    start = time.perf_counter()
    if not _ORPHANS_REMOVED:  # once per process: a study of many quick cases lists the folder once
        _remove_orphans()
        _ORPHANS_REMOVED.append(True)
    with tempfile.TemporaryDirectory(prefix=f"softhand-case-{os.getpid()}-") as tmp:
        CASE_FOLDERS.add(tmp)
        try:
            out = (kind if callable(kind) else resolve_kind(kind))(dict(params), design, Path(tmp))
            numbers, extra = _split_output(out)
        except Exception as exc:  # a failing case is data, not a crash
            return {"status": "failed", "error": f"{type(exc).__name__}: {exc}",
                    "traceback": traceback.format_exc(),
                    "wall_time_s": time.perf_counter() - start}
        files = {p.relative_to(tmp).as_posix(): p.read_bytes()
                 for p in sorted(Path(tmp).rglob("*")) if p.is_file()}
    CASE_FOLDERS.discard(tmp)  # after the folder is gone (an exception leaves a name of none)
    return {"status": "done", "numbers": numbers, **extra, "files": files,
            "wall_time_s": time.perf_counter() - start}


_ORPHANS_REMOVED: list = []


def _remove_orphans() -> None:
    """Remove the case folders of processes that no longer run (killed by SIGKILL, which no
    process can clean up after): each folder is named after the process that made it."""
    for folder in Path(tempfile.gettempdir()).glob("softhand-case-*-*"):
        pid = folder.name.split("-")[2]
        try:
            if not pid.isdigit() or folder.lstat().st_uid != os.getuid():
                continue
            os.kill(int(pid), 0)
        except ProcessLookupError:  # that process is gone
            shutil.rmtree(folder, ignore_errors=True)
        except OSError:  # alive but another user's, or the folder vanished meanwhile
            continue


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
        numbers[key] = finite_or_none(array)  # a case file holds no NaN or Infinity (see _record)
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
    try:
        for rel, data in files.items():
            (tmp / rel).parent.mkdir(parents=True, exist_ok=True)
            (tmp / rel).write_bytes(data)
        write_json(tmp / (RESULT if record["status"] == "done" else FAILED), record)
        if final.is_symlink() or final.exists() and not final.is_dir():
            final.unlink()  # a damaged case: the link itself goes, never what it points to
        elif final.exists():
            shutil.rmtree(final)  # an earlier failure, a corrupt file, or a result of other inputs
        os.rename(tmp, final)
    except BaseException:  # Ctrl-C, SIGTERM, a full disk: no half-written folder stays behind
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return final


def remove_leftovers(sdir: Path, key: str) -> None:
    """Temporary folders of case ``key`` a killed run left (only its claim holder calls this)."""
    for tmp in sdir.glob(f".{key}.*.tmp"):
        shutil.rmtree(tmp, ignore_errors=True)


def _provenance(params: dict, design: HandDesign, output: dict) -> dict:
    return {"inputs": params, "design": design.to_dict(), "design_hash": design.hash(), "code": code_version(),
            "versions": package_versions(), "mesh": output.get("mesh"),
            "solver": output.get("solver"), "wall_time_s": output["wall_time_s"],
            "finished_utc": datetime.now(timezone.utc).isoformat(timespec="seconds")}
