"""Argument helpers shared by the verbs: value lists, the design option, tables."""
from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from softhand.reduced.vocabulary.design import HandDesign

from softhand.reduced.vocabulary.design_files import load_design
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.io.files import json_text
# the value lists' reader and limits, for the verbs (study files read values the same way)
from softhand.studies.io.values import MAX_FEM_POINTS, MAX_POINTS, MOST_FEM_POINTS, MOST_POINTS, NUMBER_LIST, \
    ONE_NUMBER, parse_values  # noqa: F401


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


#: most worker processes of one run (``--workers``)
MAX_WORKERS = 256


def check_workers(workers: int | None) -> int | None:
    """``--workers`` if absent (None) or a whole number in [1, MAX_WORKERS], else InputError."""
    if workers is not None and not 1 <= workers <= MAX_WORKERS:
        raise InputError("--workers", workers, f"must be a whole number in [1, {MAX_WORKERS}]")
    return workers


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
    from softhand.reduced.equations.reservoir import check_holds

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
