r"""Finger model ``"fem"``: W_f(theta) and Q(theta) of one finger calibrated from the finger FEM.

Dimensional analysis. The finger FEM (Neo-Hookean tube, inextensible windings, rigid links
holding rings of the tube) has one modulus, mu_sf, and the lengths a, b, d, the link length
L = l0 / 6 (5 equal hinges) and the tie width w. So

.. math:: \frac{P}{\mu_{sf}} = \tilde p\Big(\theta; \frac{b}{a}, \frac{d}{a}, \frac{L}{a},
          \frac{w}{L}\Big), \qquad \frac{\Delta Q}{a^3} = \tilde q(\theta; \dots).

The physics already known carries most of it: the paper's eq. (28) for P (the table's
``prior``: ``"paper"``, or ``"rings"``: eq. (28) with the tube stretching only over its untied
length l0 - 6 w, the finger FEM's kinematic bound, see :func:`~softhand.reduced.calibrated.finger_fem.prior_pressure`), and for the oil
the kinematic a^2 pi d theta of eq. (2) (the tube's axis lengthens by d theta) plus the tube's
own dilation under pressure, a^3 kappa P / mu_sf. The table ``reduced/calibrated/data/finger_fem.csv``
holds the FEM's (theta, P/mu, Delta Q/a^3) at the sampled designs; this model fits

.. math:: y = \ln\frac{P_{FEM}}{P_{prior}}, \qquad
          \ln\kappa = \ln\frac{\Delta Q_{FEM}/a^3 - \pi (d/a)\,\theta}{P_{FEM}/\mu_{sf}}

over the features a free tube segment's physics names (ln b/a, ln d/a, ln L/a, the tied share
-ln(1 - w/L) and the untied gap's shape factor s = b / (L - w) squared: a short segment
bonded at both ends cannot contract, so it stiffens as s^2; :mod:`.finger_fem_terms`), as
the table's ``# fit:`` line says. A table of the design space (12 designs or more) is
interpolated by radial basis functions (the table names them: cubic in the shipped one) with a
linear polynomial, per design a line in theta (the stretch's z: in ln theta;
:class:`~.finger_fem_terms.KernelFit`, exact at the table's designs; chosen over polynomial
least squares and the other kernels by leave-one-design-out error); a table of a few designs
is fitted by least squares in linear terms (older tables: polynomial degrees). So P(theta) = P_prior(theta)
e^{y} and Delta Q = a^2 pi d theta + a^3 kappa P(theta) / mu_sf. Beyond the table's largest
angle theta_max (and below -theta_max) y and ln kappa are held at their end values.

Another rubber. The table's FEM runs are Neo-Hookean: P/mu_sf is the tube's geometry. A design
with another rubber (``design.finger_material``) takes the rubber's pure-shear nominal stress,
scaled to its initial modulus mu_sf, in the prior's integral (eq. (10) generalised, as in
:func:`softhand.reduced.equations.finger.finger_force`); y, kappa and the stretch's z stay the
geometry's. Measured against the FEM run with the rubber: docs/finger.md.

Energy consistency. Per design, P(theta) and Delta Q(theta) are sampled at 0.5 deg and
interpolated by cubic Hermite polynomials; dW_f/dtheta is defined as P dQ/dtheta (a quintic
per piece) and W_f as its exact integral (3-point Gauss per piece, W_f(0) = 0), so
P dQ/dtheta = dW_f/dtheta holds to rounding and (27), (28), (25) follow from the
virtual-work balance unchanged.

Its space: the table's ``# range:`` narrowed to its own designs (a table answers only where
it was measured). Designs whose groups leave it, or that do not have 5 equal hinges, raise
one InputError naming the group and its range; ``softhand calibrate finger --design`` makes
a table for such a design. Units: mm, MPa, N mm, rad.
"""
from __future__ import annotations

import math
from functools import lru_cache
from typing import NamedTuple

import numpy as np

