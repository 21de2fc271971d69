"""Small input files read safely: a regular file of at most MAX_FILE_BYTES, or TOML; anything
else is one :class:`reduced.errors.InputError` line naming the option."""
from __future__ import annotations

import tomllib
from pathlib import Path

from .errors import InputError

__all__ = ["MAX_FILE_BYTES", "read_input_file", "read_toml"]


#: largest design / study / data file read [bytes]; a bigger one (or /dev/zero) is refused
MAX_FILE_BYTES = 1_000_000


def read_input_file(path: str | Path, field: str, what: str) -> bytes:
    """The bytes of a small regular input file; InputError (one line) for anything else."""
    path = Path(path)
    try:
        with open(path, "rb") as f:
            if not path.is_file():
                raise InputError(field, str(path), f"is not a regular file; give {what}")
            data = f.read(MAX_FILE_BYTES + 1)
    except FileNotFoundError:
        raise InputError(field, str(path), f"no such file; give {what}") from None
    except IsADirectoryError:
        raise InputError(field, str(path), f"is a directory; give {what}") from None
    except OSError as exc:
        raise InputError(field, str(path), f"cannot be read ({exc.strerror or exc}); "
                         f"give {what}") from None
    if len(data) > MAX_FILE_BYTES:
        raise InputError(field, str(path), f"is larger than {MAX_FILE_BYTES} bytes; give {what}")
    return data


def read_toml(path: str | Path, field: str, what: str) -> dict:
    """A small TOML file as a dict; InputError (one line) if unreadable or not TOML."""
    data = read_input_file(path, field, what)
    try:
        return tomllib.loads(data.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(field, str(path), f"is not valid TOML ({exc})") from None
