"""Study files: parsing, sweeps as products, design axes, and one-line errors for bad files."""
import math

import pytest

from softhand.reduced.vocabulary.design import HandDesign
from softhand.studies.cli.main import main
from softhand.studies.batch.studyfile import KINDS, load_study, resolve_kind

GOOD = """
kind = "curve"
design = "d.toml"
[sweep]
theta_deg = "0:90:30"
mu_sf_MPa = [1.0, 1.3]
"""


def write(tmp_path, text, name="s.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_sweep_is_the_product_and_design_axes_change_the_design(tmp_path):
    write(tmp_path, 'V0_mm3 = 16000.0\n', "d.toml")  # relative to the study file
    study = load_study(write(tmp_path, GOOD))
    assert study.name == "s" and study.kind == "curve"
    cases = study.cases()
    assert len(cases) == 4 * 2  # 0, 30, 60, 90 (stop included) x two moduli
    assert sorted({p["theta_deg"] for p, _ in cases}) == [0.0, 30.0, 60.0, 90.0]
    assert {d.mu_sf for _, d in cases} == {1.0, 1.3}
    assert all(d.V0 == 16000.0 and "mu_sf_MPa" not in p for p, d in cases)


def test_inline_design_overrides_over_a_base_file(tmp_path):
    write(tmp_path, 'd_mm = 12.0\n', "base.toml")
    study = load_study(write(tmp_path, """kind = "curve"
[design]
file = "base.toml"
theta0_deg = 25.0
[sweep]
pressure_mpa = [0.1, 0.2]
"""))
    assert study.design.d == 12.0 and math.isclose(study.design.theta0, math.radians(25.0))
    assert study.design.a == HandDesign().a


def test_every_registered_kind_resolves_to_a_function():
    for name in KINDS:
        assert callable(resolve_kind(name))


BAD = {
    "unknown top key": ('kind = "curve"\ncolour = 1\n[sweep]\ntheta_deg = [1]\n', "colour"),
    "unknown kind": ('kind = "curl"\n[sweep]\ntheta_deg = [1]\n', "kind"),
    "empty sweep axis": ('kind = "curve"\n[sweep]\ntheta_deg = []\n', "empty sweep"),
    "no sweep": ('kind = "curve"\n', "sweep"),
    "unknown axis": ('kind = "curve"\n[sweep]\nthetta_deg = [1]\n', "thetta_deg"),
    "wrong axis type": ('kind = "curve"\n[sweep]\ntheta_deg = [1, true]\n', "theta_deg"),
    "bad range": ('kind = "curve"\n[sweep]\ntheta_deg = "0:90"\n', "start:stop:step"),
    "wrong type": ('kind = "curve"\ndescription = 3\n[sweep]\ntheta_deg = [1]\n', "description"),
    "mesh on reduced kind": ('kind = "curve"\nmesh_size_mm = 2\n[sweep]\ntheta_deg = [1]\n',
                             "mesh_size_mm"),
    "bad design key": ('kind = "curve"\n[design]\nl0 = 3\n[sweep]\ntheta_deg = [1]\n', "l0"),
    "bad design value": ('kind = "curve"\n[sweep]\nb_mm = [5.0, -1.0]\ntheta_deg = [1]\n', "b_mm"),
    "missing design file": ('kind = "curve"\ndesign = "nope.toml"\n[sweep]\ntheta_deg = [1]\n',
                            "nope.toml"),
    "not TOML": ('kind = curve\n', "not valid TOML"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_study_file_is_one_line_and_exit_2(tmp_path, capsys, case):
    text, needle = BAD[case]
    path = write(tmp_path, text)
    assert main(["study", "status", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err, err


def test_missing_study_file_is_one_line(tmp_path, capsys):
    assert main(["study", "run", str(tmp_path / "none.toml")]) == 2
    assert capsys.readouterr().err.count("\n") == 1
