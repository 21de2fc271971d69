"""``softhand calibrate finger``: the table of the reduced finger model ``"fem"`` from the FEM.

* ``--space FILE.toml --out FILE.csv``: every design of a design space (see
  :mod:`softhand.studies.calibration.finger`) by the finger FEM, as a batch study on the runner
  (results/<name>/, resumable, ``--workers N``, ``--scheduler local|tcp://...``), then the
  nondimensional table with its provenance (the package's is reduced/calibrated/data/finger_fem.csv);
* ``--design FILE.toml --out FILE.csv``: the same for one design (any geometry with 5 equal
  hinges), and a design file FILE_fem.toml next to the table that uses it
  (``finger_model = "fem"``, ``finger_table = "FILE.csv"``);
* ``--check FILE.toml [--table FILE.csv]``: the designs of FILE.toml by FEM against the
  calibrated model (the package's table or ``--table``): theta at every FEM pressure, dQ,
  and the pressure at 60 deg; ``--json`` for the numbers.
"""
from __future__ import annotations

import shlex
import sys

from softhand.studies.cli.args import add_json_option, add_progress_option, print_json, print_table

HELP = "calibrate the reduced finger model 'fem' from the finger FEM (design space or one design)"


def configure(parser) -> None:
    what = parser.add_subparsers(dest="what", required=True, metavar="MODEL")
    finger = what.add_parser("finger", help="the finger model's table (W_f, Q) from the finger FEM")
    source = finger.add_mutually_exclusive_group(required=True)
    source.add_argument("--space", metavar="FILE.toml", help="design space (studies/finger_space.toml)")
    source.add_argument("--design", metavar="FILE.toml", help="one design, e.g. outside the space")
    source.add_argument("--check", metavar="FILE.toml",
                        help="held-out designs: FEM against the calibrated model")
    finger.add_argument("--out", metavar="FILE.csv", help="the table to write (--space, --design)")
    finger.add_argument("--table", metavar="FILE.csv",
                        help="--check: the table to check (default: the package's)")
    finger.add_argument("--workers", type=int, default=1, metavar="N",
                        help="worker processes (default 1)")
    finger.add_argument("--scheduler", default=None, metavar="ADDRESS|local",
                        help="run on a Dask cluster at ADDRESS ('local' starts a LocalCluster)")
    finger.add_argument("--results", default="results", metavar="DIR",
                        help="results root of the FEM cases (default: results)")
    add_progress_option(finger)
    finger.add_argument("--finished", action="store_true",
                        help="run no FEM: use the designs already finished in --results (the "
                             "others are listed as pending)")
    add_json_option(finger)


def run(args) -> int:
    from softhand.reduced.vocabulary.errors import InputError
    from softhand.studies.calibration import space as fc
    from softhand.studies.calibration.finger_table import write_design_with_table, write_table

    from softhand.studies.cli.args import check_workers

    check_workers(args.workers)
    if args.table is not None and args.check is None:
        raise InputError("--table", args.table, "is the table --check compares with the FEM; --space "
                                                "and --design write one (--out)")
    if args.table is not None:
        from softhand.reduced.calibrated.finger_fem import check_table

        try:
            check_table(args.table)  # read and fitted before any FEM
        except InputError as exc:
            raise exc.renamed("--table") from None
    if args.check is None and not args.out:
        raise InputError("--out", None, "give the table to write, e.g. --out finger_fem.csv")
    if args.check is not None and args.out:
        raise InputError("--out", args.out, "not with --check, which compares a table with the "
                                            "FEM and writes none")
    if args.check is not None:
        return _check(_load_space(args.check), args)
    if args.design:
        from softhand.studies.calibration.finger_table import check_design_file

        check_design_file(args.out, (args.design,))
    given_space = _load_space(args.space) if args.space else fc.single_design_space(args.design)
    space = neo_hookean(given_space)
    results = _run(space, args)
    if results is None:
        return 1
    space, results = _finished_only(space, results)
    given = ("--space", args.space), ("--design", args.design), ("--out", args.out), \
        ("--workers", args.workers if args.workers != 1 else None), ("--scheduler", args.scheduler)
    command = "softhand calibrate finger " + " ".join(f"{k} {shlex.quote(str(v))}" for k, v in given
                                                      if v is not None)
    from softhand.studies.batch.runner import study_dir
    from softhand.studies.calibration.finger import as_study
    from softhand.studies.io.files import kept_if_unwritable

    with kept_if_unwritable(f"{args.out} (the FEM cases are kept in {study_dir(as_study(space), args.results)}: "
                            f"rerun with --finished)", "calibrate"):
        path = write_table(args.out, space, results, command)
        print(f"table: {path} ({len(space.points)} designs)")
        if args.design:
            toml = write_design_with_table(given_space.designs()[0], path)
            print(f"design using it: {toml}")
    return 0


