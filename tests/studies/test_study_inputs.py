"""Study files: every kind's parameters checked at load time (before any case runs), the
contradictions refused, and damaged numbers in a case file recomputed."""
import json
import re

import pytest

from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.batch.runner import RESULT, case_state, plan, read_case, run_study, study_dir
from softhand.studies.batch.studyfile import load_study
from softhand.studies.cli.main import main

FINGER = ('kind = "finger_bend"\n[params]\ntheta_target_deg = 64.0\np_max_mpa = 2.0\np_step_mpa = 0.5\n'
          "{extra}[sweep]\na_mm = [4.0]\n")
GRASP = 'kind = "grasp"\n[params]\nmass_kg = 2.0\n{extra}[sweep]\ntheta_deg = [40, 45]\npressure_mpa = [0.8]\n'
W = "weights = [0.1, 0.2, 0.2, 0.25, 0.25]\n"


def _load(tmp_path, text):
    path = tmp_path / "s.toml"
    path.write_text(text)
    return load_study(path)


@pytest.mark.parametrize("text, field", [
    ('kind = "curve"\n[sweep]\npressure_mpa = [0.5, 5.0]\n', "pressure_mpa"),  # beyond the design's range
    ('kind = "reservoir"\nmesh_size_mm = 24.0\n[design]\nV0_mm3 = 100.0\n[sweep]\ntheta_max_deg = [180.0]\n',
     "V0_mm3"),  # less oil than the fingers take
    ('kind = "curve"\n[sweep]\ntheta_deg = [10]\nV0_mm3 = [17800.0, 1.0e7]\n', "V0_mm3"),  # sheet x344
])
def test_cases_the_design_cannot_answer_are_refused_at_load_time(tmp_path, text, field):
    """These failed as cases (exit 1, a failed.json) after the run began."""
    with pytest.raises(InputError) as info:
        _load(tmp_path, text)
    assert field in info.value.field or field in str(info.value)


@pytest.mark.parametrize("text, field", [
    # finger_bend: every key bend_case reads is required (it ran the FEM, then raised KeyError)
    ('kind = "finger_bend"\n[params]\npressures_mpa = [0.2, 0.5]\n[sweep]\na_mm = [4.0]\n', "theta_target_deg"),
    (FINGER.format(extra="pressures_mpa = [-0.2, 0.5]\n"), "pressures_mpa"),
    (FINGER.format(extra="pressures_mpa = [0.5, 0.2]\n"), "pressures_mpa"),
    (FINGER.format(extra="pressures_mpa = [0.2, 1e9]\n"), "pressures_mpa"),
    (FINGER.format(extra="pressures_mpa = [0.2]\n").replace("p_step_mpa = 0.5", "p_step_mpa = 1e-6"),
     "p_step_mpa"),
    (FINGER.format(extra="pressures_mpa = [0.2]\n").replace("[sweep]\na_mm = [4.0]",
                                                            "[sweep]\na_mm = [4.0]\np_max_mpa = [1.0, 1e9]")
     .replace("p_max_mpa = 2.0\n", ""), "p_max_mpa"),                       # a sweep axis's value
    (FINGER.format(extra="pressures_mpa = [0.2]\naxial_size_mm = 5.0\n").replace(
        'kind = "finger_bend"\n', 'kind = "finger_bend"\nmesh_size_mm = 6.0\n'), "axial_size_mm"),
    # grasp: weights as softhand grasp takes them
    (GRASP.format(extra="weights = [0, 0, 0, 0, 0]\n"), "weights"),
    (GRASP.format(extra="weights = [1e300, 1, 1, 1, 1]\n"), "weights"),
    (GRASP.format(extra="weights = [0.2, 0.2, 0.2, 0.2]\n"), "weights"),  # n_s = 5
    (GRASP.format(extra=W + "diameter_mm = 180.0\n"), "diameter_mm"),
    (GRASP.format(extra=W).replace("theta_deg = [40, 45]", "theta_deg = [40, 45]\ndiameter_mm = [180.0]"),
     "diameter_mm"),
    # a design key both in [design] and on a sweep axis (the sweep silently won)
    (GRASP.format(extra=W).replace('kind = "grasp"\n', 'kind = "grasp"\n[design]\nV0_mm3 = 16000.0\n')
     .replace("[sweep]\n", "[sweep]\nV0_mm3 = [15000.0, 17000.0]\n"), "V0_mm3"),
])
def test_bad_case_parameters_are_refused_at_load_time(tmp_path, text, field):
    with pytest.raises(InputError) as info:
        _load(tmp_path, text)
    assert field in info.value.field


