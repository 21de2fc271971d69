"""A synthetic finger calibration table whose 'FEM' points follow the calibrated model's class
exactly (tests of the fit, the table reader and the table's range use it)."""
import math

import numpy as np

from softhand.reduced.calibrated import finger_fem
from softhand.reduced.equations import hand
from softhand.studies.calibration.finger_table import table_csv
from softhand.studies.calibration.space import finger_design

#: a known residual the fit's model class holds exactly: y = ln(P / P_28) and ln kappa, where
#: dQ = a^2 pi d theta + a^3 kappa P / mu_sf
Y = (0.25, 0.05, 0.1)   # y = Y0 + Y1 x_shape + Y2 theta, x_shape: (b / (L - w))^2 scaled
K = (1.2, -0.3, 0.08)   # ln kappa = K0 + K1 x_tie + K2 theta, x_tie: -ln(1 - w / L) scaled


def _scaled(v, lo, hi):
    return 2 * (v - lo) / (hi - lo) - 1


def truth(d, theta, ties):
    """(P, dQ) of the model class at design d from Y, K (the scalings over the ties' range)."""
    L = d.l0 / 6
    shape = lambda w: (d.b / (L - w))**2  # noqa: E731
    tie = lambda w: -math.log1p(-w / L)  # noqa: E731
    xs = _scaled(shape(d.tie_width), shape(ties[0]), shape(ties[-1]))
    xt = _scaled(tie(d.tie_width), tie(ties[0]), tie(ties[-1]))
    P = hand.finger_pressure(theta, d.replace(finger_model="paper")) * np.exp(Y[0] + Y[1] * xs + Y[2] * theta)
    kappa = np.exp(K[0] + K[1] * xt + K[2] * theta)
    return P, d.a**2 * math.pi * d.d * theta + d.a**3 * kappa * P / d.mu_sf


def synthetic_table(tmp_path, ties=(5.0, 10.0, 15.0)):
    """A table whose 'FEM' points follow Y, K exactly, over the tie width only."""
    designs = [finger_design({"a_mm": 4.0, "b_mm": 5.0, "d_mm": 15.0, "l0_mm": 180.0,
                              "tie_width_mm": t}) for t in ties]
    groups = [finger_fem.groups_of(d) for d in designs]
    rows = []
    for i, (d, g) in enumerate(zip(designs, groups)):
        for theta in (0.2, 0.6, 1.0):
            P, dQ = truth(d, theta, ties)
            rows.append({"design": i, **g, "theta": theta, "p_tilde": float(P) / d.mu_sf,
                         "q_tilde": float(dQ) / d.a**3})
    ranges = {k: (v, v) for k, v in groups[0].items()}
    ranges["tie_link"] = (groups[0]["tie_link"], groups[-1]["tie_link"])
    path = tmp_path / "synthetic.csv"
    path.write_text(table_csv(rows, ranges, ["synthetic test table"], "p_terms=s2 th, q_terms=lt th"))
    return path, designs, ties
