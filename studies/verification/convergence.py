"""Richardson extrapolation of a quantity computed on three meshes refined by a fixed ratio."""
from __future__ import annotations

import math

from softhand.reduced.vocabulary.errors import InputError


def richardson(coarse: float, medium: float, fine: float, ratio: float = 2.0) -> tuple[float, float]:
    """(observed order p, extrapolated value) of f(h) = f0 + C h^p from h, h/ratio, h/ratio^2.

    p = log(``|f_m - f_c|`` / ``|f_f - f_m|``) / log(ratio), f0 = f_f + (f_f - f_m) / (ratio^p - 1).
    Needs monotone convergence (both differences of one sign, shrinking); otherwise the
    three values say nothing about the limit and this raises InputError.
    """
    d1, d2 = medium - coarse, fine - medium
    if d1 == 0 or d2 == 0 or (d1 > 0) != (d2 > 0) or abs(d2) >= abs(d1):
        raise InputError("mesh sequence", (coarse, medium, fine),
                         "must converge monotonically (differences of one sign, shrinking)")
    p = math.log(d1 / d2) / math.log(ratio)
    return p, fine + d2 / (ratio ** p - 1)
