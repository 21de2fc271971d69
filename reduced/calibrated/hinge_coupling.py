r"""The finger FEM's free hinges over the design space: how a free finger shares its bend among its
hinges, and its condensed stiffness there, the coupling of the hinges through the tube.

The blocked-hinge table (:mod:`~softhand.reduced.calibrated.hinge_table`) gives each hinge's
moment as a function of its own bend, measured with every hinge locked at one bend: the hinges'
energies add up, E = sum_j E_j(theta_j; P). The finger FEM's hinges are not independent: the tube
runs on under the ties. Its free finger bends the base hinge more than the others (the paper's
design: 5.7 % above the mean at 0.9 and at 1.5 MPa, the tip's 1.7 % below), and the Hessian of
its energy in the hinge angles there, the condensed stiffness S, is 9 % below the table's
per-hinge stiffness and couples neighbouring hinges by 5 % of it. :mod:`~softhand.reduced.calibrated.finger_hinges`
corrects the table's moments to second order about that free state.

The data (``data/grasp_hinge_coupling.csv``, written by ``python -m
softhand.studies.calibration.hinge_coupling``): for the designs of the hinge grid's design space and
the paper's, at cavity pressures 0.1-2.4 MPa, the free hinges' shares of the bend s_j = q_j /
mean(q) and sigma = S / (a^2 pi d) [MPa]. A design's are interpolated over the grid's designs as
:mod:`~softhand.reduced.calibrated.hinge_space` interpolates its ratios (SciPy's RBFInterpolator,
cubic kernel, a linear polynomial, in the finger table's kernel features; exact at every design of
the grid), linearly in P between the table's pressures and constant beyond them. Its free hinge
angles are q_j = theta_free(P) s_j / n_s with theta_free the calibrated finger's bend (so the free
finger bends as the calibrated finger does, shared as the FEM shares it). The grid is of the
paper's rubber, and so is S here: :func:`softhand.reduced.calibrated.finger_hinges.condensed_stiffness`
carries it to another rubber by the blocked-hinge table's stiffness (S over the table's diagonal
stiffness is the tube's geometry, not its rubber's: measured on a fitted Yeoh rubber).
"""
from __future__ import annotations

import math
from functools import lru_cache
from pathlib import Path
from typing import NamedTuple

import numpy as np

from softhand.reduced.calibrated import hinge_space
from softhand.reduced.calibrated.finger_fem import GROUPS
from softhand.reduced.calibrated.finger_fem_terms import KERNEL_FEATURES
from softhand.reduced.equations import hand
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.vocabulary.inputfiles import read_number_table

#: the free hinges over the design space, written by the hinge coupling study
COUPLING_FILE = Path(__file__).resolve().parent / "data" / "grasp_hinge_coupling.csv"


class Grid(NamedTuple):
    """The free hinges of the grid's designs, on common pressures."""

    x: np.ndarray       #: (D, F) the designs' kernel features, scaled to [0, 1]
    lo: np.ndarray      #: (F,) the features' lowest values
    span: np.ndarray    #: (F,) and their spans
    p: np.ndarray       #: (K,) pressures [MPa], increasing
    s: np.ndarray       #: (D, K, n) the hinges' shares of the bend
    sigma: np.ndarray   #: (D, K, n, n) S / (a^2 pi d) [MPa]


