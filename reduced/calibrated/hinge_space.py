r"""The blocked-hinge table carried to any design of the calibrated space.

The fine table (:mod:`~softhand.reduced.calibrated.hinge_table`, free nodes at 13 pressures,
0.1 MPa steps) is the paper's design's: 15 min of finger FEM. Another design's rates differ
from it by ratios that are smooth in the bend and the pressure (design B, a 5, b 4, d 16,
l0 160, ties 8, against the paper's: 0.96 bent, 0.885 straight, 0.665 bent backwards at low
pressure; its moment bent backwards at zero pressure 0.54), so they are measured on a coarse
grid of locked states over the design space and interpolated over it:

* **The grid** (``data/grasp_hinge_space.csv``, written by ``python -m
  softhand.studies.calibration.hinges --space``): for every design of the space, a hinge
  table of its own on the same few nodes (reverse bends theta < 0 locked from P = 0; free
  states at pressures P0, each at the design's own free bend) and pressure steps. One of its
  designs is the paper's.
* **The ratios** r = a_j / a_j(paper) on every node, step and hinge, and r_m = m0_j /
  m0_j(paper) on the reverse nodes, interpolated over the design space in their logarithms by
  SciPy's RBFInterpolator (cubic kernel, a linear polynomial) in the finger table's kernel
  features (:data:`~softhand.reduced.calibrated.finger_fem_terms.KERNEL_FEATURES`, scaled to
  [0, 1] over the grid's designs): exact at every design of the grid, so 1 at the paper's.
* **The design's table**: the fine table's nodes and pressures, its free nodes moved to the
  design's own free bends at their pressures P0 (the calibrated finger's), its rates times r
  and its reverse moments times r_m, both linear between the grid's nodes (in P0 for free
  nodes, in theta for reverse ones) and its pressures, constant beyond them.

The grid is of the paper's rubber; another rubber's moments bent backwards are scaled by the
free curves' pressures at a small bend (:func:`reverse_scale`). A design may instead name a
table of its own (``hinge_table``; :func:`design_table`).
"""
from __future__ import annotations

import math
from dataclasses import replace
from functools import lru_cache
from pathlib import Path
from typing import NamedTuple

import numpy as np

from softhand.reduced.calibrated import hinge_table
from softhand.reduced.calibrated.finger_fem import GROUPS, groups_of
from softhand.reduced.calibrated.finger_fem_terms import BASE, KERNEL_FEATURES
from softhand.reduced.equations import hand
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.vocabulary.inputfiles import read_number_table

#: the paper's design's table, written by the hinges study
TABLE_FILE = Path(__file__).resolve().parent / "data" / "grasp_hinges.csv"
#: the grid over the design space, written by the hinges study with its space option
SPACE_FILE = Path(__file__).resolve().parent / "data" / "grasp_hinge_space.csv"
#: the columns before the rates a_1..a_n
COLUMNS = ("design", *GROUPS, "P0", "theta", "P")


class Space(NamedTuple):
    """The grid's ratios to the paper's design, one row per design."""

    x: np.ndarray        #: (D, F) the designs' kernel features, scaled to [0, 1]
    lo: np.ndarray       #: (F,) the features' lowest values
    span: np.ndarray     #: (F,) and their spans
    log_r: np.ndarray    #: (D, nodes, K, n) ln(a_j / a_j(paper))
    log_rm: np.ndarray   #: (D, reverse nodes, n) ln(m0_j / m0_j(paper))
    node: np.ndarray     #: (nodes,) a reverse node's bend [rad] (< 0), a free node's P0 [MPa]
    reverse: np.ndarray  #: (nodes,) True for a reverse node (they come first)
    p: np.ndarray        #: (K,) the grid's pressures [MPa]


def features(design: HandDesign) -> np.ndarray:
    """The design's kernel features, those of the finger table's fit
    (:data:`~softhand.reduced.calibrated.finger_fem_terms.KERNEL_FEATURES`)."""
    return _features(groups_of(design))


def _features(groups: dict) -> np.ndarray:
    return np.array([float(BASE[f](groups, 0.0)) for f in KERNEL_FEATURES])