from softhand.reduced.equations import finger
from softhand.reduced.calibrated.finger_curves import Curves, energy_curves
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.calibrated.finger_fem_terms import KernelFit, term_matrix
from softhand.reduced.calibrated.finger_fem_table import (A_RHO, COLUMNS, GROUPS, LABELS, PRIORS, SIZE_STRETCH, STRETCH,
                                                     TABLE_FILE, Table, table_error, read_table)
from softhand.reduced.materials.rubber_parameters import CRITICAL_DISTANCE_MM, between_sizes

__all__ = ["TABLE_FILE", "GROUPS", "COLUMNS", "STRETCH", "SIZE_STRETCH", "A_RHO", "PRIORS", "Table", "read_table",
           "check_table", "groups_of", "curves", "rubber_stretch", "FEM"]

N_LINKS = 6
# ---------------------------------------------------------------------- groups and the fit
def groups_of(design: HandDesign) -> dict:
    """The design's groups b/a, d/a, link/a, tie/link (5 equal hinges required)."""
    links = np.asarray(design.link_lengths)
    if design.n_s != N_LINKS - 1 or np.ptp(links) > 1e-6 * design.l0:
        raise InputError("hinge_s_mm", list(design.hinge_s),
                         'finger_model "fem" is calibrated for n_s = 5 equal hinges '
                         f"(l0/6 apart: {[round(design.l0 * k / 6, 3) for k in range(1, 6)]})")
    L = design.l0 / N_LINKS
    return {"b_a": design.b / design.a, "d_a": design.d / design.a, "link_a": L / design.a,
            "tie_link": design.tie_width / L}


def lstsq_terms(groups: dict, theta, target, terms) -> np.ndarray:
    """Least-squares coefficients of ``target`` in [1, terms] (columns scaled to unit norm for
    the conditioning, the coefficients returned for the unscaled columns); None if the
    columns are dependent (too few designs for the terms)."""
    A = term_matrix(groups, theta, terms)
    norm = np.linalg.norm(A, axis=0)
    if np.linalg.matrix_rank(A / norm) < A.shape[1]:
        return None
    return np.linalg.lstsq(A / norm, target, rcond=None)[0] / norm


class _Tube(NamedTuple):
    """A tube that eq. (10) integrates over: a design's lengths a, b, d, l0 [mm] and its rubber
    (None: Neo-Hookean, mu = 1)."""

    a: float
    b: float
    d: float
    l0: float
    finger_rubber: object = None

    mu_sf = 1.0  # the groups' pressure is P / mu_sf

    @property
    def finger_is_neo_hookean(self) -> bool:
        return self.finger_rubber is None


def prior_pressure(theta, groups: dict, prior: str, rubber=None):
    """P / mu_sf [-] of the physics the fit corrects: eq. (28) ("paper"), or eq. (28) with the
    tube stretching over its untied length l0 - 6 w only ("rings": the tied rings cannot
    stretch, the kinematic bound of the finger FEM). ``rubber``: the tube's rubber scaled to
    an initial shear modulus of 1 (its pure-shear stress in eq. (10)'s integral); None:
    Neo-Hookean, the paper's zeta_f."""
    L = groups["link_a"]
    l0 = N_LINKS * L * ((1.0 - groups["tie_link"]) if prior == "rings" else 1.0)
    # eq. (10) needs only the tube's lengths; any point of the groups' box, not only a design
    free = _Tube(a=1.0, b=groups["b_a"], d=groups["d_a"], l0=l0, finger_rubber=rubber)

    def force(t):
        return finger.finger_force(t, free) / (math.pi * groups["d_a"])

    # bent backwards beyond the angle where the outermost fibre halves its length, P continues
    # linearly (C1): the short untied length of "rings" would otherwise compress it to nothing
    lo = -0.5 * l0 / (groups["d_a"] + 1.0 + groups["b_a"])
    theta = np.asarray(theta, float)
    P = force(np.maximum(theta, lo))
    if np.any(theta < lo):
        h = 1e-6
        slope = (force(lo + h) - force(lo - h)) / (2 * h)
        P = np.where(theta < lo, P + slope * (theta - lo), P)
    return P


