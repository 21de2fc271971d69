"""The report of ``softhand reproduce``: ``report.md`` (the sections in order, each with its
text, figures and links, or why it is missing) and ``summary.csv`` (every headline number)."""
from __future__ import annotations

import re
from datetime import datetime, timezone
from pathlib import Path

from softhand.studies.batch.runner import FAILED, code_version
from softhand.studies.io.files import write_atomic, write_csv
from softhand.studies.io.outputs import record_outputs
from softhand.studies.reproduce.section import Context, Outcome

SECTION_MD = "section.md"  #: a section's own text, in its folder
#: the files a run writes beside the section folders
REPORT_FILES = ("report.md", "summary.csv")


def write_report(out: Path, ctx: Context, outcomes: list[Outcome]) -> Path:
    """``report.md`` (sections in order, with their figures) and ``summary.csv``."""
    code = code_version()
    lines = ["# softhand reproduce: the paper's results, recomputed", "",
             f"- generated {datetime.now(timezone.utc).isoformat(timespec='seconds')}, "
             f"softhand {code['softhand']} (sources {code['source_sha256']})",
             f"- mode: {'quick (CI-sized meshes)' if ctx.quick else 'full'}; "
             f"design hash `{ctx.design.hash()}`",
             "- every number below was computed by this code for these inputs; a section "
             "marked *reused* was computed by an earlier run of the identical code and inputs",
             "", "| section | status | wall time [s] | note |", "|---|---|---|---|"]
    lines += [f"| [{o.section.title}](#{_anchor(o.section.title)}) | {o.status} | "
              f"{o.wall_time_s:.1f} | {_one_line(o.detail)} |" for o in outcomes]
    for o in outcomes:
        lines += ["", f"## {o.section.title}", ""] + _body(out, o)
    out.mkdir(parents=True, exist_ok=True)
    write_csv(out / "summary.csv", _summary_rows(outcomes), ["section", "status", "name", "value"])
    report = write_atomic(out / "report.md", "\n".join(lines) + "\n")
    record_outputs(out, REPORT_FILES, verb="reproduce")
    return report


def _body(out: Path, o: Outcome) -> list[str]:
    if o.status in ("done", "reused"):
        text = (out / o.section.key / SECTION_MD).read_text()
        note = [f"*reused: computed {o.detail}*", ""] if o.status == "reused" else []
        return note + [_relink(text, o.section.key)]
    if o.status == "failed":
        return [f"**failed**: `{_one_line(o.detail)}` (traceback in "
                f"`{o.section.key}/{FAILED}`)"]
    return [f"*{o.status}*" + (f": {o.detail}" if o.detail else "")]


def _relink(markdown: str, folder: str) -> str:
    """Make a section's relative links (images, files) relative to the report."""
    return re.sub(r"\]\((?![a-z]+:|#|/)([^)]+)\)", rf"]({folder}/\1)", markdown)


def _anchor(title: str) -> str:
    return re.sub(r"[^a-z0-9 -]", "", title.lower()).replace(" ", "-")


def _one_line(text: str) -> str:
    return " ".join(str(text).split())[:200].replace("|", "/")


def _summary_rows(outcomes: list[Outcome]) -> list[dict]:
    rows = []
    for o in outcomes:
        for name, value in (o.numbers or {}).items():
            rows.append({"section": o.section.key, "status": o.status, "name": name,
                         "value": value})
        if not o.numbers:
            rows.append({"section": o.section.key, "status": o.status, "name": "", "value": ""})
    return rows
