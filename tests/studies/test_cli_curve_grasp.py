"""softhand curve / grasp: columns, JSON shapes, the plot, bad input -> one line, exit 2."""
import json
import math

import numpy as np
import pytest

from softhand.reduced.equations import grasp, hand
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.cli.main import main

D = HandDesign()


def run_json(capsys, *argv):
    assert main([*argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_curve_by_angle(capsys):
    out = run_json(capsys, "curve", "--theta-deg", "0:90:10")
    rows = out["rows"]
    assert [r["theta_deg"] for r in rows] == pytest.approx(np.arange(0, 91, 10))  # stop included
    assert set(rows[0]) == {"theta_deg", "P_MPa", "P_no_reservoir_MPa", "V_mm3", "p_reservoir_MPa", "h_mm",
                            "lambda_r"}
    for r in rows:  # eq. (27): P = p_finger - p_r, and p_finger is eq. (28)'s pressure
        assert r["P_MPa"] == pytest.approx(r["P_no_reservoir_MPa"] - r["p_reservoir_MPa"], abs=1e-12)
    assert rows[0]["P_no_reservoir_MPa"] == 0.0 and rows[0]["P_MPa"] < 0
    assert rows[0]["V_mm3"] == D.V0
    assert rows[5]["P_MPa"] == pytest.approx(float(hand.pressure(math.radians(50), D)), rel=1e-12)
    assert out["design"]["V0_mm3"] == D.V0


def test_curve_with_the_fem_reservoir_model_has_no_ellipse_columns(capsys, tmp_path):
    design = tmp_path / "softhand.fem.toml"
    design.write_text('reservoir_model = "fem"\n')
    rows = run_json(capsys, "curve", "--theta-deg", "0,30", "--design", str(design))["rows"]
    assert set(rows[0]) == {"theta_deg", "P_MPa", "P_no_reservoir_MPa", "V_mm3", "p_reservoir_MPa"}
    assert rows[0]["p_reservoir_MPa"] == pytest.approx(-rows[0]["P_MPa"], abs=1e-12)  # theta = 0: no finger


def test_curve_by_pressure_and_table(capsys):
    rows = run_json(capsys, "curve", "--pressure-mpa", "0,0.4,0.8")["rows"]
    assert set(rows[0]) == {"P_MPa", "theta_deg", "theta_no_reservoir_deg"}
    for r in rows:  # the angles (rounded to 1e-10 deg, dP/dtheta < 3 MPa/rad) reproduce the pressures
        assert hand.pressure(math.radians(r["theta_deg"]), D) == pytest.approx(r["P_MPa"], abs=1e-10)
        assert r["theta_deg"] > r["theta_no_reservoir_deg"]  # the reservoir helps
    assert main(["curve", "--theta-deg", "0:90:15"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[:3] == ["theta_deg", "P_MPa", "P_no_reservoir_MPa"] and len(lines) == 8


def test_curve_plot(tmp_path, capsys):
    path = tmp_path / "fig7.png"
    assert main(["curve", "--pressure-mpa", "0:0.8:0.1", "--plot", str(path)]) == 0
    assert path.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("suffix, magic", [(".eps", b"%!PS-Adobe-3.0 EPSF"), (".ps", b"%!PS-Adobe-3.0")])
def test_curve_plot_in_postscript_says_nothing_on_stderr(tmp_path, capfd, caplog, suffix, magic):
    """PostScript has no translucency: matplotlib's backend logs (to stderr, outside pytest)
    that it draws it opaque; the plot is read the same, so the line is not shown."""
    path = tmp_path / f"fig7{suffix}"
    assert main(["curve", "--pressure-mpa", "0:0.8:0.1", "--plot", str(path)]) == 0
    assert path.read_bytes().startswith(magic)
    assert capfd.readouterr().err == "" and not caplog.records


def test_grasp_json(capsys):
    out = run_json(capsys, "grasp", "--pressure-mpa", "0.89", "--theta-deg", "50", "--mass-kg", "2",
                   "--weights", "paper180", "--normalise")
    w = np.array(grasp.PAPER_WEIGHTS[180.0]) / 1.4
    F = grasp.grasp_forces(0.89, math.radians(50), 2.0, w, D)
    assert out["F_v_N"] == pytest.approx(float(F.F_v), rel=1e-12)
    assert out["F_v_kgf"] == pytest.approx(out["F_v_N"] / 9.80665)
    assert out["F_y_N"] == pytest.approx(2 * D.g / 4)
    assert out["w"] == pytest.approx(w) and out["w_sum"] == pytest.approx(1.0)


def test_grasp_warns_on_weight_sum(capsys):
    assert main(["grasp", "--pressure-mpa", "1", "--theta-deg", "40", "--mass-kg", "1",
                 "--weights=-0.13,0,0.67,0.33,0.53"]) == 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "sum to 1.4" in err


@pytest.mark.parametrize("argv, field", [
    (["curve", "--theta-deg", "0:-10:5"], "--theta-deg"),
    (["curve", "--theta-deg", "0:400:100"], "--theta-deg"),
    (["curve", "--pressure-mpa", "0,9"], "--pressure-mpa"),
    (["curve", "--theta-deg", "a,b"], "--theta-deg"),
    (["grasp", "--pressure-mpa", "0.9", "--theta-deg", "50", "--mass-kg", "-2",
      "--diameter-mm", "180"], "--mass-kg"),
    (["grasp", "--pressure-mpa", "0.9", "--theta-deg", "50", "--mass-kg", "2",
      "--diameter-mm", "-5"], "--diameter-mm"),
    (["grasp", "--pressure-mpa", "0.9", "--theta-deg", "50", "--mass-kg", "2",
      "--weights", "0.5,0.5"], "--weights"),
    (["grasp", "--pressure-mpa", "0.9,1", "--theta-deg", "50", "--mass-kg", "2",
      "--diameter-mm", "180"], "--pressure-mpa"),
])
def test_bad_input_is_one_line_exit_2(argv, field, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and field in err


GRASP = ["grasp", "--theta-deg", "50", "--mass-kg", "2"]


@pytest.mark.parametrize("argv, allowed", [
    (["curve", "--theta-deg", "1,,2"], "start:stop:step (step > 0, stop >= start) or a comma-separated list"),
    ([*GRASP, "--pressure-mpa", "1e309", "--weights", "paper180"], "must be one number in [-5, 5]"),
    ([*GRASP, "--pressure-mpa", "0:1:-1", "--weights", "paper180"], "must be one number in [-5, 5]"),
    ([*GRASP, "--pressure-mpa", "1", "--weights=1,,2"],
     "must be a comma-separated list of finite numbers, or one of paper180, paper240"),
    (["weights", "--diameter-mm", "180", "--pressure-mpa", "x"], "must be a number in [0.01, 5]"),
])
def test_a_bad_value_is_told_what_its_field_takes(argv, allowed, capsys):
    """A field of one number is not told it may be a range; --weights is told the paper's names."""
    assert main(argv) == 2
    assert allowed in capsys.readouterr().err


@pytest.mark.parametrize("text, argv, field", [
    ("V0_mm3 = 3000.0\n", ["curve", "--theta-deg", "0:90:10"], "V0_mm3"),  # 4737 mm^3 needed at 90 deg
    ("bogus = 1\n", ["curve", "--theta-deg", "0:90:10"], "bogus"),
    ("b_mm = -5.0\n", ["curve", "--pressure-mpa", "0.5"], "b_mm"),
    ("n_s = 4\nhinge_s_mm = [40.0, 80.0, 120.0, 160.0]\n",
     ["grasp", "--pressure-mpa", "1", "--theta-deg", "40", "--mass-kg", "2", "--weights", "paper180"],
     "n_s = 4"),
])
def test_bad_design_is_one_line_exit_2(tmp_path, capsys, text, argv, field):
    design = tmp_path / "design.toml"
    design.write_text(text)
    assert main([*argv, "--design", str(design)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and field in err


def test_usage_errors_exit_2(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["curve", "--theta-deg", "0:90:10", "--pressure-mpa", "0.1"])
    assert exc.value.code == 2
    with pytest.raises(SystemExit) as exc:
        main(["grasp", "--pressure-mpa", "0.9", "--theta-deg", "50", "--mass-kg", "2"])
    assert exc.value.code == 2


def test_grasp_whose_fem_w_does_not_converge_is_one_line_exit_1(capsys, monkeypatch):
    """--diameter-mm takes w from the grasp FEM; when that stops, one line (no residual history,
    no traceback) and exit 1, as for every FEM that gives up."""
    from softhand.fem.newton import NotConverged
    from softhand.studies import weights

    def stops(case):
        raise NotConverged("Newton stopped at P = 0.6 MPa on the way to 0.8 MPa; residual history ['1']",
                           [1.0], None)

    monkeypatch.setattr(weights, "weights", stops)
    argv = ["grasp", "--pressure-mpa", "0.8", "--theta-deg", "40", "--mass-kg", "1", "--diameter-mm", "150"]
    assert main(argv) == 1
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "Traceback" not in err
    assert "P = 0.6 MPa" in err and "residual history" not in err


def test_the_pressures_of_a_curve_are_those_both_models_reach():
    """P -> theta answers with and without the reservoir, or names the pressures both reach:
    the larger of the two lower ends, the smaller of the upper ones (each end a pressure its
    model reaches, eq. (27) / (28) at the end of its bend range)."""
    from softhand.reduced.equations import hand

    d = HandDesign()
    (lo_r, hi_r), (lo_f, hi_f) = hand.pressure_span(d, True), hand.pressure_span(d, False)
    lo, hi = max(lo_r, lo_f), min(hi_r, hi_f)
    assert lo_r != lo_f and hi_r != hi_f  # the two models' ranges differ at both ends here
    theta, theta_free = hand.bend_angles(np.array([lo, hi]), d)
    np.testing.assert_allclose(hand.pressure(theta, d, reservoir=True), [lo, hi], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(hand.pressure(theta_free, d, reservoir=False), [lo, hi], rtol=1e-9, atol=1e-12)
    for outside in (lo - 1e-3, hi + 1e-3):
        with pytest.raises(InputError, match=f"must be in \\[{lo:.4g}, {hi:.4g}\\] MPa"):
            hand.bend_angles(outside, d)