def unit_rubber(design: HandDesign):
    """The design's tube rubber scaled to an initial shear modulus of 1; None if Neo-Hookean."""
    return None if design.finger_is_neo_hookean else design.finger_rubber.scaled(1.0 / design.mu_sf)


def stretch_prior(theta, groups: dict):
    """Eq. (8)'s strain at the tube's outer fibre, (d + a + b) theta / l0 [-]: the physics the
    fit of the rubber's converged stretch corrects."""
    return (groups["d_a"] + 1.0 + groups["b_a"]) * np.asarray(theta, float) / (N_LINKS * groups["link_a"])


def stretch_columns(rows: dict) -> tuple[str, ...]:
    """The table's stretch columns the fit uses: one per a/rho of
    :data:`~softhand.reduced.calibrated.finger_fem_table.A_RHO` where it has them, else its
    designs' own ``s_tilde`` (older tables), else none."""
    if SIZE_STRETCH[0] in rows:
        return SIZE_STRETCH
    return (STRETCH,) if STRETCH in rows else ()


def fit_targets(rows: dict, prior: str, path="table") -> tuple[np.ndarray, ...]:
    """The residuals a table's rows give the fit: y = ln(P / P_prior), ln kappa and, per stretch
    column (:func:`stretch_columns`), z = ln(s_tilde / eq. (8)'s strain)."""
    y = np.empty(rows["theta"].size)
    for i in np.unique(rows["design"]):  # the prior per design, all its angles at once
        at = rows["design"] == i
        g = {k: float(rows[k][at][0]) for k in GROUPS}
        y[at] = np.log(rows["p_tilde"][at] / prior_pressure(rows["theta"][at], g, prior))
    dilation = rows["q_tilde"] - math.pi * rows["d_a"] * rows["theta"]
    if np.any(dilation <= 0):
        raise table_error(path, "has dQ/a^3 <= pi (d/a) theta in a row: below the tube's kinematic "
                         "oil volume of eq. (2)")
    ln_kappa = np.log(dilation / rows["p_tilde"])
    strain = stretch_prior(rows["theta"], rows)
    return (y, ln_kappa, *(np.log(rows[c] / strain) for c in stretch_columns(rows)))


class _TermsFit:
    """y and ln kappa by least squares in the table's terms."""

    def __init__(self, table: Table, targets, path):
        r = table.rows
        self.terms, self.betas = (table.p_terms, table.q_terms, *[table.p_terms] * (len(targets) - 2)), []
        for terms, target in zip(self.terms, targets):  # the stretch's z in P's terms
            try:
                beta = lstsq_terms(r, r["theta"], target, terms)
            except (np.linalg.LinAlgError, ValueError) as error:  # e.g. SVD on columns that overflow
                raise table_error(path, f"has '# fit:' terms whose least-squares fit fails ({error}); "
                                 f"use fewer or lower powers") from None
            if beta is None:
                raise table_error(path, f"has too few designs ({np.unique(r['design']).size}) for the "
                                 f"fit's terms ({' '.join(terms)}); use fewer in '# fit:'")
            self.betas.append(beta)

    def __call__(self, groups: dict, theta):
        return tuple(term_matrix(groups, theta, terms) @ beta for terms, beta in zip(self.terms, self.betas))


@lru_cache(maxsize=8)
def _fit(path: str) -> tuple[Table, object, float]:
    """(table, fit, theta_max): fit(groups, theta) -> (y, ln kappa[, z of the stretch])."""
    table = read_table(path)
    targets = fit_targets(table.rows, table.prior, path)
    if table.kernel is None:
        fit = _TermsFit(table, targets, path)
    else:
        try:
            fit = KernelFit(table.rows, targets, table.kernel, table.features)
        except np.linalg.LinAlgError as error:  # designs at one point of the features
            raise table_error(path, f"has designs that coincide in its '# fit:' features "
                             f"({' '.join(table.features)}), so the kernel interpolant cannot be built "
                             f"({error}); name features that tell the designs apart") from None
        except ValueError as error:
            raise table_error(path, f"has {error}") from None
    return table, fit, float(table.rows["theta"].max())


