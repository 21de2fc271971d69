"""The calibration table of the finger model ``"fem"``: its CSV format, reading and checks.

``reduced/calibrated/data/finger_fem.csv`` (or a table of one design made by ``softhand calibrate finger
--design``) holds the finger FEM's (theta, P/mu_sf, Delta Q/a^3) at sampled designs, after
comment lines with its provenance, the groups' calibrated ranges (``# range:``) and the fit
(``# fit: prior=rings, kernel=cubic, features=lb ld lL lt s2`` for an interpolant
over many designs; ``# fit: prior=rings, p_terms=s2 lb th, q_terms=lt th`` for least squares
in named terms; in older tables polynomial degrees ``design_degree=D, theta_degree=T``); :mod:`softhand.reduced.calibrated.finger_fem` fits
and uses it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.calibrated.finger_fem_terms import KERNEL_FEATURES, MAX_FACTORS, check_terms, legacy_terms
from softhand.reduced.vocabulary.inputfiles import plain_float, read_number_table

TABLE_FILE = Path(__file__).resolve().parent / "data" / "finger_fem.csv"
#: the nondimensional groups, in table column order
GROUPS = ("b_a", "d_a", "link_a", "tie_link")
LABELS = {"b_a": "b/a", "d_a": "d/a", "link_a": "link/a", "tie_link": "tie/link"}
COLUMNS = ("design", *GROUPS, "theta", "p_tilde", "q_tilde")
#: the optional column after them: the FEM's converged rubber stretch less 1
#: (:mod:`softhand.fem.rubber_stretch`) of the table's own designs
STRETCH = "s_tilde"
#: a / rho of the optional last columns: the stretch less 1 averaged over a ball of radius a / x
#: (rho the rubber's critical distance, a length of its own, so the measure is not the groups'
#: alone: a finger of a = 3 mm and its twin of a = 4 mm differ by ~5 %); a = 2 to 8 mm at 2 mm
A_RHO = (1.0, 1.5, 2.0, 3.0, 4.0)
SIZE_STRETCH = tuple(f"s_a_rho_{x:g}" for x in A_RHO)
#: the physics a table's residual is taken against (see :func:`~softhand.reduced.calibrated.finger_fem.prior_pressure`)
PRIORS = ("paper", "rings")
#: the radial basis functions a kernel fit may use (scipy.interpolate.RBFInterpolator's)
KERNELS = ("thin_plate_spline", "cubic", "linear")


#: the largest design id (a table holds at most a few thousand designs)
MAX_DESIGN_ID = 10**6
#: the highest design degree of an older table's '# fit:' line (its terms are counted too)
MAX_DESIGN_DEGREE = 6


@dataclass(frozen=True)
class Table:
    """A calibration table: FEM rows, the calibrated ranges and the fit's degrees."""

    source: str  #: file name, for messages
    rows: dict  #: column -> array
    ranges: dict  #: group -> (min, max)
    p_terms: tuple[str, ...]  #: the terms of y = ln(P / P_prior) (finger_fem_terms), or ()
    q_terms: tuple[str, ...]  #: the terms of ln kappa, or ()
    prior: str = "paper"  #: the physics the residual is taken against, one of PRIORS
    header: tuple[str, ...] = ()  #: the provenance comment lines
    kernel: str | None = None  #: a kernel fit's radial basis function (instead of the terms)
    features: tuple[str, ...] = ()  #: the features a kernel fit interpolates in


def table_error(path, allowed: str) -> InputError:
    """The InputError of a bad calibration table ``path``: its field, the file and what is wrong."""
    return InputError("finger_table", str(path), allowed)


#: column -> (lowest, highest) of a row: theta [rad] of a bend up to a full turn; the
#: pressure and oil per mu_sf and a^3 of any finger the FEM can solve
ROW_LIMITS = {"theta": (1e-6, 2 * math.pi), "p_tilde": (1e-9, 1e6), "q_tilde": (1e-9, 1e6),
              **{c: (1e-9, 100.0) for c in (STRETCH, *SIZE_STRETCH)}}


def read_table(path: str | Path = TABLE_FILE) -> Table:
    """Read a finger calibration CSV; InputError naming the file on any problem."""
    path = Path(path)
    comments, header, values = read_number_table(path, "finger_table", "a CSV written by softhand calibrate finger",
                                                 COLUMNS, optional=(STRETCH, *SIZE_STRETCH))
    rows = {c: values[:, i] for i, c in enumerate(header)}
    if np.any(rows["theta"] <= 0) or np.any(rows["p_tilde"] <= 0) or np.any(rows["q_tilde"] <= 0):
        raise table_error(path, "theta, p_tilde and q_tilde must be positive (the P = 0 state is implied)")
    for column, (lo, hi) in ROW_LIMITS.items():
        if column not in rows:
            continue
        bad = np.flatnonzero((rows[column] < lo) | (rows[column] > hi))
        if bad.size:
            raise table_error(path, f"has {column} = {rows[column][bad[0]]:g} in data row {bad[0] + 1}; a "
                             f"finger's FEM gives {lo:g} to {hi:g}")
    _check_designs(rows, path)
    ranges, spec, prior = _header(comments, path)
    for g in GROUPS:
        lo, hi = ranges[g]
        if np.any(rows[g] < lo * (1 - 1e-9)) or np.any(rows[g] > hi * (1 + 1e-9)):
            raise table_error(path, f"has {LABELS[g]} outside its '# range:' [{lo:g}, {hi:g}]")
    declared, ranges = ranges, _measured(ranges, rows)
    if "kernel" in spec:
        if spec["kernel"] not in KERNELS:
            raise table_error(path, f"has kernel={spec['kernel']}; allowed: {', '.join(KERNELS)}")
        try:
            features = check_terms(spec.get("features", "").split())
        except ValueError as error:
            raise table_error(path, f"has '# fit:' features: {error}") from None
        unknown = [f for f in features if f not in KERNEL_FEATURES]
        if unknown:
            raise table_error(path, f"has '# fit:' feature {unknown[0][:40]!r}; a kernel fit's features are "
                             f"among {', '.join(KERNEL_FEATURES)}")
        return Table(path.name, rows, ranges, (), (), prior=prior, header=comments,
                     kernel=spec["kernel"], features=features)
    terms = _terms(spec, declared, path)
    return Table(path.name, rows, ranges, *terms, prior=prior, header=tuple(comments))


