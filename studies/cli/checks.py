"""Checks the CLI runs on every verb's arguments before any work starts.

* every float option is finite (argparse's ``float`` accepts ``nan`` and ``inf``), every
  text option not blank;
* every output (``--out``, ``--plot``, ``--results``, ``--write-calibration``) can be
  written: the right kind of path (folder or file, a known picture suffix) under a folder
  this process can create files in; probed with a temporary file that is removed at once,
  so a refused command leaves nothing behind;
* the cache folder (``SOFTHAND_CACHE``): if it cannot be written, a warning; results are
  then computed without caching them.
"""
from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
from pathlib import Path

from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.io.manifest import check_single

#: picture suffixes of matplotlib's writers (--plot) and of the 3D renderer (inspect --out)
PLOT_SUFFIXES = (".png", ".pdf", ".svg", ".jpg", ".jpeg", ".eps", ".ps", ".tif", ".tiff", ".webp")
RENDER_SUFFIXES = (".png", ".jpg", ".jpeg")
#: suffixes of the renderer's animations (inspect --animate)
ANIMATION_SUFFIXES = (".gif", ".mp4")

#: argument name -> kind of output, per verb where it differs from the default
OUTPUTS = {"out": "dir", "plot": "plot", "results": "dir", "write_calibration": "file"}
VERB_OUTPUTS = {"fit": {"out": "toml"}, "material": {"out": "toml"},
                "inspect": {"out": "render", "animate": "animation"},
                "calibrate": {"out": "csv"}, "reservoir": {"write_calibration": "csv"}}
#: file suffixes an output kind must end in (a design TOML, a table)
SUFFIXES = {"plot": PLOT_SUFFIXES, "render": RENDER_SUFFIXES, "animation": ANIMATION_SUFFIXES,
            "toml": (".toml",), "csv": (".csv",)}
#: the first bytes of an output kind's files that say softhand wrote them (a calibration table)
MARKS = {"csv": b"# FEM calibration of "}
#: output kinds whose writer reads the suffix as it is spelled (the 3D renderer: not '.PNG')
EXACT_SUFFIX = ("render", "animation")
#: argument names of the files a verb reads (an output may not be one of them)
INPUTS = ("data", "design", "task", "space", "check", "table", "disturbance", "file")
#: verbs that may use the on-disk caches (meshes, grasp weights)
CACHE_VERBS = ("bend", "weights", "grasp", "study", "reproduce", "reservoir")


def option_name(dest: str, parser) -> str:
    """The option string the user typed for argparse destination ``dest`` (also in sub-commands)."""
    for action in parser._actions:
        if action.dest == dest and action.option_strings:
            return max(action.option_strings, key=len)
        for sub in (getattr(action, "choices", None) or {}).values() \
                if isinstance(action, argparse._SubParsersAction) else ():
            name = option_name(dest, sub)
            if name != dest:
                return name
    return dest


def check_finite(args, parser) -> None:
    """Every float argument finite, every text argument not blank; InputError naming its
    option (a blank file name would be read as the current folder, '')."""
    for dest, value in vars(args).items():
        if isinstance(value, float) and not math.isfinite(value):
            raise InputError(option_name(dest, parser), value, "must be a finite number")
        if isinstance(value, str) and not value.strip():
            raise InputError(option_name(dest, parser), value, "is empty")


def check_outputs(verb: str, args, parser) -> None:
    """Every output argument given can be written; InputError naming the option."""
    kinds = {**OUTPUTS, **VERB_OUTPUTS.get(verb, {})}
    seen = {}
    for dest, kind in kinds.items():
        value = getattr(args, dest, None)
        if value is not None:
            same = next((d for d, p in seen.items() if os.path.abspath(p) == os.path.abspath(value)), None)
            if same is not None:
                raise InputError(option_name(dest, parser), value, f"is also {option_name(same, parser)}; "
                                                                   "give each output its own name")
            seen[dest] = value
            check_writable(value, kind, option_name(dest, parser))
            if kind != "dir":
                _not_an_input(value, option_name(dest, parser), args, parser)
                if value not in run_outputs(verb, args):  # (those the run stages, checks, replaces)
                    check_single(value, option_name(dest, parser), MARKS.get(kind))  # never the user's


def _named_files(verb: str, args) -> list[str]:
    """The file outputs named on the command line (``--plot FILE``, ``--out FILE.toml``, ...)."""
    kinds = {**OUTPUTS, **VERB_OUTPUTS.get(verb, {})}
    return [getattr(args, d) for d, kind in kinds.items() if kind != "dir" and getattr(args, d, None) is not None]


def single_outputs(verb: str, args) -> list[str]:
    """The file outputs named on the command line that are not one of the run's own outputs in
    its ``--out`` folder."""
    return [v for v in _named_files(verb, args) if v not in run_outputs(verb, args)]


def run_outputs(verb: str, args) -> list[str]:
    """Of the file outputs named, those that are outputs of the run's own ``--out`` folder by its
    manifest (e.g. ``design --plot DIR/pareto.png``: staged and committed with the run)."""
    from softhand.studies.io.manifest import read_manifest

    out = getattr(args, "out", None) if {**OUTPUTS, **VERB_OUTPUTS.get(verb, {})}.get("out") == "dir" else None
    if out is None:
        return []
    entries = read_manifest(Path(out)).get("entries") or {}
    return [v for v in _named_files(verb, args) if os.path.abspath(os.path.dirname(v)) == os.path.abspath(out)
            and isinstance(entries.get(os.path.basename(v)), dict)
            and not entries[os.path.basename(v)].get("single")]


