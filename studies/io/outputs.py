"""Where a run's outputs go and what it may replace there: the one rule every verb follows.

A run into a folder writes only the names it declares (its manifest,
``.softhand-outputs.json``), stages them in a private folder inside and renames them into place
when the run is whole; it replaces only what an earlier softhand run wrote there, never a file
or folder of the user's, and never deletes what it did not write (:func:`replaced_outputs`).
A run that keeps its pieces as they finish (``reproduce``'s sections) records each in the
manifest as it lands (:func:`record_outputs`).
"""
from __future__ import annotations

import fnmatch
import glob
import os
import shutil
import sys
import time
import uuid
from contextlib import contextmanager
from pathlib import Path

from softhand.studies.io.files import STAGED_RUNS, UNWRITTEN, EXIT_UNWRITTEN, write_json
from softhand.studies.io.manifest import (MANIFEST, check_unchanged, entries_of, manifest_run,  # noqa: F401
                                          owned_outputs, read_manifest)


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


#: where a run that could not write all its outputs keeps the ones it did (if the user has a
#: folder of that name, ``incomplete-<run>`` beside it)
INCOMPLETE = "incomplete"
_STAGE = ".softhand-stage-"


def check_owned(folder: str | Path, names, field: str, verb: str | None = None) -> None:
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
    owned, entries = owned_outputs(folder), read_manifest(folder).get("entries")
    entries = entries if isinstance(entries, dict) else {}
    for name in names:
        for path in folder.glob(name) if glob.has_magic(name) else [folder / name]:
            if not (path.exists() or path.is_symlink()):
                continue
            if path.name not in owned:
                raise InputError(field, str(path), "was not written by an earlier softhand run into "
                                                   "this folder and the run writes there; move it away "
                                                   "or give another folder")
            check_unchanged(path, entries.get(path.name), field, verb)


@contextmanager
def replaced_outputs(folder: str | Path | None, names, *, verb: str = "softhand", field: str = "--out"):
    """A verb's run into ``folder``, writing only the files and folders ``names`` (its manifest;
    a name may be a pattern, e.g. ``sheet_V*_rz.vtu``).

    Yields a private staging folder inside ``folder``; the verb writes its outputs there. When
    the block finishes, each output is renamed into place in one step and the earlier run's
    outputs (those its manifest names, nothing else) are removed: the folder holds one run's
    whole result, a reader never sees a half-written one. If the block does not finish (an
    error, Ctrl-C, SIGTERM) the staging folder is removed, with the folders the run made to hold
    it (``results/bend`` and ``results`` of a first run), and the earlier result stays as it
    was. If some output could not be written (:func:`softhand.studies.io.files.kept_if_unwritable`: disk full, file-size
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
    check_owned(folder, names, field, verb)
    made = [d for d in (folder, *folder.parents) if not (d.exists() or d.is_symlink())]  # deepest first
    _remove_dead_stages(folder)
    stage = folder / f"{_STAGE}{os.getpid()}-{uuid.uuid4().hex[:8]}"
    stage.mkdir(parents=True)
    seen, unwritten = manifest_run(folder), len(UNWRITTEN)
    STAGED_RUNS.append(stage)  # the warnings of writes refused in it: one line when it ends
    try:
        yield stage
    except BaseException:
        STAGED_RUNS.pop()
        shutil.rmtree(stage, ignore_errors=True)
        for d in made:  # the folders this run made, if nothing else went into them meanwhile
            _rmdir_quietly(d)
        raise
    record = {"run": uuid.uuid4().hex, "verb": verb, "pid": os.getpid(),
              "finished_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
              "outputs": sorted(p.name for p in stage.iterdir() if any(fnmatch.fnmatchcase(p.name, n) for n in names))}
    STAGED_RUNS.pop()
    with _folder_lock(folder):
        if len(UNWRITTEN) > unwritten:
            _keep_incomplete(folder, stage, record, UNWRITTEN[unwritten:], verb)
            return
        if manifest_run(folder) != seen:
            print(f"softhand {verb}: warning: another run finished into {folder} while this one ran; "
                  f"its outputs are replaced by this run's", file=sys.stderr)
        _commit(folder, stage, record, names)


def _commit(folder: Path, stage: Path, record: dict, names) -> None:
    """Rename the staged outputs into ``folder`` and the earlier run's of these ``names`` away
    (each in one step; a folder cannot be replaced by a rename, so an earlier one goes first);
    the manifest last. Another verb's outputs in the folder stay, and stay in the manifest."""
    trash = stage / ".earlier"
    trash.mkdir()
    new = set(record["outputs"])
    earlier = read_manifest(folder).get("entries")
    earlier = earlier if isinstance(earlier, dict) else {}
    kept = set()
    for k, name in enumerate(sorted(owned_outputs(folder))):
        if not (any(fnmatch.fnmatchcase(name, n) for n in names) or name.startswith(INCOMPLETE)):
            kept.add(name)  # another verb's: not touched (an incomplete run's pieces are replaced)
            continue
        path = folder / name
        if (path.exists() or path.is_symlink()) and (name not in new or path.is_dir() and not path.is_symlink()):
            os.replace(path, trash / str(k))
    kept_entries = {n: e for n, e in earlier.items() if n in kept}
    record = {**record, "outputs": sorted(new | kept),
              "entries": {**kept_entries, **entries_of(stage, new, record["verb"])}}
    for name in record["outputs"]:
        if name in new:
            os.replace(stage / name, folder / name)
    write_json(stage / MANIFEST, record)
    os.replace(stage / MANIFEST, folder / MANIFEST)
    shutil.rmtree(stage, ignore_errors=True)


