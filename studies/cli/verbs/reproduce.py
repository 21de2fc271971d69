"""``softhand reproduce [--out DIR] [--quick]``: the paper's results, end to end, in one report."""
from __future__ import annotations

import os

from softhand.studies.cli.args import add_design_option, add_progress_option, design_from_args

HELP = "recompute every result of the paper into a report (Markdown + PNG + CSV + VTK)"


def configure(parser) -> None:
    parser.add_argument("--out", default="results/reproduce", metavar="DIR",
                        help="output folder (default: results/reproduce)")
    parser.add_argument("--quick", action="store_true",
                        help="CI-sized meshes and fewer points (under a minute on 2 cores)")
    from softhand.studies.reproduce.core import sections

    parser.add_argument("--only", default=None, metavar="KEY,KEY",
                        help="build only these sections (the report's folders): "
                             + ", ".join(s.key for s in sections()))
    parser.add_argument("--fresh", action="store_true",
                        help="recompute every section, even those a previous run finished")
    parser.add_argument("--workers", type=int, default=None, metavar="N",
                        help="sections built side by side in N processes (default: the CPU count; "
                             "1 builds them one by one in this process, with each FEM path's own bar)")
    add_progress_option(parser)
    add_design_option(parser)


def run(args) -> int:
    from softhand.reduced.vocabulary.errors import InputError
    from softhand.studies.cli.checks import check_choices
    from softhand.studies.io.outputs import check_output_tree
    from softhand.studies.reproduce.core import REPORT_FILES, check_design, exit_code, reproduce, sections

    from softhand.studies.cli.args import check_workers

    check_workers(args.workers)
    keys = [s.key for s in sections()]
    only = None
    if args.only is not None:
        only = tuple(k.strip() for k in args.only.split(","))
        check_choices("--only", only, keys, "section", shown=args.only)
        skipped = [s.key for s in sections() if s.key in only and not s.in_quick]
        if args.quick and len(skipped) == len(only):
            raise InputError("--only", args.only, f"names only sections --quick skips ({', '.join(skipped)}); "
                                                  "drop --quick to build them")
    check_output_tree(args.out, "--out", files=REPORT_FILES, folders=keys)
    design = design_from_args(args)
    check_design(design)
    outcomes = reproduce(args.out, quick=args.quick, design=design, only=only,
                         fresh=args.fresh, progress=not args.no_progress,
                         workers=args.workers or os.cpu_count() or 1)
    width = max(len(o.section.key) for o in outcomes)
    for o in outcomes:
        detail = f"  {o.detail}" if o.status in ("failed", "not available") else ""
        print(f"{o.section.key:<{width}}  {o.status:<13} {o.wall_time_s:7.1f} s{detail}")
    print(f"report: {args.out}/report.md")
    return exit_code(outcomes)
