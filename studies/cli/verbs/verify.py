"""``softhand verify``: run the FEM verification suite; a table per case; exit 1 on a failure."""
from __future__ import annotations

import sys

from softhand.studies.cli.checks import check_choices
from softhand.studies.cli.args import add_json_option, add_progress_option, print_json, print_table

HELP = "FEM verification suite: closed forms vs FEM on small meshes (exit 1 if any fails)"

COLUMNS = ["quantity", "exact", "fem", "rel_error", "tolerance", "passed"]


def configure(parser) -> None:
    parser.add_argument("--quick", action="store_true",
                        help="coarser meshes and fewer load levels (CI-sized)")
    parser.add_argument("--case", action="append", default=None, metavar="NAME",
                        help="run only this case (repeatable); default: all")
    add_json_option(parser)
    add_progress_option(parser)


def run(args) -> int:
    from tqdm import tqdm

    from softhand.studies.verification.registry import REGISTRY, run_case

    names = args.case or list(REGISTRY)
    check_choices("--case", names, list(REGISTRY), "case")
    rows = []
    for name in tqdm(names, desc="verify", unit="case", file=sys.stderr, leave=False,
                     disable=args.no_progress):
        checks, seconds = run_case(name, quick=args.quick)
        rows += [c.row() for c in checks]
        if not args.json:
            print(f"\n{name}  ({seconds:.1f} s)")
            print_table([c.row() for c in checks], COLUMNS, digits=6)
    failed = [r for r in rows if not r["passed"]]
    if args.json:
        print_json(rows)
    else:
        print(f"\n{len(rows) - len(failed)} of {len(rows)} checks passed")
    return 1 if failed else 0
