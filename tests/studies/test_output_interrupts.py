"""What the outputs rule promises, in real processes: a file-size limit (RLIMIT_FSIZE) during a
write, SIGTERM and SIGKILL during a run, two runs into one folder (docs/outputs.md)."""
import json
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from softhand.studies.io.files import EXIT_UNWRITTEN

from softhand.studies.io.outputs import INCOMPLETE, MANIFEST

ROOT = Path(__file__).resolve().parents[2]
#: real bend FEM runs in subprocesses: 2 to 8 minutes in all (part of the CI suite)
pytestmark = pytest.mark.slow
#: the bend verb, its VTK writer marking each state written (``MARK``) and then sleeping
#: ``SLEEP`` seconds: time to signal a run while its series is half-written
BEND = '''
import os, sys, time
from softhand.studies import bending
real = bending.vtk_writer
def slow_writer(path, then=None):
    writer = real(path, then)
    inner = writer.write
    def write(model, y, P):
        inner(model, y, P)
        with open(os.environ["MARK"], "a") as f:
            f.write(f"{P}\\n")
        time.sleep(float(os.environ.get("SLEEP", "0")))
    writer.write = write
    return writer
bending.vtk_writer = slow_writer
from softhand.studies.cli.main import main
sys.exit(main(sys.argv[1:]))
'''
#: a small, quick finger FEM (coarse layered mesh, two pressures)
BEND_ARGS = ["bend", "--peak-mpa", "0", "--axial-size-mm", "20", "--no-progress"]


def _env(tmp_path, **extra) -> dict:
    return {**os.environ, "SOFTHAND_CACHE": str(tmp_path / "cache"),
            "PYTHONDONTWRITEBYTECODE": "1", "MARK": str(tmp_path / "mark"), **extra}


def _bend(tmp_path, out, pressures="0.1,0.2", limit=None, **env):
    def fsize():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return subprocess.Popen([sys.executable, "-c", BEND, *BEND_ARGS, "--pressure-mpa", pressures,
                             "--out", str(out)], env=_env(tmp_path, **env), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, preexec_fn=fsize if limit else None,
                            cwd=tmp_path)


def _visible(folder: Path) -> dict:
    """What a reader of ``folder`` sees: every file not hidden, with its bytes."""
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file() and not any(part.startswith(".") for part in p.relative_to(folder).parts)}


@pytest.fixture(scope="module")
def earlier(tmp_path_factory) -> Path:
    """A complete bend result (0.1 and 0.2 MPa), copied by each test as its earlier run."""
    tmp = tmp_path_factory.mktemp("earlier")
    run = _bend(tmp, tmp / "out")
    out, err = run.communicate(timeout=600)
    assert run.returncode == 0, err
    return tmp / "out"


def _copy(earlier: Path, tmp_path) -> Path:
    out = tmp_path / "out"
    shutil.copytree(earlier, out)
    return out


def _wait_for_mark(tmp_path, run, timeout=300.0) -> None:
    """Until the run has written a state into its staging folder."""
    start = time.monotonic()
    while not (tmp_path / "mark").exists() or not (tmp_path / "mark").read_text().strip():
        assert run.poll() is None, run.communicate()
        assert time.monotonic() - start < timeout
        time.sleep(0.1)


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGKILL])
def test_a_signalled_rerun_leaves_the_earlier_result_whole(earlier, tmp_path, signum):
    """SIGTERM or SIGKILL while the rerun's series is half-written: the folder still shows the
    earlier complete result, byte for byte (an interrupted rerun had left it empty; after
    kill -9 a partial finger.pvd without result.json was read as a normal series)."""
    out = _copy(earlier, tmp_path)
    before = _visible(out)
    run = _bend(tmp_path, out, "0.15,0.25", SLEEP="60")
    _wait_for_mark(tmp_path, run)
    run.send_signal(signum)
    _, err = run.communicate(timeout=60)
    assert _visible(out) == before
    if signum == signal.SIGTERM:
        assert run.returncode == 130 and "Traceback" not in err
        assert sorted(p.name for p in out.iterdir() if p.name.startswith(".")) == [MANIFEST]
        return
    stages = [p for p in out.iterdir() if p.name.startswith(".softhand-stage-")]
    assert len(stages) == 1 and (stages[0] / "finger.pvd").exists()  # hidden, and never read
    # the next run resumes: it completes, replaces the earlier result whole, removes the stage
    (tmp_path / "mark").unlink()
    rerun = _bend(tmp_path, out, "0.15,0.25")
    _, err = rerun.communicate(timeout=600)
    assert rerun.returncode == 0, err
    assert not any(p.name.startswith(".softhand-stage-") for p in out.iterdir())
    result = json.loads((out / "result.json").read_text())
    assert [row["P_cavity_MPa"] for row in result["rows"]] == pytest.approx([0.15, 0.25])