@lru_cache(maxsize=2)
def read(path: str = str(SPACE_FILE)) -> Space:
    """The grid CSV: the columns :data:`COLUMNS`, then the rates a_1 to a_n.

    Each design's rows are one hinge table, all on the same nodes and pressures; one design is
    the paper's."""
    _, columns, data = read_number_table(path, "hinge_space", "the grid CSV of softhand.studies.calibration.hinges")
    n = len(columns) - len(COLUMNS)
    if n < 1 or columns != (*COLUMNS, *(f"a_{j}" for j in range(1, n + 1))):
        raise InputError("hinge_space", path, f"needs the header {','.join(COLUMNS)},a_1,...,a_n")
    paper = features(HandDesign())
    tables, nodes, X = [], [], []
    for i in np.unique(data[:, 0]):
        rows = data[data[:, 0] == i]
        t = hinge_table.from_rows(rows[:, len(COLUMNS) - 2:], path)
        tables.append(t)
        free = rows[:, len(COLUMNS) - 2] >= 0
        nodes.append(np.r_[t.theta[t.theta < 0], np.unique(rows[free, len(COLUMNS) - 3])])
        X.append(_features(dict(zip(GROUPS, rows[0, 1:5]))))
    X = np.array(X)
    ref = np.flatnonzero(np.all(np.abs(X - paper) < 1e-6, axis=1))
    same = all(len(k) == len(nodes[0]) and np.allclose(k, nodes[0]) and t.a.shape == tables[0].a.shape
               and np.allclose(t.p, tables[0].p) for k, t in zip(nodes, tables))
    if not same or len(ref) != 1 or len(tables) < len(KERNEL_FEATURES) + 2:
        raise InputError("hinge_space", path, f"needs {len(KERNEL_FEATURES) + 2} designs or more, one the paper's, "
                                              "all on the same nodes and pressures")
    a = np.array([t.a for t in tables])
    reverse = nodes[0] < 0
    m0 = np.array([t.m0[reverse] for t in tables])
    if np.any(a <= 0) or np.any(m0 >= 0):
        raise InputError("hinge_space", path, "needs positive rates and negative moments bent backwards")
    lo, span = X.min(axis=0), np.ptp(X, axis=0)
    return Space((X - lo) / np.where(span > 0, span, 1.0), lo, np.where(span > 0, span, 1.0),
                 np.log(a / a[ref]), np.log(m0 / m0[ref]), nodes[0], reverse, tables[0].p)


