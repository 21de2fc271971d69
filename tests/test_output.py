"""Atomic writes: whole files or nothing, ordinary permissions."""
import json
import os
import stat

import numpy as np
import pytest

from softhand.studies.io.files import write_atomic, write_csv, write_json


def test_write_json_round_trip_with_numpy(tmp_path):
    path = write_json(tmp_path / "sub" / "r.json", {"a": np.arange(3), "b": np.float64(1.5)})
    assert json.loads(path.read_text()) == {"a": [0, 1, 2], "b": 1.5}


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
