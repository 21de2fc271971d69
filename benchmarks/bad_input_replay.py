"""Replay bad inputs against the installed ``softhand`` command, one subprocess per case.

    python benchmarks/bad_input_replay.py [--timeout 60] [--only VERB] [-v]

Every case must exit 2 with exactly one line on stderr (``softhand ...: error: ...``), no
traceback, nothing on stdout and nothing written in its scratch folder. Each case runs in a
fresh copy of the scratch folder (inputs of every file type: designs, studies, tasks, design
spaces, CSV data, VTK). A case that runs longer than the timeout has started work instead of
refusing it. Prints the cases that fail and a count; exit 1 if any failed.
"""
from __future__ import annotations

import argparse
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "tests"), str(ROOT / "tests" / "studies")]  # the cases and their files

from test_bad_inputs import FILES, STUDIES, _design_files  # noqa: E402
from bad_input_cases import EXTRA_FILES, replay_cases  # noqa: E402


def _scratch(root: Path) -> None:
    for name, text in {**FILES, **_design_files(), **STUDIES, **EXTRA_FILES}.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(text if isinstance(text, bytes) else text.encode())
    (root / "adir").mkdir()


def _snapshot(root: Path) -> dict:
    return {str(p.relative_to(root)): p.stat().st_mtime_ns for p in root.rglob("*")}


def _one(argv, template: Path, timeout: float) -> str | None:
    """None if the case is refused cleanly, else what went wrong."""
    work = Path(tempfile.mkdtemp(prefix="replay-"))
    try:
        shutil.copytree(template, work, dirs_exist_ok=True, symlinks=True)
        before = _snapshot(work)
        env = {**os.environ, "SOFTHAND_CACHE": str(work / "cache")}
        start = time.monotonic()
        try:
            proc = subprocess.Popen([sys.executable, "-m", "softhand.studies.cli", *argv], cwd=work,
                                    env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                    start_new_session=True)
        except OSError as exc:  # e.g. an argument longer than the system allows: no shell can
            return None if exc.errno == 7 else f"cannot start: {exc}"
        try:
            out, err = proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()
            return f"still running after {timeout:g} s (work started, not refused)"
        err = err.decode(errors="replace")
        lines = err.splitlines()
        problems = []
        if proc.returncode != 2:
            problems.append(f"exit {proc.returncode}")
        if len(lines) != 1:
            problems.append(f"{len(lines)} stderr lines")
        if "Traceback" in err:
            problems.append("traceback")
        if lines and not (lines[-1].startswith("softhand") and "error:" in lines[-1]):
            problems.append("not a softhand error line")
        if len(err) > 1500:
            problems.append(f"{len(err)} characters on stderr")
        if out:
            problems.append("stdout not empty")
        after = _snapshot(work)
        changed = sorted(k for k in after if before.get(k) != after[k])
        if changed:
            problems.append(f"wrote {changed[:3]}")
        if not problems:
            return None
        tail = lines[-1][:300] if lines else ""
        return f"{', '.join(problems)} ({time.monotonic() - start:.1f} s): {tail}"
    finally:
        shutil.rmtree(work, ignore_errors=True)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timeout", type=float, default=60.0)
    parser.add_argument("--only", default=None, help="run only the cases of these verbs (a,b)")
    parser.add_argument("-v", "--verbose", action="store_true")
    args = parser.parse_args()
    only = None if args.only is None else args.only.split(",")
    cases = [(n, a) for n, a in replay_cases() if only is None or (a and a[0] in only)]
    failed = 0
    with tempfile.TemporaryDirectory() as tmp:
        template = Path(tmp)
        _scratch(template)
        for name, argv in cases:
            problem = _one(argv, template, args.timeout)
            if problem:
                failed += 1
                print(f"FAIL {name}: softhand {' '.join(argv)[:160]}\n     {problem}", flush=True)
            elif args.verbose:
                print(f"ok   {name}", flush=True)
    print(f"{len(cases) - failed} of {len(cases)} cases refused cleanly; {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
