"""Which terms the finger model ``"fem"`` fits: forward selection by leave-one-design-out error.

The table's residuals (y = ln(P_FEM / P_prior) and ln kappa, :func:`reduced.finger_fem.fit_targets`)
are fitted linearly in a constant and terms of :mod:`reduced.finger_fem_terms`. Which terms is
not wholly fixed beforehand: starting from given terms (the calibration starts from the
physics' linear terms, a test from theta alone), each step adds the candidate (a varying base
feature, a product of two, or a base feature times theta) that most lowers the rms error of
predicting every design from the table without it (all of that design's rows left out, the fit
redone), and stops when no candidate lowers it by ``min_gain`` (relative), when it is zero to
rounding, or when another term would leave fewer than ``designs_per_term`` designs per
coefficient. Leaving out a whole design, not
a row, is what the model is used for: a design the table has not seen.
"""
from __future__ import annotations

from itertools import combinations_with_replacement

import numpy as np

from softhand.reduced.finger_fem import lstsq_terms
from softhand.reduced.finger_fem_table import GROUPS
from softhand.reduced.finger_fem_terms import DESIGN_BASE, term_matrix

__all__ = ["candidates", "loo_rms", "select_terms"]


def candidates(rows: dict) -> list[str]:
    """The terms a selection may add: the base features that vary over the rows' designs,
    their products of two (squares included), theta^2 and each of them times theta."""
    varying = []
    for f in DESIGN_BASE:
        v = term_matrix(rows, rows["theta"], (f,))[:, 1]
        if np.ptp(v) > 1e-9 * max(np.abs(v).max(), 1.0):
            varying.append(f)
    pairs = ["*".join(c) for c in combinations_with_replacement(varying, 2)]
    return varying + pairs + ["th*th"] + [f"{f}*th" for f in varying]


def loo_rms(rows: dict, target: np.ndarray, terms) -> float:
    """rms over all rows of the error predicting each design's rows from the others' (inf if
    a fold cannot determine the terms)."""
    ids = rows["design"]
    errors = np.empty_like(target)
    for i in np.unique(ids):
        out = ids == i
        rest = {k: np.asarray(v)[~out] for k, v in rows.items()}
        beta = lstsq_terms(rest, rest["theta"], target[~out], terms)
        if beta is None:
            return np.inf
        held = {k: np.asarray(v)[out] for k, v in rows.items()}
        errors[out] = term_matrix(held, held["theta"], terms) @ beta - target[out]
    return float(np.sqrt(np.mean(errors**2)))


def select_terms(rows: dict, target: np.ndarray, min_gain: float = 0.02, designs_per_term: int = 2,
                 start=("th",)) -> tuple[tuple[str, ...], float, list[tuple[str, float]]]:
    """(terms, their leave-one-design-out rms, the path [(term added, rms after)]) for ``target``
    over the table ``rows`` (GROUPS, theta and design columns), adding to the terms ``start``."""
    n_designs = np.unique(rows["design"]).size
    terms = list(start)
    best = loo_rms(rows, target, terms)
    path = [(" ".join(terms), best)]
    pool = [c for c in candidates(rows) if c not in terms]
    while pool and best > 1e-12 and (len(terms) + 2) * designs_per_term <= n_designs:
        scores = [loo_rms(rows, target, terms + [c]) for c in pool]
        k = int(np.argmin(scores))
        if not scores[k] < best * (1 - min_gain):
            break
        terms.append(pool.pop(k))
        best = scores[k]
        path.append((terms[-1], best))
    return tuple(terms), best, path


def group_rows(rows: dict) -> dict:
    """The columns select_terms needs, as arrays (rows given as a list of dicts or as columns)."""
    if isinstance(rows, dict):
        return {k: np.asarray(rows[k], float) for k in ("design", *GROUPS, "theta")}
    return {k: np.array([r[k] for r in rows], float) for k in ("design", *GROUPS, "theta")}