def test_two_runs_into_one_folder_leave_one_whole_result(tmp_path):
    """Two bend runs into one folder both exited 0 with the folder's finger.pvd describing one
    run and its states partly the other's. Now each stages its own; the one that finishes last
    replaces the other's whole and says so; the folder holds one run's files only."""
    out = tmp_path / "out"
    runs = [_bend(tmp_path, out, p) for p in ("0.1,0.2", "0.15,0.25,0.3")]
    outputs = [run.communicate(timeout=900) for run in runs]
    assert [run.returncode for run in runs] == [0, 0], [e for _, e in outputs]
    assert sum("another run finished into" in err for _, err in outputs) == 1
    rows = json.loads((out / "result.json").read_text())["rows"]
    pressures = [row["P_cavity_MPa"] for row in rows]
    assert pressures in ([0.1, 0.2], [0.15, 0.25, 0.3])
    steps = re.findall(r'timestep="([^"]+)"[^>]*file="([^"]+)"', (out / "finger.pvd").read_text())
    assert [float(t) for t, _ in steps] == pytest.approx(pressures)
    assert all((out / name).is_file() for _, name in steps)
    assert sorted(p.name for p in (out / "finger").glob("*.vtm")) == [Path(n).name for _, n in steps]
    assert len((out / "table.csv").read_text().splitlines()) == len(pressures) + 1


def test_a_file_size_limit_is_one_warning_the_results_printed_and_the_pieces_kept(earlier, tmp_path):
    """RLIMIT_FSIZE of 200 kB: the finger's VTK blocks cannot be written; result.json and
    table.csv can. One warning line, exit 3, the table on stdout, the pieces written in
    DIR/incomplete/ and the earlier result untouched."""
    out = _copy(earlier, tmp_path)
    before = _visible(out)
    run = _bend(tmp_path, out, "0.15,0.25", limit=200_000)
    stdout, err = run.communicate(timeout=600)
    assert run.returncode == EXIT_UNWRITTEN, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "warning" in lines[0] and "File too large" in lines[0], lines
    assert "0.15" in stdout and "0.25" in stdout  # the rows
    assert {k: v for k, v in _visible(out).items() if not k.startswith(INCOMPLETE)} == before
    kept = json.loads((out / INCOMPLETE / "result.json").read_text())
    assert [row["P_cavity_MPa"] for row in kept["rows"]] == pytest.approx([0.15, 0.25])
    record = json.loads((out / INCOMPLETE / MANIFEST).read_text())
    assert record["complete"] is False and "finger.pvd" in record["missing"][0]


def _limited(tmp_path, argv, limit):
    def fsize():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return subprocess.run([sys.executable, "-m", "softhand.studies.cli.main", *argv], env=_env(tmp_path),
                          capture_output=True, text=True, preexec_fn=fsize, cwd=tmp_path, timeout=600)


GOOD_MATERIAL = ("mode,stretch,stress_MPa\nuniaxial,1.2,0.203\nuniaxial,1.5,0.421\nuniaxial,1.8,0.598\n"
                 "uniaxial,2.1,0.748\nuniaxial,2.4,0.893\nuniaxial,2.7,1.024\nuniaxial,3,1.157\n")


@pytest.mark.parametrize("verb", ["design", "material", "inspect", "study"])
def test_other_verbs_under_a_file_size_limit(earlier, tmp_path, verb):
    """design (16 s of work, nothing printed), material fit --out (the fit not printed),
    inspect --out and study run (the run stopped) ended in tracebacks: now one warning line,
    exit 3, the results on stdout, what was finished kept."""
    task = ROOT / "studies" / "designs" / "tasks" / "paper_task.toml"
    (tmp_path / "m.csv").write_text(GOOD_MATERIAL)
    (tmp_path / "s.toml").write_text('kind = "curve"\n[sweep]\ntheta_deg = [10, 20, 30]\n')
    argv, limit, printed = {
        "design": (["design", "--task", str(task), "--no-fem", "--no-progress", "--out", "d"], 100, "optimum:"),
        "material": (["material", "fit", "--data", "m.csv", "--model", "yeoh", "--out", "m.toml"], 20, "C10"),
        # inspect colours by the converged rubber stretch by default and prints its range
        "inspect": (["inspect", str(earlier / "finger.pvd"), "--out", "x.png"], 1000, "rubber_stretch"),
        "study": (["study", "run", "s.toml", "--workers", "1", "--results", "r", "--no-progress"], 300,
                  "0 done"),
    }[verb]
    run = _limited(tmp_path, argv, limit)
    assert run.returncode == EXIT_UNWRITTEN, run.stderr
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and "warning" in lines[0] and "File too large" in lines[0], lines
    assert printed in run.stdout
    if verb == "design":  # nothing half-written in the folder, the pieces in incomplete/
        assert not (tmp_path / "d" / "result.json").exists()
