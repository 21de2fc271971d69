"""``softhand study report``: plots and a Markdown summary of a study's results."""
from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np

from softhand.studies.io.files import save_figure, write_atomic
from softhand.studies.batch.cases import own_study_dir
from softhand.studies.batch.runner import index_rows, write_index
from softhand.studies.batch.studyfile import Study

MAX_LINES = 10  #: curves per plot; more combinations of the other axes are not drawn


def write_report(study: Study, results_root: str | Path = "results") -> Path:
    """Write ``results/<study>/report.md`` and ``report/*.png``; return the Markdown path."""
    sdir = own_study_dir(study, results_root, write=True, outputs=("index.csv", "report.md", "report"))
    rows = index_rows(study, results_root)
    write_index(study, results_root)
    axes = [name for name, _ in study.axes]
    done = [r for r in rows if r["status"] == "done"]
    outputs = _scalar_outputs(done, axes)
    figures = [_plot(study, done, axes, name, sdir / "report" / f"{name}.png")
               for name in outputs] if done else []
    text = _markdown(study, rows, axes, outputs, [f for f in figures if f], sdir)
    return write_atomic(sdir / "report.md", text)


def _scalar_outputs(rows: list[dict], axes: list[str]) -> list[str]:
    skip = {"case", "status", "wall_time_s", "error", *axes}
    names = dict.fromkeys(k for r in rows for k in r if k not in skip)
    # null: a case's nan (not applicable, e.g. a run that never settles), drawn as a gap
    return [n for n in names if all(_is_number(r.get(n)) or (n in r and r[n] is None) for r in rows)
            and any(_is_number(r.get(n)) for r in rows)]


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _plot(study: Study, rows: list[dict], axes: list[str], name: str, path: Path) -> Path | None:
    """``name`` against the first numeric axis, one line per combination of the others."""
    xaxis = next((a for a in axes if all(_is_number(r[a]) for r in rows)), None)
    if xaxis is None:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    others = [a for a in axes if a != xaxis]
    groups = {}
    for row in rows:
        groups.setdefault(tuple(row[a] for a in others), []).append(row)
    fig, ax = plt.subplots(figsize=(5.5, 3.8))
    for label, members in itertools.islice(groups.items(), MAX_LINES):
        members.sort(key=lambda r: r[xaxis])
        x = np.array([r[xaxis] for r in members], dtype=float)
        y = np.array([np.nan if r[name] is None else r[name] for r in members], dtype=float)
        text = ", ".join(f"{a}={v}" for a, v in zip(others, label)) or None
        ax.plot(x, y, "o-", ms=3, label=text)
    ax.set_xlabel(xaxis)
    ax.set_ylabel(name)
    ax.set_title(f"{study.name}: {name}")
    ax.grid(alpha=0.3)
    if others:
        ax.legend(fontsize=7)
    return save_figure(fig, path)


def _markdown(study: Study, rows, axes, outputs, figures, sdir: Path) -> str:
    counts = {s: sum(r["status"] == s for r in rows) for s in ("done", "failed", "pending")}
    lines = [f"# Study `{study.name}` ({study.kind})", ""]
    if study.description:
        lines += [study.description, ""]
    lines += [f"- design hash: `{study.design.hash()}`",
              *(f"- sweep `{name}`: {_short(values)}" for name, values in study.axes),
              *(f"- fixed `{k}` = {v}" for k, v in study.params.items()),
              f"- cases: {len(rows)} — done {counts['done']}, failed {counts['failed']}, "
              f"pending {counts['pending']}", ""]
    lines += [f"![{f.stem}]({f.relative_to(sdir).as_posix()})" for f in figures] + [""]
    columns = ["case", "status", *axes, *outputs]
    lines += ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(_cell(r.get(c)) for c in columns) + " |" for r in rows]
    failed = [r for r in rows if r["status"] == "failed"]
    if failed:
        lines += ["", "## Failed cases", ""]
        lines += [f"- `{r['case']}` ({_point(r, axes)}): {r['error']}" for r in failed]
    return "\n".join(lines) + "\n"


def _short(values) -> str:
    if len(values) <= 8:
        return ", ".join(map(str, values))
    return f"{values[0]} … {values[-1]} ({len(values)} values)"


def _point(row: dict, axes: list[str]) -> str:
    return ", ".join(f"{a}={row[a]}" for a in axes)


def _cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.5g}"
    return str(value)
