"""The manifest of an output folder: what earlier softhand runs wrote there, and whether it is
still what they wrote (:mod:`softhand.studies.io.outputs` decides from it what a run may replace).

``.softhand-outputs.json`` holds the last run's id, verb, process and time, ``outputs`` (the
names softhand wrote into the folder) and ``entries`` (each name's kind, and a folder's every
name inside it, as it was written).
"""
from __future__ import annotations

import json
import os
from pathlib import Path

from softhand.studies.io.files import read_bounded

#: the record of what the runs into a folder wrote there (see :func:`softhand.studies.io.outputs.replaced_outputs`)
MANIFEST = ".softhand-outputs.json"


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


def check_unchanged(path: Path, entry, field: str, verb: str | None = None) -> None:
    """An earlier run's output ``path`` is still what it wrote (its manifest ``entry``; none from
    a manifest before entries were kept): a file still a file, a folder a folder holding nothing
    but what the run put in it, each name of the kind it was; and it is an output of ``verb``'s
    (None: any). Else InputError: replacing it would lose what the user, or another verb, put there."""
    from softhand.reduced.vocabulary.errors import InputError

    if not isinstance(entry, dict):
        return
    if verb is not None and entry.get("verb") not in (None, verb) and not entry.get("single"):
        raise InputError(field, str(path), f"was written by softhand {entry['verb']}, and softhand {verb} "
                                           "writes its own there; give another folder")
    if entry.get("single"):
        raise InputError(field, str(path), "is the file another softhand command wrote there as its output "
                                           "(--plot, --out FILE); move it away or give another folder")
    now = entry_of(path)
    if now["kind"] != entry.get("kind"):
        raise InputError(field, str(path), f"is a {now['kind']} where an earlier softhand run wrote a "
                                           f"{entry.get('kind')}, and the run replaces it; move it away "
                                           "or give another folder")
    untyped = lambda names: {n.rstrip("/@") for n in names}  # noqa: E731  (an entry before kinds were kept)
    extra = sorted(set(now.get("contents", ())) - set(entry.get("contents", ())) if entry.get("typed")
                   else untyped(now.get("contents", ())) - untyped(entry.get("contents", ())))
    if extra:
        inside = path / extra[0].rstrip("/@")
        raise InputError(field, str(inside), "was not written by an earlier softhand run into this folder "
                                             "and the run replaces the folder; move it away or give "
                                             "another folder")


def entry_of(path: Path) -> dict:
    """What stands at ``path`` for the manifest: its kind and, for a folder, every name in it
    (relative paths; links not followed)."""
    if path.is_symlink():
        return {"kind": "link"}
    if not path.is_dir():
        return {"kind": "file"}
    contents = []  # a folder's names end in '/', a link's in '@': a name that changed kind is another name
    for root, dirs, files in os.walk(path):
        rel = Path(root).relative_to(path)
        contents += [str(rel / n) + ("@" if (Path(root) / n).is_symlink() else "/") for n in dirs]
        contents += [str(rel / n) + ("@" if (Path(root) / n).is_symlink() else "") for n in files]
    return {"kind": "folder", "contents": sorted(contents), "typed": True}


def entries_of(folder: Path, names, verb: str | None = None) -> dict:
    """The manifest's entries of ``names`` as they stand in ``folder`` now (written by ``verb``)."""
    return {n: {**entry_of(folder / n), **({"verb": verb} if verb else {})}
            for n in names if (folder / n).exists() or (folder / n).is_symlink()}


def read_manifest(folder: Path) -> dict:
    """The folder's manifest as a dict ({} if there is none or it does not parse)."""
    try:
        record = json.loads(read_bounded(folder / MANIFEST, 1 << 20))
    except (OSError, ValueError, RecursionError):
        return {}
    return record if isinstance(record, dict) else {}


def manifest_run(folder: Path):
    """The id of the last run recorded in the folder's manifest (None: none)."""
    return read_manifest(folder).get("run")


def check_single(path, field: str, mark: bytes | None = None) -> None:
    """A file output named on the command line (``--plot FILE``, ``--out FILE.toml``): if something
    stands there, it is a file an earlier softhand command wrote there as such an output (its
    folder's manifest says so; :func:`softhand.studies.io.outputs.record_single`), or a plain file
    that begins with ``mark`` (a calibration table's first line: the shipped tables, regenerated
    in place). Else InputError: a file of the user's, or one of a run's outputs, is never replaced."""
    from softhand.reduced.vocabulary.errors import InputError

    path = Path(path)
    if not (path.exists() or path.is_symlink()):
        return
    if mark is not None and path.is_file() and not path.is_symlink():
        try:
            with path.open("rb") as f:
                if f.read(len(mark)) == mark:
                    return
        except OSError:
            pass
    entry = (read_manifest(path.parent).get("entries") or {}).get(path.name) \
        if path.name in owned_outputs(path.parent) else None
    if not (isinstance(entry, dict) and entry.get("single") and entry.get("kind") == "file"
            and entry_of(path)["kind"] == "file"):
        raise InputError(field, str(path), "exists and was not written by an earlier softhand command as "
                                           "this kind of output; move it away or give another file name")
