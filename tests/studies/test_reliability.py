"""Concurrent runs of one study, corrupt case files and cache entries, signals, pipes."""
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from softhand.studies.cli.main import main
from softhand.studies.batch.runner import RESULT, plan, study_dir
from softhand.studies.batch.studyfile import load_study
from softhand.studies.io.outputs import MANIFEST

from conftest import CI_MESH_ARGS
from test_runner import _default_sigint, install_kind

ROOT = Path(__file__).resolve().parents[2]

#: the curve kind, slowed down so that concurrent runs overlap, logging every computation
LOGGED_CURVE = '''
import os, time
from softhand.studies.batch.kinds import curve
def case(params, design, outdir):
    time.sleep(params["sleep_s"])
    fd = os.open(params["log"], os.O_WRONLY | os.O_APPEND | os.O_CREAT)
    os.write(fd, (repr(sorted(params.items())) + "\\n").encode())
    os.close(fd)
    return curve({"theta_deg": params["theta_deg"]}, design, outdir)
'''


def _env(tmp_path) -> dict:
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(ROOT)]),
            "SOFTHAND_CACHE": str(tmp_path / "cache")}


def _cli(*args) -> list[str]:
    return [sys.executable, "-m", "softhand.studies.cli.main", *args]


def _logged_study(tmp_path, monkeypatch, sleep_s: float) -> Path:
    install_kind(tmp_path, "loggedcurve", LOGGED_CURVE)
    monkeypatch.syspath_prepend(str(tmp_path))
    path = tmp_path / "s.toml"
    path.write_text(f'kind = "loggedcurve"\n[params]\nsleep_s = {sleep_s}\nlog = "{tmp_path / "log"}"\n'
                    '[sweep]\ntheta_deg = "0:90:3"\n')
    return path


@pytest.fixture
def logged_study(tmp_path, monkeypatch):
    """31 cases of 0.1 s each: long enough for concurrent runs and signals to overlap them."""
    return _logged_study(tmp_path, monkeypatch, 0.1)


@pytest.fixture
def quick_study(tmp_path, monkeypatch):
    return _logged_study(tmp_path, monkeypatch, 0.0)


def _check_results(study, root) -> None:
    """Every case done, with the numbers of the reduced model itself."""
    from softhand.reduced.vocabulary.design import HandDesign
    from softhand.studies.batch.kinds import curve

    sdir = study_dir(study, root)
    for case in plan(study):
        record = json.loads((sdir / case.key / RESULT).read_text())
        expect = curve({"theta_deg": case.params["theta_deg"]}, HandDesign(), sdir)
        assert record["status"] == "done"
        assert record["numbers"] == pytest.approx({k: float(v) for k, v in expect.items()}, rel=1e-12)


