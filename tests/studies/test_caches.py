"""Caches (grasp weights, meshes): a damaged entry is computed again, an unwritable cache is
a warning, and the keys carry the package version."""
import json
from pathlib import Path

import pytest

from softhand.meshes import cache as mesh_cache
from softhand.studies.cli.main import main


def _fake_compute(calls):
    def compute(case, out=None, progress=None):
        calls.append(case.diameter_mm)
        return {"diameter_mm": case.diameter_mm, "w": [0.2] * 5, "w_sum": 1.0, "theta_deg": 40.0,
                "F_v_fem_N": 3.0, "mesh_size_mm": case.mesh_size_mm, "ndofs": 10}
    return compute


@pytest.mark.parametrize("damage", ["truncated", "empty", "null", "{}", "edited", "other key"])
def test_a_corrupt_weights_cache_entry_is_recomputed(tmp_path, monkeypatch, capsys, damage):
    import softhand.studies.weights as sw

    calls = []
    monkeypatch.setenv("SOFTHAND_CACHE", str(tmp_path))
    monkeypatch.setattr(sw, "compute", _fake_compute(calls))
    argv = ["weights", "--diameter-mm", "200", "--json"]
    assert main(argv) == 0 and main(argv) == 0 and len(calls) == 1
    [entry] = (tmp_path / "weights").glob("*.json")
    text = entry.read_text()
    record = json.loads(text)
    entry.write_text({"truncated": text[:40], "empty": "", "null": "null", "{}": "{}",
                      "edited": text.replace('"theta_deg": 40.0', '"theta_deg": 41.0'),
                      "other key": json.dumps({**record, "key": "0" * 20})}[damage])
    capsys.readouterr()
    assert main(argv) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["cached"] is False and json.loads(out)["theta_deg"] == 40.0
    assert "invalid cache entry" in err and len(calls) == 2
    assert main(argv) == 0 and json.loads(capsys.readouterr().out)["cached"] is True


def test_an_unwritable_cache_is_a_warning_and_the_result_is_printed(tmp_path, monkeypatch, capsys):
    import softhand.studies.weights as sw

    (tmp_path / "a_file").write_text("")
    monkeypatch.setenv("SOFTHAND_CACHE", str(tmp_path / "a_file" / "cache"))
    monkeypatch.setattr(sw, "compute", _fake_compute([]))
    assert main(["weights", "--diameter-mm", "200", "--json"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["w"] == [0.2] * 5
    assert "cannot be written" in err and "not cached" in err and "Traceback" not in err


def rectangle(model, params, size):
    model.occ.addRectangle(0, 0, 0, params["width"], params["height"])
    model.occ.synchronize()
    model.addPhysicalGroup(2, [t for _, t in model.getEntities(2)], name="domain")


@pytest.mark.parametrize("damage", ["truncated", "empty", "swapped", "no checksum"])
def test_a_corrupt_cached_mesh_is_generated_again(tmp_path, monkeypatch, capsys, damage):
    monkeypatch.setenv("SOFTHAND_CACHE", str(tmp_path))
    params = {"width": 3.0, "height": 1.0}
    path = mesh_cache.cached_msh(rectangle, params, size=0.5)
    good = path.read_bytes()
    other = mesh_cache.cached_msh(rectangle, {"width": 2.0, "height": 1.0}, size=0.5)
    if damage == "no checksum":
        Path(f"{path}.sha256").unlink()
    else:
        path.write_bytes({"truncated": good[: len(good) // 2], "empty": b"",
                          "swapped": other.read_bytes()}[damage])
    assert mesh_cache.cached_msh(rectangle, params, size=0.5) == path
    assert mesh_cache.valid_entry(path)
    assert mesh_cache.load_mesh(rectangle, params, size=0.5).p[0].max() == pytest.approx(3.0)
    if damage != "no checksum":
        assert "does not match its checksum" in capsys.readouterr().err


def test_mesh_and_weights_cache_keys_carry_the_package_version(monkeypatch):
    from softhand.studies.weights import WeightsCase

    key, wkey = mesh_cache.mesh_key(rectangle, {"w": 1}, size=1.0, order=1), WeightsCase().key()
    monkeypatch.setattr(mesh_cache, "_softhand_version", lambda: "999.0")
    monkeypatch.setattr("softhand.studies.weights._package_version", lambda: "999.0")
    assert mesh_cache.mesh_key(rectangle, {"w": 1}, size=1.0, order=1) != key
    assert WeightsCase().key() != wkey


# ---------------------------------------------------------------- FEM failures
