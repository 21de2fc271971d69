"""Rubber test data: nominal stress vs stretch, read from a CSV file and checked.

Data: a CSV file with the columns ``mode`` (``uniaxial``, ``equibiaxial``, ``pure-shear``;
any mix), ``stretch`` [-] and ``stress_MPa`` (nominal stress: force per reference area,
in the stretched direction); ``lambda`` and ``nominal_stress_MPa`` are accepted as other
names of the last two, ``biaxial``, ``planar`` (and ``ut``, ``et``, ``ps``) of the modes.
Lines starting with ``#`` are comments.

Refused (one :class:`~softhand.reduced.vocabulary.errors.InputError`), as no rubber test gives them: a stretch
outside :data:`STRETCH_LIMITS`, a stress beyond :data:`MAX_STRESS` MPa, data whose largest
stress is below :data:`MIN_STRESS` MPa, and a stress of the wrong sign (negative in tension,
positive in compression, nonzero at stretch 1) beyond :data:`SIGN_SCATTER` of the largest.
The fit (:mod:`softhand.reduced.materials.material_fit`) refuses, besides, data with too few
distinct points for its model.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softhand.reduced.materials import rubber_base
from softhand.reduced.fitting.csvdata import read_rows
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.vocabulary.inputfiles import plain_float

_MODE_ALIASES = {"uniaxial": "uniaxial", "ut": "uniaxial", "equibiaxial": "equibiaxial",
                 "biaxial": "equibiaxial", "et": "equibiaxial", "eb": "equibiaxial",
                 "pure-shear": "pure-shear", "pure_shear": "pure-shear", "ps": "pure-shear",
                 "planar": "pure-shear"}
COLUMNS = ("mode", "stretch", "stress_MPa")
_COLUMN_ALIASES = {"mode": "mode", "stretch": "stretch", "lambda": "stretch",
                   "stress_mpa": "stress_MPa", "nominal_stress_mpa": "stress_MPa"}
#: stretches a rubber test can give [-]; also the bounds of ``--stability-range``
STRETCH_LIMITS = (0.01, 100.0)
#: largest ``|nominal stress|`` of a rubber test [MPa]
MAX_STRESS = 1e4
#: the data's largest ``|stress|`` must reach this [MPa] (1 Pa): else there is no stiffness to fit
MIN_STRESS = 1e-6
#: a stress of the wrong sign is allowed as scatter up to this fraction of the largest ``|stress|``
SIGN_SCATTER = 0.01


@dataclass(frozen=True)
class StressData:
    """Test points: mode per row, stretch [-], nominal stress [MPa]."""

    mode: np.ndarray
    stretch: np.ndarray
    stress: np.ndarray
    source: str = "data"
    lines: np.ndarray | None = None  #: line number in the file per row (for messages)

    def __len__(self):
        return int(self.stretch.size)

    def predict(self, material: rubber_base.Rubber) -> np.ndarray:
        out = np.empty(len(self))
        for m in np.unique(self.mode):
            rows = self.mode == m
            out[rows] = material.nominal_stress(m, self.stretch[rows])
        return out


def read_test_data(path) -> StressData:
    """Read the CSV (see the module docstring); one InputError naming file, line, column."""
    path = Path(path)
    given, rows = read_rows(path)
    header = [_COLUMN_ALIASES.get(c.lower(), c) for c in given]
    if sorted(header) != sorted(COLUMNS):
        raise InputError(f"{path.name}: columns", ",".join(given), f"must be {','.join(COLUMNS)}")
    mode, lam, stress, lines = [], [], [], []
    for line, cells in rows:
        if len(cells) != len(header):
            raise InputError(f"{path.name}: line {line}", ",".join(cells),
                             f"has {len(cells)} cells; the header has {len(header)}")
        cell = dict(zip(header, cells))
        name = _MODE_ALIASES.get(cell["mode"].lower())
        if name is None:
            raise InputError(f"{path.name}: line {line}, column mode", cell["mode"],
                             f"must be one of {', '.join(rubber_base.MODES)}")
        mode.append(name)
        lam.append(_number(path.name, line, "stretch", cell["stretch"], positive=True))
        stress.append(_number(path.name, line, "stress_MPa", cell["stress_MPa"]))
        lines.append(line)
    data = StressData(np.array(mode), np.array(lam), np.array(stress), path.name, np.array(lines))
    check_data(data)
    return data


def check_data(data: StressData) -> None:
    """Refuse data no rubber test gives (see the module docstring); one InputError naming the row."""
    lo, hi = STRETCH_LIMITS
    bad = np.flatnonzero(~((data.stretch >= lo) & (data.stretch <= hi)))
    if bad.size:
        i = bad[0]
        raise InputError(_cell(data, i, "stretch"), f"{data.stretch[i]:g}",
                         f"must be in [{lo:g}, {hi:g}]: rubber tests never leave that range")
    bad = np.flatnonzero(~(np.abs(data.stress) <= MAX_STRESS))
    if bad.size:
        i = bad[0]
        raise InputError(_cell(data, i, "stress_MPa"), f"{data.stress[i]:g}",
                         f"must be in [{-MAX_STRESS:g}, {MAX_STRESS:g}] MPa (nominal stress of a rubber)")
    top = float(np.max(np.abs(data.stress)))
    if not top >= MIN_STRESS:
        raise InputError(f"{data.source}: column stress_MPa", f"largest ``|stress|`` {top:g} MPa",
                         f"must be at least {MIN_STRESS:g} MPa (1 Pa): no stiffness to fit "
                         "(stresses are in MPa)")
    tol = SIGN_SCATTER * top
    side = np.sign(data.stretch - 1.0)
    wrong = np.where(side == 0, np.abs(data.stress) > tol, side * data.stress < -tol)
    if np.any(wrong):
        i = int(np.flatnonzero(wrong)[0])
        lam, what = data.stretch[i], data.mode[i]
        if side[i] == 0:
            need = "must be 0 at stretch 1 (undeformed: every model has zero stress there)"
        elif side[i] > 0:
            need = f"must be positive in tension (stretch {lam:g} > 1, {what})"
        else:
            need = f"must be negative in compression (stretch {lam:g} < 1, {what})"
        other = "nonzero" if side[i] == 0 else "the other sign"
        raise InputError(_cell(data, i, "stress_MPa"), f"{data.stress[i]:g}",
                         f"{need}; {other} only as scatter up to {SIGN_SCATTER:.0%} of the "
                         f"largest ``|stress|`` ({top:g} MPa)")


def _cell(data, i, col):
    """Where row i is: the file's line, or the row number of data built in code."""
    where = f"line {data.lines[i]}" if data.lines is not None else f"row {i + 1}"
    return f"{data.source}: {where}, column {col}"


def _number(name, line, col, text, positive=False):
    try:
        value = plain_float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or (positive and not value > 0):
        raise InputError(f"{name}: line {line}, column {col}", text,
                         "must be a positive number" if positive else "must be a finite number")
    return value
