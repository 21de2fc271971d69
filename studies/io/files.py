"""Writing results: atomic (temp file + rename), so nothing half-written is left behind."""
from __future__ import annotations

import csv
import fnmatch
import glob
import io
import json
import logging
import math
import os
import shutil
import stat
import sys
import time
import uuid
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
    folder's ancestors are folders; a named folder is no symbolic link (a run would write through
    it out of ``folder``). InputError naming ``field`` and the path otherwise."""
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
        if path.is_symlink():
            raise InputError(field, str(path), "is a symbolic link, and the run writes a folder there; "
                                               "it does not follow it out of the folder: replace it by "
                                               "a folder")
    for name in files:
        if (folder / name).is_dir():
            raise InputError(field, str(folder / name), "is a folder, and the run writes a file "
                                                        "there; move it away or give another folder")


#: the record of what the last run into a folder wrote there (see :func:`replaced_outputs`)
MANIFEST = ".softhand-outputs.json"
#: where a run that could not write all its outputs keeps the ones it did
INCOMPLETE = "incomplete"
#: the exit code of a run whose results are computed and printed but not all written
EXIT_UNWRITTEN = 3
#: the outputs this process could not write since :func:`reset_unwritten` (the CLI's exit code)
UNWRITTEN: list[str] = []
_STAGE = ".softhand-stage-"
#: the staging folders of the runs going on in this process (innermost last)
_STAGED: list[Path] = []


def reset_unwritten() -> None:
    UNWRITTEN.clear()


def owned_outputs(folder: str | Path) -> set[str]:
    """The names an earlier softhand run wrote into ``folder`` (its manifest); empty if none."""
    try:
        record = json.loads(read_bounded(Path(folder) / MANIFEST, 1 << 20))
        names = record.get("outputs") if isinstance(record, dict) else None
    except (OSError, ValueError, RecursionError):
        return set()
    # plain names only: a damaged or edited manifest cannot point a run outside the folder
    return {n for n in names if isinstance(n, str) and n not in ("", ".", "..", MANIFEST) and "/" not in n
            and "\0" not in n} if isinstance(names, list) else set()


def check_owned(folder: str | Path, names, field: str) -> None:
    """Before any work: every output ``names`` that already stands in ``folder`` was written
    there by an earlier softhand run (its manifest names it); else InputError: a run replaces
    only its own earlier outputs, never a file or folder of the user's of the same name."""
    from softhand.reduced.vocabulary.errors import InputError

    folder = Path(folder)
    if not folder.is_dir():
        return
    record = folder / MANIFEST
    if record.is_symlink() or record.exists() and not record.is_file():
        raise InputError(field, str(record), "is where a run records its outputs, and is no plain file; "
                                             "remove it or give another folder")
    owned = owned_outputs(folder)
    for name in (*names, INCOMPLETE):
        for path in folder.glob(name) if glob.has_magic(name) else [folder / name]:
            if (path.exists() or path.is_symlink()) and path.name not in owned:
                raise InputError(field, str(path), "was not written by an earlier softhand run into "
                                                   "this folder and the run writes there; move it away "
                                                   "or give another folder")


@contextmanager
def replaced_outputs(folder: str | Path | None, names, *, verb: str = "softhand", field: str = "--out"):
    """A verb's run into ``folder``, writing only the files and folders ``names`` (its manifest;
    a name may be a pattern, e.g. ``sheet_V*_rz.vtu``).

    Yields a private staging folder inside ``folder``; the verb writes its outputs there. When
    the block finishes, each output is renamed into place in one step and the earlier run's
    outputs (those its manifest names, nothing else) are removed: the folder holds one run's
    whole result, a reader never sees a half-written one. If the block does not finish (an
    error, Ctrl-C, SIGTERM) the staging folder is removed and the earlier result stays as it
    was. If some output could not be written (:func:`kept_if_unwritable`: disk full, file-size
    limit), the pieces written go to ``folder/incomplete/`` and the earlier result stays too.
    An output of the user's of the same name is refused (:func:`check_owned`). Two runs into
    one folder: each stages its own; the last to finish replaces the other's result whole (a
    warning says so). ``folder`` None: no outputs asked; yields None. The verb says where its
    folder is (its pieces written inside are not announced one by one).
    """
    if folder is None:
        yield None
        return
    folder, names = Path(folder), tuple(names)
    check_owned(folder, names, field)
    made = not folder.exists()
    _remove_dead_stages(folder)
    stage = folder / f"{_STAGE}{os.getpid()}-{uuid.uuid4().hex[:8]}"
    stage.mkdir(parents=True)
    seen, unwritten = _manifest_run(folder), len(UNWRITTEN)
    _STAGED.append(stage)  # the warnings of writes refused in it: one line when it ends
    try:
        yield stage
    except BaseException:
        _STAGED.pop()
        shutil.rmtree(stage, ignore_errors=True)
        if made:
            _rmdir_quietly(folder)
        raise
    record = {"run": uuid.uuid4().hex, "verb": verb, "pid": os.getpid(),
              "finished_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
              "outputs": sorted(p.name for p in stage.iterdir() if any(fnmatch.fnmatchcase(p.name, n) for n in names))}
    _STAGED.pop()
    with _folder_lock(folder):
        if len(UNWRITTEN) > unwritten:
            _keep_incomplete(folder, stage, record, UNWRITTEN[unwritten:], verb)
            return
        if _manifest_run(folder) != seen:
            print(f"softhand {verb}: warning: another run finished into {folder} while this one ran; "
                  f"its outputs are replaced by this run's", file=sys.stderr)
        _commit(folder, stage, record)


