"""Make the SYNTHETIC example data for ``softhand fit`` (these are not measurements).

    python studies/data/make_example.py      # rewrites example_bending.csv, example_grasp.csv

The stated synthetic model: the paper's design (studies/designs/paper.toml) with
V0_mm3 = 15000 and mu_sf_MPa = 1.30 (everything else as in Table I), evaluated by the
reduced model with reservoir, plus independent Gaussian noise with a fixed seed:

* example_bending.csv: free bending, theta(P) of eq. (27) at P = 0, 0.1, ..., 0.8 MPa for
  four fingers (the paper's protocol, section III-B), noise sigma = 1.5 deg on theta;
* example_grasp.csv: a 2 kg, 180 mm object (the paper's w), P = 0.6 ... 0.9 MPa; theta is
  the angle at which the finger presses with F_v = 2, 4, 6 N (eqs. (25), (29)), then
  sigma = 0.3 N of noise is added to F_v.

Fitting V0_mm3 and mu_sf_MPa to either file should give back 15000 mm^3 and 1.30 MPa
within the standard errors that ``softhand fit`` reports.
"""
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from softhand.reduced.vocabulary.design_files import design_from_dict, load_design
from softhand.reduced.vocabulary import paper
from softhand.reduced.equations.grasp import angle_at
from softhand.reduced.equations.hand import bend_angle
from softhand.studies.io.files import write_atomic

HERE = Path(__file__).resolve().parent
TRUTH = {"V0_mm3": 15000.0, "mu_sf_MPa": 1.30}  #: the synthetic hand's parameters
SEED = 8  #: numpy default_rng seed: the same data set on every run
SIGMA_THETA_DEG = 1.5  #: noise on the bend angle
SIGMA_F_V_N = 0.3  #: noise on the grasping force


def _header(what: str) -> str:
    truth = ", ".join(f"{k} = {v:g}" for k, v in TRUTH.items())
    return (f"# SYNTHETIC data, not measurements: {what}\n"
            f"# made by studies/data/make_example.py from the paper's design with {truth},\n"
            f"# reduced model with reservoir, Gaussian noise, numpy default_rng(seed={SEED}).\n")


def bending(design, rng) -> str:
    P = np.repeat(np.round(np.arange(0.0, 0.85, 0.1), 2), 4)
    finger = np.tile(np.arange(1, 5), P.size // 4)
    theta = np.degrees(bend_angle(P, design)) + SIGMA_THETA_DEG * rng.standard_normal(P.size)
    lines = [f"{p:.2f},{t:.2f},{f}" for p, t, f in zip(P, theta, finger)]
    what = f"free bending, theta noise sigma = {SIGMA_THETA_DEG} deg"
    return _header(what) + "P_pump_MPa,theta_deg,finger\n" + "\n".join(lines) + "\n"


def grasp(design, rng) -> str:
    fig8 = paper.FIG8[0]  # the paper's 180 mm / 2 kg object at its Fig. 8 pressures
    w, mass, diameter = paper.WEIGHTS[fig8.diameter_mm], fig8.mass_kg, fig8.diameter_mm
    rows = []
    for P in fig8.pressures_mpa:
        for F_v in (2.0, 4.0, 6.0):
            theta = float(np.degrees(angle_at(P, mass, w, design, F_v=F_v)))
            rows.append((P, round(theta, 2), F_v + SIGMA_F_V_N * rng.standard_normal()))
    lines = [f"{P:.2f},{t:.2f},{mass:g},{F:.3f},{diameter:g}" for P, t, F in rows]
    what = f"2 kg, 180 mm object, F_v noise sigma = {SIGMA_F_V_N} N"
    return _header(what) + "P_pump_MPa,theta_deg,mass_kg,F_v_N,diameter_mm\n" + "\n".join(lines) + "\n"


def main() -> None:
    design = design_from_dict(TRUTH, load_design())
    rng = np.random.default_rng(SEED)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the paper's 180 mm w sums to 1.40; used as printed
        write_atomic(HERE / "example_bending.csv", bending(design, rng))
        write_atomic(HERE / "example_grasp.csv", grasp(design, rng))


if __name__ == "__main__":
    main()
