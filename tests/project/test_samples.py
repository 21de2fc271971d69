"""The sample sessions of README.md and the docs pages print what the page shows.

Each ``$ softhand ...`` line of a code block of README.md or docs/*.md is run (in a scratch folder that sees the
repository's ``studies/``) and its output compared line by line with the lines below it (words exactly, numbers to the
digits shown): a
line ``...`` in the README skips printed lines up to the next one shown, and
``(exit code N)`` after a line marks an error line (on stderr) and the exit code. The FEM
verbs' samples (``verify``, ``bend``, ``weights``, ...) take minutes and are re-measured by
hand; these are the ones a test can afford. Each ``>>>`` Python session of those pages runs as a
doctest.
"""
import doctest
import re
import shlex
from pathlib import Path

import pytest

from softhand.studies.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
#: the pages whose samples are run: the front page and every docs page but the tutorial, whose
#: steps run in order, each as a process of its own (test_tutorial.py)
PAGES = [ROOT / "README.md", *sorted(p for p in (ROOT / "docs").glob("*.md") if p.name != "tutorial.md")]
#: the samples run here, by the start of their command line (all of the reduced model's
#: verbs, and the reservoir sheet's FEM, ~2 s)
FAST = ("curve ", "grasp ", "control ", "fit ", "material fit ", "reservoir")
_EXIT = re.compile(r"\s+\(exit code (\d+)\)$")


def samples(text: str):
    """[(command line, shown output lines)] of a page's code blocks, in order. A command line
    ending in ``\\`` goes on on the next; ``$ cat > FILE <<EOF`` shows a file's lines up to ``EOF``."""
    found, command, shown, inside, heredoc = [], None, [], False, None
    for line in text.splitlines():
        if heredoc is not None:
            if line.strip() == heredoc:
                found.append((command, shown))
                command, shown, heredoc = None, [], None
            else:
                shown.append(line)
            continue
        if line.strip().startswith("```"):
            if command is not None:
                found.append((command, shown))
            command, shown, inside = None, [], not inside
            continue
        if not inside:
            continue
        if line.strip().startswith("$ "):
            if command is not None:
                found.append((command, shown))
            command, shown = line.strip()[2:], []
            if command.startswith("cat > ") and "<<" in command:
                heredoc = command.split("<<")[1].strip().strip("'\"")
        elif command is not None and command.endswith("\\") and not shown:
            command = command[:-1].rstrip() + " " + line.strip()
        elif command is not None:
            shown.append(line.rstrip())
    return found


def _fast(command: str) -> bool:
    return command.startswith("cat > ") or (
        command.startswith("softhand ") and command[len("softhand "):].startswith(FAST))


#: the samples with output shown (a block may also list commands alone), page by page
SAMPLES = [(page.relative_to(ROOT).as_posix(), *s) for page in PAGES for s in samples(page.read_text())
           if _fast(s[0]) and any(s[1])]


_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _same_line(shown: str, printed: str) -> bool:
    """The same words, and numbers equal to the last digit shown (rel. 1e-3, or both below
    1e-9 in size: a round-off residual such as 5.8e-15 may differ between machines)."""
    if _NUMBER.sub("#", shown).split() != _NUMBER.sub("#", printed).split():
        return False
    pairs = zip(map(float, _NUMBER.findall(shown)), map(float, _NUMBER.findall(printed)))
    return all(abs(a - b) <= 1e-3 * abs(a) or max(abs(a), abs(b)) < 1e-9 for a, b in pairs)


def _matches(shown: list[str], printed: list[str]) -> bool:
    """printed equals shown line by line, where a shown ``...`` stands for any run of printed lines."""
    if not shown:
        return not printed
    if shown[0] == "...":
        return any(_matches(shown[1:], printed[k:]) for k in range(len(printed) + 1))
    return bool(printed) and _same_line(shown[0], printed[0]) and _matches(shown[1:], printed[1:])


def test_the_pages_show_samples_of_every_fast_verb():
    shown = {c.split()[1] for _, c, _ in SAMPLES if c.startswith("softhand ")}
    assert shown >= {"curve", "grasp", "control", "fit", "material", "reservoir"}, shown


@pytest.fixture(scope="module")
def scratch(tmp_path_factory):
    """One folder for all samples (a later sample may read what an earlier one wrote)."""
    folder = tmp_path_factory.mktemp("readme")
    (folder / "studies").symlink_to(ROOT / "studies")
    return folder


@pytest.mark.parametrize("page, command, shown", SAMPLES, ids=[f"{p}: {c}" for p, c, _ in SAMPLES])
def test_a_sample_prints_what_its_page_shows(page, command, shown, scratch, monkeypatch, capsys):
    monkeypatch.chdir(scratch)
    if command.startswith("cat > "):  # a file a later sample reads
        (scratch / shlex.split(command)[2]).write_text("\n".join(shown) + "\n")
        return
    argv = shlex.split(command.split("  #")[0])[1:]
    code = _EXIT.search(shown[-1]) if shown else None
    shown = [_EXIT.sub("", line) for line in shown]
    while shown and not shown[-1]:
        shown.pop()
    try:
        got = main(argv)
    except SystemExit as exc:  # argparse's own errors
        got = exc.code
    out, err = capsys.readouterr()
    expected = int(code.group(1)) if code else 0
    assert got == expected, (command, err)
    printed = (err if code else out).rstrip("\n").splitlines()
    assert _matches(shown, [line.rstrip() for line in printed]), (
        f"{command}\n--- {page}\n" + "\n".join(shown) + "\n--- printed\n" + "\n".join(printed))


def test_the_front_page_shows_a_python_session():
    assert "\n>>> " in (ROOT / "README.md").read_text()


@pytest.mark.parametrize("page", [p for p in PAGES if "\n>>> " in p.read_text()], ids=lambda p: p.name)
def test_a_python_session_prints_what_its_page_shows(page, monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    failed, tried = doctest.testfile(str(page), module_relative=False, verbose=False, report=True,
                                     optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert tried and not failed, f"{page.name}: {failed} of {tried} examples failed (printed above)"
