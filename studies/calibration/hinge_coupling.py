"""The hinges' coupling table of :mod:`softhand.reduced.calibrated.hinge_coupling` from the finger FEM:
the free finger's hinge angles and its condensed stiffness over a design space.

For every design of a design space and the paper's, the free finger (no load on its hinges) is
followed through the cavity pressures ``PRESSURES`` (:func:`softhand.fem.hand.finger_sweep.solve_pressures`);
at each its reduced tangent is factorised and condensed onto the hinge angles,
S = 2 [(K_r^{-1})_qq]^{-1} (:func:`softhand.fem.hand.hold_finger.condensed_stiffness`): the moments
that hold the hinges a little off their free bends, all of them at once, tube and windings
included. Written per design and pressure: the hinges' shares of the bend s_j = q_j / mean(q) and
sigma_jk = S_jk / (a^2 pi d) [MPa] (the upper triangle). A design whose free finger stops converging
below the highest pressure keeps the pressures it reached. Run::

    python -m softhand.studies.calibration.hinge_coupling --space studies/hinge_space.toml --workers 2 \\
        --out reduced/calibrated/data/grasp_hinge_coupling.csv

each design one case of the batch runner (``--results``/<space>_coupling/, resumable; ``--scheduler``
for Dask).
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from softhand.reduced.vocabulary.design import HandDesign
from softhand.studies.calibration import tables
from softhand.studies.calibration.hinges import run_space, space_parser
from softhand.studies.io.files import write_atomic

#: cavity pressures of the free states [MPa]
PRESSURES = tuple(round(0.1 * k, 9) for k in range(1, 25))


def free_rows(design: HandDesign, pressures=PRESSURES) -> list[tuple]:
    """Rows (P, s_1..s_n, sigma_jk for j <= k) of the design's free finger on the default mesh."""
    from softhand.fem.hand.finger import FingerModel, FingerOptions, solve_pressures
    from softhand.fem.hand.hold_finger import condensed_stiffness
    from softhand.fem.linsolve import make_solver
    from softhand.fem.newton import NotConverged

    model = FingerModel(design, FingerOptions())
    states = []
    try:
        solve_pressures(model, pressures, callback=states.append)
    except NotConverged:  # the pressures reached are kept
        pass
    n, unit = design.n_s, design.a ** 2 * math.pi * design.d
    upper = np.triu_indices(n)
    solver, rows = make_solver(symmetric=True, precision="double"), []
    for s in states:
        solver.factorize(model.residual_tangent(s.y, s.P)[1])
        S = condensed_stiffness(solver, model.ndofs, n)
        q = np.asarray(s.q, float)
        rows.append((s.P, *(q / q.mean()), *(S[upper] / unit)))
    return rows


def coupling_case(params: dict, design: HandDesign, outdir: Path) -> dict:
    """Kind ``hinge_coupling`` of the batch runner: one design's free states (:func:`free_rows`)."""
    return {"rows": [[float(v) for v in row] for row in free_rows(design)]}


def columns(n_s: int) -> list[str]:
    """The CSV's columns after the design's: P, s_1..s_n, sigma_jk (j <= k)."""
    j, k = np.triu_indices(n_s)
    return ["P", *(f"s_{i}" for i in range(1, n_s + 1)), *(f"sigma_{a + 1}{b + 1}" for a, b in zip(j, k))]


def space_text(space_file: str, results: str = "results", workers: int = 1, command: str = "",
               scheduler: str | None = None, progress: bool = True) -> str:
    """The coupling CSV over the designs of a design space and the paper's (module doc)."""
    from softhand.reduced.calibrated.finger_fem import GROUPS, groups_of

    designs, numbers = run_space(space_file, "hinge_coupling", "coupling", "free hinges' stiffness over a design space",
                                 results, workers, scheduler, progress)
    rows = []
    for i, (d, case) in enumerate(zip(designs, numbers)):
        g = groups_of(d)
        rows += [(i, *(g[k] for k in GROUPS), *row) for row in case["rows"]]
    head = [tables.written_by("FEM hinge coupling of reduced/calibrated/hinge_coupling.py"), command,
            f"model: finger FEM (fem/hand/finger.py) on the default mesh, {len(designs)} designs (the paper's and "
            f"those of {Path(space_file).name}); the free finger at P = {PRESSURES[0]:g}..{PRESSURES[-1]:g} MPa, "
            "its reduced tangent condensed onto the hinge angles",
            "groups as the finger table's; P [MPa]; s_j = q_j / mean(q) of the free hinge angles; "
            "sigma_jk = S_jk / (a^2 pi d) [MPa], S the condensed stiffness of the whole finger [N mm/rad]"]
    return tables.table_text(head, ["design", *GROUPS, *columns(HandDesign().n_s)], rows)


def main(argv=None) -> int:
    args = space_parser(__doc__.splitlines()[0]).parse_args(argv)
    command = "python -m softhand.studies.calibration.hinge_coupling " + " ".join(sys.argv[1:] if argv is None else argv)
    write_atomic(args.out, space_text(args.space, args.results, max(1, args.workers), command, args.scheduler,
                                      not args.no_progress))
    from softhand.reduced.calibrated import hinge_coupling

    hinge_coupling.read.cache_clear()
    loo = hinge_coupling.leave_one_out(hinge_coupling.read(args.out))
    print(tables.leave_one_out_line(len(loo), [("shares", loo[:, 0], loo[:, 0]),
                                             ("stiffness diagonal", loo[:, 1], loo[:, 1])]), file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
