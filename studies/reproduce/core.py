"""``softhand reproduce``: every result of the paper, end to end, into one report.

The report is a list of :class:`~softhand.studies.reproduce.section.Section` s. Each calls the owning module's library
function (never the CLI), writes its PNG/CSV/VTK files and a ``section.md`` into its
own folder ``<out>/<section>/``, and returns its headline numbers. A section is

* **not available** when a module or function it needs is not in this build;
* **failed** when it raises: the error is reported and the other sections go on;
* **reused** when ``<out>/<section>/result.json`` holds the same inputs (section,
  size, design hash, code version): a killed or repeated run resumes where it
  stopped. ``fresh=True`` recomputes everything.

A section's folder is written through the batch runner (:func:`softhand.studies.batch.cases.execute_case`
in a private temporary folder, then :func:`softhand.studies.batch.cases.commit`: one rename), so an
interrupted run leaves nothing half-written. ``<out>/report.md`` and
``<out>/summary.csv`` are assembled from the section folders at the end.
"""
from __future__ import annotations

import hashlib
import importlib
import json
import math
import sys
from pathlib import Path

from softhand.reduced.equations import finger
from softhand.reduced.vocabulary import paper
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.io.outputs import MANIFEST, check_owned, record_outputs
from softhand.studies.reproduce.report import REPORT_FILES, SECTION_MD, write_report
from softhand.studies.reproduce.section import Context, Outcome, Section
from softhand.studies.batch.runner import FAILED, RESULT, code_version, commit, execute_case, outcome_record

#: the largest bend the report's sections ask of the hand (Figs. 7 and 8: 0-90 deg)
THETA_MAX_DEG = 90.0
_ACTIVE: dict = {}  #: the sections of the current reproduce() call, by key
_SHOW: dict = {"progress": True}  #: whether the current reproduce() call shows progress


def sections() -> list[Section]:
    """Every section of the report, in order (imported here to keep start-up light)."""
    from softhand.studies.reproduce import fem_sections as reproduce_fem
    from softhand.studies.reproduce import sections as reproduce_sections

    return reproduce_sections.REDUCED_SECTIONS + reproduce_fem.SECTIONS


def missing(section: Section) -> str:
    """'' if everything ``section`` needs exists, else what is missing."""
    for need in section.needs:
        module_name, _, attr = need.partition(":")
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as exc:
            return f"module {exc.name} is not in this build"
        if attr and not hasattr(module, attr):
            return f"{module_name}.{attr} is not in this build"
    return ""


