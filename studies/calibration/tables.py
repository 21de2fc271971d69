"""The one writer of the calibration tables the reduced model ships (finger, reservoir, hinges).

A table is ``#`` provenance lines (who wrote it, when, at which commit, by which command, with
which model and mesh), a header row and rows of numbers; it is written atomically, so a table
is whole or absent. :func:`softhand.reduced.vocabulary.inputfiles.read_number_table` is its one reader.
"""
from __future__ import annotations

import subprocess
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from softhand.studies.io.files import write_atomic

__all__ = ["git_commit", "written_by", "table_text", "write_table", "leave_one_out_line"]


def git_commit() -> str:
    """The checkout's short commit hash, or "unknown" outside a git checkout."""
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, cwd=Path(__file__).parent, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def written_by(what: str, detail: str = "") -> str:
    """The first provenance line: ``what``, written <UTC time> at commit <hash>``detail`` by"""
    return f"{what}, written {datetime.now(timezone.utc):%Y-%m-%d %H:%M} UTC at commit {git_commit()}{detail} by"


def table_text(provenance: list[str], columns, rows, formats: dict | None = None) -> str:
    """The CSV text: ``provenance`` as ``#`` lines, the header, then ``rows`` (sequences in the
    order of ``columns``), each number written with ``formats[column]`` (default ``.10g``)."""
    formats = formats or {}
    fmt = [formats.get(c, ".10g") for c in columns]
    lines = [f"# {line}" for line in provenance] + [",".join(columns)]
    lines += [",".join(format(v, f) for v, f in zip(row, fmt)) for row in rows]
    return "\n".join(lines) + "\n"


def write_table(path, provenance: list[str], columns, rows, formats: dict | None = None) -> Path:
    """Write :func:`table_text` to ``path`` atomically; the path written."""
    return write_atomic(path, table_text(provenance, columns, rows, formats))


def leave_one_out_line(designs: int, parts) -> str:
    """One line of a design-space grid's leave-one-out: parts (name, per-design relative errors (D,),
    per-design worst errors (D,)) as "name rms R %, worst W %"."""
    return f"leave-one-out over {designs} designs: " + "; ".join(
        f"{name} rms {100 * float(np.sqrt(np.mean(np.square(rms)))):.2f} %, worst {100 * float(np.max(worst)):.1f} %"
        for name, rms, worst in parts)
