"""docs/tutorial.md prints what it shows: every ``$ softhand ...`` line is run, in order.

As the README's samples (test_samples.py's reader and comparison: words exactly, numbers
to the digits shown, ``...`` for any run of lines, ``(exit code N)`` after the last line),
but each command runs as the user runs it, a process of its own in one scratch folder that
sees the repository's ``docs/`` and ``studies/`` (a later step reads what an earlier one
wrote). A shown line that starts with ``softhand VERB:`` is a line of stderr (a note, an
error, ``wrote FILE``), the others are stdout. The FEM steps (the design's proof, its
picture) run on the tutorial task's CI-sized mesh and take minutes: marked slow.
"""
from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from test_samples import _EXIT, _matches, _same_line, samples

ROOT = Path(__file__).resolve().parents[2]
TEXT = (ROOT / "docs" / "tutorial.md").read_text()
STEPS = [s for s in samples(TEXT) if s[0].startswith("softhand ")]
#: the steps with the FEM in them (minutes on two loaded cores), and those reading its results
SLOW = ("softhand design ", "softhand inspect ")
FEM_RESULT = "mygripper/"
_STDERR = re.compile(r"^softhand [a-z ]+: ")


def test_the_tutorial_shows_its_files_as_they_are():
    """The design, task and data files the tutorial prints are the ones shipped in docs/tutorial/."""
    for name in ("gripper.toml", "ball160.toml"):
        assert (ROOT / "docs" / "tutorial" / name).read_text().strip() in TEXT, name
    assert len(STEPS) >= 8 and any(c.startswith("softhand design ") for c, _ in STEPS)


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    folder = tmp_path_factory.mktemp("tutorial")
    for name in ("docs", "studies"):
        (folder / name).symlink_to(ROOT / name)
    return folder


def _in_order(shown: list[str], printed: list[str]) -> bool:
    """Each shown line matches a printed line, in the order shown."""
    rest = iter(printed)
    return all(any(_same_line(line, p) for p in rest) for line in shown)


@pytest.mark.parametrize("command, shown", [
    pytest.param(c, s, marks=pytest.mark.slow) if c.startswith(SLOW) or FEM_RESULT in c else (c, s)
    for c, s in STEPS],
    ids=[c for c, _ in STEPS])
def test_a_tutorial_step_prints_what_the_tutorial_shows(command, shown, scratch):
    argv = shlex.split(command.split("  #")[0])[1:]
    code = _EXIT.search(shown[-1]) if shown else None
    shown = [_EXIT.sub("", line) for line in shown]
    while shown and not shown[-1]:
        shown.pop()
    run = subprocess.run([sys.executable, "-m", "softhand.studies.cli.main", *argv], cwd=scratch,
                         capture_output=True, text=True, timeout=1800)
    assert run.returncode == (int(code.group(1)) if code else 0), (command, run.stderr[-2000:])
    out = [line.rstrip() for line in run.stdout.rstrip("\n").splitlines()]
    err = [line.rstrip() for line in re.split(r"[\r\n]", run.stderr) if _STDERR.match(line)]
    want_out = [line for line in shown if not _STDERR.match(line)]
    want_err = [line for line in shown if _STDERR.match(line)]
    assert _matches(want_out, out), f"{command}\n--- tutorial\n" + "\n".join(want_out) + "\n--- printed\n" + "\n".join(out)
    assert _in_order(want_err, err), f"{command}\n--- tutorial\n" + "\n".join(want_err) + "\n--- stderr\n" + "\n".join(err)
