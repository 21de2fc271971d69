r"""The finger FEM's blocked-hinge table: the oil each hinge draws per radian at fixed pressure,
A_j(theta, P) = dV/d theta_hat_j, and the moment that holds a hinge off its free bend,

.. math:: M_j(\theta, P) = -\int_{P_{free}(\theta)}^{P} A_j(\theta, p)\,dp ,

zero on the free curve P_free(theta) of the calibrated finger and falling (the hinge pushes
closed harder) as the pressure rises above it at a fixed bend: dM_j/dP = -A_j, a Maxwell
relation of the finger's potential E(q, P) (dE/dP = -V).

A hinge bent *backwards* (theta < 0, as a heavy object's pad pushes the base hinges past
straight) has no free state at P >= 0: there the moment is anchored at zero pressure by the one
the FEM needs to hold the unpressurised finger at that bend,

.. math:: M_j(\theta < 0, P) = M_j^0(\theta) - \int_0^P A_j(\theta, p)\,dp ,

with M_j^0 measured with the hinges locked there (the tube bent backwards is about three times
softer than the free curve continued below zero says: 655 against 1 895 N mm at -12 deg).
M_j^0 is linear in theta between the reverse nodes and 0 at theta = 0, where both laws agree.

The table (``data/grasp_hinges.csv``, written by ``python -m softhand.studies.calibration.hinges``)
holds a_j = A_j / (a^2 pi d) at the free bends theta_i of a few pressures P0_i, measured with
the hinges locked there while the pressure rises, at the middle P of each step (and at a few
reverse bends theta_i < 0, locked from P = 0; their row at P = 0 holds m0_j = M_j^0 / (a^2 pi d)
[MPa] instead of a rate): so A_j grows
with P at a fixed bend as the locked tube swells (1.20 to 1.35 a^2 pi d at a 7.4 deg hinge bend
from 0.35 to 0.95 MPa). Between the steps A_j is linear in P; below a node's first step (P < P0_i,
the hinge bent beyond its free bend) and above its last it keeps its end value; between the
nodes it is linear in theta, extended linearly beyond them. M_j is the exact integral of that
function (piecewise quadratic in P). Units: rad, MPa, mm^3/rad, N mm/rad.
"""
from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np

from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.vocabulary.inputfiles import read_number_table


class HingeTable(NamedTuple):
    """a_j(theta_i, p_k) on a grid: nodes theta_i (increasing), pressures p_k (equally spaced)."""

    theta: np.ndarray   #: (nodes,) hinge bend n_s theta_hat of each node [rad], increasing
    p: np.ndarray       #: (K,) pressures [MPa], equally spaced
    a: np.ndarray       #: (nodes, K, n_s) A_j / (a^2 pi d)
    cum: np.ndarray     #: (nodes, K, n_s) int_{p_0}^{p_k} a_j dp
    m0: np.ndarray      #: (nodes, n_s) M_j^0 / (a^2 pi d) [MPa] of a reverse node (theta < 0), else 0


@lru_cache(maxsize=4)
def read(path: str) -> HingeTable:
    """The CSV (columns theta, P, a_1..a_n; rows of one node together, P rising; a reverse node's
    first row at P = 0 holds its m0_j)."""
    what = "the hinge CSV of softhand.studies.calibration.hinges"
    _, columns, data = read_number_table(path, "hinge_table", what)
    n = len(columns) - 2
    if n < 1 or columns != ("theta", "P", *(f"a_{j}" for j in range(1, n + 1))):
        raise InputError("hinge_table", path, "needs the header theta,P,a_1,...,a_n")
    return from_rows(data, path)


def from_rows(data: np.ndarray, path="") -> HingeTable:
    """The table of rows (theta, P, a_1..a_n) as :func:`read` parses them (``path`` names them in errors)."""
    n = data.shape[1] - 2
    anchor = data[:, 1] == 0.0
    if np.any(data[anchor, 0] >= 0) or not np.array_equal(np.unique(data[anchor, 0]), np.sort(data[anchor, 0])) \
            or not np.array_equal(np.unique(data[anchor, 0]), np.unique(data[data[:, 0] < 0, 0])):
        raise InputError("hinge_table", path, "needs one row at P = 0 (its moment) for each bend below 0, "
                                              "and none for the others")
    anchors, data = data[anchor], data[~anchor]
    theta = np.unique(data[:, 0])
    p = np.unique(np.round(data[:, 1], 9))
    step = np.diff(p)
    if len(theta) < 2 or len(p) < 2 or np.ptp(step) > 1e-6 * step[0]:
        raise InputError("hinge_table", path, "needs two bends or more and equally spaced pressures")
    a = np.full((len(theta), len(p), n), np.nan)
    a[np.searchsorted(theta, data[:, 0]), np.searchsorted(p, np.round(data[:, 1], 9))] = data[:, 2:]
    for i in range(len(theta)):   # below a node's first step its first value, above its last its last
        rows = np.flatnonzero(np.isfinite(a[i, :, 0]))
        if not len(rows) or np.any(np.diff(rows) != 1):
            raise InputError("hinge_table", path, f"needs the pressures of bend {theta[i]:.6g} in one run")
        a[i, :rows[0]], a[i, rows[-1] + 1:] = a[i, rows[0]], a[i, rows[-1]]
    at = np.searchsorted(theta, anchors[:, 0])
    if np.any(theta[np.minimum(at, len(theta) - 1)] != anchors[:, 0]):
        raise InputError("hinge_table", path, "needs rates for every bend whose moment at P = 0 it gives")
    m0 = np.zeros((len(theta), n))
    m0[at] = anchors[:, 2:]
    return with_rates(theta, p, a, m0)


