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


def test_the_calibration_estimate_deals_cases_to_the_worker_that_frees_first():
    """bench_calibration's table time for N workers from measured case times: the list schedule
    worked by hand (2 workers: 3 | 3, then 2 to each, then the last 2 to the first: 7)."""
    import runpy

    bench = runpy.run_path(str(ROOT / "benchmarks" / "bench_calibration.py"), run_name="imported")
    schedule = bench["list_schedule"]
    assert schedule([3.0, 3.0, 2.0, 2.0, 2.0], 2) == 7.0
    assert schedule([3.0, 3.0, 2.0, 2.0, 2.0], 1) == 12.0
    assert schedule([3.0, 3.0, 2.0, 2.0, 2.0], 8) == 3.0  # more workers than cases: the longest
    assert schedule([1.0, 1.0, 1.0, 5.0], 2) == 6.0  # in order, not longest first (that would give 5)
