"""``softhand study run|status|report FILE``: batch studies from a TOML study file."""
from __future__ import annotations

import sys

from softhand.studies.cli.args import add_progress_option, check_workers, print_json

HELP = "run a batch study (TOML file) on a process pool or a Dask cluster; status; report"

_SHOWN = 20  #: cases listed per state before "... and N more"


def configure(parser) -> None:
    actions = parser.add_subparsers(dest="action", required=True, metavar="ACTION")
    run = actions.add_parser("run", help="run every case not yet done (resumable)")
    run.add_argument("--workers", type=int, default=None, metavar="N",
                     help="worker processes (default: the CPU count; 1 runs in this process)")
    run.add_argument("--scheduler", default=None, metavar="ADDRESS|local",
                     help="run on a Dask cluster at ADDRESS ('local' starts a LocalCluster)")
    run.add_argument("--fresh", action="store_true",
                     help="recompute every case, also those already done")
    add_progress_option(run)
    status = actions.add_parser("status", help="print done / pending / failed cases")
    status.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    actions.add_parser("report", help="write plots and a Markdown summary of the results")
    for sub in (run, status, actions.choices["report"]):
        sub.add_argument("file", metavar="FILE", help="study TOML file (see studies/*.toml)")
        sub.add_argument("--results", default="results", metavar="DIR",
                         help="results root (default: results); the study writes DIR/<name>/")
        sub.add_argument("--max-cases", type=int, default=None, metavar="N",
                         help="allow a study of up to N cases (default 10000)")


def run(args) -> int:
    from softhand.reduced.vocabulary.errors import InputError
    from softhand.studies.batch.studyfile import MAX_CASES, load_study

    if args.max_cases is not None and not 1 <= args.max_cases <= 10**7:
        raise InputError("--max-cases", args.max_cases, "must be a whole number in [1, 10000000]")
    if args.action == "run":
        check_workers(args.workers)
    study = load_study(args.file, max_cases=args.max_cases or MAX_CASES)
    return {"run": _run, "status": _status, "report": _report}[args.action](study, args)


def _run(study, args) -> int:
    from softhand.studies.batch.runner import run_study, study_dir

    s = run_study(study, results_root=args.results, workers=args.workers,
                  scheduler=args.scheduler, progress=not args.no_progress, fresh=args.fresh)
    print(f"study {study.name} ({study.kind}): {s.total} cases: "
          f"{s.total - len(s.failed) - s.not_run} done ({s.computed} computed, {s.reused} reused), "
          f"{len(s.failed)} failed, {s.not_run} not run"
          + (f"; {s.corrupt} case files that did not parse were recomputed" if s.corrupt else ""))
    print(f"index: {study_dir(study, args.results) / 'index.csv'}")
    for key, error in list(s.failed.items())[:_SHOWN]:
        print(f"  failed {key}: {error}")
    return 0 if s.ok else 1


def _status(study, args) -> int:
    from softhand.studies.batch.runner import other_sources, read_case, status, study_dir

    groups = status(study, args.results)
    sdir = study_dir(study, args.results)
    if args.json:
        print_json({"study": study.name, "kind": study.kind,
                    **{state: [{"case": c.key, **c.point,
                                **({"error": (read_case(sdir, c) or {}).get("error")} if state == "failed" else {})}
                               for c in cases] for state, cases in groups.items()}})
        return 0
    total = sum(map(len, groups.values()))
    print(f"study {study.name} ({study.kind}): {total} cases: "
          + ", ".join(f"{len(groups[s])} {s}" for s in ("done", "pending", "failed"))
          + (f", {len(groups['corrupt'])} corrupt (case files that do not parse; "
             f"'study run' recomputes them)" if groups["corrupt"] else ""))
    stale = other_sources(study, groups["done"], args.results)
    if stale:
        print(f"  note: {len(stale)} done cases were computed by other package sources "
              f"(an edited working tree); 'study run --fresh' recomputes them all")
    for state in ("failed", "corrupt", "pending"):
        for case in groups[state][:_SHOWN]:
            point = " ".join(f"{k}={v}" for k, v in case.point.items())
            error = f": {(read_case(sdir, case) or {}).get('error')}" if state == "failed" else ""
            print(f"  {state:<7} {case.key}  {point}{error}")
        if len(groups[state]) > _SHOWN:
            print(f"  ... and {len(groups[state]) - _SHOWN} more {state}")
    return 0


def _report(study, args) -> int:
    from softhand.studies.batch.report import write_report

    from softhand.studies.batch.runner import study_dir
    from softhand.studies.io.files import kept_if_unwritable

    with kept_if_unwritable(study_dir(study, args.results) / "report.md", "study"):  # e.g. a read-only study
        path = write_report(study, args.results)
        print(f"report: {path}", file=sys.stdout)
    return 0
