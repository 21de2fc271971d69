"""A failed FEM path: the last converged state saved next to one clear error line.

Every verb whose FEM can stop (Newton gives up past a limit point, a sheet or tube that no
longer holds) calls :func:`save_last_converged` with the state it reached: its fields go to
``DIR/result.json`` (``"failed": true``, the error, what was reached) and, written by the
verb's ``write_files``, to its VTK and tables; the user sees one line on stderr
that names the load reached and the files, and the exit code is 1.
"""
from __future__ import annotations

import sys
from pathlib import Path

from softhand.studies.io.files import write_json

from softhand.studies.io.outputs import replaced_outputs


def save_last_converged(out: Path, verb: str, what: str, message: str, reached: str,
                        record: dict, write_files=None, files: str = "", *, names=None,
                        shown: Path | None = None) -> int:
    """Write ``record`` (+ failed, error) to ``out/result.json`` and ``write_files(folder)``'s
    files; one error line naming ``reached`` (e.g. 'P = 0.55 MPa'); returns the exit code 1.
    ``names``: the verb's outputs, written as one run's whole result (:func:`~softhand.studies.io.outputs.replaced_outputs`);
    None: ``out`` is already the run's staging folder, its outputs named as in ``shown``."""
    shown = Path(out) if shown is None else Path(shown)
    where = f"{shown}/result.json" + (f" and {shown}/{files}" if files else "")
    try:
        with replaced_outputs(out if names is not None else None, names or (), verb=verb) as stage:
            folder = Path(out) if stage is None else stage
            folder.mkdir(parents=True, exist_ok=True)
            if write_files is not None:
                write_files(folder)
            write_json(folder / "result.json", {"failed": True, "error": message, **record})
        saved = f"is in {where}"
    except OSError as exc:
        saved = f"could not be saved in {shown} ({exc.strerror or exc})"
    print(f"softhand {verb}: error: the {what} stopped: {message}; the last converged state "
          f"({reached}) {saved}", file=sys.stderr)
    return 1
