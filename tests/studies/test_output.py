"""Atomic writes: whole files or nothing, ordinary permissions."""
import json
import os
import stat
from pathlib import Path

import numpy as np
import pytest

from softhand.studies.io.files import write_atomic, write_csv, write_json
from softhand.studies.io.outputs import MANIFEST
from conftest import CI_MESH_ARGS


def test_write_json_round_trip_with_numpy(tmp_path):
    path = write_json(tmp_path / "sub" / "r.json", {"a": np.arange(3), "b": np.float64(1.5)})
    assert json.loads(path.read_text()) == {"a": [0, 1, 2], "b": 1.5}


def _strict(text):
    """json.loads refusing NaN / Infinity, as JavaScript's, Go's and serde's parsers do."""
    def refuse(constant):
        raise ValueError(f"not JSON: {constant}")
    return json.loads(text, parse_constant=refuse)


def test_numbers_that_are_not_finite_are_null_in_strict_json(tmp_path):
    """A design's constraint 'below the limit point' had "limit": Infinity: Python reads it,
    strict parsers refuse the whole file."""
    obj = {"inf": float("inf"), "list": [float("nan"), 1.0], "np": np.float64(-np.inf),
           "array": np.array([1.0, np.inf]), "nested": ({"x": -float("inf")},), "ok": 2.5, "flag": True}
    expected = {"inf": None, "list": [None, 1.0], "np": None, "array": [1.0, None],
                "nested": [{"x": None}], "ok": 2.5, "flag": True}
    assert _strict(write_json(tmp_path / "r.json", obj).read_text()) == expected


def test_json_printed_by_a_verb_is_strict(tmp_path, capsys):
    from softhand.studies.cli.main import main

    assert main(["design", "--task", "studies/designs/tasks/paper_task.toml", "--no-fem", "--json",
                 "--no-progress", "--out", str(tmp_path)]) == 0
    printed = _strict(capsys.readouterr().out)
    limit = next(c for c in printed["constraints"] if c["name"].startswith("reservoir_below_limit_point"))
    assert limit["limit"] is None  # no limit point: the sheet's p_r(V) rises throughout
    assert _strict((tmp_path / "result.json").read_text()) == printed


def test_files_get_ordinary_permissions_not_mkstemps_0600(tmp_path):
    path = write_atomic(tmp_path / "f.txt", "x")
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~umask


def test_failed_write_leaves_nothing_behind(tmp_path):
    with pytest.raises(TypeError):
        write_atomic(tmp_path / "f.txt", 12345)  # not bytes or str
    assert list(tmp_path.iterdir()) == []


def test_csv_lists_become_semicolon_cells(tmp_path):
    path = write_csv(tmp_path / "t.csv", [{"P": 0.1, "w": [0.2, 0.8]}])
    assert path.read_text().splitlines() == ["P,w", "0.1,0.2;0.8"]


def test_a_reservoir_run_replaces_the_last_runs_outputs_and_keeps_them_whole_when_stopped(tmp_path, monkeypatch):
    from softhand.studies.cli.main import main
    from softhand.studies.io import reservoir_files

    out = tmp_path / "rs"
    (tmp_path / "rs").mkdir()
    (out / "notes.txt").write_text("the user's")
    assert main(["reservoir", "--volume-mm3", "13000,15000,17000", "--out", str(out), "--no-progress"]) == 0
    assert len(list(out.glob("sheet_V*_rz.vtu"))) == 3
    assert main(["reservoir", "--volume-mm3", "14000", "--out", str(out), "--no-progress"]) == 0
    assert sorted(p.name for p in out.glob("sheet_V*_rz.vtu")) == ["sheet_V14000_rz.vtu"]  # none stale

    write = reservoir_files.write_sheet_vtk

    def stopped(result, folder):  # Ctrl-C half-way through the VTK
        write(result, folder)
        raise KeyboardInterrupt

    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    monkeypatch.setattr(reservoir_files, "write_sheet_vtk", stopped)
    assert main(["reservoir", "--volume-mm3", "16000", "--out", str(out), "--no-progress"]) == 130
    # the earlier complete result stays whole, nothing of the stopped run shows
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == before
    assert sorted(p.name for p in out.iterdir() if p.is_dir()) == ["sheet"]


def test_a_stopped_bend_leaves_no_half_written_series(tmp_path, monkeypatch):
    from softhand.studies import bending
    from softhand.studies.cli.main import main

    real = bending.run

    def stopped(study, on_state=None, model=None):  # Ctrl-C once a loaded state is in the series
        def once(m, state):
            on_state(m, state)
            if state.P > 0:
                raise KeyboardInterrupt
        return real(study, on_state=once, model=model)

    monkeypatch.setattr(bending, "run", stopped)
    out = tmp_path / "b"
    out.mkdir()
    (out / "notes.txt").write_text("the user's")
    assert main(["bend", *CI_MESH_ARGS, "--pressure-mpa", "0.2,0.4", "--peak-mpa", "0",
                 "--out", str(out), "--no-progress"]) == 130
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]


def test_a_design_run_replaces_the_last_runs_outputs_and_keeps_them_whole_when_stopped(tmp_path, monkeypatch, capsys):
    from softhand.studies.cli.main import main
    from softhand.studies.io import files

    task = str(Path(__file__).resolve().parents[2] / "studies" / "designs" / "tasks" / "paper_task.toml")
    out = tmp_path / "d"
    (out / "knee").mkdir(parents=True)
    (out / "knee" / "design.toml").write_text("the user's, not a run's")
    (out / "notes.txt").write_text("the user's")
    argv = ["design", "--task", task, "--no-fem", "--no-progress", "--json", "--out", str(out)]
    assert main(argv) == 2  # a folder of the user's where the run writes one: refused, kept
    assert "knee" in capsys.readouterr().err and (out / "knee" / "design.toml").read_text() == "the user's, not a run's"
    (out / "knee" / "design.toml").unlink()
    (out / "knee").rmdir()
    assert main(argv) == 0
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "design.toml", "notes.txt", "result.json"]
    before = {p.name: p.read_bytes() for p in out.iterdir()}

    def stopped(path, data):
        raise KeyboardInterrupt

    monkeypatch.setattr(files, "write_atomic", stopped)
    assert main(argv) == 130
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before  # the earlier result whole, no orphan
