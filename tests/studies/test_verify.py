"""The verification suite (softhand verify): every registered case passes on CI-sized meshes.

Each case compares the FEM with a closed form (studies/verification/closed_forms.py); its docstring
says what bounds its tolerance. The CLI test checks the table/JSON contract and exit codes.
"""
import json

import pytest

from softhand.studies.verification import closed_forms as cf
from softhand.studies.cli.main import main
from softhand.studies.verification.registry import REGISTRY, Check, run_case


@pytest.mark.slow
@pytest.mark.parametrize("name", list(REGISTRY))
def test_case_passes(name):
    checks, _ = run_case(name, quick=True)
    assert checks and all(c.case == name for c in checks)
    for check in checks:
        assert check.passed, check.row()


def test_check_errors():
    assert Check("c", "q", 2.0, 2.02, 0.01).rel_error == pytest.approx(0.01)
    assert not Check("c", "q", 2.0, 2.05, 0.01).passed
    assert Check("c", "order", 2.0, 3.1, 0.1, at_least=True).passed  # faster is fine
    assert not Check("c", "order", 2.0, 1.0, 0.1, at_least=True).passed
    assert not Check("c", "q", 1.0, float("nan"), 0.1).passed


def test_closed_forms_limits():
    """Small-strain limits: Lame's incompressible tube 2 mu eps (1 - Ri^2/Ro^2); Hooke's
    E eps with E = 9 kappa mu / (3 kappa + mu); rel 1e-5 bounds the O(eps) nonlinearity."""
    mu, eps = 1.15, 1e-6
    assert cf.tube_pressure_plane_strain(1 + eps, 4.0, 9.0, mu) == pytest.approx(
        2 * mu * eps * (1 - 16 / 81), rel=1e-5)
    kappa = 1e4 * mu
    assert cf.uniaxial_nominal_stress(1 + eps, mu, kappa) == pytest.approx(
        9 * kappa * mu / (3 * kappa + mu) * eps, rel=1e-5)
    lam_z = cf.ring_tube_axial_stretch(0.5, 4.0, 9.0, mu)
    assert cf.ring_tube_pressure(lam_z, 4.0, 9.0, mu) == pytest.approx(0.5, rel=1e-12)


def test_cli_json_and_unknown_case(capsys):
    assert main(["verify", "--quick", "--case", "uniaxial", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert rows and set(rows[0]) >= {"case", "exact", "fem", "rel_error", "tolerance", "passed"}
    assert main(["verify", "--case", "nope"]) == 2
    assert "nope" in capsys.readouterr().err


def test_cli_exit_1_on_a_failed_check(monkeypatch, capsys):
    import softhand.studies.verification.registry as verify

    monkeypatch.setitem(verify.REGISTRY, "broken", f"{__name__}:failing_case")
    assert main(["verify", "--case", "broken"]) == 1
    assert "0 of 1 checks passed" in capsys.readouterr().out


def failing_case(quick):
    return [Check("broken", "a wrong number", 1.0, 2.0, 0.1)]
