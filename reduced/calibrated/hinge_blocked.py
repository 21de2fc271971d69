r"""The coupled hinges held far below their free bends: the finger FEM's correction beyond second order.

The coupled moments of :mod:`softhand.reduced.calibrated.finger_hinges` are the blocked-hinge table's
corrected to second order about the finger FEM's free state q_f: exact in M and dM/dq there. A grasp
holds hinges far from it (the base hinge of a finger pressing the paper's 180 mm sphere at 0.9 MPa
sits at a fifth of its free bend). There the finger FEM held by grasp-like hinge loads
(:mod:`softhand.studies.calibration.hinge_blocked`) needs other moments than the table, locked at
one bend for every hinge, says: less where a held hinge has a neighbour bent more than itself, and
at the base hinge, next to the fixed base. The miss is fitted, design by design and pressure by
pressure, as the gradient of an energy in r_j = q_j / q_fj,

.. math:: e(q) = P\,a^2\pi d\,\bar q_f \Big[c_p \sum_{j=1}^{n-1} (r_j - r_{j+1})^2 (2 - r_j - r_{j+1})^2
          + c_b\,(1 - r_1)^3 + c_o \sum_j (1 - r_j)^3\Big],

whose pair term is zero for hinges held alike (as the table was measured) and does not load a free
neighbour (its gradient in r_k vanishes at r_k = 1), and which leaves M and dM/dq at q_f as they
were (every gradient starts at second order there). :func:`moments`, :func:`stiffness` and
:func:`energy` add it to the coupled hinges, with the coefficients' mean over the designs of
``data/grasp_hinge_blocked.csv`` (each design left out, the mean of the others predicts its held
hinges better than interpolating over the design space does: its coefficients vary from design to
design more than the features explain), linear in P between the table's pressures, constant above
them and fading to zero at P = 0 below the first; the designs are of the paper's rubber and the
energy scales with P a^2 pi d.
r is taken through a smooth clamp to [-0.5, 1.5] (a tanh of width 0.25 beyond), so a hinge bent
back against a small free bend at a low pressure meets a bounded correction. Units: mm, N, MPa, rad.
"""
from __future__ import annotations

import math
from functools import lru_cache
from pathlib import Path
from typing import NamedTuple

import numpy as np

from softhand.reduced.calibrated import hinge_space
from softhand.reduced.calibrated.finger_fem import GROUPS
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.vocabulary.inputfiles import read_number_table

#: the fitted coefficients, written by the blocked hinges study
FIT_FILE = Path(__file__).resolve().parent / "data" / "grasp_hinge_blocked.csv"
#: the terms of the correction's energy, in the order of their coefficients
TERMS = ("c_pair", "c_base", "c_own")
#: r is clamped smoothly to [LOW, HIGH] ...
LOW, HIGH = -0.5, 1.5
#: ... by a tanh of this width beyond
WIDTH = 0.25
#: designs a table needs (the mean over them is the correction)
MIN_DESIGNS = 4
#: the least free hinge angle [rad] r is taken against
_Q_MIN = 1e-6


class Table(NamedTuple):
    """The designs' coefficients on common pressures."""

    p: np.ndarray       #: (K,) pressures [MPa], increasing
    c: np.ndarray       #: (D, K, len(TERMS)) each design's coefficients


@lru_cache(maxsize=2)
def read(path: str = str(FIT_FILE)) -> Table:
    """The CSV: design, the finger table's groups, P, the coefficients; every design on the same pressures."""
    head = ("design", *GROUPS, "P", *TERMS)
    _, _, data = read_number_table(path, "hinge_blocked", "the CSV of softhand.studies.calibration.hinge_blocked",
                                   head)
    return table(data, path)


def table(data: np.ndarray, path: str = "") -> Table:
    """The :class:`Table` of the CSV's rows (D * K, len(head)); InputError naming ``path`` where they do not fit."""
    P = len(GROUPS) + 1
    p = np.unique(np.round(data[:, P], 9))
    C = []
    for i in np.unique(data[:, 0]):
        rows = data[data[:, 0] == i]
        if not np.array_equal(np.round(rows[:, P], 9), p):
            raise InputError("hinge_blocked", path,
                             f"design {i:g}: needs the pressures {', '.join(map(str, p))} in order")
        C.append(rows[:, P + 1:])
    if len(C) < MIN_DESIGNS:
        raise InputError("hinge_blocked", path, f"needs {MIN_DESIGNS} designs or more")
    return Table(p, np.array(C))


@lru_cache(maxsize=256)
def coefficients(P: float, path: str = str(FIT_FILE)) -> np.ndarray:
    """The coefficients (len(TERMS),) at cavity pressure P [MPa]: the mean over the table's designs,
    linear between its pressures, constant above them and fading linearly to zero below the first
    (a pressure effect: with r = q / q_f and q_f shrinking with P, held constant the correction's
    stiffness would not vanish with P). Read-only (cached per pressure)."""
    t = read(path)
    i0, i1, w = hinge_space._lerp(float(P), t.p)
    c = t.c.mean(axis=0)
    out = ((1 - w) * c[i0] + w * c[i1]) * min(1.0, max(float(P), 0.0) / t.p[0])
    out.setflags(write=False)
    return out


