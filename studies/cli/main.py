"""The ``softhand`` command line.

Each verb lives in ``studies/cli/verbs/<verb>.py`` and defines

* ``HELP``: one line for ``softhand --help``;
* ``configure(parser)``: adds its arguments to an :class:`argparse.ArgumentParser`;
* ``run(args) -> int``: does the work, prints, returns the exit code.

Verb modules are imported only when their verb is called, so ``softhand curve``
never pays for importing the FEM stack. Bad input anywhere (an
:class:`softhand.reduced.vocabulary.errors.InputError`, or an argparse error) becomes one line on
stderr and exit code 2.
"""
from __future__ import annotations

import argparse
import errno
import importlib
import os
import re
import signal
import sys
import time
import warnings
from pathlib import Path

from softhand.reduced.vocabulary.errors import InputError, Note, short
from softhand.reduced.vocabulary.inputfiles import plain_float
from softhand.reduced.vocabulary.versions import package_version

#: verb -> module under studies.commands; the order is the order of ``--help``.
VERBS = (
    "curve", "grasp", "control", "fit",
    "verify", "reservoir", "bend", "weights",
    "design", "study", "calibrate", "inspect", "reproduce", "material", "hold",
)


#: errors of a write the disk refuses: full, a file-size limit, a quota, read-only
WRITE_ERRNOS = (errno.ENOSPC, errno.EFBIG, errno.EDQUOT, errno.EROFS)


