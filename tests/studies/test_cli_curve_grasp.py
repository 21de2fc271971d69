"""softhand curve / grasp: columns, JSON shapes, the plot, bad input -> one line, exit 2."""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from softhand.reduced.equations import grasp, hand, reservoir
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.cli.main import main

ROOT = Path(__file__).resolve().parents[2]

D = HandDesign()


def run_json(capsys, *argv):
    assert main([*argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_curve_by_angle(capsys):
    out = run_json(capsys, "curve", "--theta-deg", "0:90:10")
    rows = out["rows"]
    assert [r["theta_deg"] for r in rows] == pytest.approx(np.arange(0, 91, 10))  # stop included
    assert set(rows[0]) == {"theta_deg", "P_pump_MPa", "P_cavity_MPa", "V_mm3", "p_reservoir_MPa", "h_mm",
                            "lambda_r"}
    for r in rows:  # eq. (27): P = p_finger - p_r, and p_finger is eq. (28)'s pressure
        assert r["P_pump_MPa"] == pytest.approx(r["P_cavity_MPa"] - r["p_reservoir_MPa"], abs=1e-12)
    assert rows[0]["P_cavity_MPa"] == 0.0 and rows[0]["P_pump_MPa"] < 0
    assert rows[0]["V_mm3"] == D.V0
    assert rows[5]["P_pump_MPa"] == pytest.approx(float(hand.pressure(math.radians(50), D)), rel=1e-12)
    assert out["design"]["V0_mm3"] == D.V0


def test_curve_with_the_fem_reservoir_model_has_no_ellipse_columns(capsys, tmp_path):
    design = tmp_path / "softhand.fem.toml"
    design.write_text('reservoir_model = "fem"\n')
    rows = run_json(capsys, "curve", "--theta-deg", "0,30", "--design", str(design))["rows"]
    assert set(rows[0]) == {"theta_deg", "P_pump_MPa", "P_cavity_MPa", "V_mm3", "p_reservoir_MPa"}
    assert rows[0]["p_reservoir_MPa"] == pytest.approx(-rows[0]["P_pump_MPa"], abs=1e-12)  # theta = 0: no finger


def test_curve_by_pressure_and_table(capsys):
    rows = run_json(capsys, "curve", "--pressure-mpa", "0,0.4,0.8")["rows"]
    assert set(rows[0]) == {"P_pump_MPa", "theta_deg", "P_cavity_MPa", "theta_no_reservoir_deg"}
    for r in rows:  # the angles (rounded to 1e-10 deg, dP/dtheta < 3 MPa/rad) reproduce the pressures
        theta = math.radians(r["theta_deg"])
        assert hand.pressure(theta, D) == pytest.approx(r["P_pump_MPa"], abs=1e-10)
        # the cavity holds the pump's pressure plus the reservoir's at that bend (eq. (27))
        V = reservoir.oil_volume(theta, D)
        p_r = float(reservoir.state(np.array([V]), D)["p_reservoir_MPa"][0])
        assert r["P_cavity_MPa"] == pytest.approx(r["P_pump_MPa"] + p_r, abs=1e-9)
        assert r["theta_deg"] > r["theta_no_reservoir_deg"]  # the reservoir helps
    assert main(["curve", "--theta-deg", "0:90:15"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[:3] == ["theta_deg", "P_pump_MPa", "P_cavity_MPa"] and len(lines) == 8


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
    assert capfd.readouterr().err == f"softhand curve: wrote {path}\n" and not caplog.records


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


#: a 3-finger gripper of a user's own (not the paper's): the finger of the "fem" model bends
#: 28.9 deg free at a pump pressure of 1 MPa
GRIPPER = "l0_mm = 150.0\na_mm = 3.5\nb_mm = 4.0\nd_mm = 13.0\nn = 3\n"


def test_grasp_fem_past_the_free_bend_is_an_error_naming_the_bend(tmp_path, capsys):
    """At a bend the free finger does not reach at that pressure no placement of the object is
    touched: one line naming the free bend (below which it would press) and the pump pressure
    from which it presses at the bend asked, exit 2 -- not F_v = 0 with the object 480 mm deep."""
    from softhand.reduced.calibrated import finger_hinges

    design = tmp_path / "gripper.toml"
    design.write_text(GRIPPER)
    argv = ["grasp", "--model", "fem", "--diameter-mm", "120", "--mass-kg", "0.8", "--pressure-mpa", "1.0",
            "--theta-deg", "60", "--design", str(design)]
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and err.startswith("softhand grasp: error: --theta-deg")
    from softhand.reduced.vocabulary.design_files import load_design

    fem = finger_hinges.fem_finger(load_design(design))
    P_cavity = 1.0 + float(hand.pressure(math.radians(60), fem, reservoir=False) - hand.pressure(math.radians(60), fem))
    free = math.degrees(float(hand.bend_angle(P_cavity, fem, reservoir=False)))
    assert f"bends only to {free:.4g} deg" in err and f"bends below {free:.4g} deg" in err
    P_from = float(hand.pressure(math.radians(60), fem))
    assert f"from P_pump = {P_from:.4g} MPa on" in err
    # and from that pump pressure on the finger does press at 60 deg (eq. (29): F_v > 0)
    assert main([*argv[:-4], "--pressure-mpa", f"{P_from + 0.2:.3f}", "--theta-deg", "60",
                 "--design", str(design), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["contact_link"] >= 1 and result["F_v_N"] > 0


def _figures(monkeypatch) -> list:
    """The matplotlib figures the verbs save (``save_figure`` still writes them)."""
    from softhand.studies.io import files

    saved, save = [], files.save_figure
    monkeypatch.setattr(files, "save_figure", lambda fig, path, **kw: (saved.append(fig), save(fig, path, **kw))[1])
    return saved


def test_curve_plot_is_titled_with_its_design_and_finger_model(tmp_path, capsys, monkeypatch):
    saved = _figures(monkeypatch)
    design = tmp_path / "gripper.toml"
    design.write_text(GRIPPER)
    path = tmp_path / "one.png"
    assert main(["curve", "--pressure-mpa", "0:1:0.5", "--design", str(design), "--model", "fem",
                 "--plot", str(path)]) == 0
    assert path.read_bytes()[:4] == b"\x89PNG"
    assert saved[-1].axes[0].get_title() == "Free bending, reduced model: gripper, finger model fem"
    assert capsys.readouterr().err.splitlines()[-1] == f"softhand curve: wrote {path}"
    assert main(["curve", "--pressure-mpa", "0:1:0.5", "--plot", str(path)]) == 0
    assert saved[-1].axes[0].get_title() == "Free bending, reduced model: the paper's design, finger model paper"
    assert "pump pressure P_pump" in saved[-1].axes[0].get_xlabel()


def test_curve_compare_overlays_designs_and_models_on_one_plot(tmp_path, capsys, monkeypatch):
    """Two designs on both finger models: four curves on one plot, each named in its legend, and
    each curve's rows the ones the design alone prints."""
    saved = _figures(monkeypatch)
    (tmp_path / "gripper.toml").write_text(GRIPPER)
    (tmp_path / "paper.toml").write_text((ROOT / "studies" / "designs" / "paper.toml").read_text())
    path = tmp_path / "compare.png"
    argv = ["curve", "--theta-deg", "0:60:30", "--compare", str(tmp_path / "paper.toml"),
            str(tmp_path / "gripper.toml"), "--model", "paper,fem", "--plot", str(path), "--json"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)["curves"]
    labels = [f"{name}, finger model {model}" for name in ("paper", "gripper") for model in ("paper", "fem")]
    assert [c["label"] for c in out] == labels
    legend = [t.get_text() for t in saved[-1].axes[0].get_legend().get_texts()]
    assert legend == labels and path.read_bytes()[:4] == b"\x89PNG"
    assert main(["curve", "--theta-deg", "0:60:30", "--design", str(tmp_path / "gripper.toml"),
                 "--model", "fem", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["rows"] == out[3]["rows"]


def test_grasp_fem_in_the_crease_of_two_pads_prints_both(tmp_path, capsys):
    """A ball between pads 3 and 4 (the state of neither pad alone): the JSON names the second
    pad, its normal force and its point beside the first, and F_v is the state's."""
    from softhand.reduced.calibrated import finger_hinges, grasp_fem
    from softhand.reduced.vocabulary.design_files import load_design

    design = tmp_path / "crease.toml"
    design.write_text("a_mm = 6.0\nd_mm = 13.59\nl0_mm = 162.49\nhinge_s_mm = ["
                      + ", ".join(f"{s * 162.49 / 180.0!r}" for s in (30.0, 60.0, 90.0, 120.0, 150.0)) + "]\n")
    fem = finger_hinges.fem_finger(load_design(design))
    s = grasp_fem.grasp_state(fem, 150.0, 1.6785, 1.0)
    assert s.crease is not None
    P_pump = 1.6785 - float(hand.finger_pressure(s.theta, fem)) + float(hand.pressure(s.theta, fem))
    assert main(["grasp", "--model", "fem", "--diameter-mm", "150", "--mass-kg", "1", "--pressure-mpa", repr(P_pump),
                 "--theta-deg", repr(math.degrees(s.theta)), "--design", str(design), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert (out["contact_link"], out["crease_link"]) == (3, 4)
    assert out["crease_force_N"] == pytest.approx(s.crease[0], rel=1e-5)
    assert out["contact_force_N"] == pytest.approx(s.N, rel=1e-3, abs=1e-4)
    assert out["F_v_N"] == pytest.approx(s.F_v, rel=1e-6)
    np.testing.assert_allclose(out["crease_point_mm"], s.crease[1], atol=1e-4)
