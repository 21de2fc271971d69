"""Measured points for calibration, read from a CSV file whose column names carry units.

Two kinds of data, told apart by their columns:

* **free bending** (eq. (27)): ``P_pump_MPa, theta_deg`` and optionally ``finger``
  (a label per row, e.g. 1..4: the paper measures all four fingers at each pressure);
* **grasp** (eqs. (25), (29)): ``P_pump_MPa, theta_deg, mass_kg, F_v_N`` and optionally
  ``diameter_mm`` (the object diameter, which picks the weight vector w) and ``finger``.

The pressure is the pump's (with the reservoir, the cavity's less the reservoir's); a column
``P_MPa``, its name before pressures said which, is read as ``P_pump_MPa``.
Lines starting with ``#`` are comments (a data file should say where it came from).
Inside, angles are in radians (``theta``); degrees only in the file. Every problem
(no such file, empty file, unknown or missing column, text in a number, a row with the
wrong number of cells) is an :class:`~softhand.reduced.vocabulary.errors.InputError` naming the file, the
line and the column.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.vocabulary.inputfiles import csv_cells, plain_float

#: column -> what it holds (unit in the name)
COLUMNS = {
    "P_pump_MPa": "pump pressure P [MPa]",
    "theta_deg": "bend angle theta of the finger [deg]",
    "finger": "finger label (optional; any whole number)",
    "mass_kg": "mass m of the grasped object [kg]",
    "F_v_N": "grasping force F_v normal to the finger, eq. (29) [N]",
    "diameter_mm": "object diameter, selects the weight vector w (optional) [mm]",
}
#: column -> (lowest, highest) allowed value of a measurement
LIMITS = {"P_pump_MPa": (-5.0, 5.0), "theta_deg": (-90.0, 180.0), "mass_kg": (0.0, 100.0),
          "F_v_N": (-1e4, 1e4), "diameter_mm": (1.0, 1000.0)}
#: a column's earlier name -> its name
OLD_NAMES = {"P_MPa": "P_pump_MPa"}
BENDING_COLUMNS = ("P_pump_MPa", "theta_deg")
GRASP_COLUMNS = ("P_pump_MPa", "theta_deg", "mass_kg", "F_v_N")


@dataclass(frozen=True)
class Measurements:
    """Measured points, one entry per row; arrays of equal length."""

    kind: str  #: "bending" (free bending, eq. (27)) or "grasp" (eqs. (25), (29))
    P: np.ndarray  #: pump pressure [MPa]
    theta: np.ndarray  #: bend angle [rad]
    finger: np.ndarray | None = None  #: finger label per row, or None
    mass: np.ndarray | None = None  #: object mass [kg] (grasp only)
    F_v: np.ndarray | None = None  #: measured grasping force [N] (grasp only)
    diameter: np.ndarray | None = None  #: object diameter [mm] (grasp, optional)
    source: str = "data"  #: file name, for messages

    def __len__(self) -> int:
        return int(self.P.size)

    @property
    def observed(self) -> np.ndarray:
        """The measured quantity the fit matches, in the data's units: theta [deg] or F_v [N]."""
        return np.degrees(self.theta) if self.kind == "bending" else self.F_v

    @property
    def unit(self) -> str:
        return "deg" if self.kind == "bending" else "N"

    @property
    def quantity(self) -> str:
        return "theta_deg" if self.kind == "bending" else "F_v_N"


def read_measurements(path: str | Path) -> Measurements:
    """Read a measurement CSV (see the module docstring); raises InputError on any problem."""
    path = Path(path)
    header, rows = read_rows(path)
    header = [OLD_NAMES.get(c, c) for c in header]
    columns = _parse_columns(path.name, header, rows)
    kind = "grasp" if "F_v_N" in columns or "mass_kg" in columns else "bending"
    required = GRASP_COLUMNS if kind == "grasp" else BENDING_COLUMNS
    missing = [c for c in required if c not in columns]
    if missing:
        raise InputError(f"{path.name}: columns", ",".join(header),
                         f"missing column {', '.join(missing)}; {kind} data needs "
                         f"{', '.join(required)}")
    if kind == "bending" and "diameter_mm" in columns:
        raise InputError(f"{path.name}: columns", ",".join(header),
                         "diameter_mm belongs to grasp data (with mass_kg and F_v_N)")
    return Measurements(
        kind=kind, P=columns["P_pump_MPa"], theta=np.radians(columns["theta_deg"]),
        finger=columns.get("finger"), mass=columns.get("mass_kg"), F_v=columns.get("F_v_N"),
        diameter=columns.get("diameter_mm"), source=path.name,
    )


def read_rows(path: Path) -> tuple[list[str], list[tuple[int, list[str]]]]:
    """Header cells and (line number, cells) of the data rows; comments and blank lines skipped."""
    from softhand.reduced.vocabulary.inputfiles import read_input_file

    data = read_input_file(path, "--data", "a CSV file")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise InputError("--data", str(path), "is not a UTF-8 text (CSV) file") from None
    lines = [(i, line) for i, line in enumerate(text.splitlines(), start=1)
             if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise InputError("--data", str(path), "is empty; need a header row "
                         f"(e.g. {','.join(BENDING_COLUMNS)}) and data rows")
    parsed = [(i, [c.strip() for c in cells])
              for (i, _), cells in zip(lines, csv_cells([line for _, line in lines], "--data", path))]
    (_, header), rows = parsed[0], parsed[1:]
    if not rows:
        raise InputError("--data", str(path), "has a header but no data rows")
    return header, rows


def _parse_columns(name: str, header: list[str], rows) -> dict[str, np.ndarray]:
    for col in header:
        if col not in COLUMNS:
            raise InputError(f"{name}: column", col,
                             f"unknown column; allowed: {', '.join(COLUMNS)}")
    if len(set(header)) != len(header):
        raise InputError(f"{name}: columns", ",".join(header), "a column appears twice")
    for line, cells in rows:
        if len(cells) != len(header):
            raise InputError(f"{name}: line {line}", ",".join(cells),
                             f"has {len(cells)} cells; the header has {len(header)}")
    return {col: np.array([_number(name, line, col, cells[j]) for line, cells in rows])
            for j, col in enumerate(header)}


def _number(name: str, line: int, col: str, text: str) -> float:
    try:
        value = plain_float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise InputError(f"{name}: line {line}, column {col}", text, "must be a finite number")
    if col == "finger" and value != int(value):
        raise InputError(f"{name}: line {line}, column {col}", text, "must be a whole number")
    if col in ("mass_kg", "diameter_mm") and not value > 0:
        raise InputError(f"{name}: line {line}, column {col}", text, "must be positive")
    lo, hi = LIMITS.get(col, (-math.inf, math.inf))
    if not lo <= value <= hi:
        raise InputError(f"{name}: line {line}, column {col}", text, f"must be in [{lo:g}, {hi:g}]")
    return value
