"""Each study's result is computed, summarised and written once: the verb's ``--json`` is the
result's summary, the files the verb writes are the ones the result writes, and the batch kind
keeps the result's numbers. The grasp FEM is replaced by a closed-form stand-in (w linear in D)
where only the pipeline is under test; the FEM itself is tested in tests/fem/test_grasp.py."""
import contextlib
import io
import json
import math
from pathlib import Path

import numpy as np
import pytest

from softhand.reduced.equations import grasp
from softhand.reduced.vocabulary.design import HandDesign
from softhand.studies.cli.main import main

ROOT = Path(__file__).resolve().parents[2]


def verb_json(argv: list[str]) -> dict:
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        assert main([*argv, "--json"]) == 0
    return json.loads(out.getvalue())


def same_files(a: Path, b: Path) -> list[str]:
    """The same outputs, byte for byte (a verb's folder also holds its run's manifest)."""
    from softhand.studies.io.outputs import MANIFEST

    names = sorted(p.name for p in a.iterdir() if p.name != MANIFEST)
    assert names == sorted(p.name for p in b.iterdir() if p.name != MANIFEST)
    for name in names:
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    return names


# ---------------------------------------------------------------- control
def test_control_result_is_what_the_verb_prints_and_writes(tmp_path):
    from softhand.studies.control import ControlStudy, run

    argv = ["control", "--theta-ref-deg", "40", "--mass-kg", "1", "--t-end-s", "4", "--push-at-s", "2",
            "--mode", "pressure", "--out", str(tmp_path / "verb")]
    printed = verb_json(argv)
    result = run(ControlStudy(theta_ref=math.radians(40.0), mass_kg=1.0, t_end_s=4.0, push_at_s=2.0))
    assert result.write(tmp_path / "study", "pressure") == ["control_angle.csv", "control_pressure.csv",
                                                            "summary.json"]
    assert same_files(tmp_path / "verb", tmp_path / "study") == sorted(result.write(tmp_path / "x"))
    assert printed == json.loads(json.dumps(result.summary("pressure")))
    assert printed["summary"]["mode"] == "pressure" and printed["other_mode"]["mode"] == "angle"
    # the series at the sensor rate: 100 Hz over [0, 4) s
    series = result.series("angle")
    assert len(series) == 400 and series[1]["t_s"] == pytest.approx(0.01)
    assert series[-1]["t_s"] == pytest.approx(3.99)
    # Table II's states are the window means of the simulation: state a before the push at 2 s
    a = result.rows[0]
    sim = result.flex.angle
    window = (sim.t >= 1.0 - 1e-9) & (sim.t < 2.0 - 1e-9)
    assert a["state"] == "a_no_push" and a["P_pump_MPa"] == pytest.approx(sim.P[window].mean(), rel=1e-3)


def test_control_kind_keeps_the_studys_numbers(tmp_path):
    from softhand.studies.batch.kinds import control
    from softhand.studies.control import ControlStudy, run

    record = control({"theta_ref_deg": 45.0, "t_end_s": 6.0, "push_at_s": 3.0}, HandDesign(), tmp_path)
    result = run(ControlStudy(theta_ref=math.radians(45.0), t_end_s=6.0, push_at_s=3.0))
    assert record["P_before_MPa"] == result.flex.angle_summary.P_before
    assert [record[f"F_v_{r['state']}_kgf"] for r in result.rows] == [r["F_v_estimated_kgf"] for r in result.rows]


# ---------------------------------------------------------------- fit
def test_fit_result_is_what_the_verb_prints_and_writes(tmp_path):
    from softhand.reduced.fitting.csvdata import read_measurements
    from softhand.reduced.vocabulary.design_files import load_design
    from softhand.studies.fit import FitStudy, run

    data = ROOT / "studies" / "data" / "example_bending.csv"
    printed = verb_json(["fit", "--data", str(data), "--params", "V0_mm3,mu_sf_MPa",
                         "--out", str(tmp_path / "verb.toml")])
    result = run(FitStudy(read_measurements(data), ("V0_mm3", "mu_sf_MPa"), data_name=str(data)))
    result.write(tmp_path / "study.toml")
    assert (tmp_path / "verb.toml").read_text() == (tmp_path / "study.toml").read_text()
    assert printed == json.loads(json.dumps(result.summary()))
    # the written design is the fitted one (read back through the design file reader)
    fitted = load_design(tmp_path / "study.toml")
    assert fitted.V0 == pytest.approx(result.fit.values[0], rel=1e-5)
    assert fitted.mu_sf == pytest.approx(result.fit.values[1], rel=1e-5)


