"""The hinge table of :mod:`softhand.reduced.calibrated.grasp_fem` from the finger FEM: each hinge's oil per radian at
fixed pressure, A_j(theta, P) = dV/d theta_hat_j, at the hinge's bend theta and the cavity pressure P.

On the finger FEM's mesh, the free finger at each pressure P0 of ``PRESSURES`` (bend
theta_free(P0)); there every hinge is locked by a stiff torsion spring (``SPRING`` on the half
model; its deflection is the moment it supplies, physical = twice the half model's) and the
pressure raised in steps of ``DP`` up to ``TOP`` (or as far as the locked finger converges), as a blocked finger's is when an object holds it: the moment the
spring takes up per MPa is dM_j/dP = -A_j at fixed hinge angles (a Maxwell relation of the
finger's potential E(q, P), dE/dP = -V), read at the middle of each step. At P0 = 0 the finger
is straight. Written nondimensionally against the hinge's bend theta = n_s theta_hat_j:
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
#: cavity pressures of the free states [MPa], the pressure step with the hinges locked, the highest pressure
PRESSURES, DP, TOP = (0.0, 0.1, 0.2, 0.3, 0.4, 0.6, 0.8, 1.0, 1.2, 1.6, 2.0, 2.5, 3.0), 0.1, 4.0


def volume_rates(model, pressures=PRESSURES, dP: float = DP, top: float = TOP, progress=None):
    """Rows (theta_free(P0) [rad], P [MPa], A (n_s,) [mm^3/rad]): the locked hinges' A_j at the
    middle P of each pressure step above each free state."""
    from softhand.fem.hand.finger import solve_pressures
    from softhand.fem.linsolve import make_solver
    from softhand.fem.newton import NewtonOptions, NotConverged
    from softhand.fem.newton_path import PathOptions, solve_path

    d = model.design
    n, scale = d.n_s, d.mu_sf * d.a ** 2 * d.l0
    free, _ = solve_pressures(model, pressures)
    rows = []
    for s in free:
        levels = s.P + dP * np.arange(1, int(round((top - s.P) / dP)) + 1)
        moments = {}

        def fun(y, P, s=s):
            return model.residual_tangent(y, P, lambda q: (-SPRING * (q - s.q), -SPRING * np.eye(n)))

        def keep(P, y, s=s, moments=moments):
            moments[round(P, 9)] = 2.0 * SPRING * (np.asarray(model.constraint.q(y)) - s.q)

        try:
            solve_path(fun, s.y, PathOptions(steps=len(levels), predictor="secant", newton=NewtonOptions(rtol=1e-10)),
                       solver=make_solver(symmetric=True), scale_t=lambda P: scale, t0=s.P, stops=levels, callback=keep)
        except NotConverged:  # the locked finger's path ends below TOP: the table keeps what it reached
            levels = levels[:sum(round(P, 9) in moments for P in levels)]
        M = [np.zeros(n)] + [moments[round(P, 9)] for P in levels]
        for k, P in enumerate(levels):
            rows.append((s.theta, P - 0.5 * dP, (M[k + 1] - M[k]) / dP))
        if progress is not None:
            progress(s)
    return rows


def table_text(design: HandDesign, mesh_size_mm: float | None = None, command: str = "") -> str:
    """The CSV: provenance lines, then theta, P, a_1..a_n."""
    from softhand.fem.hand.finger import FingerModel, FingerOptions
    from softhand.studies.weights import finger_options

    options = FingerOptions() if mesh_size_mm is None else finger_options(mesh_size_mm)
    model = FingerModel(design, options)
    rows = volume_rates(model, progress=lambda s: print(f"free state at {s.P:g} MPa done", file=sys.stderr))
    unit = design.a ** 2 * math.pi * design.d
    mesh = "the default mesh" if mesh_size_mm is None else f"the grasp mesh (h = {mesh_size_mm:g} mm)"
    head = [tables.written_by("FEM hinge table of reduced/calibrated/grasp_fem.py"),
            command,
            f"model: finger FEM (fem/hand/finger.py) of the paper's design (Table I) on {mesh} "
            f"({model.ndofs} unknowns); free states at P0 = {', '.join(f'{p:g}' for p in PRESSURES)} MPa, "
            f"hinges locked there by springs of {SPRING:g} N mm/rad (half model), P raised in steps of {DP:g} MPa to {TOP:g}",
            "theta = the free bend at P0 [rad] (a hinge's bend n_s theta_hat); P = the step's middle [MPa]; "
            "a_j = A_j/(a^2 pi d), A_j = dV/d theta_hat_j at fixed P"]
    columns = ["theta", "P", *(f"a_{j}" for j in range(1, design.n_s + 1))]
    return tables.table_text(head, columns, [(t, P, *(A / unit)) for t, P, A in rows])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="CSV file to write")
    parser.add_argument("--mesh-size-mm", type=float, default=None,
                        help="finger element size of a graded grasp-style mesh (default: the finger FEM's default mesh)")
    args = parser.parse_args(argv)
    command = "python -m softhand.studies.calibration.hinges " + " ".join(sys.argv[1:] if argv is None else argv)
    text = table_text(HandDesign(), args.mesh_size_mm, command)
    write_atomic(args.out, text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
