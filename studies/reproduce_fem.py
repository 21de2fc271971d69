"""The FEM sections of ``softhand reproduce`` (see :mod:`studies.reproduce_sections`).

Each calls the owning study module's library function with the section's mesh size:
CI-sized with ``--quick``, the module's default otherwise.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from studies.output import save_figure, write_csv
from studies.reproduce import Context, Section
from studies.reproduce_sections import figure, md_table


# ---------------------------------------------------------------------- FEM verification
def verify(ctx: Context, outdir: Path):
    """The FEM core against closed forms (``softhand verify``), case by case."""
    from studies.verify import REGISTRY, run_case

    rows, errors = [], []
    for name in REGISTRY:
        try:
            checks, seconds = run_case(name, quick=ctx.quick)
        except Exception as exc:  # one broken case must not hide the others
            errors.append(f"- `{name}`: {type(exc).__name__}: {exc}")
            continue
        rows += [{**c.row(), "wall_time_s": seconds} for c in checks]
    if rows:
        write_csv(outdir / "verify.csv", rows)
    passed = sum(bool(r["passed"]) for r in rows)
    numbers = {"checks": len(rows), "passed": passed, "cases_failing_to_run": len(errors),
               "max_rel_error": max((r["rel_error"] for r in rows), default=math.nan)}
    table = md_table(rows, ["case", "quantity", "exact", "fem", "rel_error", "tolerance",
                            "passed"]) if rows else "*no check ran*"
    text = f"""The FEM core against closed forms ({'CI-sized' if ctx.quick else 'default'} meshes):
{passed} of {len(rows)} checks pass ([verify.csv](verify.csv)).

{table}
"""
    if errors:
        text += "\nCases that did not run:\n\n" + "\n".join(errors) + "\n"
    return text, numbers


SECTIONS: list[Section] = [
    Section("verify", "FEM verification against closed forms",
            ("studies.verify:run_case", "studies.verify:REGISTRY"), verify, in_quick=False),
]
