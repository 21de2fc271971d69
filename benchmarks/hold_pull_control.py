"""The FEM hold's limit with its pull stepped as a force and drawn by displacement, on the kept reference holds.

The holding limits kept as the fast model's reference (``studies/data/hold_fem_limits.json``) were
first measured with the pull stepped as a force (``HoldOptions(pull_control="force")``); those
re-run with the pull drawn (``pull_control="displacement"``: a stiff spring's far end moved along
the pull, the limit the first maximum of its force along the slide) keep the drawn limit as
``fem_limit_N`` and the stepped one as ``fem_limit_stepped_N``. This runs the kept whole-hand FEM
holds drawn and prints, per case, the stepped limit, the drawn one, the fast model's and the fast
model's error against each. Only the cases the FEM holds are run: the pull's control does not
change the closing or the letting go.

Each FEM hold takes minutes (2-12 min on the default mesh, one core each); rows are appended to a
JSON-lines file as they finish, and a run started again skips the cases already there. Split the
cases over processes with ``--worker k/n``; ``--table`` prints the comparison of what is in the
file (seconds).

    python benchmarks/hold_pull_control.py [--out results/hold_pull_control.jsonl] [--worker 0/2] [--only TEXT]
    python benchmarks/hold_pull_control.py --table [--out ...] [--markdown]
"""
from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

from softhand.studies import hold_reference as reference

DEFAULT_OUT = Path("results/hold_pull_control.jsonl")


def held_cases(data: dict) -> list[dict]:
    """The kept cases the FEM holds (a limit, or its whole weight with no pull to spare)."""
    return [c for c in data["cases"] if c["fem_limit_N"] > 0 or c.get("fem_weight_share", 0.0) >= 1.0]


def stepped(case: dict) -> float:
    """The case's holding limit with the pull stepped as a force."""
    return case.get("fem_limit_stepped_N", case["fem_limit_N"])


def done(out: Path) -> dict:
    """The rows in the JSON-lines file, by case name."""
    if not out.exists():
        return {}
    return {row["name"]: row for row in map(json.loads, out.read_text(encoding="utf-8").splitlines()) if row}


def run(out: Path, worker: tuple[int, int], only: str | None) -> None:
    from softhand.fem.hand.hold import solve_hold
    from softhand.fem.hand.hold_options import HoldOptions
    from softhand.reduced.holding.hold import DOWN

    data, (k, n) = reference.load(), worker
    finished = done(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="softhand-pull-") as folder:
        for i, case in enumerate(held_cases(data)):
            if i % n != k or case["name"] in finished or (only and only not in case["name"]):
                continue
            design, obj, P = reference.case_inputs(case, data["designs"], Path(folder))
            t0, pulls = time.perf_counter(), []

            def tick(record, name=case["name"]):
                if record.stage == "pull":
                    pulls.append([round(record.pull_N, 4), round(float(record.pose[1]), 3)])
                    print(f"  {name[:50]}: pull {record.pull_N:.4f} N, {record.pose[1]:.3f} mm down", flush=True)

            result = solve_hold(design, obj, P_cavity_MPa=P, pull_direction=case.get("pull", DOWN),
                                options=HoldOptions(pull_control="displacement"), progress=tick)
            row = {"name": case["name"], "stepped_N": stepped(case), "drawn_N": result.holding_limit_N,
                   "held": result.held, "P_cavity_MPa": P, "seconds": time.perf_counter() - t0,
                   "notes": list(result.notes), "pulls": pulls}
            with out.open("a", encoding="utf-8") as f:
                f.write(json.dumps(row) + "\n")
            print(f"{case['name']}: stepped {stepped(case):.3f} N, drawn {result.holding_limit_N:.3f} N "
                  f"({row['seconds']:.0f} s)", flush=True)


def table(out: Path, markdown: bool) -> None:
    data = reference.load()
    rows = done(out)
    cases = [c for c in held_cases(data) if c["name"] in rows]
    fast = {r.name: r for r in reference.compare() if r.name in rows}
    sep = " | " if markdown else "  "
    head = ["case", "stepped FEM [N]", "drawn FEM [N]", "fast [N]", "fast vs stepped", "fast vs drawn"]
    print(("| " + sep.join(head) + " |\n|" + "---|" * len(head)) if markdown else sep.join(head))
    within = {"stepped": [0, 0], "drawn": [0, 0]}
    for case in cases:
        r, f = rows[case["name"]], fast[case["name"]]
        errors = {}
        for key, fem in (("stepped", r["stepped_N"]), ("drawn", r["drawn_N"])):
            errors[key] = f.fast_limit_N / fem - 1.0 if f.fast_held and fem > 0 else float("nan")
            within[key][0] += abs(errors[key]) <= 0.05
            within[key][1] += abs(errors[key]) <= 0.10
        cells = [case["name"], f"{r['stepped_N']:.2f}", f"{r['drawn_N']:.2f}",
                 f"{f.fast_limit_N:.2f}" if f.fast_held else "not held",
                 *(f"{100 * e:+.1f} %" if e == e else "—" for e in (errors["stepped"], errors["drawn"]))]
        print(("| " + sep.join(cells) + " |") if markdown else sep.join(cells))
    total = sum(r["seconds"] for r in rows.values())
    print(f"# {len(cases)} FEM holds drawn ({total / 60:.0f} min of FEM); the fast limit within 5 % / 10 % of the "
          f"stepped FEM's on {within['stepped'][0]} / {within['stepped'][1]}, of the drawn FEM's on "
          f"{within['drawn'][0]} / {within['drawn'][1]}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT, help="the JSON-lines file of rows")
    parser.add_argument("--worker", default="0/1", help="k/n: run every n-th case from the k-th")
    parser.add_argument("--only", help="run only the cases whose name contains this")
    parser.add_argument("--table", action="store_true", help="print the comparison of the rows in --out")
    parser.add_argument("--markdown", action="store_true", help="with --table: a markdown table")
    args = parser.parse_args()
    if args.table:
        table(args.out, args.markdown)
        return
    k, n = (int(v) for v in args.worker.split("/"))
    if not 0 <= k < n:
        parser.error(f"--worker {args.worker}: k/n with 0 <= k < n")
    run(args.out, (k, n), args.only)


if __name__ == "__main__":
    main()
