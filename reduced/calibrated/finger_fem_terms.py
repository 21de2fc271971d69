"""The terms the finger model ``"fem"`` fits its residuals with: named functions of the groups.

A fit is linear in a constant and a list of *terms*; a term is one base feature or a product
of base features joined by ``*`` (``lb*th``, ``lt*lt``). The base features are those a free
tube segment's physics names:

======  ==========================================================================
``lb``   ln(b/a): the wall's thickness
``ld``   ln(d/a): the lever arm of the plate
``lL``   ln(L/a): the link length (hinge spacing, L = l0 / 6)
``lt``   -ln(1 - w/L): the tied share of a link (w the tie width)
``s2``   (b / (L - w))^2: the squared shape factor of the untied segment (a short segment
         bonded at both ends cannot contract, so it stiffens as this square)
``th``   theta [rad], the finger's bend
======  ==========================================================================

A table names its terms in its ``# fit:`` line (``p_terms=s2 lb ld th``); older tables give
polynomial degrees instead, which :func:`legacy_terms` turns into the same list. A table of
the design space is instead interpolated over :data:`~softhand.reduced.calibrated.finger_fem_terms.KERNEL_FEATURES` (:class:`KernelFit`).
"""
from __future__ import annotations

from itertools import combinations_with_replacement

import numpy as np

__all__ = ["BASE", "KERNEL_FEATURES", "KernelFit", "legacy_terms", "check_terms", "term_matrix"]


def _gap(g):
    return np.asarray(g["link_a"], float) * (1.0 - np.asarray(g["tie_link"], float))


#: base feature -> function of (groups, theta); groups' values may be arrays
BASE = {
    "lb": lambda g, th: np.log(np.asarray(g["b_a"], float)),
    "ld": lambda g, th: np.log(np.asarray(g["d_a"], float)),
    "lL": lambda g, th: np.log(np.asarray(g["link_a"], float)),
    "lt": lambda g, th: -np.log1p(-np.asarray(g["tie_link"], float)),
    "s2": lambda g, th: (np.asarray(g["b_a"], float) / _gap(g))**2,
    "th": lambda g, th: np.asarray(th, float),
}


#: the most terms a least-squares fit may name, and the most factors in one term (th^12 of
#: theta = pi is 1e6: beyond that the columns stop telling designs apart in double precision)
MAX_TERMS, MAX_FACTORS = 100, 12


def check_terms(terms) -> tuple[str, ...]:
    """The terms as a tuple; ValueError naming the first one that is not a product of BASE
    (of at most MAX_FACTORS factors), or if there are more than MAX_TERMS."""
    terms = tuple(terms)
    if len(terms) > MAX_TERMS:
        raise ValueError(f"{len(terms)} terms; at most {MAX_TERMS}")
    for term in terms:
        factors = term.split("*")
        if not term or any(f not in BASE for f in factors):
            raise ValueError(f"term {term!r}: allowed are products of {', '.join(BASE)} joined by '*'")
        if len(factors) > MAX_FACTORS:
            raise ValueError(f"term {term[:40]!r}... has {len(factors)} factors; at most {MAX_FACTORS}")
    return terms


def term_matrix(groups: dict, theta, terms) -> np.ndarray:
    """[1, term_1, ..., term_k] at the groups and theta (broadcast together); (..., k + 1)."""
    base = {}
    columns = []
    for term in terms:
        value = 1.0
        for f in term.split("*"):
            if f not in base:
                base[f] = BASE[f](groups, theta)
            value = value * base[f]
        columns.append(value)
    shape = np.broadcast_shapes(np.shape(theta), *(np.shape(c) for c in columns))
    return np.stack([np.ones(shape)] + [np.broadcast_to(c, shape) for c in columns], axis=-1)


