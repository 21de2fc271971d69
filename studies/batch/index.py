"""A study's state from its results folder: status, provenance checks, ``index.csv``."""
from __future__ import annotations

from pathlib import Path

from softhand.studies.batch.cases import Case, case_state, code_version, own_study_dir, plan, read_case, study_dir
from softhand.studies.batch.studyfile import Study
from softhand.studies.io.files import write_csv


def status(study: Study, results_root: str | Path = "results") -> dict[str, list[Case]]:
    """Cases grouped by state: {'done', 'failed', 'pending', 'corrupt' (recomputed by a run)}."""
    sdir = own_study_dir(study, results_root, write=False)
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
