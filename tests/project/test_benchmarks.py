"""The benchmark scripts stay runnable: each imports what it uses (a moved module or test file
breaks a script no test runs), and the bad-input replay runs its cases of one verb."""
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCRIPTS = sorted((ROOT / "benchmarks").glob("*.py"))


@pytest.mark.parametrize("script", SCRIPTS, ids=[s.name for s in SCRIPTS])
def test_a_benchmark_script_imports(script):
    """Its imports and definitions, without running it (loaded under a name other than __main__)."""
    code = (f"import runpy, sys; sys.path.insert(0, {str(script.parent)!r}); "  # as a script: its folder first
            f"runpy.run_path({str(script)!r}, run_name='imported')")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert run.returncode == 0, run.stderr[-2000:]


def test_the_bad_input_replay_refuses_every_hold_case():
    run = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "bad_input_replay.py"), "--only", "hold"],
                         capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert run.returncode == 0 and run.stdout.strip().endswith("0 failed"), run.stdout[-2000:] + run.stderr[-2000:]
