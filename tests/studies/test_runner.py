"""The batch runner: Dask == process pool, kill and resume, failures recorded, case keys."""
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from softhand.reduced.vocabulary.design import HandDesign
from softhand.studies.cli.main import main
from softhand.studies.batch.runner import RESULT, case_key, plan, run_study, status, study_dir
from softhand.studies.batch.studyfile import load_study

ROOT = Path(__file__).resolve().parents[2]

N_SLOW = 24  # cases of the killed-run test
SLOW_KIND = '''
import time
def case(params, design, outdir):
    time.sleep(params["sleep_s"])
    (outdir / "field.txt").write_text("x" * 100000)   # a file the kind writes, like a VTK
    return {"y": params["x"] ** 2 * design.mu_sf}
'''


def install_kind(where: Path, module: str, code: str) -> str:
    """A plugin kind as an installed package declares it: module ``module`` with a ``case``
    function, and a dist-info whose ``softhand.kinds`` entry point names it; on the path
    once ``where`` is on sys.path / PYTHONPATH. Returns the kind's name."""
    (where / f"{module}.py").write_text(code)
    dist = where / f"softhand_test_{module}-0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text(f"Metadata-Version: 2.1\nName: softhand-test-{module}\nVersion: 0\n")
    (dist / "entry_points.txt").write_text(f"[softhand.kinds]\n{module} = {module}:case\n")
    return module


