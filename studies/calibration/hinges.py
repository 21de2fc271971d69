"""The hinge table of :mod:`softhand.reduced.calibrated.grasp_fem` from the finger FEM: each hinge's oil per radian at
fixed pressure, A_j(theta) = dV/d theta_hat_j.

On the grasp FEM's mesh, the free finger at each pressure P of ``PRESSURES`` (bend theta_free(P));
there every hinge is locked by a stiff torsion spring (``SPRING`` on the half model; its
deflection is the moment it supplies, physical = twice the half model's) and the pressure
raised by ``DP``: the moment the spring takes up per MPa is dM_j/dP = -A_j at fixed hinge
angles (a Maxwell relation of the finger's potential E(q, P), dE/dP = -V). At P = 0 that is the
straight finger's. Written nondimensionally against the hinge's bend theta = n_s theta_hat_j:
a_j = A_j / (a^2 pi d). Run::

    python -m softhand.studies.calibration.hinges --out reduced/calibrated/data/grasp_hinges.csv
"""
from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from softhand.reduced.vocabulary.design import HandDesign
from softhand.studies.calibration import tables
from softhand.studies.io.files import write_atomic

#: torsion spring locking each hinge, on the half model [N mm/rad] (~1e4 times the finger's)
SPRING = 1e7
#: cavity pressures of the free states [MPa] and the pressure step with the hinges locked
PRESSURES, DP = (0.0, 0.2, 0.4, 0.6, 0.8), 0.05


def volume_rates(model, pressures=PRESSURES, dP: float = DP):
    """(theta_free (k,) [rad], A (k, n_s) [mm^3/rad]): the free bends and the locked hinges' A_j."""
    from softhand.fem.hand.finger import solve_pressures
    from softhand.fem.linsolve import make_solver
    from softhand.fem.newton import NewtonOptions
    from softhand.fem.newton_path import PathOptions, solve_path

    d = model.design
    n, scale = d.n_s, d.mu_sf * d.a ** 2 * d.l0
    free, _ = solve_pressures(model, pressures)
    rates = []
    for s in free:
        def fun(y, t, s=s):
            return model.residual_tangent(y, s.P + t * dP, lambda q: (-SPRING * (q - s.q), -SPRING * np.eye(n)))
        res = solve_path(fun, s.y, PathOptions(steps=1, newton=NewtonOptions(rtol=1e-10)),
                         solver=make_solver(symmetric=True), scale_t=lambda t: scale)
        q = np.asarray(model.constraint.q(res.x[-1]))
        rates.append(2.0 * SPRING * (q - s.q) / dP)
    return np.array([s.theta for s in free]), np.array(rates)


def table_text(design: HandDesign, mesh_size_mm: float | None = None, command: str = "") -> str:
    """The CSV: provenance lines, then theta, a_1..a_n (hinge bends theta_free(P) / 1 per row)."""
    from softhand.fem.hand.finger import FingerModel
    from softhand.studies.weights import MESH_SIZE, finger_options

    h = MESH_SIZE if mesh_size_mm is None else mesh_size_mm
    model = FingerModel(design, finger_options(h))
    theta, A = volume_rates(model)
    a = A / (design.a ** 2 * math.pi * design.d)
    head = [tables.written_by("FEM hinge table of reduced/calibrated/grasp_fem.py"),
            command,
            f"model: finger FEM (fem/hand/finger.py) of the paper's design (Table I) on the grasp mesh "
            f"(h = {h:g} mm, {model.ndofs} unknowns); free states at P = {', '.join(f'{p:g}' for p in PRESSURES)} MPa, "
            f"hinges locked by springs of {SPRING:g} N mm/rad (half model), P + {DP:g} MPa",
            "theta = the free bend at that P [rad] (a hinge's bend n_s theta_hat); a_j = A_j/(a^2 pi d), "
            "A_j = dV/d theta_hat_j at fixed P"]
    columns = ["theta", *(f"a_{j}" for j in range(1, design.n_s + 1))]
    return tables.table_text(head, columns, [(t, *r) for t, r in zip(theta, a)])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="CSV file to write")
    parser.add_argument("--mesh-size-mm", type=float, default=None, help="finger element size (default: the grasp FEM's)")
    args = parser.parse_args(argv)
    command = "python -m softhand.studies.calibration.hinges " + " ".join(sys.argv[1:] if argv is None else argv)
    text = table_text(HandDesign(), args.mesh_size_mm, command)
    write_atomic(args.out, text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
