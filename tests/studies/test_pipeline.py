"""One result pipeline: the paper's data and the version lookup in one place each; a study's
result writes, plots and summarises itself, and what it writes is what it computed."""
import csv
import json
import math
import re
from importlib.metadata import version
from pathlib import Path

import numpy as np
import pytest

from softhand.reduced.dynamics import control
from softhand.reduced.equations import grasp, reservoir
from softhand.reduced.vocabulary import paper
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.versions import package_version

from conftest import CI_FINGER

ROOT = Path(__file__).resolve().parents[2]
SOURCES = [p for layer in ("fem", "reduced", "meshes", "studies") for p in (ROOT / layer).rglob("*.py")]


def test_the_papers_numbers_are_written_once():
    assert grasp.PAPER_WEIGHTS is paper.WEIGHTS and control.PAPER_TABLE_II is paper.TABLE_II
    assert paper.table_i() == HandDesign()  # Table I's file and the design's defaults agree
    assert math.isclose(sum(paper.WEIGHTS[180.0]), 1.40)  # as printed, violating eq. (23)
    assert [g.diameter_mm for g in paper.FIG8] == sorted(paper.WEIGHTS)
    assert all(min(g.pressures_mpa) <= g.weights_at_mpa <= max(g.pressures_mpa) for g in paper.FIG8)
    # no other module spells out a paper vector, Table II state or the Fig. 8 errors again
    literals = re.compile(r"-0\.13, 0\.0, 0\.67|0\.89, 50\.0, 0\.61|0\.22\b.*0\.39\b|0\.6, 0\.7, 0\.8, 0\.9")
    repeated = [p.relative_to(ROOT).as_posix() for p in SOURCES
                if p.name != "paper.py" and literals.search(p.read_text())]
    assert repeated == []


def test_one_version_lookup():
    assert package_version() == version("softhand")
    assert package_version("no-such-distribution-softhand", "not installed") == "not installed"
    callers = [p.relative_to(ROOT).as_posix() for p in SOURCES
               if re.search(r"from importlib\.metadata import[^\n]*\bversion\b", p.read_text())]
    assert callers == ["reduced/vocabulary/versions.py"]


@pytest.fixture(scope="module")
def bent(tmp_path_factory):
    """The finger FEM on the CI mesh at 0 and 0.3 MPa with the whole hand, written and plotted."""
    from softhand.fem.hand.finger import FingerOptions
    from softhand.studies.bending import BendingStudy, run, vtk_writer

    out = tmp_path_factory.mktemp("bend")
    options = FingerOptions(**CI_FINGER)
    seen = []
    result = run(BendingStudy(pressures_mpa=(0.0, 0.3), options=options, hand=True),
                 on_state=vtk_writer(out / "finger.pvd", then=lambda model, state: seen.append(state.P)))
    names = result.write(out)
    result.plot(out / "fig7.png")
    return result, out, names, seen


def test_the_whole_hand_is_both_fems_against_eq27(bent):
    result, *_ = bent
    d = HandDesign()
    h = result.hand.summary()
    for r, row in zip(result.rows, h["rows"]):
        assert row["theta_deg"] == r["theta_deg"]
        assert math.isclose(row["V_mm3"], d.V0 - d.n * r["dQ_mm3"])
        assert math.isclose(row["P_pump_fem_MPa"], r["P_cavity_MPa"] - row["p_reservoir_fem_MPa"])
    # the straight finger: the pump pulls by the sheet's pressure at V0. The sheet FEM run
    # here against the FEM-calibrated reduced reservoir (a shipped table, interpolated):
    assert result.rows[0]["dQ_mm3"] == 0.0
    calibrated = float(reservoir.pressure(d.V0, d.replace(reservoir_model="fem")))
    assert math.isclose(h["offset_fem_MPa"], calibrated, rel_tol=2e-3)
    assert math.isclose(-h["rows"][0]["P_pump_fem_MPa"], calibrated, rel_tol=2e-3)


def test_the_result_writes_what_it_computed(bent):
    from softhand.studies.io.render import load_scene

    result, out, names, seen = bent
    assert names == ["result.json", "table.csv", "hand.csv"]
    assert seen == [0.0, 0.3]
    saved = json.loads((out / "result.json").read_text())
    assert saved["hand"]["rows"] == json.loads(json.dumps(result.hand.rows))
    assert [float(r["theta_deg"]) for r in csv.DictReader(open(out / "table.csv"))] == \
        pytest.approx([r["theta_deg"] for r in result.rows], rel=1e-12)
    assert len(list(csv.DictReader(open(out / "hand.csv")))) == 2
    scene, step, steps = load_scene(out / "finger.pvd")  # the last step: 0.3 MPa
    assert steps == 2 and "tube" in scene.keys()
    assert (out / "fig7.png").stat().st_size > 10_000
    assert np.isfinite(saved["rows"][-1]["theta_deg"]) and saved["rows"][-1]["theta_deg"] > 0


def test_the_whole_hand_stops_where_the_reservoir_runs_dry():
    """Rows whose oil n dQ exceeds V0 have no reservoir pressure (nan) and are announced in one
    warning; the rows before keep the sheet FEM's answer of a run without them."""
    from softhand.studies.compare import whole_hand

    d = HandDesign()
    dry = d.V0 / d.n * 1.01
    rows = [{"P_cavity_MPa": 0.2, "theta_deg": 8.0, "dQ_mm3": 500.0}, {"P_cavity_MPa": 0.9, "theta_deg": 90.0, "dQ_mm3": dry}]
    with pytest.warns(UserWarning, match=r"take more oil than V0 = 17800 mm\^3 from 90 deg on"):
        h = whole_hand(rows, d)
    assert math.isnan(h.rows[1]["P_pump_fem_MPa"]) and math.isnan(h.rows[1]["P_pump_eq27_MPa"])
    alone = whole_hand(rows[:1], d)
    assert h.rows[0] == alone.rows[0] and h.max_abs_difference_MPa() == alone.max_abs_difference_MPa()