def write_study(tmp_path, text, name="s.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def results_by_key(root: Path, study) -> dict:
    sdir = study_dir(study, root)
    return {c.key: json.loads((sdir / c.key / RESULT).read_text())["numbers"] for c in plan(study)}


def test_dask_local_cluster_gives_the_same_results_as_the_process_pool(tmp_path):
    pytest.importorskip("dask.distributed")
    study = load_study(write_study(tmp_path, 'kind = "curve"\n[sweep]\n'
                                   'theta_deg = "0:90:15"\nmu_sf_MPa = [1.0, 1.3]\n'))
    pool = run_study(study, results_root=tmp_path / "pool", workers=2, progress=False)
    dask = run_study(study, results_root=tmp_path / "dask", workers=2, scheduler="local",
                     progress=False)
    assert pool.ok and dask.ok and pool.computed == dask.computed == 14
    a, b = results_by_key(tmp_path / "pool", study), results_by_key(tmp_path / "dask", study)
    assert a == b  # bit-identical: the same function on the same inputs
    # and the curve is the curve: without reservoir P(0) = 0 (eq. (28)), P rises with theta
    rows = sorted((c.point["mu_sf_MPa"], c.point["theta_deg"], a[c.key]) for c in plan(study))
    assert all(r[2]["P_cavity_MPa"] == 0.0 for r in rows if r[1] == 0.0)


def _default_sigint():
    """The child's SIGINT disposition back to the default, as a terminal's foreground job has
    it. A test run started in the background of a shell without job control (``cmd &`` in a
    script, as a CI runner may do) has SIGINT ignored; that is inherited across exec, Python
    then installs no KeyboardInterrupt handler, and the child ran to the end (exit 0) despite
    the SIGINT."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGINT])
def test_killed_run_resumes_with_only_the_missing_cases(tmp_path, monkeypatch, sig):
    install_kind(tmp_path, "slowkind", SLOW_KIND)
    monkeypatch.syspath_prepend(str(tmp_path))
    # 24 cases of 0.25 s on 2 workers: 3 s, so the signal after the 3rd lands mid-run even on
    # a loaded machine (with 12 cases a loaded CI run once finished before the signal)
    path = write_study(tmp_path, 'kind = "slowkind"\n[params]\nsleep_s = 0.25\n'
                       f'[sweep]\nx = "1:{N_SLOW}:1"\n')
    study, root = load_study(path), tmp_path / "res"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(ROOT)])}
    proc = subprocess.Popen([sys.executable, "-m", "softhand.studies.cli.main", "study", "run", str(path),
                             "--workers", "2", "--results", str(root), "--no-progress"],
                            env=env, start_new_session=True, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, preexec_fn=_default_sigint)
    sdir = study_dir(study, root)
    deadline = time.monotonic() + 60
    while len(list(sdir.glob(f"[!.]*/{RESULT}"))) < 3 and time.monotonic() < deadline:
        time.sleep(0.05)
    os.killpg(proc.pid, sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == (-signal.SIGKILL if sig == signal.SIGKILL else 130), err.decode()[-2000:]

    # every case folder that exists is complete and readable
    before = {p.parent.name: p.read_bytes() for p in sdir.glob(f"[!.]*/{RESULT}")}
    folders = [p for p in sdir.iterdir() if p.is_dir() and not p.name.startswith(".")]
    assert {p.name for p in folders} == set(before)
    assert all(json.loads(b)["status"] == "done" for b in before.values())
    assert all((sdir / k / "field.txt").stat().st_size == 100000 for k in before)
    assert 3 <= len(before) < N_SLOW

    summary = run_study(study, results_root=root, workers=1, progress=False)
    assert summary.ok and summary.reused == len(before) and summary.computed == N_SLOW - len(before)
    assert all((sdir / k / RESULT).read_bytes() == b for k, b in before.items())
    assert not list(sdir.glob(".*.tmp"))  # the killed run's temporary folders are gone
    assert len(status(study, root)["done"]) == N_SLOW


FAILING_KIND = '''
def case(params, design, outdir):   # a case that raises when it runs (after the study's checks)
    if params["pressure_mpa"] == 4.5:
        raise ValueError("pressure_MPa = 4.5: beyond this hand's largest pressure")
    return {"theta_deg": 10.0 * params["pressure_mpa"]}
'''


def test_a_failing_case_is_recorded_and_the_others_finish(tmp_path, capsys, monkeypatch):
    install_kind(tmp_path, "failingkind", FAILING_KIND)
    monkeypatch.syspath_prepend(str(tmp_path))
    path = write_study(tmp_path, 'kind = "failingkind"\n[sweep]\npressure_mpa = [0.5, 4.5, 0.8]\n')
    root = tmp_path / "res"
    args = ["study", "run", str(path), "--workers", "1", "--results", str(root), "--no-progress"]
    assert main(args) == 1
    assert "1 failed" in capsys.readouterr().out
    study = load_study(path)
    groups = status(study, root)
    assert [c.point["pressure_mpa"] for c in groups["failed"]] == [4.5]
    assert sorted(c.point["pressure_mpa"] for c in groups["done"]) == [0.5, 0.8]
    failed = json.loads((study_dir(study, root) / groups["failed"][0].key / "failed.json")
                        .read_text())
    assert "pressure_MPa" in failed["error"] and "Traceback" in failed["traceback"]
    index = (study_dir(study, root) / "index.csv").read_text().splitlines()
    assert len(index) == 4 and sum(",failed," in line for line in index) == 1
    assert main(["study", "status", str(path), "--results", str(root)]) == 0
    assert "2 done, 0 pending, 1 failed" in capsys.readouterr().out
    assert main(["study", "report", str(path), "--results", str(root)]) == 0
    assert (study_dir(study, root) / "report" / "theta_deg.png").stat().st_size > 0


def test_case_key_follows_the_inputs_not_their_spelling():
    paper = HandDesign()
    assert case_key("curve", {"theta_deg": 10}, paper) == case_key("curve", {"theta_deg": 10.0}, paper)
    assert case_key("curve", {"theta_deg": 10.0}, paper) != case_key("curve", {"theta_deg": 11.0}, paper)
    assert case_key("curve", {"theta_deg": 10.0}, paper) != \
        case_key("curve", {"theta_deg": 10.0}, paper.replace(mu_sf=1.2))


DYING_KIND = '''
import os, pathlib, time
def case(params, design, outdir):
    marker = pathlib.Path(params["marker"])
    if params["x"] == 3 and not marker.exists():   # the worker dies once, mid-study
        marker.touch()
        os._exit(1)
    time.sleep(0.05)
    return {"y": params["x"]}
'''


def test_a_killed_worker_loses_nothing_and_its_cases_are_rerun(tmp_path, monkeypatch):
    install_kind(tmp_path, "dyingkind", DYING_KIND)
    monkeypatch.syspath_prepend(str(tmp_path))
    study = load_study(write_study(tmp_path, f'kind = "dyingkind"\n[params]\n'
                                   f'marker = "{tmp_path / "died"}"\n[sweep]\nx = "1:8:1"\n'))
    summary = run_study(study, results_root=tmp_path / "res", workers=2, progress=False)
    assert (tmp_path / "died").exists()  # a worker did die
    assert summary.ok and summary.computed == 8
    assert sorted(v["y"] for v in results_by_key(tmp_path / "res", study).values()) == list(range(1, 9))


def test_a_pool_broken_between_two_submissions_loses_nothing(tmp_path, monkeypatch):
    """A worker can die after wait() returned and before the next case is submitted: then
    submit() itself raises BrokenProcessPool. That case, too, goes to the next pool."""
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    from softhand.studies.batch import pool

    class BreaksOnThirdSubmit(ProcessPoolExecutor):
        submitted = 0

        def submit(self, *args, **kwargs):
            type(self).submitted += 1
            if type(self).submitted == 3:
                raise BrokenProcessPool("a worker died")
            return super().submit(*args, **kwargs)

    monkeypatch.setattr(pool, "ProcessPoolExecutor", BreaksOnThirdSubmit)
    install_kind(tmp_path, "echokind", "def case(params, design, outdir):\n"
                                       "    return {'y': params['x']}\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    study = load_study(write_study(tmp_path, 'kind = "echokind"\n[sweep]\nx = "1:6:1"\n'))
    summary = run_study(study, results_root=tmp_path / "res", workers=2, progress=False)
    assert BreaksOnThirdSubmit.submitted > 6  # the broken submission was made again
    assert summary.ok and summary.computed == 6
    assert sorted(v["y"] for v in results_by_key(tmp_path / "res", study).values()) == list(range(1, 7))


THREADS_KIND = '''
def case(params, design, outdir):
    from threadpoolctl import threadpool_info
    return {"threads": max(pool["num_threads"] for pool in threadpool_info())}
'''


def test_pool_workers_share_the_cores_threads(tmp_path, monkeypatch):
    """Two workers on two cores run one thread each in every numerical library (MKL, OpenBLAS,
    OpenMP), also in those loaded before the worker started (a forked worker inherits them)."""
    import numpy  # noqa: F401  OpenBLAS loaded in this process, so inherited by forked workers
    from threadpoolctl import threadpool_info

    from softhand.studies.batch import pool

    if max(p["num_threads"] for p in threadpool_info()) < 2:
        pytest.skip("the numerical libraries run one thread here already")

    kind = install_kind(tmp_path, "threads_kind", THREADS_KIND)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    assert [pool.thread_share(n) for n in (1, 2, 3)] == [2, 1, 1]
    study = load_study(write_study(tmp_path, f'name = "t"\nkind = "{kind}"\n[sweep]\nx = [1, 2, 3, 4]\n'))
    assert run_study(study, results_root=tmp_path / "r", workers=2, progress=False).ok
    assert {n["threads"] for n in results_by_key(tmp_path / "r", study).values()} == {1}


def test_a_commit_stopped_half_way_leaves_no_temporary_folder(tmp_path, monkeypatch):
    from softhand.studies.batch import cases

    calls = []

    def interrupted(path, obj):  # Ctrl-C while the record is written, after the files
        calls.append(path)
        raise KeyboardInterrupt

    monkeypatch.setattr(cases, "write_json", interrupted)
    with pytest.raises(KeyboardInterrupt):
        cases.commit(tmp_path / "case", {"status": "done"}, {"sub/a.vtu": b"x" * 10})
    assert calls and list(tmp_path.iterdir()) == []


def test_case_folders_of_processes_that_are_gone_are_removed(tmp_path, monkeypatch):
    import tempfile

    from softhand.studies.batch import cases

    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True).stdout.strip()
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    (tmp_path / f"softhand-case-{gone}-abc").mkdir()  # a SIGKILLed run's
    (tmp_path / f"softhand-case-{os.getpid()}-def").mkdir()  # this process's, in use
    (tmp_path / "softhand-case-xyz").mkdir()  # an older name: not this scheme's to judge
    cases._remove_orphans()
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"softhand-case-{os.getpid()}-def", "softhand-case-xyz"]