def check_table(path) -> Table:
    """The table at ``path``, read and fitted (cached): InputError naming it if either fails, so
    a run can refuse a bad table before its work rather than at its first use."""
    return _fit(str(path))[0]


def check_space(design: HandDesign, table: Table) -> dict:
    """The design's groups; InputError naming the first group outside the table's range."""
    groups = groups_of(design)
    for g in GROUPS:
        lo, hi = table.ranges[g]
        if not lo * (1 - 1e-9) <= groups[g] <= hi * (1 + 1e-9):
            raise InputError(LABELS[g], round(groups[g], 6),
                             f'outside the range [{lo:.4g}, {hi:.4g}] of finger_model "fem" '
                             f"({table.source}); calibrate this design with softhand calibrate "
                             "finger --design FILE --out FILE.csv")
    return groups


def residuals(theta, design: HandDesign) -> tuple[np.ndarray, np.ndarray]:
    """(y, ln kappa) of the fit at theta [rad] for this design:
    P = P_prior e^y, Delta Q = a^2 pi d theta + a^3 kappa P / mu_sf."""
    table, fit, theta_max = _fit(_table_path(design))
    groups = check_space(design, table)
    return fit(groups, np.clip(np.asarray(theta, float), -theta_max, theta_max))[:2]


def rubber_stretch(theta, design: HandDesign):
    """The tube's converged rubber stretch (the FEM's ``rubber_stretch``) at bend theta [rad],
    calibrated: 1 + eq. (8)'s strain x e^z, z fitted over the design space like y and ln kappa
    (held at its end value beyond the table's angles), per a/rho column of the table, and
    between them linear in ln(a/rho) (continued by the end columns' line beyond them): the
    averaging radius rho is the rubber's, so the measure depends on the tube's size a as well as
    on the groups. None if the design's table has no stretch column (tables written before it;
    a table with the designs' own ``s_tilde`` only predicts that, whatever a is)."""
    table, fit, theta_max = _fit(_table_path(design))
    columns = stretch_columns(table.rows)
    if not columns:
        return None
    groups = check_space(design, table)
    theta = np.asarray(theta, float)
    zs = np.array(fit(groups, np.clip(theta, 1e-9, theta_max))[2:])
    z = between_sizes(zs, A_RHO, design.a / CRITICAL_DISTANCE_MM) if len(columns) > 1 else zs[0]
    return 1.0 + stretch_prior(theta, groups) * np.exp(z)


def _table_path(design: HandDesign) -> str:
    return design.finger_table or str(TABLE_FILE)


@lru_cache(maxsize=64)
def curves(design: HandDesign) -> Curves:
    """The calibrated curves of ``design`` (cached per design)."""
    table = _fit(_table_path(design))[0]
    groups = check_space(design, table)

    def pressure_and_oil(t):
        y, ln_kappa = residuals(t, design)
        P = design.mu_sf * prior_pressure(t, groups, table.prior, unit_rubber(design)) * np.exp(y)
        return P, design.a**2 * math.pi * design.d * t + design.a**3 * np.exp(ln_kappa) * P / design.mu_sf

    return energy_curves(pressure_and_oil, design.a**2 * math.pi * design.l0)


def _energy(theta, design):
    return curves(design).energy(theta)


def _energy_rate(theta, design):
    return curves(design).energy_rate(theta)


def _volume(theta, design):
    c = curves(design)
    return c.Q0 + c.dQ(theta)


def _volume_rate(theta, design):
    return curves(design).dQ.derivative(theta)


FEM = finger.FingerFunctions(energy=_energy, energy_rate=_energy_rate, volume=_volume,
                             volume_rate=_volume_rate, check=lambda design: check_table(_table_path(design)))
finger.register_model("fem", FEM)