def test_four_simultaneous_runs_compute_every_case_once(logged_study, tmp_path):
    root = tmp_path / "res"
    runs = [subprocess.Popen(_cli("study", "run", str(logged_study), "--workers", "2",
                                  "--results", str(root), "--no-progress"),
                             env=_env(tmp_path), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
            for _ in range(4)]
    outputs = [run.communicate(timeout=300) for run in runs]
    assert [run.returncode for run in runs] == [0] * 4, [e.decode()[-1500:] for _, e in outputs]
    assert not any(b"Traceback" in err for _, err in outputs)
    study = load_study(logged_study)
    log = (tmp_path / "log").read_text().splitlines()
    assert len(log) == len(set(log)) == len(plan(study)) == 31  # every case computed exactly once
    computed = [int(out.decode().split(" computed")[0].rsplit("(", 1)[1]) for out, _ in outputs]
    assert sum(computed) == 31
    _check_results(study, root)
    index = (study_dir(study, root) / "index.csv").read_text().splitlines()
    assert len(index) == 32 and all(",done," in line for line in index[1:])


DAMAGES = ("truncated", "empty", "null", "list", "no numbers", "folder only")


def test_corrupt_case_files_are_reported_and_recomputed(quick_study, tmp_path, capsys):
    root = tmp_path / "res"
    argv = ["study", "run", str(quick_study), "--workers", "1", "--results", str(root), "--no-progress"]
    assert main(argv) == 0
    study = load_study(quick_study)
    sdir = study_dir(study, root)
    for damage, case in zip(DAMAGES, plan(study)[3:]):  # one case file damaged each way
        path = sdir / case.key / RESULT
        text = path.read_text()
        if damage == "folder only":
            path.unlink()
            continue
        path.write_text({"truncated": text[: len(text) // 2], "empty": "", "null": "null",
                         "list": "[1, 2]", "no numbers": json.dumps({**json.loads(text),
                                                                     "numbers": None})}[damage])
    capsys.readouterr()
    assert main(["study", "status", str(quick_study), "--results", str(root)]) == 0
    out = capsys.readouterr().out
    assert "25 done" in out and "6 corrupt" in out
    assert main(["study", "status", str(quick_study), "--results", str(root), "--json"]) == 0
    assert len(json.loads(capsys.readouterr().out)["corrupt"]) == 6
    assert main(["study", "report", str(quick_study), "--results", str(root)]) == 0
    (tmp_path / "log").unlink()
    assert main(argv) == 0
    out, err = capsys.readouterr()
    assert "6 case files do not parse; recomputing them" in err
    assert "(6 computed, 25 reused)" in out
    assert len((tmp_path / "log").read_text().splitlines()) == 6  # only those
    _check_results(study, root)


def test_a_file_where_a_case_folder_goes_is_refused_before_any_case_runs(quick_study, tmp_path, capsys):
    """A case's folder is committed by a rename after it is computed: a file in its place
    would fail then; it is one error line before the first case instead."""
    root = tmp_path / "res"
    study = load_study(quick_study)
    sdir = study_dir(study, root)
    sdir.mkdir(parents=True)
    blocker = sdir / plan(study)[5].key
    blocker.write_text("not a case folder")
    argv = ["study", "run", str(quick_study), "--workers", "1", "--results", str(root), "--no-progress"]
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and f"'{blocker}': is not a folder" in err
    assert not (tmp_path / "log").exists() and sorted(p.name for p in sdir.iterdir()) == [blocker.name]
    blocker.unlink()
    assert main(argv) == 0


@pytest.mark.parametrize("group", [False, True], ids=["SIGTERM to the parent", "Ctrl-C to the group"])
def test_sigterm_stops_a_run_like_ctrl_c(logged_study, tmp_path, group):
    """SIGTERM to the parent only (a process manager), or SIGINT to the whole process group (Ctrl-C
    in a terminal): exit 130, finished cases kept, and no case's private folder left behind."""
    root, tmp = tmp_path / "res", tmp_path / "tmp"
    tmp.mkdir()
    proc = subprocess.Popen(_cli("study", "run", str(logged_study), "--workers", "2",
                                 "--results", str(root), "--no-progress"), start_new_session=True,
                            env={**_env(tmp_path), "TMPDIR": str(tmp)}, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, preexec_fn=_default_sigint)
    sdir = study_dir(load_study(logged_study), root)
    deadline = time.monotonic() + 60
    while len(list(sdir.glob(f"[!.]*/{RESULT}"))) < 2 and time.monotonic() < deadline:
        time.sleep(0.05)
    if group:
        os.killpg(proc.pid, signal.SIGINT)
    else:
        proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err.decode()[-1500:]
    assert err.decode().strip() == "softhand study: interrupted; finished results are kept"
    index = (sdir / "index.csv").read_text().splitlines()
    done = [line for line in index[1:] if ",done," in line]
    assert 2 <= len(done) < 31 and len(index) == 32
    assert list(tmp.iterdir()) == []  # the cases in flight: their folders removed


def _children(pid: int) -> list[int]:
    text = Path(f"/proc/{pid}/task/{pid}/children").read_text()
    return [int(p) for p in text.split()]


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0]
    except FileNotFoundError:
        return False
    return state != "Z"


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs Linux /proc")
def test_pool_workers_die_with_a_killed_parent(logged_study, tmp_path):
    proc = subprocess.Popen(_cli("study", "run", str(logged_study), "--workers", "2",
                                 "--results", str(tmp_path / "res"), "--no-progress"),
                            env=_env(tmp_path), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while len(_children(proc.pid)) < 2 and time.monotonic() < deadline:
        time.sleep(0.05)
    workers = _children(proc.pid)
    assert len(workers) >= 2
    proc.kill()  # SIGKILL: no handler runs in the parent
    proc.wait(timeout=30)
    deadline = time.monotonic() + 20
    while any(map(_alive, workers)) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not any(map(_alive, workers))


def _forked_worker(folder: str, report) -> None:
    """A pool worker's life after its set-up: a case's folder, three threads a library starts, and
    asleep in a read, as a worker waiting for its next case."""
    import threading

    from softhand.studies.batch import cases, pool

    pool._worker_init(os.getppid(), 1)
    os.makedirs(folder)
    cases.CASE_FOLDERS.add(folder)
    masks = []

    def library_thread():
        masks.append(signal.SIGTERM in signal.pthread_sigmask(signal.SIG_BLOCK, set()))
        time.sleep(60)

    for _ in range(3):
        threading.Thread(target=library_thread, daemon=True).start()
    while len(masks) < 3:
        time.sleep(0.01)
    report.send(all(masks) and signal.SIGTERM in signal.pthread_sigmask(signal.SIG_BLOCK, set()))
    os.read(os.pipe()[0], 1)


@pytest.mark.skipif(not hasattr(signal, "pthread_sigmask"), reason="needs POSIX signal masks")
def test_a_worker_takes_its_sigterm_in_a_thread_of_its_own(tmp_path):
    """A process's signal goes to any of its threads that does not block it, and Python runs handlers
    only in the main thread: a worker asleep in a read of the pool's pipe, whose library's thread took
    the parent's death signal, slept on (about one killed parent in 60). In a worker forked as the
    pool forks them, SIGTERM is blocked in every thread but the one that waits for it; it ends the
    worker at once and removes the case's folder."""
    import multiprocessing

    ctx = multiprocessing.get_context("fork")
    mine, theirs = ctx.Pipe()
    folder = tmp_path / "case"
    worker = ctx.Process(target=_forked_worker, args=(str(folder), theirs))
    worker.start()
    assert mine.poll(30) and mine.recv() is True  # blocked in the main thread and in the later ones
    assert folder.is_dir()
    os.kill(worker.pid, signal.SIGTERM)
    worker.join(10)
    assert worker.exitcode == 128 + signal.SIGTERM
    assert not folder.exists()


def test_a_closed_pipe_is_quiet(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text('kind = "curve"\n[sweep]\ntheta_deg = "0:90:1"\n')
    proc = subprocess.Popen(_cli("study", "status", str(path), "--results", str(tmp_path)),
                            env=_env(tmp_path), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()  # like '| head -0': the reader is gone before the first line
    err = proc.stderr.read()
    proc.wait(timeout=60)
    assert err == b"" and proc.returncode == 141


# ---------------------------------------------------------------- caches
def test_a_failed_load_step_names_the_pressures_reached(monkeypatch):
    import numpy as np

    import softhand.fem.hand.finger_sweep as ff
    from softhand.fem.newton import NotConverged

    y = np.arange(3.0)

    def failing(*args, **kwargs):  # the path solver gives up at load fraction 0.25 of the step
        raise NotConverged("load step cut back below 1e-4 at t = 0.25", [1.0], y, (0.25, 2 * y))

    monkeypatch.setattr(ff, "solve_path", failing)
    with pytest.raises(NotConverged) as err:
        ff._solve_one(None, None, 0.7, [(0.5, y)], None, None, None, 1.0, np.zeros(4))  # no softened model
    assert err.value.pressure == pytest.approx(0.55)  # 0.5 + 0.25 (0.7 - 0.5)
    assert "above P = 0.55 MPa on the way to 0.7 MPa" in str(err.value)
    assert err.value.last_converged[0] == pytest.approx(0.55) and list(err.value.last_converged[1]) == [0, 2, 4]


def test_bend_failure_is_one_line_with_the_pressure_and_out_never_mixes_runs(tmp_path, monkeypatch,
                                                                              capsys):
    from softhand.studies import bending
    from softhand.fem.newton import NotConverged

    out = tmp_path / "bend"
    out.mkdir()
    for name in ("result.json", "table.csv", "hand.csv", "finger.pvd", "notes.txt"):
        (out / name).write_text("an earlier run")
    (out / "finger").mkdir()
    (out / "finger" / "finger_0003.vtm").write_text("an earlier run")
    earlier = ["result.json", "table.csv", "hand.csv", "finger.pvd", "finger"]  # not notes.txt: the user's
    (out / MANIFEST).write_text(json.dumps({"run": "earlier", "outputs": earlier}))

    def failing(study, on_state=None, model=None):
        error = NotConverged("Newton did not converge above P = 0.03 MPa on the way to 0.1 MPa",
                             [1.0], None, None)
        error.pressure = 0.03
        raise error

    monkeypatch.setattr(bending, "run", failing)
    assert main(["bend", "--pressure-mpa", "0.1", "--out", str(out)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "P = 0.03 MPa" in err[0] and "Traceback" not in err[0]
    result = json.loads((out / "result.json").read_text())
    assert result["failed"] and "0.03 MPa" in result["error"] and result["rows"] == []
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "notes.txt", "result.json"]  # the user's file stays


def test_an_output_that_fails_after_the_computation_loses_nothing(tmp_path, monkeypatch, capsys):
    """The disk refuses the picture after the curve is computed: a warning, the rows printed."""
    from softhand.studies.io import files

    def full_disk(path, data):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(files, "write_atomic", full_disk)
    assert main(["curve", "--theta-deg", "0:90:30", "--plot", str(tmp_path / "c.png"), "--json"]) == 3
    out, err = capsys.readouterr()
    assert len(json.loads(out)["rows"]) == 4
    assert "warning" in err and "No space left on device" in err and not (tmp_path / "c.png").exists()


def test_a_real_reservoir_failure_saves_the_last_converged_state(tmp_path, monkeypatch, capsys):
    """The reservoir FEM really stops (Newton held to 4 iterations a step and no cut-back below
    500 mm^3, against 12 and 1e-6 by default, on a 4 x 1 element sheet): exit 1, one line
    naming the volume and pressure reached, and that state in result.json and the VTK."""
    import functools

    import softhand.fem.hand.reservoir as fr
    from softhand.fem.volume_path import volume_path_options

    monkeypatch.setattr(fr, "volume_path_options", functools.partial(volume_path_options, max_iter=4,
                                                                     min_step=500.0))
    out = tmp_path / "sheet"
    argv = ["reservoir", "--n-radial", "4", "--n-thick", "1", "--volume-mm3", "20000", "--out", str(out)]
    assert main(argv) == 1
    stderr = capsys.readouterr().err
    err = [line for line in stderr.splitlines() if "error" in line]  # also the progress bar's
    assert len(err) == 1 and stderr.rstrip().endswith(err[0]) and "Traceback" not in stderr, err
    result = json.loads((out / "result.json").read_text())
    last = result["last_converged"]
    assert result["failed"] and 0 < last["V_mm3"] < 20000 and last["p_MPa"] > 0
    assert f"V = {last['V_mm3']:.6g} mm^3, p = {last['p_MPa']:.6g} MPa" in err[0]
    assert "no equilibrium at V = " in err[0] and f"{out}/sheet.pvd" in err[0]
    import numpy as np
    import pyvista
    from scipy.integrate import simpson

    # the VTK holds the state reached: the oil volume under its wet surface (z = 0 before
    # inflating; Simpson's rule, exact on the quadratic elements) is the volume named
    sheet = pyvista.read(out / f"sheet_V{last['V_mm3']:.0f}_rz.vtu")
    points, u = np.asarray(sheet.points), np.asarray(sheet.point_data["displacement_mm"])
    wet = points[:, 1] == 0.0
    r, z = points[wet, 0] + u[wet, 0], u[wet, 1]
    order = np.argsort(r)
    assert simpson(2 * np.pi * r[order] * z[order], x=r[order]) == pytest.approx(last["V_mm3"], rel=1e-6)


@pytest.mark.slow
def test_a_grasp_fem_that_stops_saves_the_states_it_reached(tmp_path, monkeypatch, capsys):
    """A real grasp FEM failure: the second contact state's Newton is held to no iteration, so
    its load path cuts back to nothing. One error line naming the cavity pressure reached;
    result.json and grasp.pvd hold the states reached: the first converged (contact within
    the gap tolerance, the object's forces in equilibrium with a bent finger), the second
    where its path stopped, at the first's pressure."""
    import dataclasses
    import re

    from softhand.fem.hand import grasp
    from softhand.fem.newton import NewtonOptions

    solve = grasp.GraspModel.solve

    def second_state_fails(self, P, *, start=None):
        if start is not None:
            self.options = dataclasses.replace(self.options, newton=NewtonOptions(max_iter=0))
        return solve(self, P, start=start)

    monkeypatch.setattr(grasp.GraspModel, "solve", second_state_fails)
    out = tmp_path / "w"
    assert main(["weights", "--diameter-mm", "180", "--pressure-mpa", "0.8", *CI_MESH_ARGS,
                 "--no-cache", "--no-progress", "--out", str(out)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "P_cavity = 0.8 MPa" in err[0] and "Traceback" not in err[0], err
    result = json.loads((out / "result.json").read_text())
    assert result["failed"] and result["last_converged_P_cavity_MPa"] == pytest.approx(0.8)
    first, stopped = result["states"]
    assert first["P_cavity_MPa"] == stopped["P_cavity_MPa"] == pytest.approx(0.8)
    assert first["max_penetration_mm"] <= grasp.GraspOptions().gap_tol
    assert sum(first["contact_force_N"]) > 0 and first["theta_deg"] > 0
    datasets = re.findall(r"<DataSet[^>]*file=\"([^\"]+)\"", (out / "grasp.pvd").read_text())
    assert len(datasets) == 2 and all((out / f).is_file() for f in datasets)


def test_damaged_case_state_is_recomputed_never_followed_nor_waited_on(quick_study, tmp_path, capsys):
    """A finished case's folder replaced by a symbolic link (to a valid result elsewhere), its
    result.json by a FIFO (status and run hung on it), by a 600 MB file (read whole) or by
    JSON nested 200 000 deep: each case is 'corrupt' and recomputed; the link's target and
    the other files are never touched."""
    root = tmp_path / "res"
    argv = ["study", "run", str(quick_study), "--workers", "1", "--results", str(root), "--no-progress"]
    assert main(argv) == 0
    study = load_study(quick_study)
    sdir = study_dir(study, root)
    link, fifo, huge, deep = plan(study)[:4]
    elsewhere = tmp_path / "elsewhere"
    shutil.move(sdir / link.key, elsewhere)
    (sdir / link.key).symlink_to(elsewhere, target_is_directory=True)
    kept = {p.name: p.read_bytes() for p in elsewhere.iterdir()}
    (sdir / fifo.key / RESULT).unlink()
    os.mkfifo(sdir / fifo.key / RESULT)
    with open(sdir / huge.key / RESULT, "r+b") as f:
        f.truncate(600 * 2**20)  # sparse: no 600 MB on the disk
    (sdir / deep.key / RESULT).write_text("[" * 200_000 + "]" * 200_000)
    capsys.readouterr()
    start = time.monotonic()
    assert main(["study", "status", str(quick_study), "--results", str(root)]) == 0
    assert "4 corrupt" in capsys.readouterr().out and time.monotonic() - start < 30
    (tmp_path / "log").unlink()
    assert main(argv) == 0
    assert len((tmp_path / "log").read_text().splitlines()) == 4
    assert not (sdir / link.key).is_symlink() and {p.name: p.read_bytes() for p in elsewhere.iterdir()} == kept
    _check_results(study, root)


def test_damaged_claims_and_report_folders_are_one_line(quick_study, tmp_path, capsys):
    """A folder where a case's claim lock goes, symbolic links for .claims/ or report/ (followed
    out of --results before): one error line, exit 2, nothing written through the link."""
    root = tmp_path / "res"
    study = load_study(quick_study)
    sdir = study_dir(study, root)
    (sdir / ".claims" / f"{plan(study)[0].key}.lock").mkdir(parents=True)
    argv = ["study", "run", str(quick_study), "--workers", "1", "--results", str(root), "--no-progress"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "claim lock" in err[0]
    shutil.rmtree(sdir / ".claims")
    outside = tmp_path / "outside"
    outside.mkdir()
    for name, action in ((".claims", "run"), ("report", "report")):
        (sdir / name).symlink_to(outside, target_is_directory=True)
        assert main(["study", action, str(quick_study), "--results", str(root)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "symbolic link" in err[0]
        (sdir / name).unlink()
    assert list(outside.iterdir()) == []


def test_a_users_files_in_a_study_folder_are_never_replaced(quick_study, tmp_path, capsys):
    """A report.md, index.csv or study.json of the user's in the study's folder (a folder no
    softhand run wrote them into): run and report refuse in one line, exit 2, the files as they
    were; after the user moves them away both run, and run again over their own outputs."""
    root = tmp_path / "res"
    sdir = study_dir(load_study(quick_study), root)
    sdir.mkdir(parents=True)
    mine = {"report.md": "my notes\n", "index.csv": "a,b\n1,2\n", "study.json": '{"mine": 1}\n'}
    for name, text in mine.items():
        (sdir / name).write_text(text)
    for action in ("report", "run", "report"):
        argv = ["study", action, str(quick_study), "--results", str(root)] + (
            ["--workers", "1", "--no-progress"] if action == "run" else [])
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "was not written by an earlier softhand run" in err[0]
        assert {n: (tmp_path / n if (tmp_path / n).exists() else sdir / n).read_text() for n in mine} == mine
        name = next(n for n in mine if f"{sdir / n}'" in err[0])
        (sdir / name).rename(tmp_path / name)  # moved away: the next refusal names another file
    for action in ("run", "report", "run", "report"):
        argv = ["study", action, str(quick_study), "--results", str(root)] + (
            ["--workers", "1", "--no-progress"] if action == "run" else [])
        assert main(argv) == 0
    assert {n: (tmp_path / n).read_text() for n in mine} == mine


def test_case_named_folders_in_a_folder_no_study_wrote_are_the_users(quick_study, tmp_path, capsys):
    """A folder named like a case, with files of the user's, in a study folder no softhand run
    wrote (no manifest): refused before any case runs, the files as they were."""
    root = tmp_path / "res"
    study = load_study(quick_study)
    mine = study_dir(study, root) / plan(study)[0].key
    mine.mkdir(parents=True)
    (mine / "precious.txt").write_text("the user's")
    argv = ["study", "run", str(quick_study), "--workers", "1", "--results", str(root), "--no-progress"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "was not written by an earlier softhand run" in err[0]
    assert (mine / "precious.txt").read_text() == "the user's"


def test_a_read_only_finished_study_is_one_warning(quick_study, tmp_path, monkeypatch, capsys):
    """run and report of a finished study whose folder refuses writes (tests run as root, for
    whom chmod refuses nothing: the refusal is simulated): tracebacks before; now the summary,
    one warning line, exit 3."""
    from softhand.studies.batch import index, report

    root = tmp_path / "res"
    argv = ["study", "run", str(quick_study), "--workers", "1", "--results", str(root), "--no-progress"]
    assert main(argv) == 0
    capsys.readouterr()

    def refused(path, *args, **kwargs):
        raise PermissionError(13, "Permission denied", str(path))

    monkeypatch.setattr(index, "write_csv", refused)
    monkeypatch.setattr(report, "write_atomic", refused)
    assert main(argv) == 3
    out, err = capsys.readouterr()
    assert "31 done" in out and len(err.strip().splitlines()) == 1 and "Permission denied" in err
    assert main(["study", "report", str(quick_study), "--results", str(root)]) == 3
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


def test_a_weights_cache_entry_that_is_a_fifo_or_nested_deep_is_recomputed(tmp_path, capsys):
    from softhand.studies.weights_cache import read_entry

    fifo, deep = tmp_path / "fifo.json", tmp_path / "deep.json"
    os.mkfifo(fifo)
    deep.write_text("[" * 200_000 + "]" * 200_000)
    assert read_entry(fifo, "k") is None and read_entry(deep, "k") is None
    assert capsys.readouterr().err.count("invalid cache entry") == 2


def test_a_folded_mesh_in_a_weights_study_is_refused_before_any_case(tmp_path, capsys):
    """gmsh 10 mm graded at the ring edges folds (tests/test_meshes.py): the weights study's
    cases failed one by one after the others ran; now one line when the run starts."""
    study = tmp_path / "w.toml"
    study.write_text('kind = "weights"\nmesh_size_mm = 10.0\n[sweep]\ndiameter_mm = [180.0, 200.0]\n')
    assert main(["study", "run", str(study), "--workers", "1", "--results", str(tmp_path / "r"),
                 "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "fold over themselves" in err[0]
    assert not (tmp_path / "r" / "w").exists() or not any((tmp_path / "r" / "w").iterdir())