def _not_an_input(path, field: str, args, parser) -> None:
    """An output file that is one of the files read (the same file, by any path) would
    overwrite it: InputError naming both options."""
    if not os.path.isfile(path):
        return
    for dest in INPUTS:
        given = getattr(args, dest, None)
        if isinstance(given, str) and os.path.isfile(given) and os.path.samefile(path, given):
            raise InputError(field, str(path), f"is the file {option_name(dest, parser)} reads; writing "
                                               f"it would overwrite it: give another file")


def check_choices(option: str, names, allowed, what: str, shown: str | None = None) -> None:
    """Each of ``names`` (a list the user gave to ``option``) is one of ``allowed`` and named
    once; ``what`` names one of them ("case", "section"), ``shown`` the value as typed."""
    shown = ",".join(names) if shown is None else shown
    unknown = [n for n in names if n not in allowed]
    if unknown or not names:
        bad = unknown[0] if unknown and unknown[0] else shown  # a blank name: the whole value
        raise InputError(option, bad, f"allowed: {', '.join(allowed)}")
    if len(set(names)) != len(names):
        raise InputError(option, shown, f"names a {what} twice; name each once")


def check_writable(path, kind: str, field: str) -> None:
    """``path`` can be written as a ``kind`` ('dir', 'file' or one of SUFFIXES) output."""
    text = str(path)
    if not text.strip() or "\0" in text:
        raise InputError(field, text, "must be a file or folder name")
    p = Path(text)
    _check_name_lengths(p, field, text)
    if kind == "dir":
        if p.is_symlink() and not p.exists():
            raise InputError(field, text, "is a broken symbolic link; give a folder")
        if p.exists() and not p.is_dir():
            raise InputError(field, text, "exists and is not a folder; give a folder")
        folder = p
    else:
        if p.is_dir() or text.endswith(os.sep):
            raise InputError(field, text, "is a folder; give a file name")
        suffixes = SUFFIXES.get(kind)
        suffix = p.suffix if kind in EXACT_SUFFIX else p.suffix.lower()
        if suffixes and suffix not in suffixes:
            case = " (lower case)" if kind in EXACT_SUFFIX else ""
            ends = f"one of {', '.join(suffixes)}" if len(suffixes) > 1 else suffixes[0]
            raise InputError(field, text, f"must end in {ends}{case}")
        folder = p.parent
    _probe(folder, field, text)


def _check_name_lengths(p: Path, field: str, text: str) -> None:
    """Each part of ``p`` within the file system's name length, the whole within its path
    length (else the first write fails with 'File name too long', after the work is done)."""
    existing = _nearest_existing(p)
    try:
        name_max = os.pathconf(existing, "PC_NAME_MAX")
        path_max = os.pathconf(existing, "PC_PATH_MAX")
    except (OSError, ValueError, AttributeError):  # not POSIX, or not known: common limits
        name_max, path_max = 255, 4096
    longest = max(p.parts, key=lambda part: len(os.fsencode(part)), default="")
    if len(os.fsencode(longest)) > name_max:
        raise InputError(field, text, f"has a name of {len(os.fsencode(longest))} bytes; "
                         f"at most {name_max} per folder or file name")
    if len(os.fsencode(str(p.absolute()))) >= path_max:
        raise InputError(field, text, f"is a path of more than {path_max} bytes")


def check_readable_folder(path, field: str) -> None:
    """``path`` is a folder or not there yet (a results root that is only read)."""
    text = str(path)
    if not text.strip() or "\0" in text:
        raise InputError(field, text, "must be a folder name")
    if Path(text).exists() and not Path(text).is_dir():
        raise InputError(field, text, "exists and is not a folder; give a folder")


def _nearest_existing(path: Path) -> Path:
    """``path`` or its nearest ancestor that exists (os.path.exists: False, not an error, for a
    name too long)."""
    while not os.path.exists(path) and path != path.parent:
        path = path.parent
    return path


def _probe(folder: Path, field: str, text: str) -> None:
    existing = _nearest_existing(folder)
    if not existing.is_dir():
        raise InputError(field, text, f"cannot be created: {existing} is not a folder")
    try:
        with tempfile.TemporaryFile(dir=existing):
            pass
    except OSError as exc:
        raise InputError(field, text, f"cannot be written: {existing}: "
                         f"{exc.strerror or exc}") from None


def cache_writable() -> bool:
    """True if the cache folder (``SOFTHAND_CACHE``) can be written."""
    from softhand.meshes.cache import cache_dir

    try:
        check_writable(cache_dir().parent, "dir", "SOFTHAND_CACHE")
    except InputError:
        return False
    return True


def warn_cache(verb: str) -> None:
    """A warning on stderr if a verb that caches cannot write its cache."""
    if verb in CACHE_VERBS and not cache_writable():
        from softhand.meshes.cache import cache_dir

        print(f"softhand {verb}: warning: the cache {cache_dir().parent} cannot be written; "
              f"computing without caching", file=sys.stderr)
