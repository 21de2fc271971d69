"""The blocked finger's hinge moments and volume rates: the finger FEM against the fast hold model's hinges.

The fast hold model's finger (``finger_model = "fem"``) holds hinge j with
M_j = -int A_j(theta_j, p) dp from P_free(theta_j) to P, A_j from the hinge table measured on
equally bent fingers locked at their free bends while the pressure rises. Here the finger FEM
(default mesh) is held by generalised forces Q on its hinges, as an object's pad holds it, at
cavity pressure P: its hinge angles q, the fast model's moments at those q (equal to Q where the
fast model is exact) and the moments coupled through the tube
(:func:`softhand.reduced.calibrated.finger_hinges.coupled_moments`), and the FEM's volume rates at fixed q, A = S dq/dP (S the condensed
stiffness, dq the hinge angles' change under the same Q from P to P + dP), against the table's
A_j(theta_j, P); and S itself (its diagonal and the coupling of neighbouring hinges) against the
fast model's dM_j/dq_j. Prints one block per Q; no assertions.

    python benchmarks/blocked_hinges.py [--pressure-mpa 0.9] [--q=-600,-300,0,0,0 --q=...] [--design FILE]

(``--design``: another design, with its own ``hinge_table`` if the file names one.)
"""
from __future__ import annotations

import argparse
import math

import numpy as np

from softhand.fem.hand.finger import FingerModel, FingerOptions
from softhand.fem.hand.hold_finger import HeldFinger
from softhand.reduced.calibrated.finger_hinges import coupled_moments, fem_finger, hinge_moments, volume_rate
from softhand.reduced.vocabulary.design_files import load_design


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pressure-mpa", type=float, default=0.9)
    parser.add_argument("--dp-mpa", type=float, default=0.05)
    parser.add_argument("--q", action="append", default=None,
                        help="generalised hinge forces Q [N mm], comma-separated, base hinge first "
                             "(--q=-600,-300,0,0,0; repeat for more)")
    parser.add_argument("--design", default=None, help="design TOML file (default: the paper's design)")
    args = parser.parse_args()
    args.q = args.q or ["-600,-300,0,0,0", "-900,-600,-300,0,0"]
    design = fem_finger(load_design(args.design))
    unit = design.a ** 2 * math.pi * design.d
    finger = HeldFinger(FingerModel(design, FingerOptions()))
    P, dP = args.pressure_mpa, args.dp_mpa
    finger.solve(P, np.zeros(design.n_s), steps=4)
    print(f"free finger at {P:g} MPa: q = {np.round(np.degrees(finger.q), 3)} deg; "
          f"fast model's M there {np.round(hinge_moments(finger.q, P, design), 1)} N mm")
    for text in args.q:
        Q = np.array([float(v) for v in text.split(",")])
        finger.solve(P, Q, steps=2)
        q0, S0 = finger.q.copy(), finger.S.copy()
        finger.solve(P + dP, Q)
        A = 0.5 * (S0 + finger.S) @ (finger.q - q0) / dP
        print(f"Q = {Q} N mm: q = {np.round(np.degrees(q0), 3)} deg")
        print(f"  fast model's M(q)       {np.round(hinge_moments(q0, P, design), 1)} N mm")
        print(f"  coupled through the tube {np.round(coupled_moments(q0, P, design), 1)} N mm")
        print(f"  FEM A / (a^2 pi d)      {np.round(A / unit, 3)}")
        print(f"  table A(theta_j, P) / ...{np.round(volume_rate(design.n_s * q0, P, fem_finger(design)) / unit, 3)}")
        h = 1e-6
        K = [(hinge_moments(q0 + h * e, P, design) - hinge_moments(q0 - h * e, P, design))[j] / (2 * h)
             for j, e in enumerate(np.eye(design.n_s))]
        print(f"  FEM stiffness S diagonal {np.round(np.diag(S0), 0)} N mm/rad, next to it "
              f"{np.round(np.diag(S0, 1), 0)} (the fast model's hinges are uncoupled)")
        print(f"  fast model's dM_j/dq_j   {np.round(K, 0)} N mm/rad")


if __name__ == "__main__":
    main()