def _measured(ranges: dict, rows) -> dict:
    """The declared ranges narrowed to the table's own designs: a table answers only where it
    was measured (one that declares a whole box over a few designs is held to those)."""
    return {g: (max(lo, float(rows[g].min())), min(hi, float(rows[g].max()))) for g, (lo, hi) in ranges.items()}


def _check_designs(rows: dict, path) -> None:
    """Each design (a whole-number id) one point of the groups, each of its angles once: a
    design's rows are one FEM curve."""
    ids = rows["design"]
    wrong = (ids < 0) | (ids > MAX_DESIGN_ID) | (ids != np.round(ids))
    if np.any(wrong):
        bad = int(np.flatnonzero(wrong)[0])
        raise table_error(path, f"has design = {ids[bad]:g} in data row {bad + 1}; design ids are whole numbers "
                         f"in 0..{MAX_DESIGN_ID}")
    for i in np.unique(ids):
        at = np.flatnonzero(ids == i)
        for g in GROUPS:
            if np.ptp(rows[g][at]) > 1e-9 * np.max(np.abs(rows[g][at])):
                raise table_error(path, f"has design {i:g} at more than one {LABELS[g]} ({rows[g][at].min():g} to "
                                 f"{rows[g][at].max():g}); a design's rows are one FEM curve of one design")
        theta, count = np.unique(rows["theta"][at], return_counts=True)
        if np.any(count > 1):
            raise table_error(path, f"has design {i:g} at theta = {theta[count > 1][0]:g} rad more than once; "
                             f"a design's rows are one FEM curve")


def _terms(spec: dict, ranges: dict, path) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(p_terms, q_terms) named by the '# fit:' line, or made from its degrees (older tables)."""
    if "p_terms" in spec or "q_terms" in spec:
        try:
            return tuple(check_terms(spec.get(k, "").split()) for k in ("p_terms", "q_terms"))
        except ValueError as error:
            raise table_error(path, f"has a '# fit:' {error}") from None
    try:
        degrees = (int(spec["design_degree"]), int(spec["theta_degree"]))
    except (KeyError, ValueError):
        raise table_error(path, "needs the lines '# range: b_a=lo:hi, d_a=..., link_a=..., tie_link=...' "
                         "and '# fit: p_terms=..., q_terms=...' (or design_degree=D, "
                         "theta_degree=T)") from None
    if min(degrees) < 0 or degrees[0] > MAX_DESIGN_DEGREE or degrees[1] > MAX_FACTORS:
        raise table_error(path, f"has '# fit:' design_degree={degrees[0]}, theta_degree={degrees[1]}; "
                         f"allowed 0..{MAX_DESIGN_DEGREE} and 0..{MAX_FACTORS}")
    varying = {g: ranges[g][1] > ranges[g][0] * (1 + 1e-9) for g in GROUPS}
    terms = tuple(legacy_terms(kind, varying, *degrees) for kind in ("p", "q"))
    try:
        return tuple(check_terms(t) for t in terms)
    except ValueError as error:
        raise table_error(path, f"has '# fit:' degrees giving {error}") from None


def _header(comments: list[str], path) -> tuple[dict, dict, str]:
    """The '# range: g=lo:hi, ...' line's ranges, the '# fit: key=value, ...' line, its prior."""
    spec = {}
    for line in comments:
        body = line.lstrip("#").strip()
        for tag in ("range:", "fit:"):
            if body.startswith(tag):
                for item in body[len(tag):].split(","):
                    key, _, value = item.strip().partition("=")
                    spec[key.strip()] = value.strip()
    try:
        ranges = {g: tuple(plain_float(v) for v in spec[g].split(":")) for g in GROUPS}
    except (KeyError, ValueError):
        raise table_error(path, "needs the lines '# range: b_a=lo:hi, d_a=..., link_a=..., tie_link=...' "
                         "and '# fit: p_terms=..., q_terms=...' (or design_degree=D, "
                         "theta_degree=T)") from None
    if any(len(r) != 2 or not 0 < r[0] <= r[1] < math.inf for r in ranges.values()):
        raise table_error(path, "has a range lo:hi with not 0 < lo <= hi < inf")
    prior = spec.get("prior", "paper")
    if prior not in PRIORS:
        raise table_error(path, f"has prior={prior}; allowed: {', '.join(PRIORS)}")
    if ranges["tie_link"][1] >= 1.0:
        raise table_error(path, "has tie/link >= 1: a ring cannot be wider than its link")
    return ranges, spec, prior
