"""``softhand hold``: the answers, the JSON keys, the map's files and bad input (one line, exit 2)."""
import json
import os
import subprocess
import sys

import pytest


def _run(*args, cwd=None):
    env = dict(os.environ)
    return subprocess.run([sys.executable, "-m", "softhand.studies.cli.main", "hold", *args],
                          capture_output=True, text=True, cwd=cwd, env=env, timeout=600)


def test_json_keys_and_both_pressures():
    p = _run("--object", "sphere:180", "--mass-kg", "0.5", "--pressure-mpa", "1.2", "--json")
    assert p.returncode == 0, p.stderr
    data = json.loads(p.stdout)
    assert data["model"] == "reduced" and data["held"] is True
    assert {"holding_limit_N", "pull_direction", "contacts", "P_pump_MPa", "P_cavity_MPa"} <= set(data)
    assert data["P_pump_MPa"] == pytest.approx(1.2, abs=1e-8) and data["P_cavity_MPa"] > 1.2
    assert set(data["contacts"][0]) >= {"finger", "link", "normal_N", "friction_N", "state"}


def test_least_pressure_answers_and_holds_the_margin():
    """The least pump pressure for 2x the weight: at it the holding limit is one weight (within the
    bisection's 1e-4 MPa), the pressure of the same object held at 1x is lower."""
    p = _run("--object", "sphere:180", "--mass-kg", "0.5", "--margin", "2", "--json", "--no-progress")
    assert p.returncode == 0, p.stderr
    two = json.loads(p.stdout)
    assert two["holding_limit_N"] >= two["required_holding_limit_N"] == pytest.approx(0.5 * 9.80665)
    one = json.loads(_run("--object", "sphere:180", "--mass-kg", "0.5", "--json", "--no-progress").stdout)
    assert one["least_P_pump_MPa"] < two["least_P_pump_MPa"]


def test_map_writes_table_and_plot(tmp_path):
    p = _run("--object", "sphere:180", "--map", "pressure=0.6,1.2,1.8", "mass=0.2,1", "--out", str(tmp_path),
             "--no-progress")
    assert p.returncode == 0, p.stderr
    lines = (tmp_path / "hold_map.csv").read_text().splitlines()
    assert len(lines) == 1 + 6 and "margin" in lines[0]
    assert (tmp_path / "hold_map.png").stat().st_size > 1000


@pytest.mark.parametrize("args, field", [
    (("--object", "sphere:180", "--pressure-mpa", "1", "--pull", "0,0,0"), "--pull"),
    (("--object", "sphere:180", "--map", "pressure=0:2:0.01", "mass=0:5:0.01"), "--map"),
    (("--object", "sphere:180", "--mass-kg", "5", "--max-pump-mpa", "0.5", "--no-progress"), "--max-pump-mpa"),
    (("--object", "sphere:180", "--friction", "-0.1", "--pressure-mpa", "1"), "--friction"),
    (("--object", "cone:3", "--pressure-mpa", "1"), "--object"),
    (("--object", "box:400x50x400", "--pressure-mpa", "1"), "object"),
])
def test_bad_input_is_one_line_exit_2(args, field):
    p = _run(*args)
    assert p.returncode == 2, p.stdout + p.stderr
    assert len(p.stderr.strip().splitlines()) == 1 and field in p.stderr


def test_out_follows_the_output_rule(tmp_path):
    """--out writes only the hold's own files, staged and renamed into place (a rerun replaces them
    whole, a file of the user's stays); a folder of the user's where an output goes is refused
    before any work, one line, exit 2."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine\n")
    args = ("--object", "sphere:180", "--mass-kg", "0.5", "--pressure-mpa", "1.2", "--out", str(out))
    for _ in range(2):
        p = _run(*args)
        assert p.returncode == 0, p.stderr
        assert json.loads((out / "result.json").read_text())["model"] == "reduced"
    assert sorted(q.name for q in out.iterdir() if not q.name.startswith(".")) == ["notes.txt", "result.json"]
    assert (out / "notes.txt").read_text() == "mine\n"
    theirs = tmp_path / "theirs"
    (theirs / "hold").mkdir(parents=True)  # the user's folder named as the FEM's VTK series
    (theirs / "hold" / "keep.txt").write_text("mine\n")
    p = _run("--object", "sphere:180", "--pressure-mpa", "1.2", "--out", str(theirs))
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and "--out" in p.stderr
    assert (theirs / "hold" / "keep.txt").read_text() == "mine\n"