def ratios(space: Space, design: HandDesign, leave_out: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The design's ratios to the paper's, interpolated over the grid's designs.

    Returns (r (nodes, K, n), r_m (reverse nodes, n)); ``leave_out``: a design of the grid the
    interpolant leaves out (a leave-one-out check)."""
    return _ratios_at(space, features(design), leave_out)


def _ratios_at(space: Space, x, leave_out: int | None):
    from scipy.interpolate import RBFInterpolator

    keep = np.arange(len(space.x)) != (-1 if leave_out is None else leave_out)
    y = np.concatenate([space.log_r.reshape(len(space.x), -1), space.log_rm.reshape(len(space.x), -1)], axis=1)
    rbf = RBFInterpolator(space.x[keep], y[keep], kernel="cubic", degree=1)
    out = np.exp(rbf(((x - space.lo) / space.span)[None, :])[0])
    k = space.log_r[0].size
    return out[:k].reshape(space.log_r.shape[1:]), out[k:].reshape(space.log_rm.shape[1:])


def leave_one_out(space: Space) -> np.ndarray:
    """Each design of the grid predicted without it: (D, 4) relative errors of its ratios.

    Per design the rms and the largest error of the rates, then of the moments bent backwards
    (the paper's row too: its ratios are 1 by definition, predicted all the same)."""
    out = []
    for k in range(len(space.x)):
        x = space.lo + space.span * space.x[k]
        r, rm = _ratios_at(space, x, k)
        er, em = r / np.exp(space.log_r[k]) - 1, rm / np.exp(space.log_rm[k]) - 1
        out.append([np.sqrt(np.mean(er ** 2)), np.max(np.abs(er)), np.sqrt(np.mean(em ** 2)), np.max(np.abs(em))])
    return np.array(out)


def _lerp(x, xp):
    """(i, i + 1, w) of linear interpolation at x between the increasing xp, constant beyond."""
    if len(xp) == 1:
        zero = np.zeros(np.shape(x), int)
        return zero, zero, np.zeros(np.shape(x))
    i = np.clip(np.searchsorted(xp, x) - 1, 0, len(xp) - 2)
    return i, i + 1, np.clip((x - xp[i]) / (xp[i + 1] - xp[i]), 0.0, 1.0)


def carried(fine: hinge_table.HingeTable, design: HandDesign, space: Space, leave_out: int | None = None):
    """The design's hinge table: the paper's design's carried by the grid's ratios.

    ``fine`` is the paper's design's table; ``design`` has the calibrated finger
    (``finger_model = "fem"``); see the module doc."""
    return carry(fine, design, space, *ratios(space, design, leave_out))


def carry(fine: hinge_table.HingeTable, design: HandDesign, space: Space, r, rm):
    """A fine table carried to a design by ratios given on the grid (:func:`carried`).

    r (grid nodes, K, n) and r_m (reverse grid nodes, n) on the grid of ``space``."""
    paper = HandDesign(finger_model="fem")
    forward = fine.theta >= 0
    P0 = np.zeros(len(fine.theta))
    P0[fine.theta > 0] = hand.finger_pressure(fine.theta[fine.theta > 0], paper)
    keep = ~forward | (P0 <= hand.pressure_span(design, reservoir=False)[1])
    theta = fine.theta.copy()
    theta[forward & keep] = hand.bend_angle(P0[forward & keep], design, reservoir=False)
    theta[forward & (P0 == 0)] = 0.0
    # the grid's ratios at the fine nodes: in theta between reverse nodes, in P0 between free ones
    rev, free = np.flatnonzero(space.reverse), np.flatnonzero(~space.reverse)
    i0, i1, w = _lerp(fine.theta, space.node[rev])
    j0, j1, v = _lerp(P0, space.node[free])
    a0 = np.where(forward, free[j0], rev[i0])
    a1 = np.where(forward, free[j1], rev[i1])
    s = np.where(forward, v, w)[:, None, None]
    r_nodes = (1 - s) * r[a0] + s * r[a1]                       # (fine nodes, K grid, n)
    k0, k1, u = _lerp(fine.p, space.p)
    r_fine = (1 - u)[None, :, None] * r_nodes[:, k0] + u[None, :, None] * r_nodes[:, k1]
    m_fine = np.where(forward[:, None], 1.0, (1 - w)[:, None] * rm[i0] + w[:, None] * rm[i1])
    return hinge_table.with_rates(theta[keep], fine.p, (fine.a * r_fine)[keep], (fine.m0 * m_fine)[keep])


#: the small bend [rad] at which the free curves' pressures carry the reverse moments to another rubber
REVERSE_SECANT = math.radians(2.0)


def paper_rubber(design: HandDesign) -> HandDesign:
    """The design's geometry in the paper's rubber, on the carried table (no ``hinge_table`` of its own)."""
    return replace(design, mu_sf=HandDesign().mu_sf, finger_material=None, hinge_table="")


@lru_cache(maxsize=16)
def reverse_scale(design: HandDesign) -> float:
    """The factor carrying the table's moments at zero pressure of a hinge bent backwards (those of
    the design's geometry with the paper's rubber) to the design's rubber: the ratio of the two
    free curves' pressures at a small bend, P_free(2 deg), 1 for the paper's rubber."""
    twin = paper_rubber(design)
    if design.hinge_table or replace(design, hinge_table="") == twin:
        return 1.0
    return float(hand.finger_pressure(REVERSE_SECANT, design) / hand.finger_pressure(REVERSE_SECANT, twin))


def design_table(design: HandDesign) -> hinge_table.HingeTable:
    """The blocked-hinge table a design's fast hold uses.

    Its own ``hinge_table``, else the paper's design's carried to its geometry (:func:`carried`);
    the design has the calibrated finger. InputError if the table does not fit the design."""
    own = bool(design.hinge_table)
    t = hinge_table.read(design.hinge_table if own else str(TABLE_FILE))
    if t.a.shape[-1] != design.n_s:
        raise InputError("hinge_table" if own else "n_s", design.hinge_table if own else design.n_s,
                         f"{'has' if own else 'the hinge table has'} {t.a.shape[-1]} hinges; the design has {design.n_s}")
    return t if own or _papers_geometry(design) else _carried(design)  # the paper's geometry: the table itself


@lru_cache(maxsize=16)
def _papers_geometry(design: HandDesign) -> bool:
    paper = HandDesign()
    return all(getattr(design, k) == getattr(paper, k) for k in ("a", "b", "d", "l0", "tie_width", "hinge_s"))


@lru_cache(maxsize=16)
def _carried(design: HandDesign) -> hinge_table.HingeTable:
    """The paper's design's table, carried to the design's geometry by the grid over the design
    space (:mod:`softhand.reduced.calibrated.hinge_space`)."""
    return carried(hinge_table.read(str(TABLE_FILE)), design, read())
