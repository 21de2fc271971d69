"""Small input files read safely: a regular file of at most MAX_FILE_BYTES, or TOML; anything
else is one :class:`softhand.reduced.vocabulary.errors.InputError` line naming the option."""
from __future__ import annotations

import csv
import re
import stat
import tomllib
from pathlib import Path
from typing import NamedTuple

import numpy as np

from softhand.reduced.vocabulary.errors import InputError

__all__ = ["MAX_FILE_BYTES", "MAX_NESTING", "NumberTable", "csv_cells", "nesting_depth", "plain_float",
           "read_input_file", "read_number_table", "read_toml"]


#: largest design / study / data file read [bytes]; a bigger one (or /dev/zero) is refused
MAX_FILE_BYTES = 1_000_000
#: deepest nesting of tables and arrays in an input file (the files' own need at most 4)
MAX_NESTING = 16
#: a key of more than MAX_NESTING dotted parts (opening a line, a table header or a key of an
#: inline table), its strings emptied: refused before parsing, since tomllib takes time
#: quadratic in a dotted key's parts (20 000: 1-8 s)
_DEEP_KEY = re.compile(r'(?:^|[{,])[ \t]*\[{0,2}[ \t]*(?:(?:[A-Za-z0-9_-]+|"")[ \t]*\.[ \t]*){%d,}' % MAX_NESTING,
                       re.MULTILINE)
#: TOML's strings (multi-line first), and its comments once the strings are gone
_STRINGS = re.compile(r'"""[\s\S]*?"""|\'\'\'[\s\S]*?\'\'\'|"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'')
_COMMENT = re.compile(r"#[^\n]*")
#: a number as a data file or a command line writes it: ASCII decimal, optional exponent, or
#: nan / inf (refused as not finite by whoever reads it)
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|[+-]?(?:nan|inf|infinity)",
                     re.IGNORECASE | re.ASCII)


def plain_float(text: str) -> float:
    """float() of a plain ASCII number (spaces around it allowed); ValueError for what float()
    would also take but no data file or command line means: '1_0' (read as 10), other
    scripts' digits ('٥', '２')."""
    if not _NUMBER.fullmatch(text.strip()):
        raise ValueError(f"not a plain number: {text!r}")
    return float(text)


def read_input_file(path: str | Path, field: str, what: str) -> bytes:
    """The bytes of a small regular input file; InputError (one line) for anything else."""
    if not str(path).strip():  # Path('') is '.', which would be reported instead
        raise InputError(field, str(path), f"is empty; give {what}")
    if "\0" in str(path):  # no file system has such a name (os.stat raises ValueError)
        raise InputError(field, str(path), f"contains a NUL character; give {what}")
    path = Path(path)
    try:
        mode = path.stat().st_mode  # before opening: a FIFO's open waits for a writer
        if stat.S_ISDIR(mode):
            raise IsADirectoryError
        if not stat.S_ISREG(mode):
            raise InputError(field, str(path), f"is not a regular file; give {what}")
        with open(path, "rb") as f:
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


def csv_cells(lines, field: str, path) -> list[list[str]]:
    """The cells of CSV text lines (csv.reader); InputError (one line) where the csv module
    cannot read them (e.g. a cell beyond its field size limit, 131 072 characters)."""
    try:
        return list(csv.reader(lines))
    except csv.Error as exc:
        raise InputError(field, str(path), f"is not a CSV file this reader can read ({exc})") from None


class NumberTable(NamedTuple):
    """A calibration table as read: its comment lines (the provenance), header and numbers."""

    comments: tuple[str, ...]  #: the ``#`` lines, as written
    columns: tuple[str, ...]   #: the header's column names
    values: np.ndarray         #: (rows, columns), every value finite


def read_number_table(path: str | Path, field: str, what: str, columns=None, optional=()) -> NumberTable:
    """The one reader of the calibration tables (CSV of numbers after ``#`` provenance lines).

    ``columns``: the header it must have (or None: any), which may go on with the ``optional``
    columns, in their order (a table written before they existed lacks them). InputError naming ``field`` and the
    file if it is unreadable, not UTF-8, lacks the header, or has a cell that is not a finite
    number or a row of the wrong length."""
    data = read_input_file(path, field, what)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise InputError(field, str(path), "is not a text (CSV) file") from None
    comments = tuple(line for line in text.splitlines() if line.startswith("#"))
    lines = [line for line in text.splitlines() if line.strip() and not line.startswith("#")]
    header = tuple(c.strip() for c in lines[0].split(",")) if lines else ()
    allowed = None if columns is None else \
        [tuple(columns) + tuple(optional[:k]) for k in range(len(optional) + 1)]
    if not header or (allowed is not None and header not in allowed):
        shown = ",".join(columns or ("...",)) + "".join(f"[,{c}]" for c in optional)
        raise InputError(field, str(path), f"needs the header {shown}")
    try:
        values = np.array([[plain_float(x) for x in line.split(",")] for line in lines[1:]], ndmin=2)
    except ValueError:
        raise InputError(field, str(path), "has a cell that is not a number") from None
    if values.shape[0] == 0 or values.shape[1] != len(header) or not np.all(np.isfinite(values)):
        raise InputError(field, str(path), f"needs rows of {len(header)} finite numbers")
    return NumberTable(comments, header, values)


def read_toml(path: str | Path, field: str, what: str) -> dict:
    """A small TOML file as a dict; InputError (one line) if unreadable or not TOML."""
    data = read_input_file(path, field, what)
    deep = InputError(field, str(path), f"nests tables or arrays more than {MAX_NESTING} deep; give {what}")
    try:
        text = data.decode("utf-8")
        if _DEEP_KEY.search(_COMMENT.sub("", _STRINGS.sub('""', text))):
            raise deep
        table = tomllib.loads(text)
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(field, str(path), f"is not valid TOML ({exc})") from None
    except RecursionError:  # arrays nested thousands deep
        raise InputError(field, str(path), f"nests arrays or tables more than the parser's "
                         f"limit; give {what}") from None
    if nesting_depth(table, MAX_NESTING + 1) > MAX_NESTING:  # dotted keys nest without recursion
        raise deep
    return table


def nesting_depth(value, limit: int = 10_000) -> int:
    """How deep dicts and lists nest in ``value`` (a scalar: 0); iterative, so any depth is
    measured without recursion; stops counting at ``limit``."""
    deepest, stack = 0, [(value, 0)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, (dict, list)) and depth < limit:
            deepest = max(deepest, depth + 1)
            stack.extend((v, depth + 1) for v in (item.values() if isinstance(item, dict) else item))
    return deepest
