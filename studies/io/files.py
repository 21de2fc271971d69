"""Writing results: atomic (temp file + rename), so nothing half-written is left behind, and a
write the disk refuses after the work is a warning, not a lost result.

Where a run's outputs go, and what it may replace there, is :mod:`softhand.studies.io.outputs`.
"""
from __future__ import annotations

import csv
import io
import json
import logging
import math
import os
import stat
import sys
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from softhand.meshes.atomic import atomic_path


#: the exit code of a run whose results are computed and printed but not all written
EXIT_UNWRITTEN = 3
#: the outputs this process could not write since :func:`reset_unwritten` (the CLI's exit code)
UNWRITTEN: list[str] = []
#: the staging folders of the runs going on in this process, innermost last
#: (:func:`softhand.studies.io.outputs.replaced_outputs` keeps it)
STAGED_RUNS: list[Path] = []


def reset_unwritten() -> None:
    UNWRITTEN.clear()


def write_atomic(path: str | Path, data: bytes | str) -> Path:
    """Write ``data`` to ``path`` through a temporary file in the same folder and a rename."""
    payload = data.encode() if isinstance(data, str) else data
    with atomic_path(path) as tmp:
        tmp.write_bytes(payload)
    return Path(path)


def write_json(path: str | Path, obj) -> Path:
    return write_atomic(path, json_text(obj) + "\n")


def json_text(obj, indent: int | None = 1) -> str:
    """Strict JSON of ``obj``, which every parser reads: numpy arrays and scalars converted, and
    a number that is not finite (an unbounded limit, a value never reached) as null."""
    return json.dumps(finite_or_none(obj), indent=indent, default=jsonable, allow_nan=False)


def finite_or_none(value):
    """``value`` with every number that is not finite as None (JSON null: not applicable, e.g.
    an unbounded limit, a run that never settles), through dicts, lists, tuples and numpy."""
    if isinstance(value, float):  # numpy's float64 too
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: finite_or_none(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite_or_none(v) for v in value]
    if isinstance(value, (np.ndarray, np.generic)):
        return finite_or_none(value.tolist())
    return value


def write_csv(path: str | Path, rows: list[dict], columns: list[str] | None = None) -> Path:
    columns = columns or (list(rows[0]) if rows else [])
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=columns, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: _csv_cell(row.get(k)) for k in columns})
    return write_atomic(path, buf.getvalue())


def figure(ncols: int = 1, *, width: float = 5.5, height: float = 4.0):
    """A matplotlib figure (Agg, no display) with ``ncols`` axes side by side: (fig, axes)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, ncols, figsize=(width * ncols, height), squeeze=False)
    return fig, axes[0]


def save_figure(fig, path: str | Path, *, dpi: int = 150) -> Path:
    """Save a matplotlib figure atomically (format from the suffix) and close it."""
    import matplotlib.pyplot as plt

    path = Path(path)
    buf = io.BytesIO()
    # PostScript draws the grids' and bands' translucency opaque, and matplotlib's backend logs
    # a line saying so on stderr, not in the verb's own format: the plot is read the same
    ps_log = logging.getLogger("matplotlib.backends.backend_ps")
    level = ps_log.level
    ps_log.setLevel(logging.ERROR)
    try:
        fig.savefig(buf, format=path.suffix.lstrip(".") or "png", dpi=dpi, bbox_inches="tight")
    finally:
        ps_log.setLevel(level)
    plt.close(fig)
    return write_atomic(path, buf.getvalue())


def _csv_cell(value):
    if isinstance(value, (list, tuple, np.ndarray)):
        return ";".join(str(v) for v in np.ravel(value))
    return value


def jsonable(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"not JSON serialisable: {type(value).__name__}")


def read_bounded(path: str | Path, limit: int, *, binary: bool = False):
    """The text (bytes) of the regular file ``path``, at most ``limit`` bytes; OSError if it is
    not a regular file (a FIFO would block the read) or larger (ValueError)."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise OSError(21 if stat.S_ISDIR(st.st_mode) else 22, "not a regular file", str(path))
        if st.st_size > limit:
            raise ValueError(f"{path} is {st.st_size} bytes, more than {limit} allowed")
        with os.fdopen(fd, "rb", closefd=False) as f:
            data = f.read(limit + 1)
    finally:
        os.close(fd)
    if len(data) > limit:
        raise ValueError(f"{path} is more than {limit} bytes")
    return data if binary else data.decode()


@contextmanager
def kept_if_unwritable(what, verb: str, *, say_written: bool = True):
    """Write ``what`` inside this block; if the disk refuses (full, file-size limit, read-only)
    after the computation, a one-line warning instead of losing the results, which the verb
    still prints; the CLI then exits with :data:`EXIT_UNWRITTEN`. Once written, one line on
    stderr says where (``softhand VERB: wrote FILE``), unless ``say_written`` is False (a
    study's many cases: its index and report say where they are) or the run is staged
    (:func:`softhand.studies.io.outputs.replaced_outputs`: the verb names its folder)."""
    try:
        yield
    except OSError as exc:
        UNWRITTEN.append(f"{what} ({exc.strerror or exc})")
        if not STAGED_RUNS:  # in a staged run, one line says it all when the run ends
            print(f"softhand {verb}: warning: {UNWRITTEN[-1]} not written; the results are printed "
                  f"on stdout", file=sys.stderr)
    else:
        if say_written and not STAGED_RUNS:  # a staged run's verb names its folder itself
            print(f"softhand {verb}: wrote {what}", file=sys.stderr)


def unwritable_tolerant(write, what, verb: str):
    """``write`` (a function writing files as a run goes, e.g. a VTK series' states) that, once
    the disk refuses one, warns once and writes no more; the run goes on."""
    failed = []

    def guarded(*args, **kwargs):
        if failed:
            return None
        with kept_if_unwritable(what, verb):
            return write(*args, **kwargs)
        failed.append(True)

    return guarded


def write_outputs(result, verb: str, out=None, plot=None, *, shown=None) -> None:
    """A study result's ``write(out)`` and ``plot(plot)``, each where asked, each kept going
    (a warning) if the disk refuses it: the verb prints the results in any case. ``shown``:
    the folder the warning names when ``out`` is a staging folder."""
    if out:
        with kept_if_unwritable(shown or out, verb):
            result.write(out)
    if plot:
        with kept_if_unwritable(plot, verb):
            result.plot(plot)