def with_rates(theta, p, a, m0) -> HingeTable:
    """The table of nodes theta (increasing), equally spaced pressures p, rates a (nodes, K, n_s)
    and reverse moments m0 (nodes, n_s): the rates' integrals in p added."""
    cum = np.concatenate([np.zeros((len(theta), 1, a.shape[-1])),
                          np.cumsum(0.5 * (a[:, 1:] + a[:, :-1]) * (p[1] - p[0]), axis=1)], axis=1)
    return HingeTable(theta, p, a, cum, m0)


def _node_values(t: HingeTable, i, P):
    """(A, integral from p_0) of node i's a_j(p) at pressures P, both shaped like i (..., n_s)."""
    h, K = t.p[1] - t.p[0], len(t.p)
    j = np.broadcast_to(np.arange(i.shape[-1]), i.shape)
    x = (P - t.p[0]) / h
    k = np.minimum(np.maximum(np.floor(x).astype(int), 0), K - 2)
    s = np.minimum(np.maximum(x - k, 0.0), 1.0) * h          # within cell k
    a0, a1 = t.a[i, k, j], t.a[i, k + 1, j]
    A = a0 + (a1 - a0) * s / h
    F = t.cum[i, k, j] + a0 * s + 0.5 * (a1 - a0) * s * s / h
    below, above = x < 0, x > K - 1                          # constant ends
    A = np.where(below, t.a[i, 0, j], np.where(above, t.a[i, -1, j], A))
    F = F + np.where(below, x * h * t.a[i, 0, j], 0.0) + np.where(above, (x - K + 1) * h * t.a[i, -1, j], 0.0)
    return A, F


def _cell(t: HingeTable, theta):
    """(node i, weight w) of bends theta: linear between nodes i and i + 1, extended beyond the ends."""
    i = np.minimum(np.maximum(np.searchsorted(t.theta, theta) - 1, 0), len(t.theta) - 2)
    return i, (theta - t.theta[i]) / (t.theta[i + 1] - t.theta[i])


def _interpolate(t: HingeTable, theta, P):
    """(a_j, int_{p_0}^{P} a_j dp) at hinge bends theta (..., n_s) and pressures P (broadcast
    together); both nodes of every bend are read from the table in one gather."""
    theta, P = np.broadcast_arrays(np.asarray(theta, float), np.asarray(P, float))
    i, w = _cell(t, theta)
    A, F = _node_values(t, np.stack([i, i + 1]), np.stack([P, P]))
    return A[0] + w * (A[1] - A[0]), F[0] + w * (F[1] - F[0])


def _reverse_moment(t: HingeTable, theta) -> np.ndarray:
    """m0_j(theta) (..., n_s): linear between the reverse nodes and 0 at theta = 0, extended
    linearly below the last; 0 at theta >= 0."""
    i, w = _cell(t, theta)
    j = np.broadcast_to(np.arange(theta.shape[-1]), theta.shape)
    m = t.m0[i, j] + w * (t.m0[i + 1, j] - t.m0[i, j])
    return np.where(theta < 0, m, 0.0)


def volume_rate(t: HingeTable, theta, P) -> np.ndarray:
    """a_j = A_j / (a^2 pi d) at hinge bends theta (..., n_s) [rad] and cavity pressure P [MPa]."""
    return _interpolate(t, theta, P)[0]


def moment(t: HingeTable, theta, P, P_free, reverse_scale: float = 1.0) -> np.ndarray:
    """M_j / (a^2 pi d) = -int_{P_free}^{P} a_j(theta, p) dp (module doc) at bends theta (..., n_s),
    cavity pressure P and the free curve's pressure P_free at those bends; at theta < 0
    reverse_scale m0_j(theta) - int_0^P a_j dp (P_free unused; ``reverse_scale`` carries m0 to
    another design)."""
    theta = np.asarray(theta, float)
    reverse = (theta < 0) & (t.theta[0] < 0)   # a table without reverse nodes: the free curve continued
    anchor = np.where(reverse, 0.0, np.asarray(P_free, float))
    F = _interpolate(t, theta, np.stack(np.broadcast_arrays(np.asarray(P, float), anchor, theta)[:2]))[1]
    return -(F[0] - F[1]) + reverse_scale * _reverse_moment(t, theta)
