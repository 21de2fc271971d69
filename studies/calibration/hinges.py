"""The hinge table of :mod:`softhand.reduced.calibrated.grasp_fem` from the finger FEM: each hinge's oil per radian at
fixed pressure, A_j(theta, P) = dV/d theta_hat_j, at the hinge's bend theta and the cavity pressure P.

On the finger FEM's mesh, the free finger at each pressure P0 of ``PRESSURES`` (bend
theta_free(P0)); there every hinge is locked by a stiff torsion spring (``SPRING`` on the half
model; its deflection is the moment it supplies, physical = twice the half model's) and the
pressure raised in steps of ``DP`` up to ``TOP`` (or as far as the locked finger converges), as a blocked finger's is when an object holds it: the moment the
spring takes up per MPa is dM_j/dP = -A_j at fixed hinge angles (a Maxwell relation of the
finger's potential E(q, P), dE/dP = -V), read at the middle of each step. At P0 = 0 the finger
is straight. Written nondimensionally against the hinge's bend theta = n_s theta_hat_j:
a_j = A_j / (a^2 pi d).

A heavy object's pads push the base hinges past straight, where no free state at P >= 0 exists:
at each bend of ``REVERSE`` the unpressurised finger is bent backwards by the springs (in a few
steps from straight), its moment there written as the node's row at P = 0
(m0_j = M_j / (a^2 pi d), MPa), and the pressure raised as above. Run::

    python -m softhand.studies.calibration.hinges --out reduced/calibrated/data/grasp_hinges.csv
    python -m softhand.studies.calibration.hinges --design my_hand.toml --out my_hinges.csv

``--space FILE`` writes instead the grid of :mod:`softhand.reduced.calibrated.hinge_space`: every
design of a design space (and the paper's) locked on a few nodes (``GRID_*``), each design one case
of the batch runner (``--results``/<space>_hinges/, kept as it finishes: a second run does only the
others; ``--workers`` at once, or a Dask ``--scheduler``)::

    python -m softhand.studies.calibration.hinges --space studies/hinge_space.toml --workers 2 \
        --out reduced/calibrated/data/grasp_hinge_space.csv
"""
from __future__ import annotations

import argparse
import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.design_files import load_design
from softhand.studies.calibration import tables
from softhand.studies.io.files import write_atomic

#: torsion spring locking each hinge, on the half model [N mm/rad] (~1e4 times the finger's)
SPRING = 1e7
#: cavity pressures of the free states [MPa], the pressure step with the hinges locked, the highest pressure
PRESSURES, DP, TOP = (0.0, 0.1, 0.2, 0.3, 0.4, 0.6, 0.8, 1.0, 1.2, 1.6, 2.0, 2.5, 3.0), 0.1, 4.0
#: the reverse bends theta = n_s theta_hat < 0 locked from P = 0 [deg]
REVERSE = (-1.5, -3.0, -6.0, -12.0, -20.0)


def _locked(q, P):
    """The springs holding the hinges at q (half model): (Q(q'), dQ/dq') of the hinge angles q'."""
    return lambda qq: (-SPRING * (qq - q), -SPRING * np.eye(len(q)))


def _moment(model, y, q) -> np.ndarray:
    """The physical moment M = -2 SPRING (q(y) - q) [N mm] the springs locking the hinges at q hold
    the state y with (the half model carries half of it)."""
    return -2.0 * SPRING * (np.asarray(model.constraint.q(y)) - q)


def _raise(model, y, q, P0: float, dP: float, top: float):
    """The locked finger (hinges at q, state y at P0) from P0 up in steps of dP to ``top`` (or as
    far as it converges): rows (P of the step's middle, A (n_s,) [mm^3/rad]), A = -dM/dP with
    M the springs' moment (:func:`_moment`)."""
    from softhand.fem.linsolve import make_solver
    from softhand.fem.newton import NewtonOptions, NotConverged
    from softhand.fem.newton_path import PathOptions, solve_path

    d = model.design
    levels = P0 + dP * np.arange(1, int(round((top - P0) / dP)) + 1)
    if not len(levels):
        return []
    moments = {round(P0, 9): _moment(model, y, q)}

    def keep(P, yy):
        moments[round(P, 9)] = _moment(model, yy, q)

    try:
        solve_path(lambda yy, P: model.residual_tangent(yy, P, _locked(q, P)), y,
                   PathOptions(steps=len(levels), predictor="secant", newton=NewtonOptions(rtol=1e-10)),
                   solver=make_solver(symmetric=True), scale_t=lambda P: d.mu_sf * d.a ** 2 * d.l0, t0=P0,
                   stops=levels, callback=keep)
    except NotConverged:  # the locked finger's path ends below ``top``: the table keeps what it reached
        pass
    P = [round(P0, 9)] + [round(p, 9) for p in levels if round(p, 9) in moments]  # the path stops at its first failure
    return [(0.5 * (p0 + p1), -(moments[p1] - moments[p0]) / dP) for p0, p1 in zip(P[:-1], P[1:])]