def section_key(section: Section, ctx: Context) -> str:
    text = json.dumps({"section": section.key, "quick": ctx.quick, "design": ctx.design.hash(),
                       "code": code_version()}, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def run_section(params: dict, design: HandDesign, outdir: Path) -> dict:
    """A batch-runner kind: build one section into ``outdir``; return its numbers."""
    section = _ACTIVE.get(params["section"]) or next(
        s for s in sections() if s.key == params["section"])
    # progress is not a parameter of the case (it must not change what is reused)
    markdown, numbers = section.build(Context(design=design, quick=params["quick"],
                                              progress=_SHOW["progress"]), outdir)
    (outdir / SECTION_MD).write_text(markdown.strip() + "\n")
    return numbers


def check_design(design: HandDesign) -> None:
    """InputError naming the design's key if a section could not run for ``design``: its
    reservoir supplies the fingers up to THETA_MAX_DEG, and it has a hinge for each weight of
    the paper's weight vectors w, which the Table II and Fig. 8 sections use."""
    finger.check_volume(design, math.radians(THETA_MAX_DEG))
    hinges = len(paper.WEIGHTS[180.0])
    if design.n_s != hinges:
        raise InputError("n_s", design.n_s, f"must be {hinges}: the report's Table II and Fig. 8 sections "
                                            f"use the paper's weight vectors w, one weight per hinge")


def reproduce(out: str | Path = "results/reproduce", *, quick: bool = False,
              design: HandDesign | None = None, only: tuple[str, ...] | None = None,
              fresh: bool = False, progress: bool = True,
              section_list: list[Section] | None = None, workers: int = 1) -> list[Outcome]:
    """Build every section (or those in ``only``) and write ``<out>/report.md``.

    Each section's folder is renamed into ``out`` whole as it finishes and recorded in the
    folder's manifest (:func:`softhand.studies.io.outputs.record_outputs`): a rerun resumes
    from it, and a file or folder of the user's named like an output is refused before any
    work (InputError), never replaced. ``workers`` > 1: the sections to build run side by
    side in that many processes (the batch runner's pool, each with its share of the cores'
    threads), the costliest first; their own progress bars are then not drawn."""
    out = Path(out)
    ctx = Context(design=design or HandDesign(), quick=quick, progress=progress)
    _SHOW["progress"] = progress
    todo = section_list if section_list is not None else sections()
    _adopt_earlier(out, todo)
    check_owned(out, [*REPORT_FILES, *(s.key for s in todo)], "--out")
    _ACTIVE.clear()
    _ACTIVE.update((s.key, s) for s in todo)
    outcomes: dict[str, Outcome] = {}
    from tqdm import tqdm

    bar = tqdm(total=len(todo), desc="reproduce", unit="section", file=sys.stderr, disable=not progress)
    try:
        pending = []
        for section in todo:
            known = _known(section, ctx, out, only, fresh)
            if known is None:
                pending.append(section)
            else:
                outcomes[section.key] = known
                bar.update()
        if workers > 1 and len(pending) > 1:
            _build_side_by_side(pending, ctx, out, workers, outcomes, bar)
        else:
            for section in pending:  # one by one, in this process (each FEM path with its own bar)
                bar.set_postfix_str(section.key)
                outcomes[section.key] = _build(section, ctx, out)
                bar.update()
    finally:
        bar.close()
        write_report(out, ctx, [outcomes.get(s.key) or _not_built(s, ctx, only) or _finished(s, ctx, out, fresh)
                                or Outcome(s, "not run", "interrupted") for s in todo])
    return [outcomes[s.key] for s in todo]


def _build_side_by_side(pending: list[Section], ctx: Context, out: Path, workers: int,
                        outcomes: dict, bar) -> None:
    """Build ``pending`` in a pool of ``workers`` processes, the costliest first; each section
    is committed as it finishes (an interrupted run keeps those)."""
    from types import SimpleNamespace

    from softhand.studies.batch.cases import Case
    from softhand.studies.batch.pool import pool_outcomes

    cases = [Case(s.key, {}, {"section": s.key, "quick": ctx.quick}, ctx.design)
             for s in sorted(pending, key=lambda s: -s.cost)]
    workers = min(workers, len(pending))  # no idle process: each takes its share of the cores' threads
    show, _SHOW["progress"] = _SHOW["progress"], False  # the workers, forked now, draw no bars
    bar.set_postfix_str(f"{len(pending)} sections in {workers} processes")
    try:
        for case, output in pool_outcomes(SimpleNamespace(kind=run_section), iter(cases), workers):
            outcomes[case.key] = _commit(_ACTIVE[case.key], ctx, out, output)
            bar.update()
    finally:
        _SHOW["progress"] = show
    for section in pending:  # its worker died, and again in the pools that took it over
        outcomes.setdefault(section.key, Outcome(section, "failed", "its worker process died"))


def _adopt_earlier(out: Path, todo: list[Section]) -> None:
    """Record in the manifest the sections a run of an earlier softhand, which kept no
    manifest, left in ``out``: a plain folder whose own record names that section."""
    if not out.is_dir() or (out / MANIFEST).exists():
        return
    earlier = [s.key for s in todo if (out / s.key).is_dir() and not (out / s.key).is_symlink()
               and any((_read(out / s.key / name) or {}).get("section") == s.key for name in (RESULT, FAILED))]
    heads = {"report.md": "# softhand reproduce", "summary.csv": "section,status,name,value"}
    earlier += [name for name, head in heads.items() if earlier and _starts_with(out / name, head)]
    if earlier:
        record_outputs(out, earlier, verb="reproduce")


def _starts_with(path: Path, head: str) -> bool:
    from softhand.studies.io.files import read_bounded

    try:
        return path.is_file() and not path.is_symlink() and read_bounded(path, 1 << 24).startswith(head)
    except (OSError, ValueError):
        return False


def _not_built(section: Section, ctx: Context, only) -> Outcome | None:
    """The outcome of a section this run leaves out by choice (``--only``, ``--quick``), else None."""
    if only is not None and section.key not in only:
        return Outcome(section, "not selected")
    if ctx.quick and not section.in_quick:
        return Outcome(section, "skipped", "not part of --quick")
    return None


def _known(section: Section, ctx: Context, out: Path, only, fresh: bool) -> Outcome | None:
    """The section's outcome when this run does not build it (left out, not available, or
    finished by an earlier run), else None."""
    chosen = _not_built(section, ctx, only)
    if chosen is not None:
        return chosen
    try:
        lack = missing(section)
    except Exception as exc:  # the module exists but does not import: a failure, not absence
        return Outcome(section, "failed", f"{type(exc).__name__}: {exc}")
    if lack:
        return Outcome(section, "not available", lack)
    return _finished(section, ctx, out, fresh)


def _build(section: Section, ctx: Context, out: Path) -> Outcome:
    """Build the section in this process and commit it."""
    output = execute_case(run_section, {"section": section.key, "quick": ctx.quick}, ctx.design)
    return _commit(section, ctx, out, output)


def _commit(section: Section, ctx: Context, out: Path, output: dict) -> Outcome:
    """Rename the built section's folder into ``out`` (its record with it); its outcome."""
    params = {"section": section.key, "quick": ctx.quick}
    commit(out / section.key, {"section": section.key, "case": section_key(section, ctx),
                               **outcome_record(params, ctx.design, output)}, output.get("files", {}))
    record_outputs(out, [section.key], verb="reproduce")
    if output["status"] != "done":
        return Outcome(section, "failed", output["error"], output["wall_time_s"])
    return Outcome(section, "done", "", output["wall_time_s"], output["numbers"])


def _finished(section: Section, ctx: Context, out: Path, fresh: bool) -> Outcome | None:
    """The section's result on disk if it is this run's (same inputs, no ``--fresh``), else None."""
    previous = None if fresh else _read(out / section.key / RESULT)
    if previous and previous.get("case") == section_key(section, ctx):
        return Outcome(section, "reused", previous["provenance"]["finished_utc"],
                       previous["provenance"]["wall_time_s"], previous["numbers"])
    return None


def _read(path: Path) -> dict | None:
    """A section's record; None if missing or damaged (too large, a FIFO, nested too deep)."""
    from softhand.studies.io.files import read_bounded

    try:
        return json.loads(read_bounded(path, 64 << 20))
    except (OSError, ValueError, RecursionError):
        return None


def exit_code(outcomes: list[Outcome]) -> int:
    return 1 if any(o.status == "failed" for o in outcomes) else 0

