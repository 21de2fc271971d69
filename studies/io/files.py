"""Writing results: atomic (temp file + rename), so nothing half-written is left behind."""
from __future__ import annotations

import csv
import io
import json
import logging
import math
import shutil
import sys
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from softhand.meshes.atomic import atomic_path


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


def check_output_tree(folder: str | Path, field: str, *, files=(), folders=()) -> None:
    """Before any work: the output ``folder`` and the named ``files`` and ``folders`` in it
    that a run writes are each of their kind or not there yet (a file where a folder goes
    fails its first write after the computation, a folder where a file goes its last); the
    folder's ancestors are folders. InputError naming ``field`` and the path otherwise."""
    from softhand.reduced.vocabulary.errors import InputError

    folder = Path(folder)
    for ancestor in (folder, *folder.parents):
        if ancestor.exists() and not ancestor.is_dir():
            raise InputError(field, str(ancestor), "is a file where the output folder goes; move it "
                                                   "away or give another folder")
        if ancestor.is_symlink() and not ancestor.exists():
            raise InputError(field, str(ancestor), "is a broken symbolic link where the output "
                                                   "folder goes")
    for name in folders:
        path = folder / name
        if (path.exists() or path.is_symlink()) and not path.is_dir():
            raise InputError(field, str(path), "is not a folder, and the run writes a folder there; "
                                               "move it away or give another folder")
    for name in files:
        if (folder / name).is_dir():
            raise InputError(field, str(folder / name), "is a folder, and the run writes a file "
                                                        "there; move it away or give another folder")


@contextmanager
def removed_unless_finished(folder: str | Path):
    """The files written under ``folder`` in this block (new, or rewritten: another inode, size
    or time) and the folders it made, ``folder`` itself too if the block made it, are removed
    if the block does not finish (an error, Ctrl-C, SIGTERM): a run stopped half-way leaves
    none of its outputs. Others' files stay."""
    folder = Path(folder)
    existed, before = folder.exists(), _stamps(folder)
    try:
        yield
    except BaseException:
        after = _stamps(folder)
        made = [path for path in after if before.get(path) != after[path]] + ([] if existed else [folder])
        for path in sorted(made, key=lambda p: -len(p.parts)):  # files first, then their folders
            try:
                path.unlink() if after.get(path, "folder") != "folder" else path.rmdir()
            except OSError:
                pass  # a folder of others' files; a file already gone
        raise


@contextmanager
def replaced_outputs(folder: str | Path | None, patterns):
    """A verb's run into ``folder``: an earlier run's outputs there (the verb's own ``patterns``,
    nothing else) are removed first, and the files this run writes are removed if it does not
    finish (:func:`removed_unless_finished`), so the folder never mixes two runs' files nor keeps
    a half-written series. ``folder`` None: no outputs asked, nothing done."""
    if folder is None:
        yield
        return
    folder = Path(folder)
    for pattern in patterns:
        for path in folder.glob(pattern):
            shutil.rmtree(path) if path.is_dir() and not path.is_symlink() else path.unlink()
    with removed_unless_finished(folder):
        yield


def _stamps(folder: Path, depth: int = 3) -> dict:
    """{path: (inode, size, mtime) of a file, "folder" for a folder} under ``folder``, down to
    ``depth`` levels (a run's outputs: a VTK series' blocks are at the third; ``--out .``
    must not walk a whole home folder)."""
    out = {}
    levels = ("/".join(["*"] * k) for k in range(1, depth + 1))
    for path in (p for pattern in levels for p in folder.glob(pattern)) if folder.is_dir() else ():
        try:
            st = path.lstat()
        except OSError:
            continue
        out[path] = "folder" if path.is_dir() and not path.is_symlink() else (st.st_ino, st.st_size, st.st_mtime_ns)
    return out


@contextmanager
def kept_if_unwritable(what, verb: str):
    """Write ``what`` inside this block; if the disk refuses (full, gone, read-only) after the
    computation, a warning instead of losing the results, which the verb still prints; once
    written, one line on stderr says where (``softhand VERB: wrote FILE``)."""
    try:
        yield
    except OSError as exc:
        print(f"softhand {verb}: warning: {what} not written ({exc.strerror or exc}); "
              f"the results are printed on stdout", file=sys.stderr)
    else:
        print(f"softhand {verb}: wrote {what}", file=sys.stderr)


def write_outputs(result, verb: str, out=None, plot=None) -> None:
    """A study result's ``write(out)`` and ``plot(plot)``, each where asked, each kept going
    (a warning) if the disk refuses it: the verb prints the results in any case."""
    if out:
        with kept_if_unwritable(out, verb):
            result.write(out)
    if plot:
        with kept_if_unwritable(plot, verb):
            result.plot(plot)
