"""Argument helpers shared by the verbs: value lists, the design option, tables."""
from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from softhand.reduced.design import HandDesign, load_design
from softhand.reduced.errors import InputError
from softhand.reduced.inputfiles import plain_float
from softhand.studies.io.files import json_text


#: most values one range or list may give: reduced-model verbs, and FEM runs (one solve each),
#: unless --max-cases says otherwise; and the most --max-cases may allow
MAX_POINTS, MAX_FEM_POINTS = 100_000, 200
MOST_POINTS, MOST_FEM_POINTS = 1_000_000, 10_000
#: longest range or list text read [characters]
MAX_TEXT = 100_000
_FORMS = "start:stop:step (step > 0, stop >= start) or a comma-separated list of finite numbers"
#: what a field of one value or of a vector (no range) takes
ONE_NUMBER, NUMBER_LIST = "one finite number", "a comma-separated list of finite numbers"


def parse_values(text: str, field: str, max_count: int = MAX_POINTS, forms: str | None = None) -> np.ndarray:
    """``'0:90:10'`` (start:stop:step, stop included) or ``'1,2.5,3'`` -> float array.

    Every value finite; at most ``max_count`` of them (InputError otherwise). ``forms``: what
    the field takes, for the message (default: a range or list; one number if max_count is 1).
    """
    forms = forms or (ONE_NUMBER if max_count == 1 else _FORMS)
    if len(text) > MAX_TEXT:
        raise InputError(field, text, f"is longer than {MAX_TEXT} characters")
    parts = [x.strip() for x in (text.split(":") if ":" in text else text.split(","))]
    try:
        numbers = [plain_float(x) for x in parts]
    except ValueError:
        numbers = []
    if ":" in text:
        if len(numbers) != 3 or not all(map(math.isfinite, numbers)) or not numbers[2] > 0 \
                or numbers[1] < numbers[0]:
            raise InputError(field, text, f"must be {forms}")
        start, stop, step = numbers
        count = (stop - start) / step + 1
        if not count <= max_count:
            raise InputError(field, text, _too_many(_count(count), max_count))
        values = start + step * np.arange(int(math.floor(count - 1 + 1e-9)) + 1)
    else:
        values = np.array(numbers, dtype=float)
        if values.size > max_count:
            raise InputError(field, text, _too_many(values.size, max_count))
    if values.size == 0 or not np.all(np.isfinite(values)):
        raise InputError(field, text, f"must be {forms}")
    return values


def _too_many(count, max_count: int) -> str:
    more = "; --max-cases N allows more" if max_count > 1 else ""
    return f"gives {count} values; at most {max_count} allowed{more}"


def add_max_cases_option(parser: argparse.ArgumentParser, default: int, most: int) -> None:
    """``--max-cases N``: the most values one range may give (``default``; at most ``most``)."""
    parser.add_argument("--max-cases", type=int, default=None, metavar="N",
                        help=f"allow ranges of up to N values (default {default}, at most {most})")


def max_cases(args, default: int, most: int) -> int:
    """``--max-cases`` if given (a whole number in [1, most]), else ``default``."""
    n = getattr(args, "max_cases", None)
    if n is None:
        return default
    if not 1 <= n <= most:
        raise InputError("--max-cases", n, f"must be a whole number in [1, {most}]")
    return n


def _count(count: float) -> str:
    return f"{math.floor(count + 1e-9):d}" if count < 1e15 else "too many"


def check_range(field: str, value: float, lo: float, hi: float, unit: str = "") -> float:
    """``value`` if finite and in [lo, hi], else InputError naming ``field``."""
    if not (math.isfinite(value) and lo <= value <= hi):
        what, (lo, hi) = ("a whole number", (lo, hi)) if isinstance(value, int) and isinstance(lo, int) \
            and isinstance(hi, int) else ("a number", (f"{lo:g}", f"{hi:g}"))
        raise InputError(field, value, f"must be {what} in [{lo}, {hi}]{unit and ' ' + unit}")
    return value


def add_design_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--design", metavar="FILE", default=None,
                        help="design TOML file (default: the paper's, studies/designs/paper.toml)")


def add_json_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout")


def add_progress_option(parser: argparse.ArgumentParser) -> None:
    """``--no-progress``: no progress bar on stderr (logs, CI)."""
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def design_from_args(args) -> HandDesign:
    """The design of ``--design`` (the paper's without it), its V0 one its sheet can hold."""
    from softhand.reduced.reservoir import check_holds

    design = load_design(args.design)
    check_holds(design.V0, design)
    return design


def require_finite(result, args, where: str) -> None:
    """InputError naming ``--design`` if a number of ``result`` (nested dicts and lists; text,
    None and bools skipped) is not finite: the model has no answer for that design there
    (a material beyond its limit, e.g. past Gent's locking stretch), and a NaN is not printed."""
    stack = [("", result)]
    while stack:
        key, value = stack.pop()
        if isinstance(value, dict):
            stack.extend(value.items())
        elif isinstance(value, (list, tuple, np.ndarray)):
            stack.extend((key, v) for v in value)
        elif isinstance(value, (float, np.floating)) and not math.isfinite(value):
            design = getattr(args, "design", None) or "the paper's design"
            raise InputError("--design", design, f"has no finite {key or 'result'} {where}: its "
                             "model has no answer there (a material past its limit, e.g. Gent's "
                             "locking stretch, or sizes that do not fit together)")


def print_json(obj) -> None:
    """One strict JSON object on stdout (numpy converted, numbers that are not finite null)."""
    sys.stdout.write(json_text(obj) + "\n")


def print_table(rows: list[dict], columns: list[str] | None = None, *, digits: int = 4,
                file=None) -> None:
    """A plain aligned text table of ``rows`` (dicts with the same keys)."""
    file = file or sys.stdout
    if not rows:
        return
    columns = columns or list(rows[0])
    cells = [[_fmt(row[c], digits) for c in columns] for row in rows]
    widths = [max(len(c), *(len(r[i]) for r in cells)) for i, c in enumerate(columns)]
    print("  ".join(c.rjust(w) for c, w in zip(columns, widths)), file=file)
    for r in cells:
        print("  ".join(x.rjust(w) for x, w in zip(r, widths)), file=file)


def _fmt(value, digits: int) -> str:
    if isinstance(value, (float, np.floating)):
        return f"{value:.{digits}g}" if abs(value) >= 1e-3 or value == 0 else f"{value:.3e}"
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_fmt(v, digits) for v in value) + "]"
    return str(value)