class ArgumentParser(argparse.ArgumentParser):
    """argparse, but a usage error is one line and exit code 2; ``type=float`` and ``type=int``
    take plain ASCII numbers only (float() would read '1_0' as 10 and other scripts' digits)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.register("type", float, plain_float)
        self.register("type", int, _plain_int)

    def parse_known_args(self, args=None, namespace=None):
        # Python 3.11's argparse turns '--option=--' into the value [] (not a string), past
        # every check that expects one
        for token in sys.argv[1:] if args is None else args:
            if token == "--":
                break
            name, equals, value = token.partition("=")
            if name.startswith("--") and equals and value == "--":
                self.error(f"{name} = '--': must be a value ('--' ends the options)")
        return super().parse_known_args(args, namespace)

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {short(message, 400)}\n")


def _plain_int(text: str) -> int:
    """int() of ASCII digits with an optional sign (spaces around allowed); ValueError otherwise."""
    if not re.fullmatch(r"[+-]?[0-9]+", text.strip()):
        raise ValueError(f"not a plain whole number: {text!r}")
    return int(text)


def _verb_module(verb: str):
    return importlib.import_module(f"softhand.studies.cli.verbs.{verb}")


def _available_verbs() -> list[tuple[str, str]]:
    verbs = []
    for verb in VERBS:
        try:
            verbs.append((verb, _verb_module(verb).HELP))
        except ModuleNotFoundError:
            continue  # a verb not built yet is simply not listed
    return verbs


def _top_parser() -> ArgumentParser:
    lines = "\n".join(f"  {verb:<10} {help_}" for verb, help_ in _available_verbs())
    parser = ArgumentParser(
        prog="softhand",
        description="Model fluid-driven soft robot hands: reduced model and FEM.",
        epilog=f"verbs:\n{lines}\n\n'softhand VERB --help' shows a verb's options.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"softhand {package_version()}")
    parser.add_argument("verb", help="what to do (see below)")
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv or argv[0].startswith("-"):
        _top_parser().parse_args(argv or ["--help"])
        return 0
    verb, rest = argv[0], argv[1:]
    if verb not in VERBS:
        print(f"softhand: error: unknown verb {short(repr(verb), 80)}; allowed: {', '.join(VERBS)}",
              file=sys.stderr)
        return 2
    try:
        os.getcwd()  # every relative path, and some libraries' loading, go through it
    except FileNotFoundError:
        print(f"softhand {verb}: error: the current folder no longer exists; change to one that does",
              file=sys.stderr)
        return 2
    try:  # the verb's libraries take a moment to import: Ctrl-C then is one line too
        module = _verb_module(verb)
    except KeyboardInterrupt:
        print(f"softhand {verb}: interrupted", file=sys.stderr)
        return 130
    parser = ArgumentParser(prog=f"softhand {verb}", description=module.HELP)
    module.configure(parser)
    args = parser.parse_args(rest)
    previous = _sigterm_as_interrupt()
    float_errors = _quiet_float_warnings()
    form = warnings.formatwarning  # every warning shown is one line (which are shown: the filters)
    warnings.formatwarning = lambda message, category, *rest, **kw: (
        f"softhand {verb}: {'note' if issubclass(category, Note) else 'warning'}: {message}\n")
    from softhand.studies.io.files import EXIT_UNWRITTEN, UNWRITTEN, reset_unwritten

    reset_unwritten()
    try:
        _check(verb, args, parser)
        started = time.time()
        code = int(module.run(args) or 0)
        _record_single_outputs(verb, args, started)
        sys.stdout.flush()  # a closed pipe shows here, not in Python's exit
        return EXIT_UNWRITTEN if code in (0, 1) and UNWRITTEN else code  # computed, printed, not all written
    except InputError as exc:
        print(f"softhand {verb}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"softhand {verb}: interrupted; finished results are kept", file=sys.stderr)
        return 130
    except BrokenPipeError:  # e.g. 'softhand study status FILE | head': the reader left
        _silence_stdout()
        return 141
    except OSError as exc:  # a write no verb expected to fail: one line, not a traceback
        if exc.errno not in WRITE_ERRNOS:
            raise
        print(f"softhand {verb}: error: {exc.filename or 'an output'} could not be written "
              f"({exc.strerror or exc}); finished results are kept", file=sys.stderr)
        return EXIT_UNWRITTEN
    finally:
        warnings.formatwarning = form
        _restore_float_warnings(float_errors)
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _record_single_outputs(verb: str, args, started: float) -> None:
    """The file outputs named on the command line that this run wrote, recorded as softhand's in
    their folders' manifests (a later run may replace them; nothing else may): see docs/outputs.md."""
    from softhand.studies.cli.checks import single_outputs
    from softhand.studies.io.outputs import record_single

    for name in single_outputs(verb, args):
        path = Path(name)
        try:
            if path.is_file() and not path.is_symlink() and path.stat().st_mtime >= started - 1.0:
                record_single(path, verb)
        except OSError:  # a folder that takes the file but not its record: the file stands
            pass


def _check(verb: str, args, parser) -> None:
    """The checks every verb gets before it runs: finite numbers, writable outputs, cache."""
    from softhand.studies.cli.checks import check_finite, check_outputs, check_readable_folder, \
        option_name, warn_cache

    check_finite(args, parser)
    if not (verb == "study" and args.action == "status"):
        check_outputs(verb, args, parser)
    elif args.results is not None:  # status only reads: a folder, if it is there
        check_readable_folder(args.results, option_name("results", parser))
    warn_cache(verb)


def _sigterm_as_interrupt():
    """SIGTERM raises KeyboardInterrupt, as Ctrl-C does (main thread only); the old handler."""
    def interrupt(signum, frame):
        raise KeyboardInterrupt

    try:
        return signal.signal(signal.SIGTERM, interrupt)
    except ValueError:  # not the main thread
        return None


def _quiet_float_warnings() -> dict:
    """No numpy overflow / invalid-value warnings on stderr: every result the CLI prints is
    checked to be finite, and bad input is refused in one line, not after a page of warnings.
    The earlier settings, for ``_restore_float_warnings()``."""
    import numpy as np

    return np.seterr(all="ignore")


def _restore_float_warnings(settings: dict) -> None:
    import numpy as np

    np.seterr(**settings)


def _silence_stdout() -> None:
    """Point stdout at /dev/null so that Python's exit flush cannot fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