def _clamp(r):
    """(rho, d rho/dr, d2 rho/dr2) of the smooth clamp of r to [LOW, HIGH] (C2: tanh beyond)."""
    rho, d1, d2 = np.array(r, float), np.ones(np.shape(r)), np.zeros(np.shape(r))
    if LOW <= rho.min() and rho.max() <= HIGH:  # the usual case: nothing to clamp
        return rho, d1, d2
    for edge, side in ((LOW, -1.0), (HIGH, 1.0)):
        out = side * (rho - edge) > 0
        t = np.tanh((rho[out] - edge) / WIDTH)
        d1[out] = 1 - t ** 2
        d2[out] = -2 * t * (1 - t ** 2) / WIDTH
        rho[out] = edge + WIDTH * t
    return rho, d1, d2


def basis(rho) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""The terms' values (..., 3), gradients (..., n, 3) and Hessian diagonals (..., n, 3) in rho (..., n):
    sum_j (rho_j - rho_{j+1})^2 (2 - rho_j - rho_{j+1})^2, (1 - rho_1)^3 and sum_j (1 - rho_j)^3."""
    rho = np.asarray(rho, float)
    x, y = rho[..., :-1], rho[..., 1:]
    d, s = x - y, 2 - x - y
    o = 1 - rho
    value = np.stack([np.sum(d ** 2 * s ** 2, axis=-1), o[..., 0] ** 3, np.sum(o ** 3, axis=-1)], axis=-1)
    grad = np.stack([_gradient(rho, e) for e in np.eye(3)], axis=-1)
    hess = np.zeros(rho.shape + (3,))
    hess[..., :-1, 0] += 2 * s * s - 8 * d * s + 2 * d * d    # d2/dx2 of d^2 s^2
    hess[..., 1:, 0] += 2 * s * s + 8 * d * s + 2 * d * d     # d2/dy2
    hess[..., 0, 1] = 6 * o[..., 0]
    hess[..., 2] = 6 * o
    return value, grad, hess


def _gradient(rho, c) -> np.ndarray:
    """sum_t c_t d(term_t)/d rho (..., n): the terms' gradients (:func:`basis`) weighted by the
    coefficients c, without their values and curvatures (the moments, the fast hold's most called)."""
    x, y = rho[..., :-1], rho[..., 1:]
    d, s = x - y, 2 - x - y
    pair = 2 * d * s * (s - d)                 # d/dx of d^2 s^2; its d/dy is -2 d s (s + d)
    o = 1 - rho
    out = -3 * c[2] * o * o
    out[..., :-1] += c[0] * pair
    out[..., 1:] -= c[0] * 2 * d * s * (s + d)
    out[..., 0] -= 3 * c[1] * o[..., 0] ** 2
    return out


def _scaled(q, q_f, P: float, design):
    """(c, rho, d rho/dq, d2 rho/dq2, P a^2 pi d mean(q_f)) of hinge angles q (..., n) about q_f (n,)
    (a free angle below ``_Q_MIN``, a finger not yet bending, is taken as ``_Q_MIN``: the clamp then
    bounds the correction, which vanishes with P)."""
    q_f = np.maximum(np.asarray(q_f, float), _Q_MIN)
    rho, d1, d2 = _clamp(np.asarray(q, float) / q_f)
    return coefficients(P), rho, d1 / q_f, d2 / q_f ** 2, P * unit_of(design) * float(np.mean(q_f))


def energy(q, q_f, P: float, design) -> np.ndarray:
    """e(q) [N mm] (...) of the design's hinge angles q (..., n) [rad] about its free angles q_f (n,), at
    cavity pressure P [MPa]."""
    c, rho, _, _, scale = _scaled(q, q_f, P, design)
    return scale * basis(rho)[0] @ c


def moments(q, q_f, P: float, design) -> np.ndarray:
    """de/dq_j [N mm/rad] (..., n) (:func:`energy`)."""
    c, rho, d1, _, scale = _scaled(q, q_f, P, design)
    return scale * _gradient(rho, c) * d1


def stiffness(q, q_f, P: float, design) -> np.ndarray:
    """d2e/dq_j2 [N mm/rad] (..., n), the diagonal (:func:`energy`)."""
    c, rho, d1, d2, scale = _scaled(q, q_f, P, design)
    _, grad, hess = basis(rho)
    return scale * ((hess @ c) * d1 ** 2 + (grad @ c) * d2)


def unit_of(design) -> float:
    """a^2 pi d [mm^3] of the design."""
    return design.a ** 2 * math.pi * design.d