def neo_hookean(space):
    """The space with a Neo-Hookean tube of its rubber's initial shear modulus: a table holds
    the tube's geometry; finger_model "fem" adds a design's own rubber through eq. (10)'s
    pure-shear stress (:func:`softhand.reduced.calibrated.finger_fem.prior_pressure`)."""
    import dataclasses

    base = space.base
    if base.finger_is_neo_hookean:
        return space
    print(f"note: the table is built with a Neo-Hookean tube of the rubber's initial shear modulus "
          f"mu_sf_MPa = {base.mu_sf:.6g}; finger_model \"fem\" applies a design's own rubber "
          f"({base.finger_material.model} here) on top of it", file=sys.stderr)
    return dataclasses.replace(space, base=base.replace(finger_material=None))


def _run(space, args):
    """Run the space's FEM cases (resumable); [(design, record)] or None if some failed.
    With --finished: only the cases already done, without running any."""
    from softhand.reduced.vocabulary.errors import InputError
    from softhand.studies.calibration.finger import as_study
    from softhand.studies.batch.runner import case_state, plan, read_case, run_study, study_dir

    study = as_study(space)
    sdir = study_dir(study, args.results)
    if args.finished:
        cases = plan(study)
        done = [case_state(sdir, c) == "done" for c in cases]
        if not any(done):
            raise InputError("--finished", f"0 of {len(cases)} cases finished in {sdir}",
                             "needs finished cases; run without --finished")
        print(f"FEM: {sum(done)} of {len(cases)} cases finished in {sdir}; "
              f"{len(cases) - sum(done)} pending, not run (--finished)", file=sys.stderr)
        return [(c.design, read_case(sdir, c) if ok else None) for c, ok in zip(cases, done)]
    s = run_study(study, results_root=args.results, workers=args.workers,
                  scheduler=args.scheduler, progress=not args.no_progress)
    print(f"FEM: {s.total} designs: {s.computed} computed, {s.reused} reused, "
          f"{len(s.failed)} failed, {s.not_run} not run; cases in {study_dir(study, args.results)}",
          file=sys.stderr)
    for key, error in s.failed.items():
        print(f"  failed {key}: {error}", file=sys.stderr)
    if not s.ok:
        return None
    return [(case.design, read_case(sdir, case)) for case in plan(study)]


def _finished_only(space, results):
    """The space reduced to its designs with a result (all of them unless --finished)."""
    import dataclasses

    from softhand.reduced.vocabulary.errors import InputError

    n = len(space.points)
    keep = [i for i in range(n) if results[i][1] is not None]
    pair_pending = any(record is None for _, record in results[n:])
    if not keep or pair_pending:
        found = f"{len(keep)} finished designs" + (", mesh_pair pending" if pair_pending else "")
        raise InputError("--finished", found, "needs one finished design and the finished "
                                              "mesh_pair cases; run without --finished")
    return (dataclasses.replace(space, points=tuple(space.points[i] for i in keep)),
            [results[i] for i in keep] + results[n:])


def _load_space(path):
    """The design space, refused now if its mesh is too large for this machine's memory."""
    from pathlib import Path

    from softhand.studies.calibration import space as fc
    from softhand.studies.calibration.finger import check_memory

    space = fc.load_space(path)
    check_memory(space, Path(path).name)
    return space


def _check(space, args) -> int:
    from softhand.reduced.vocabulary.errors import InputError
    from softhand.studies.calibration.finger_check import heldout_rows

    results = _run(space, args)
    if results is None:
        return 1
    results = [r for r in results if r[1] is not None]
    if not results:  # --finished, and only the mesh_pair cases are
        raise InputError("--finished", "0 finished designs", "needs a finished design; run "
                                                             "without --finished")
    rows, worst = heldout_rows(results, args.table)
    if args.json:
        print_json({"rows": rows, "worst": worst})
    else:
        print_table(rows)
        print("# worst |error|: " + ", ".join(f"{k} {v:.2f} %" if k.endswith("pct") else f"{k} {v:.4f} MPa"
                                             for k, v in worst.items()))
    return 0
