r"""Starting values for rubber moduli from durometer readings (an estimate, not a measurement).

Gent's relation between Shore A hardness S and Young's modulus E [MPa]:

.. math:: E = \frac{0.0981\,(56 + 7.62336\,S)}{0.137505\,(254 - 2.54\,S)}

Source: A. N. Gent, "On the relation between indentation hardness and Young's modulus",
Trans. Inst. Rubber Ind. 34 (1958) 46-57 (reprinted in Rubber Chem. Technol. 31 (1958)
896-906); the form above is the one quoted by Qi, Joyce & Boyce, Rubber Chem. Technol. 76
(2003) 419-435. It follows from the type A durometer's spring force, which grows linearly
with the reading (numerator), and its indentation depth 2.54 mm * (1 - S/100)
(denominator), through a linear-elastic indentation solution for the truncated-cone
indenter. So it is a small-strain estimate, singular at S = 100, and meant for the type A
scale. Its accuracy is that of any hardness-modulus correlation: a starting value, not a
material parameter. Published correlations differ by about a factor of two in the middle
of the scale; at S = 70 Gent gives E = 5.5 MPa, the log-linear correlation
log10 E = 0.0235 S - 0.6403 gives 10.1 MPa (:func:`young_modulus_log_linear`).

For a nearly incompressible rubber (Poisson ratio 1/2) the initial shear modulus of the
Neo-Hookean law (5), (11) is mu = E / 3.

The paper's NBR is Shore A 70 and uses mu = 1.15 MPa; Gent gives mu = 1.84 MPa for
Shore A 70, 1.6 times more; 1.15 MPa is Gent's value for Shore A 58.9. Fit mu to
bending data (``softhand fit``) rather than trusting either number.
"""
from __future__ import annotations

import math

from softhand.reduced.vocabulary.errors import InputError

#: Shore A readings this module accepts: the type A scale is 0..100 and Gent's relation is
#: singular at 100; below ~10 and above ~90 the standard recommends other durometer types.
SHORE_A_RANGE = (0.0, 100.0)


def young_modulus_gent(shore_a: float) -> float:
    """Gent's (1958) Young's modulus [MPa] for a Shore A hardness (see the module docstring)."""
    s = _check(shore_a)
    return 0.0981 * (56.0 + 7.62336 * s) / (0.137505 * (254.0 - 2.54 * s))


def young_modulus_log_linear(shore_a: float) -> float:
    """The log-linear correlation log10 E = 0.0235 S - 0.6403 [MPa]; for comparison only."""
    return 10.0 ** (0.0235 * _check(shore_a) - 0.6403)


def shear_modulus_from_shore_a(shore_a: float) -> float:
    """Initial shear modulus mu = E/3 [MPa] of an incompressible rubber from Gent's relation."""
    return young_modulus_gent(shore_a) / 3.0


def _check(shore_a) -> float:
    lo, hi = SHORE_A_RANGE
    if isinstance(shore_a, bool) or not isinstance(shore_a, (int, float)) \
            or not math.isfinite(shore_a) or not lo < shore_a < hi:
        raise InputError("shore_a", shore_a, f"must be a Shore A hardness in ({lo:g}, {hi:g})")
    return float(shore_a)