# ---------------------------------------------------------------- weights: w(D), one case
def _linear_w(D: float) -> list[float]:
    """A weight vector linear in D that sums to 1: its piecewise-linear interpolation is exact."""
    t = (D - 120.0) / 180.0
    return [0.1 - 0.2 * t, 0.2, 0.2 + 0.1 * t, 0.25, 0.25 + 0.1 * t]


@pytest.fixture
def fake_grasp_fem(tmp_path, monkeypatch):
    import softhand.studies.weights as sw

    def compute(case, out=None, progress=None):
        if out is not None:
            Path(out).mkdir(parents=True, exist_ok=True)
            (Path(out) / "grasp.pvd").write_text("<VTKFile/>")
        w = _linear_w(case.diameter_mm)
        return {"diameter_mm": case.diameter_mm, "w": w, "w_sum": float(sum(w)), "theta_deg": 40.0,
                "hinge_deg": [8.0] * 5, "F_v_fem_N": 3.0, "F_v_reduced_N": 2.5, "contact_force_N": [0.0, 1.0],
                "mesh_size_mm": case.mesh_size_mm, "ndofs": 10, "newton_iterations": 7,
                "factorizations": 3, "wall_seconds": 0.5}

    monkeypatch.setenv("SOFTHAND_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(sw, "compute", compute)
    return compute


def test_one_grasp_case_is_what_the_verb_prints_writes_and_the_kind_keeps(fake_grasp_fem, tmp_path):
    from softhand.studies.batch.kinds import weights as weights_kind
    from softhand.studies.weights import WeightsCase, run_case

    printed = verb_json(["weights", "--diameter-mm", "200", "--mass-kg", "1", "--out", str(tmp_path / "verb")])
    result = run_case(WeightsCase(diameter_mm=200.0, mass_kg=1.0), out=tmp_path / "study")
    assert result.write(tmp_path / "study") == ["result.json", "grasp.pvd"]
    assert same_files(tmp_path / "verb", tmp_path / "study") == ["grasp.pvd", "result.json"]
    assert printed == result.summary()
    record = weights_kind({"diameter_mm": 200.0, "mass_kg": 1.0}, HandDesign(), tmp_path / "kind")
    assert record == json.loads(json.dumps(result.batch_record()))
    assert record["w"] == pytest.approx(_linear_w(200.0)) and record["solver"]["factorizations"] == 3
    assert (tmp_path / "kind" / "grasp.pvd").exists()


def test_weights_sweep_result_is_what_the_verb_prints_and_interpolates_exactly(fake_grasp_fem, tmp_path):
    from softhand.studies.weights import WeightsCase, WeightsStudy, run

    printed = verb_json(["weights", "--diameter-mm", "120,210,300", "--check-mm", "165", "--no-cache",
                         "--plot", str(tmp_path / "verb.png")])
    result = run(WeightsStudy(WeightsCase(), (120.0, 210.0, 300.0), 165.0), cache=False)
    assert printed == json.loads(json.dumps(result.summary()))
    # w linear in D: the interpolated w is the FEM's at the unseen diameter, to round-off
    assert result.check["w_interpolated"] == pytest.approx(_linear_w(165.0), abs=1e-15)
    assert result.check["max_abs_difference"] < 1e-15
    assert result.write(tmp_path / "out") == ["result.json", "table.csv"]
    saved = json.loads((tmp_path / "out" / "result.json").read_text())
    assert [r["diameter_mm"] for r in saved["rows"]] == [120.0, 210.0, 300.0]
    result.plot(tmp_path / "study.png")
    assert (tmp_path / "verb.png").stat().st_size > 10_000 and (tmp_path / "study.png").stat().st_size > 10_000


# ---------------------------------------------------------------- Fig. 8 analogue
def _fig8_result():
    """Rows of two pressures at two angles each, the reduced values by eq. (25) at their (P, theta)."""
    from softhand.studies.fig8 import Fig8Result, paper_w_F_v
    from softhand.studies.weights import WeightsCase
    from softhand.studies.weights_rows import reduced_F_v

    case = WeightsCase(diameter_mm=180.0, mass_kg=2.0)
    rows = []
    for P, theta_deg, F_fem in ((0.6, 35.0, 20.0), (0.6, 45.0, 15.0), (0.9, 40.0, 30.0), (0.9, 50.0, 25.0)):
        w = [0.05, 0.15, 0.2, 0.3, 0.3]
        F_red = reduced_F_v(P, math.radians(theta_deg), case.mass_kg, w, case.design)
        rows.append({"P_cavity_MPa": P, "theta_deg": theta_deg, "w": w, "F_v_fem_N": F_fem, "F_v_reduced_N": F_red,
                     "F_v_reduced_paper_w_N": paper_w_F_v(P, math.radians(theta_deg), case)})
    return Fig8Result(case, rows)


def test_fig8_errors_are_the_rms_and_max_of_the_rows(tmp_path):
    result = _fig8_result()
    e = np.array([(r["F_v_reduced_N"] - r["F_v_fem_N"]) / grasp.KGF for r in result.rows])
    errors = result.errors()
    assert errors["rms_error_kgf"] == pytest.approx(math.sqrt(np.mean(e**2)), rel=1e-14)
    assert errors["max_abs_error_kgf"] == pytest.approx(np.abs(e).max(), rel=1e-14)
    assert errors["paper_w_rms_error_kgf"] is not None  # the paper has a 180 mm w
    assert result.summary() == {"rows": result.rows, **errors}
    assert result.write(tmp_path) == ["fig8_fem_180mm.csv"]
    assert len((tmp_path / "fig8_fem_180mm.csv").read_text().splitlines()) == 1 + len(result.rows)


def test_fig8_lines_pass_through_the_rows_reduced_values():
    """Each pressure's eq. (25) line, with that pressure's (here common) w, at the rows' angles
    is the rows' F_v_reduced (linear interpolation on the 50-point line: ~1e-3 relative)."""
    result = _fig8_result()
    for P, theta, F_kgf in result.model_lines():
        for r in (r for r in result.rows if r["P_cavity_MPa"] == P):
            assert np.interp(r["theta_deg"], theta, F_kgf) == pytest.approx(r["F_v_reduced_N"] / grasp.KGF, rel=2e-3)


def test_weights_fig8_verb_prints_the_results_summary(monkeypatch, tmp_path):
    import softhand.studies.fig8 as f8

    seen = []

    def fake_run(study):
        seen.append(study)
        return _fig8_result()

    monkeypatch.setattr(f8, "run", fake_run)
    printed = verb_json(["weights", "--diameter-mm", "180", "--mass-kg", "2", "--fig8", "0.9,0.6",
                         "--plot", str(tmp_path / "fig8.png")])
    assert printed == json.loads(json.dumps(_fig8_result().summary()))
    assert seen[0].pressures_mpa == (0.9, 0.6) and seen[0].case.diameter_mm == 180.0
    assert (tmp_path / "fig8.png").stat().st_size > 10_000


# ---------------------------------------------------------------- grasp forces at one state
def test_grasp_kind_keeps_the_verbs_forces(tmp_path):
    from softhand.studies.batch.kinds import grasp as grasp_kind

    printed = verb_json(["grasp", "--pressure-mpa", "1.2", "--theta-deg", "40", "--mass-kg", "2",
                         "--weights", "0.1,0.2,0.2,0.25,0.25"])
    record = grasp_kind({"pressure_mpa": 1.2, "theta_deg": 40.0, "mass_kg": 2.0,
                         "weights": [0.1, 0.2, 0.2, 0.25, 0.25]}, HandDesign(), tmp_path)
    assert record == {k: printed[k] for k in ("F_x_N", "F_y_N", "F_v_N", "F_v_kgf", "w")}
    # F_v in kgf is F_v in N over g (kgf = 9.80665 N)
    assert record["F_v_kgf"] == pytest.approx(record["F_v_N"] / 9.80665, rel=1e-12)