def test_good_finger_and_grasp_studies_load(tmp_path):
    assert len(plan(_load(tmp_path, FINGER.format(extra="pressures_mpa = [0.2, 0.5]\n")))) == 1
    assert len(plan(_load(tmp_path, GRASP.format(extra=W)))) == 2
    assert len(plan(_load(tmp_path, GRASP.format(extra="diameter_mm = 180.0\n")))) == 2
    # the paper's own w for 180 mm sums to 1.4, not 1 (eq. (23)): taken, as softhand grasp takes it
    paper180 = "weights = [-0.13, 0.0, 0.67, 0.33, 0.53]\n"
    assert len(plan(_load(tmp_path, GRASP.format(extra=paper180)))) == 2


def test_a_refused_study_is_one_line_exit_2_and_writes_nothing(tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text(FINGER.format(extra="pressures_mpa = [0.5, 0.2]\n"))
    assert main(["study", "run", str(path), "--results", str(tmp_path / "res"), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "pressures_mpa" in err
    assert not (tmp_path / "res").exists()


@pytest.mark.parametrize("bad", ["NaN", "Infinity", '"lots"', "[1.0, NaN]", "{}"])
def test_a_case_file_with_bad_numbers_is_corrupt_and_recomputed(tmp_path, capsys, bad):
    study = _load(tmp_path, GRASP.format(extra=W))
    root = tmp_path / "res"
    assert run_study(study, results_root=root, workers=1, progress=False).computed == 2
    sdir, case = study_dir(study, root), plan(study)[0]
    path = sdir / case.key / RESULT
    good = json.loads(path.read_text())["numbers"]["F_x_N"]
    path.write_text(re.sub(r'("F_x_N": )[^,\n]+', r"\g<1>" + bad, path.read_text(), count=1))
    assert case_state(sdir, case) == "corrupt" and read_case(sdir, case) is None
    capsys.readouterr()
    summary = run_study(study, results_root=root, workers=1, progress=False)
    assert (summary.corrupt, summary.computed, summary.reused) == (1, 1, 1)
    assert "do not parse; recomputing" in capsys.readouterr().err
    assert json.loads(path.read_text())["numbers"]["F_x_N"] == good


def test_a_kinds_nan_is_stored_as_null_and_read_back_as_done(tmp_path):
    """nan from a kind (not applicable: a run that never settles) is JSON null, so that a case
    file holding NaN can only be a damaged one."""
    from softhand.studies.batch.cases import execute_case

    out = execute_case(lambda params, design, outdir: {"y": float("nan"), "z": [1.0, float("inf")]}, {}, None)
    assert out["status"] == "done" and out["numbers"] == {"y": None, "z": [1.0, None]}


def test_a_study_of_another_kind_under_the_same_name_is_refused(tmp_path, capsys):
    """Two studies named alike share results/<name>: the second's run, status or report would
    overwrite the first's index.csv and report. Refused naming the name; the first's files stay."""
    (tmp_path / "a.toml").write_text('name = "sa"\nkind = "curve"\n[sweep]\ntheta_deg = [10, 20]\n')
    (tmp_path / "b.toml").write_text(GRASP.replace('kind = "grasp"', 'name = "sa"\nkind = "grasp"')
                                     .format(extra="diameter_mm = 180.0\n"))
    root = tmp_path / "res"
    assert main(["study", "run", str(tmp_path / "a.toml"), "--results", str(root), "--no-progress"]) == 0
    capsys.readouterr()
    index = (root / "sa" / "index.csv").read_text()
    for verb in ("run", "status", "report"):
        assert main(["study", verb, str(tmp_path / "b.toml"), "--results", str(root)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "name = 'sa'" in err and "'curve' study" in err
    assert (root / "sa" / "index.csv").read_text() == index and not (root / "sa" / "report.md").exists()
    assert main(["study", "report", str(tmp_path / "a.toml"), "--results", str(root)]) == 0