def _keep_incomplete(folder: Path, stage: Path, record: dict, missing, verb: str) -> None:
    """A run that wrote only some outputs: those it wrote go to ``folder/incomplete/`` (an
    earlier incomplete run's is replaced; a folder of the user's of that name stays, and the
    pieces go to ``incomplete-<run>/`` beside it); the earlier result stays; its own manifest
    says what is missing."""
    try:
        write_json(stage / MANIFEST, {**record, "complete": False, "missing": list(missing)})
    except OSError:
        pass  # the disk is full: the pieces still go where the warning says
    owned = owned_outputs(folder)
    target = folder / INCOMPLETE
    if target.exists() or target.is_symlink():
        if INCOMPLETE in owned and target.is_dir() and not target.is_symlink():
            shutil.rmtree(target, ignore_errors=True)  # an earlier incomplete run's: ours
        else:
            target = folder / f"{INCOMPLETE}-{record['run'][:8]}"  # the user's: left alone
    try:
        os.replace(stage, target)
    except OSError:
        target = stage  # the pieces stay where they are; the warning says where
    else:
        try:
            record = read_manifest(folder)
            entries = record.get("entries") if isinstance(record.get("entries"), dict) else {}
            write_json(folder / MANIFEST, {**record, "outputs": sorted(owned | {target.name}),
                                           "entries": {**entries, **entries_of(folder, [target.name], verb)}})
        except OSError:
            pass
    print(f"softhand {verb}: warning: {'; '.join(missing)} not written; the results are printed on "
          f"stdout, the outputs written are in {target} (the earlier result in {folder} is kept); "
          f"exit code {EXIT_UNWRITTEN}", file=sys.stderr)


def record_single(path: str | Path, verb: str) -> None:
    """Record a file output named on the command line, just written whole (``--plot FILE``), in
    its folder's manifest, so that a later command may replace it
    (:func:`softhand.studies.io.manifest.check_single`) and a run into that folder leaves it alone."""
    path = Path(path)
    record_outputs(path.parent, [path.name], verb=verb, single=True)


def record_outputs(folder: str | Path, names, *, verb: str, single: bool = False) -> None:
    """Add ``names`` (outputs just renamed into ``folder`` whole, one by one, by a run that keeps
    its pieces as they finish; ``single``: files named on the command line) to the folder's
    manifest, so that a later run replaces them and :func:`check_owned` knows them for
    softhand's. Call :func:`check_owned` before the work."""
    folder = Path(folder)
    with _folder_lock(folder):
        record = read_manifest(folder)
        owned = owned_outputs(folder)
        entries = record.get("entries") if isinstance(record.get("entries"), dict) else {}
        new = entries_of(folder, names, verb)
        if single:
            new = {n: {**e, "single": True} for n, e in new.items()}
        write_json(folder / MANIFEST, {"run": record.get("run") or uuid.uuid4().hex, "verb": verb,
                                       "pid": os.getpid(),
                                       "finished_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                                       "outputs": sorted(owned | set(names)),
                                       "entries": {**{n: e for n, e in entries.items() if n in owned}, **new}})


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