def volume_rates(model, pressures=PRESSURES, dP: float = DP, top: float = TOP, progress=None):
    """Rows (theta_free(P0) [rad], P [MPa], A (n_s,) [mm^3/rad]): the locked hinges' A_j at the
    middle P of each pressure step above each free state."""
    return [row[1:] for row in _free_rows(model, pressures, dP, top, progress)]


def _free_rows(model, pressures, dP, top, progress):
    """Rows (P0, theta_free(P0), P, A) of :func:`volume_rates`."""
    from softhand.fem.hand.finger import solve_pressures

    free, _ = solve_pressures(model, pressures)
    rows = []
    for s in free:
        rows += [(s.P, s.theta, P, A) for P, A in _raise(model, s.y, s.q, s.P, dP, top)]
        if progress is not None:
            progress(f"free state at {s.P:g} MPa")
    return rows


def reverse_rates(model, bends_deg=REVERSE, dP: float = DP, top: float = TOP, progress=None):
    """Rows (theta [rad], P [MPa], value (n_s,)) of the reverse bends: first (theta, 0, M_j at P = 0
    [N mm]), then the locked hinges' A_j [mm^3/rad] at the middle P of each step from P = 0."""
    from softhand.fem.linsolve import make_solver
    from softhand.fem.newton import NewtonOptions
    from softhand.fem.newton_path import PathOptions, solve_path

    d = model.design
    rows = []
    for bend in bends_deg:
        theta = math.radians(bend)
        q = np.full(d.n_s, theta / d.n_s)
        bent = solve_path(lambda y, t: model.residual_tangent(y, 0.0, _locked(t * q, 0.0)), model.constraint.zero(),
                          PathOptions(steps=4, newton=NewtonOptions(rtol=1e-10)), solver=make_solver(symmetric=True),
                          scale_t=lambda t: d.mu_sf * d.a ** 2 * d.l0)
        y = bent.x[-1]
        rows.append((theta, 0.0, _moment(model, y, q)))
        rows += [(theta, P, A) for P, A in _raise(model, y, q, 0.0, dP, top)]
        if progress is not None:
            progress(f"reverse bend {bend:g} deg")
    return rows


def table_text(design: HandDesign, mesh_size_mm: float | None = None, command: str = "", top: float = TOP) -> str:
    """The CSV: provenance lines, then theta, P, a_1..a_n."""
    from softhand.fem.hand.finger import FingerModel, FingerOptions
    from softhand.studies.weights import finger_options

    options = FingerOptions() if mesh_size_mm is None else finger_options(mesh_size_mm)
    model = FingerModel(design, options)
    say = lambda what: print(f"{what} done", file=sys.stderr, flush=True)  # noqa: E731
    pressures = tuple(p for p in PRESSURES if p < top)
    rows = reverse_rates(model, top=top, progress=say) + volume_rates(model, pressures, top=top, progress=say)
    unit = design.a ** 2 * math.pi * design.d
    mesh = "the default mesh" if mesh_size_mm is None else f"the grasp mesh (h = {mesh_size_mm:g} mm)"
    which = "the paper's design (Table I)" if design == HandDesign(finger_model=design.finger_model) else \
        f"the design a {design.a:g}, b {design.b:g}, d {design.d:g}, l0 {design.l0:g}, tie {design.tie_width:g} mm"
    head = [tables.written_by("FEM hinge table of reduced/calibrated/grasp_fem.py"),
            command,
            f"model: finger FEM (fem/hand/finger.py) of {which} on {mesh} "
            f"({model.ndofs} unknowns); free states at P0 = {', '.join(f'{p:g}' for p in pressures)} MPa "
            f"and reverse bends {', '.join(f'{b:g}' for b in REVERSE)} deg at P0 = 0, "
            f"hinges locked there by springs of {SPRING:g} N mm/rad (half model), P raised in steps of {DP:g} MPa to {top:g}",
            "theta = the locked bend [rad] (a hinge's bend n_s theta_hat); P = the step's middle [MPa]; "
            "a_j = A_j/(a^2 pi d), A_j = dV/d theta_hat_j at fixed P; a reverse bend's row at P = 0 holds "
            "m0_j = M_j/(a^2 pi d) [MPa], its moment there"]
    columns = ["theta", "P", *(f"a_{j}" for j in range(1, design.n_s + 1))]
    return tables.table_text(head, columns, [(t, P, *(A / unit)) for t, P, A in rows])