def legacy_terms(kind: str, varying: dict, design_degree: int, theta_degree: int) -> tuple[str, ...]:
    """The terms of a table that gives polynomial degrees: for y (kind "p") s2 (if b/a, L/a or
    w/L varies), lb, ld; for ln kappa (kind "q") lb, ld, lL, lt; only the groups the table
    varies, their monomials up to design_degree, then th, th*th, ... up to theta_degree."""
    if kind == "p":
        names = (["s2"] if varying["b_a"] or varying["link_a"] or varying["tie_link"] else []) + \
                [n for n, g in (("lb", "b_a"), ("ld", "d_a")) if varying[g]]
    else:
        names = [n for n, g in (("lb", "b_a"), ("ld", "d_a"), ("lL", "link_a"), ("lt", "tie_link"))
                 if varying[g]]
    terms = ["*".join(c) for degree in range(1, design_degree + 1)
             for c in combinations_with_replacement(names, degree)]
    return tuple(terms + ["*".join(["th"] * k) for k in range(1, theta_degree + 1)])


#: the features a kernel fit interpolates in (the groups' logarithms and the shape factor)
KERNEL_FEATURES = ("lb", "ld", "lL", "lt", "s2")


#: per residual (y, ln kappa, the stretch's z at each averaging radius) the variable its per-design
#: line is in: theta for P and Delta Q; ln theta for z, so the stretch is a power law of the bend,
#: rubber_stretch - 1 = eq. (8)'s strain x C theta^b (over the shipped table's designs left out one
#: by one, at a/rho = 2: rms 1.12 %, worst 6.5 % against a line in theta's 1.24 %, 8.9 %:
#: docs/finger.md)
LINE_IN = ("theta", "theta", "log theta")


def _lines_in(n: int) -> tuple[str, ...]:
    """The variables of n residuals: y, ln kappa, then the stretch's z at each of the table's radii."""
    return LINE_IN[:2] + LINE_IN[2:] * (n - 2)


def _variable(name: str, theta):
    """theta, or ln theta (the stretch's: only asked for at theta > 0; floored at 1e-9 rad)."""
    return np.log(np.maximum(theta, 1e-9)) if name == "log theta" else theta


class KernelFit:
    """Residuals (y and ln kappa; the rubber stretch's where the table has it) as a radial-basis
    interpolant over the designs: per design, each residual's least-squares line a + b x in its
    variable x (:data:`LINE_IN`: theta, or ln theta for the stretch); a, b interpolated over the
    design features (scaled to [0, 1] over the table's designs) by SciPy's RBFInterpolator with a
    linear polynomial, exact at every design of the table."""

    def __init__(self, rows: dict, targets, kernel: str, features):
        from scipy.interpolate import RBFInterpolator

        ids = np.unique(rows["design"])
        coef, X = [], []
        for i in ids:
            at = rows["design"] == i
            th = rows["theta"][at]
            line = [np.polyfit(_variable(x, th), v[at], 1) if np.ptp(th) > 0 else (0.0, v[at].mean())
                    for v, x in zip(targets, _lines_in(len(targets)))]
            coef.append([c for slope, intercept in line for c in (intercept, slope)])
            g = {k: rows[k][at][0] for k in ("b_a", "d_a", "link_a", "tie_link")}
            X.append([float(BASE[f](g, 0.0)) for f in features])
        X = np.array(X)
        self.features = tuple(features)
        self.lo, self.span = X.min(axis=0), np.ptp(X, axis=0)
        if np.any(self.span <= 1e-12 * np.maximum(np.abs(self.lo), 1.0)) or ids.size < len(features) + 2:
            raise ValueError(f"{ids.size} designs: a kernel fit in {' '.join(features)} needs at least "
                             f"{len(features) + 2} designs over which every feature varies")
        self.rbf = RBFInterpolator((X - self.lo) / self.span, np.array(coef), kernel=kernel, degree=1)

    def __call__(self, groups: dict, theta) -> tuple[np.ndarray, ...]:
        x = np.array([float(BASE[f](groups, 0.0)) for f in self.features])
        c = self.rbf(((x - self.lo) / self.span)[None, :])[0]
        theta = np.asarray(theta, float)
        return tuple(c[k] + c[k + 1] * _variable(x, theta) for k, x in zip(range(0, c.size, 2), _lines_in(c.size // 2)))
