"""Value lists from text: ``'0:90:10'`` (a range) or ``'1,2.5,3'`` (a list), checked.

Used by the CLI's options and by study files alike (one reader for both).
"""
from __future__ import annotations

import math

import numpy as np

from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.vocabulary.inputfiles import plain_float

#: most values one range or list may give: reduced-model verbs, and FEM runs (one solve each),
#: unless --max-cases says otherwise; and the most --max-cases may allow
MAX_POINTS, MAX_FEM_POINTS = 100_000, 200
MOST_POINTS, MOST_FEM_POINTS = 1_000_000, 10_000
#: longest range or list text read [characters]
MAX_TEXT = 100_000
_FORMS = "start:stop:step (step > 0, stop >= start) or a comma-separated list of finite numbers"
#: what a field of one value or of a vector (no range) takes
ONE_NUMBER, NUMBER_LIST = "one finite number", "a comma-separated list of finite numbers"


def parse_values(text: str, field: str, max_count: int = MAX_POINTS, forms: str | None = None, *,
                 more: str | None = "--max-cases N allows more") -> np.ndarray:
    """``'0:90:10'`` (start:stop:step, stop included) or ``'1,2.5,3'`` -> float array.

    Every value finite; at most ``max_count`` of them (InputError otherwise). ``forms``: what
    the field takes, for the message (default: a range or list; one number if max_count is 1);
    ``more``: how the user may allow more values (None: they may not), for the message.
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
            raise InputError(field, text, _too_many(_count(count), max_count, more))
        values = start + step * np.arange(int(math.floor(count - 1 + 1e-9)) + 1)
    else:
        values = np.array(numbers, dtype=float)
        if values.size > max_count:
            raise InputError(field, text, _too_many(values.size, max_count, more))
    if values.size == 0 or not np.all(np.isfinite(values)):
        raise InputError(field, text, f"must be {forms}")
    return values


def _too_many(count, max_count: int, more: str | None) -> str:
    more = f"; {more}" if more and max_count > 1 else ""
    return f"gives {count} values; at most {max_count} allowed{more}"


def _count(count: float) -> str:
    return f"{math.floor(count + 1e-9):d}" if count < 1e15 else "too many"


def check_distinct(values, text: str, option: str) -> None:
    """Each value once (a repeated one would be one more FEM for the same answer)."""
    if np.unique(values).size != np.asarray(values).size:
        raise InputError(option, text, "gives a value twice; give each once")