#: the grid of a design space's tables (:mod:`softhand.reduced.calibrated.hinge_space`): reverse bends
#: [deg], free states' pressures, the pressure step and the highest pressure [MPa]
GRID_REVERSE, GRID_PRESSURES, GRID_DP, GRID_TOP = (-3.0, -6.0, -12.0), (0.0, 0.4, 0.8), 0.2, 2.4


def grid_rows(design: HandDesign) -> list[tuple]:
    """One design's rows (P0, theta, P, a_1..a_n) on the grid, on the finger FEM's default mesh
    (a reverse node's P0 is 0; its row at P = 0 holds m0_j)."""
    from softhand.fem.hand.finger import FingerModel, FingerOptions

    model = FingerModel(design, FingerOptions())
    unit = design.a ** 2 * math.pi * design.d
    rows = [(0.0, *row) for row in reverse_rates(model, GRID_REVERSE, GRID_DP, GRID_TOP)]
    rows += _free_rows(model, GRID_PRESSURES, GRID_DP, GRID_TOP, None)
    return [(P0, t, P, *(A / unit)) for P0, t, P, A in rows]


def grid_case(params: dict, design: HandDesign, outdir: Path) -> dict:
    """Kind ``hinge_grid`` of the batch runner: one design's rows on the grid (:func:`grid_rows`)."""
    return {"rows": [[float(v) for v in row] for row in grid_rows(design)]}


def run_space(space_file: str, kind: str, suffix: str, description: str, results: str = "results", workers: int = 1,
              scheduler: str | None = None, progress: bool = True) -> tuple[list, list]:
    """(designs, each design's case numbers) of one batch case of ``kind`` per design of a design space
    (:mod:`softhand.studies.calibration.space`) and the paper's, the paper's first (results/<space>_<suffix>/,
    resumable, a local pool or Dask); RuntimeError naming the designs that failed."""
    from softhand.studies.batch.runner import plan, read_case, run_study, study_dir
    from softhand.studies.calibration.finger import SpaceStudy
    from softhand.studies.calibration.space import VARIABLES, load_space

    space = load_space(space_file)
    designs = [HandDesign()] + [d for d in space.designs() if d != HandDesign()]
    study = SpaceStudy(name=f"{space.name}_{suffix}", kind=kind, design=HandDesign(),
                       axes=tuple((key, ()) for key in VARIABLES), params={},
                       description=description, case_list=tuple(({}, d) for d in designs))
    run = run_study(study, results_root=results, workers=workers, scheduler=scheduler, progress=progress)
    if not run.ok:
        failed = "; ".join(f"{key}: {error}" for key, error in run.failed.items())
        raise RuntimeError(f"{kind}: {len(run.failed)} designs failed, {run.not_run} not run "
                           f"({failed or 'rerun to finish them'})")
    return designs, [read_case(study_dir(study, results), case)["numbers"] for case in plan(study)]