def _commit(folder: Path, stage: Path, record: dict) -> None:
    """Rename the staged outputs into ``folder`` and the earlier run's away (each in one step;
    a folder cannot be replaced by a rename, so an earlier one goes first); the manifest last."""
    trash = stage / ".earlier"
    trash.mkdir()
    new = set(record["outputs"])
    for k, name in enumerate(sorted(owned_outputs(folder))):
        path = folder / name
        if (path.exists() or path.is_symlink()) and (name not in new or path.is_dir() and not path.is_symlink()):
            os.replace(path, trash / str(k))
    for name in record["outputs"]:
        os.replace(stage / name, folder / name)
    write_json(stage / MANIFEST, record)
    os.replace(stage / MANIFEST, folder / MANIFEST)
    shutil.rmtree(stage, ignore_errors=True)


def _keep_incomplete(folder: Path, stage: Path, record: dict, missing, verb: str) -> None:
    """A run that wrote only some outputs: those it wrote go to ``folder/incomplete/`` (the
    earlier result stays); its own manifest says what is missing."""
    try:
        write_json(stage / MANIFEST, {**record, "complete": False, "missing": list(missing)})
    except OSError:
        pass  # the disk is full: the pieces still go where the warning says
    target = folder / INCOMPLETE
    if target.exists() and (target / MANIFEST).exists():
        shutil.rmtree(target, ignore_errors=True)  # an earlier incomplete run's: ours
    if not target.exists():
        os.replace(stage, target)
        owned = owned_outputs(folder) | {INCOMPLETE}
        try:
            write_json(folder / MANIFEST, {**_manifest(folder), "outputs": sorted(owned)})
        except OSError:
            pass
    print(f"softhand {verb}: warning: {'; '.join(missing)} not written; the results are printed on "
          f"stdout, the outputs written are in {target if not stage.exists() else stage} (the earlier "
          f"result in {folder} is kept); exit code {EXIT_UNWRITTEN}", file=sys.stderr)


def _manifest(folder: Path) -> dict:
    try:
        record = json.loads(read_bounded(folder / MANIFEST, 1 << 20))
    except (OSError, ValueError, RecursionError):
        return {}
    return record if isinstance(record, dict) else {}


def _manifest_run(folder: Path):
    return _manifest(folder).get("run")


@contextmanager
def _folder_lock(folder: Path):
    """An exclusive lock on ``folder`` itself while a run commits into it (the kernel drops it
    if the process dies; no lock file is left)."""
    import fcntl

    fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)


def _remove_dead_stages(folder: Path) -> None:
    """Staging folders of runs into ``folder`` whose process is gone (SIGKILL, a power cut)."""
    for stage in folder.glob(f"{_STAGE}*") if folder.is_dir() else ():
        pid = stage.name[len(_STAGE):].split("-")[0]
        try:
            if not pid.isdigit() or stage.is_symlink() or stage.lstat().st_uid != os.getuid():
                continue
            os.kill(int(pid), 0)
        except ProcessLookupError:
            shutil.rmtree(stage, ignore_errors=True)
        except OSError:
            continue


def _rmdir_quietly(folder: Path) -> None:
    try:
        folder.rmdir()
    except OSError:
        pass


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
    (:func:`replaced_outputs`: the verb names its folder)."""
    try:
        yield
    except OSError as exc:
        UNWRITTEN.append(f"{what} ({exc.strerror or exc})")
        if not _STAGED:  # in a staged run, one line says it all when the run ends
            print(f"softhand {verb}: warning: {UNWRITTEN[-1]} not written; the results are printed "
                  f"on stdout", file=sys.stderr)
    else:
        if say_written and not _STAGED:  # a staged run's verb names its folder itself
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
