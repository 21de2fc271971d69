"""Argument helpers shared by the verbs: value lists, the design option, tables."""
from __future__ import annotations

import argparse
import json
import math
import sys

import numpy as np

from reduced.design import HandDesign, load_design
from reduced.errors import InputError
from studies.output import jsonable


def parse_values(text: str, field: str) -> np.ndarray:
    """``'0:90:10'`` (start:stop:step, stop included) or ``'1,2.5,3'`` -> float array."""
    try:
        if ":" in text:
            start, stop, step = (float(x) for x in text.split(":"))
            if not step > 0 or stop < start:
                raise ValueError
            count = int(math.floor((stop - start) / step + 1e-9)) + 1
            return start + step * np.arange(count)
        values = np.array([float(x) for x in text.split(",") if x.strip()], dtype=float)
        if values.size == 0 or not np.all(np.isfinite(values)):
            raise ValueError
        return values
    except ValueError:
        raise InputError(field, text, "must be start:stop:step (step > 0, stop >= start) "
                                      "or a comma-separated list of numbers") from None


def add_design_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--design", metavar="FILE", default=None,
                        help="design TOML file (default: the paper's, studies/designs/paper.toml)")


def add_json_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout")


def design_from_args(args) -> HandDesign:
    return load_design(args.design)


def print_json(obj) -> None:
    """One JSON object on stdout (numpy arrays and scalars converted)."""
    json.dump(obj, sys.stdout, indent=1, default=jsonable)
    sys.stdout.write("\n")


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