def space_parser(description: str) -> argparse.ArgumentParser:
    """The command line of a study over a design space (:func:`run_space`): --space, --out, --results,
    --workers, --scheduler, --no-progress."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--space", required=True, help="design-space TOML file")
    parser.add_argument("--out", required=True, help="CSV file to write")
    parser.add_argument("--results", default="results", help="the batch runner's results folder (resumable)")
    parser.add_argument("--workers", type=int, default=1, help="designs run at once")
    parser.add_argument("--scheduler", default=None, help="a Dask scheduler address, or 'local'")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    return parser


def space_text(space_file: str, results: str = "results", workers: int = 1, command: str = "",
               scheduler: str | None = None, progress: bool = True) -> str:
    """The grid CSV of :mod:`softhand.reduced.calibrated.hinge_space` over the designs of a design
    space and the paper's: one ``hinge_grid`` case per design (:func:`run_space`)."""
    from softhand.reduced.calibrated.finger_fem import groups_of
    from softhand.reduced.calibrated.hinge_space import COLUMNS

    designs, numbers = run_space(space_file, "hinge_grid", "hinges", "blocked-hinge grid over a design space", results, workers, scheduler, progress)
    rows = []
    for i, (d, case) in enumerate(zip(designs, numbers)):
        g = groups_of(d)
        rows += [(i, *(g[k] for k in COLUMNS[1:5]), *row) for row in case["rows"]]
    head = [tables.written_by("FEM hinge grid of reduced/calibrated/hinge_space.py"), command,
            f"model: finger FEM (fem/hand/finger.py) on the default mesh, {len(designs)} designs (the paper's and "
            f"those of {Path(space_file).name}); reverse bends {', '.join(f'{b:g}' for b in GRID_REVERSE)} deg and "
            f"free states at P0 = {', '.join(f'{p:g}' for p in GRID_PRESSURES)} MPa, hinges locked by springs of "
            f"{SPRING:g} N mm/rad (half model), P raised in steps of {GRID_DP:g} MPa to {GRID_TOP:g}",
            "groups as the finger table's; P0 = the free state's pressure (0 for a reverse bend); theta = the locked "
            "bend [rad]; P = the step's middle [MPa]; a_j = A_j/(a^2 pi d); a reverse bend's row at P = 0 holds "
            "m0_j = M_j/(a^2 pi d) [MPa]"]
    return tables.table_text(head, [*COLUMNS, *(f"a_{j}" for j in range(1, HandDesign().n_s + 1))], rows)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="CSV file to write")
    parser.add_argument("--mesh-size-mm", type=float, default=None,
                        help="finger element size of a graded grasp-style mesh (default: the finger FEM's default mesh)")
    parser.add_argument("--design", default=None, help="design TOML file (default: the paper's design)")
    parser.add_argument("--space", default=None,
                        help="design-space TOML file: write the grid of hinge tables over its designs instead")
    parser.add_argument("--results", default="results",
                        help="with --space: the batch runner's results folder (each design a case, resumable)")
    parser.add_argument("--workers", type=int, default=1, help="designs run at once (with --space)")
    parser.add_argument("--scheduler", default=None, help="with --space: a Dask scheduler address, or 'local'")
    parser.add_argument("--no-progress", action="store_true", help="with --space: no progress bar")
    parser.add_argument("--top-mpa", type=float, default=TOP,
                        help=f"highest cavity pressure of the locked paths [MPa] (default {TOP:g}; a hand that holds "
                             "below 2 MPa needs no more than 2.5, at about half the time)")
    args = parser.parse_args(argv)
    command = "python -m softhand.studies.calibration.hinges " + " ".join(sys.argv[1:] if argv is None else argv)
    if args.space is not None:
        from softhand.reduced.calibrated import hinge_space

        write_atomic(args.out, space_text(args.space, args.results, max(1, args.workers), command,
                                          args.scheduler, not args.no_progress))
        hinge_space.read.cache_clear()
        loo = hinge_space.leave_one_out(hinge_space.read(args.out))
        print(tables.leave_one_out_line(len(loo), [("rates", loo[:, 0], loo[:, 1]),
                                                 ("moments bent backwards", loo[:, 2], loo[:, 3])]), file=sys.stderr)
        return 0
    design = HandDesign() if args.design is None else load_design(args.design)
    if not 0.2 <= args.top_mpa <= 10.0:
        parser.error(f"--top-mpa {args.top_mpa:g}: must be in [0.2, 10] MPa")
    text = table_text(replace(design, hinge_table=""), args.mesh_size_mm, command, args.top_mpa)
    write_atomic(args.out, text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