@lru_cache(maxsize=2)
def read(path: str = str(COUPLING_FILE)) -> Grid:
    """The CSV: design, the finger table's groups, P, s_1..s_n, sigma_jk (j <= k); a design's rows
    with P rising (one that stopped below the others' highest pressure keeps its last values)."""
    _, columns, data = read_number_table(path, "hinge_coupling", "the CSV of softhand.studies.calibration.hinge_coupling")
    head = ("design", *GROUPS, "P")
    n = next((k for k in range(1, 20) if len(columns) == len(head) + k + k * (k + 1) // 2), 0)
    j, k = np.triu_indices(max(n, 1))
    if not n or columns != (*head, *(f"s_{i}" for i in range(1, n + 1)),
                            *(f"sigma_{a + 1}{b + 1}" for a, b in zip(j, k))):
        raise InputError("hinge_coupling", path, "needs the header design,<groups>,P,s_1..s_n,sigma_jk (j <= k)")
    p = np.unique(np.round(data[:, len(head) - 1], 9))
    X, S, SIG = [], [], []
    for i in np.unique(data[:, 0]):
        rows = data[data[:, 0] == i]
        at = np.searchsorted(p, np.round(rows[:, len(head) - 1], 9))
        if np.any(np.diff(at) != 1) or at[0] != 0:
            raise InputError("hinge_coupling", path, f"design {i:g}: needs the pressures from {p[0]:g} MPa in order")
        fill = np.minimum(np.arange(len(p)), len(rows) - 1)      # constant beyond its last pressure
        sig = np.zeros((len(rows), n, n))
        sig[:, j, k] = rows[:, len(head) + n:]
        sig[:, k, j] = rows[:, len(head) + n:]
        X.append(hinge_space._features(dict(zip(GROUPS, rows[0, 1:1 + len(GROUPS)]))))
        S.append(rows[fill, len(head):len(head) + n])
        SIG.append(sig[fill])
    X = np.array(X)
    if len(X) < len(KERNEL_FEATURES) + 2 or not np.all(np.isfinite(data)) or np.any(np.array(S) <= 0):
        raise InputError("hinge_coupling", path, f"needs {len(KERNEL_FEATURES) + 2} designs or more, finite values "
                                                  "and positive shares")
    lo, span = X.min(axis=0), np.ptp(X, axis=0)
    span = np.where(span > 0, span, 1.0)
    return Grid((X - lo) / span, lo, span, p, np.array(S), np.array(SIG))


def _at(grid: Grid, x, leave_out: int | None = None):
    """(s (K, n), sigma (K, n, n)) interpolated at the scaled features x, one grid design left out."""
    from scipy.interpolate import RBFInterpolator

    keep = np.arange(len(grid.x)) != (-1 if leave_out is None else leave_out)
    D = len(grid.x)
    y = np.concatenate([grid.s.reshape(D, -1), grid.sigma.reshape(D, -1)], axis=1)
    out = RBFInterpolator(grid.x[keep], y[keep], kernel="cubic", degree=1)(x[None, :])[0]
    k = grid.s[0].size
    return out[:k].reshape(grid.s.shape[1:]), out[k:].reshape(grid.sigma.shape[1:])


@lru_cache(maxsize=16)
def design_data(design: HandDesign) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(pressures (K,), shares s (K, n), S (K, n, n) [N mm/rad]) of the design's free hinges (S of its
    geometry in the paper's rubber: module doc)."""
    grid = read()
    n = grid.s.shape[-1]
    if n != design.n_s:
        raise InputError("n_s", design.n_s, f"the hinge coupling table has {n} hinges")
    s, sigma = _at(grid, (hinge_space.features(design) - grid.lo) / grid.span)
    return grid.p, s, sigma * design.a ** 2 * math.pi * design.d


def free_state(design: HandDesign, P: float) -> tuple[np.ndarray, np.ndarray]:
    """(free hinge angles q_f (n,) [rad], condensed stiffness S (n, n) [N mm/rad], of its geometry in the
    paper's rubber) of the design's calibrated finger at cavity pressure P [MPa] (module doc)."""
    p, s, S = design_data(design)
    i0, i1, w = hinge_space._lerp(float(P), p)
    theta = float(hand.bend_angle(float(P), design, reservoir=False))
    shares = (1 - w) * s[i0] + w * s[i1]
    return theta / design.n_s * shares / shares.mean(), (1 - w) * S[i0] + w * S[i1]


def leave_one_out(grid: Grid) -> np.ndarray:
    """Each design of the grid predicted without it: (D, 2) the largest relative error of its shares
    and of its stiffness's diagonal, over the pressures."""
    out = []
    for k in range(len(grid.x)):
        s, sigma = _at(grid, grid.x[k], k)
        diag = np.diagonal(sigma, axis1=1, axis2=2) / np.diagonal(grid.sigma[k], axis1=1, axis2=2) - 1
        out.append([np.max(np.abs(s / grid.s[k] - 1)), np.max(np.abs(diag))])
    return np.array(out)
