"""``softhand reproduce``: every section present, guarded, resumable; the report is complete."""
import csv
import json
import re

import numpy as np
import pytest

from softhand.studies.cli.main import main
from softhand.studies.reproduce.core import Section, exit_code, reproduce, sections

#: the cheap sections (reduced model only): the "tiny" run of the tests
REDUCED = ("fig7_reduced", "table2_reduced", "fig8_reduced", "table2_control", "fig10_control")


def test_tiny_run_writes_a_report_with_every_section(tmp_path):
    out = tmp_path / "rep"
    outcomes = reproduce(out, quick=True, only=REDUCED, progress=False)
    status = {o.section.key: o.status for o in outcomes}
    assert [o.section.key for o in outcomes] == [s.key for s in sections()]
    assert all(status[k] == "done" for k in REDUCED), status
    assert set(status.values()) <= {"done", "not available", "not selected", "skipped"}
    report = (out / "report.md").read_text()
    for s in sections():  # every section has its heading and its status in the report
        assert f"## {s.title}" in report
    for key in REDUCED:
        assert (out / key / "result.json").is_file() and f"]({key}/" in report
    assert exit_code(outcomes) == 0

    # the headline number is the one in the section's own data, computed in this run
    rows = list(csv.DictReader(open(out / "fig7_reduced" / "fig7_reduced.csv")))
    offset = [float(r["P_cavity_MPa"]) - float(r["P_pump_MPa"]) for r in rows]
    summary = {r["name"]: r["value"] for r in csv.DictReader(open(out / "summary.csv"))}
    assert np.isclose(float(summary["offset_max_MPa"]), max(offset), rtol=1e-12)  # CSV rounding

    # a second run reuses what is finished, with the same numbers
    again = reproduce(out, quick=True, only=REDUCED, progress=False)
    assert all(o.status == "reused" for o in again if o.section.key in REDUCED)
    assert [o.numbers for o in again] == [o.numbers for o in outcomes]


def _ok(ctx, outdir):
    (outdir / "data.csv").write_text("x\n1\n")
    return "see [data](data.csv)", {"x": 1.0}


def _boom(ctx, outdir):
    raise RuntimeError("solver exploded")


@pytest.mark.parametrize("workers", [1, 2])
def test_missing_and_failing_sections_are_reported_and_the_others_go_on(tmp_path, workers):
    """Also with the sections built side by side in two processes: the same outcomes, in order."""
    fake = [Section("missing", "Missing", ("no_such_module_softhand",), _ok),
            Section("attr", "Missing attribute", ("softhand.reduced.equations.hand:no_such_function",), _ok),
            Section("boom", "Boom", (), _boom),
            Section("fine", "Fine", ("softhand.reduced.equations.hand",), _ok),
            Section("costly", "Costly", (), _ok, cost=10.0)]
    outcomes = reproduce(tmp_path, section_list=fake, progress=False, workers=workers)
    assert [o.status for o in outcomes] == ["not available", "not available", "failed", "done", "done"]
    assert (tmp_path / "costly" / "data.csv").is_file()
    again = reproduce(tmp_path, section_list=fake, progress=False, workers=workers)
    assert [o.status for o in again] == ["not available", "not available", "failed", "reused", "reused"]
    assert exit_code(outcomes) == 1
    failed = json.loads((tmp_path / "boom" / "failed.json").read_text())
    assert "solver exploded" in failed["error"]
    report = (tmp_path / "report.md").read_text()
    assert "no_such_module_softhand" in report and "solver exploded" in report
    assert "see [data](fine/data.csv)" in report and (tmp_path / "fine" / "data.csv").is_file()



def _stop(ctx, outdir):
    raise KeyboardInterrupt


def test_an_interrupted_run_reports_what_it_left_out_by_choice_as_such(tmp_path):
    fake = [Section("first", "First", (), _ok), Section("stop", "Stop", (), _stop),
            Section("later", "Later", (), _ok), Section("unchosen", "Unchosen", (), _ok)]
    try:
        reproduce(tmp_path, section_list=fake, only=("first", "stop", "later"), progress=False)
    except KeyboardInterrupt:
        pass
    else:
        raise AssertionError("the interrupt was swallowed")
    report = (tmp_path / "report.md").read_text()
    status = {title: report.split(f"## {title}")[1].split("##")[0] for title in ("Stop", "Later", "Unchosen")}
    assert "interrupted" in status["Stop"] and "interrupted" in status["Later"]
    assert "not selected" in status["Unchosen"] and "interrupted" not in status["Unchosen"]

def test_cli(tmp_path, capsys):
    out = str(tmp_path / "r")
    assert main(["reproduce", "--out", out, "--only", "table2_reduced", "--no-progress"]) == 0
    assert re.search(r"table2_reduced +done", capsys.readouterr().out)
    assert main(["reproduce", "--out", out, "--only", "fig99"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_no_progress_silences_the_sections_own_bars_too(tmp_path, capsys):
    """A FEM section draws its own bar under the run's; --no-progress silences both, and the
    flag is no parameter of the case (the run with bars reuses the quiet one's result)."""
    argv = ["reproduce", "--quick", "--only", "reservoir_fem", "--out", str(tmp_path)]
    assert main([*argv, "--no-progress"]) == 0
    assert capsys.readouterr().err == ""
    assert main([*argv, "--fresh"]) == 0
    assert "inflating the sheet" in capsys.readouterr().err
    assert main(argv) == 0
    assert re.search(r"reservoir_fem\s+reused", capsys.readouterr().out)


def test_an_interrupted_rerun_reports_finished_sections_as_reused(tmp_path):
    done = [Section("first", "First", (), _ok), Section("second", "Second", (), _ok)]
    reproduce(tmp_path, section_list=done, progress=False)
    try:  # Ctrl-C in a section before the two finished ones are reached
        reproduce(tmp_path, section_list=[Section("stop", "Stop", (), _stop), *done], progress=False)
    except KeyboardInterrupt:
        pass
    else:
        raise AssertionError("the interrupt was swallowed")
    report = (tmp_path / "report.md").read_text()
    for title in ("First", "Second"):
        body = report.split(f"## {title}")[1].split("##")[0]
        assert "reused" in body and "interrupted" not in body, body
    assert "see [data](first/data.csv)" in report  # their text and numbers, as a finished run's
