"""What a section of ``softhand reproduce`` is: the context it receives, its outcome, and the
Markdown table its text uses. The section builders (:mod:`softhand.studies.reproduce.sections`,
:mod:`softhand.studies.reproduce.fem_sections`) and the report (:mod:`softhand.studies.reproduce.core`) import
this module, never each other.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from softhand.reduced.vocabulary.design import HandDesign


@dataclass(frozen=True)
class Context:
    """What every section receives."""

    design: HandDesign  #: the hand (default: the paper's Table I)
    quick: bool = False  #: CI-sized meshes and fewer points
    progress: bool = True  #: the sections' own progress bars (long FEM paths) on stderr


@dataclass(frozen=True)
class Section:
    """One result of the paper: ``build(ctx, outdir) -> (markdown, numbers)``."""

    key: str  #: folder name under the output directory
    title: str
    needs: tuple[str, ...]  #: "module" or "module:attribute" that must exist
    build: Callable  #: writes files into outdir; returns (markdown body, {name: number})
    in_quick: bool = True  #: False: skipped by --quick (reported as such)
    #: rough cost (seconds with --quick on 2 cores): sections built side by side start costliest first
    cost: float = 0.0


@dataclass
class Outcome:
    """What became of a section in one run."""

    section: Section
    status: str  #: 'done', 'reused', 'failed', 'not available', 'not selected', 'skipped'
    detail: str = ""  #: error or missing module
    wall_time_s: float = 0.0
    numbers: dict | None = None


def md_table(rows: list[dict], columns: list[str] | None = None, *, digits: int = 4) -> str:
    """A Markdown table of ``rows`` (dicts); floats to ``digits`` significant digits."""
    columns = columns or list(rows[0])

    def cell(v):
        if isinstance(v, (float, np.floating)):
            return f"{v:.{digits}g}"
        if isinstance(v, (list, tuple, np.ndarray)):
            return "(" + ", ".join(cell(x) for x in v) + ")"
        return str(v)

    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(cell(r.get(c, "")) for c in columns) + " |" for r in rows]
    return "\n".join(lines)
