"""Every pressure the verbs write says which it is: ``P_pump_MPa`` or ``P_cavity_MPa``.

With the reservoir the pump's pressure and the finger cavity's differ by the reservoir's
(eq. (27): P = p_finger - p_r), by 0.1 MPa at rest on the paper's hand; a bare ``P_MPa``
leaves the reader to guess. The verbs run here on CI-sized inputs (the reduced model's
verbs, the reservoir sheet's and the finger's FEM on coarse meshes, a batch study and the
reduced sections of the report), and every key of their ``--json`` output, of the JSON
files and of the CSV headers they write is scanned.
"""
from __future__ import annotations

import contextlib
import csv
import io
import json
from pathlib import Path

import pytest

from softhand.studies.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
#: names that do not say whose pressure they are (the names before they did)
BARE = {"P_MPa", "pressure_MPa", "P_no_reservoir_MPa", "P_free_MPa", "P_ref_MPa", "paper_P_MPa",
        "last_converged_MPa", "pump_pressure_MPa", "cavity_pressure_MPa", "target_MPa",
        "P_hand_fem_MPa", "P_finger_fem_MPa"}
NAMED = {"P_pump_MPa", "P_cavity_MPa"}
#: verbs that write no pump or cavity pressure (the fit's parameters; the sheet's own p_reservoir)
NO_PRESSURE = {"fit", "reservoir"}


def keys_of(value) -> set[str]:
    """Every dict key at any depth of a parsed JSON value."""
    if isinstance(value, dict):
        return set(value).union(*(keys_of(v) for v in value.values()))
    if isinstance(value, list):
        return set().union(*(keys_of(v) for v in value)) if value else set()
    return set()


def written_keys(folder: Path) -> set[str]:
    """The keys of every JSON file and the header of every CSV file under ``folder``."""
    found = set()
    for path in folder.rglob("*.json"):
        found |= keys_of(json.loads(path.read_text()))
    for path in folder.rglob("*.csv"):
        rows = [r for r in csv.reader(line for line in path.read_text().splitlines()
                                      if not line.startswith("#"))]
        found |= set(rows[0]) if rows else set()
    return found


def run(argv: list[str]) -> set[str]:
    """The keys of ``softhand ARGV --json``'s stdout (the verb must succeed)."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        assert main([*argv, "--json"]) == 0, argv
    return keys_of(json.loads(out.getvalue()))


#: name -> argv (``{out}``: a fresh folder whose files are scanned too)
VERBS = {
    "curve_theta": ["curve", "--theta-deg", "0:90:30"],
    "curve_pressure": ["curve", "--pressure-mpa", "0:0.8:0.4"],
    "grasp_paper": ["grasp", "--pressure-mpa", "1.7", "--theta-deg", "45", "--mass-kg", "2",
                    "--weights", "paper180", "--normalise"],
    "grasp_fem": ["grasp", "--model", "fem", "--diameter-mm", "180", "--pressure-mpa", "1.7",
                  "--theta-deg", "45", "--mass-kg", "2"],
    "control": ["control", "--theta-ref-deg", "50", "--mass-kg", "2", "--t-end-s", "6", "--out", "{out}"],
    "fit": ["fit", "--data", str(ROOT / "studies" / "data" / "example_bending.csv"), "--params", "V0_mm3"],
    "reservoir": ["reservoir", "--out", "{out}"],
    "bend": ["bend", "--pressure-mpa", "0.4", "--mesher", "gmsh", "--mesh-size-mm", "8",
             "--peak-mpa", "0", "--out", "{out}"],
}


@pytest.mark.parametrize("name", VERBS)
def test_a_verb_names_every_pressure_it_writes(name, tmp_path):
    argv = [a.replace("{out}", str(tmp_path / "out")) for a in VERBS[name]]
    found = run(argv) | written_keys(tmp_path)
    assert not found & BARE, f"{name}: {sorted(found & BARE)}"
    assert bool(found & NAMED) != (name in NO_PRESSURE), f"{name}: {sorted(found)}"


def test_a_study_and_the_report_name_every_pressure(tmp_path, monkeypatch):
    """A batch study of the curve and grasp kinds (result.json, index.csv) and the report's
    reduced sections (their CSV tables and numbers)."""
    (tmp_path / "studies").symlink_to(ROOT / "studies")
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.toml").write_text('kind = "curve"\ndesign = "studies/designs/paper.toml"\n'
                                     '[sweep]\ntheta_deg = "0:60:30"\n')
    (tmp_path / "g.toml").write_text('kind = "grasp"\n[sweep]\npressure_mpa = [1.7]\ntheta_deg = [45.0]\n'
                                     'mass_kg = [2.0]\ndiameter_mm = [180.0]\n')
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        for study in ("s.toml", "g.toml"):
            assert main(["study", "run", study, "--workers", "1", "--results", "res"]) == 0, study
        assert main(["reproduce", "--quick", "--no-progress", "--out", "rep", "--only",
                     "fig7_reduced,table2_reduced,fig8_reduced,table2_control"]) == 0
    for folder in ("res", "rep"):
        found = written_keys(tmp_path / folder)
        assert not found & BARE, f"{folder}: {sorted(found & BARE)}"
        assert found & NAMED, folder
