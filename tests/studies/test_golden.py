"""Golden outputs: every verb's ``--json`` on CI-sized inputs, pinned before a refactoring.

These are regression pins, not correctness checks (the other test modules check the numbers
against closed forms, rates and the paper). They exist so that moving code between modules
cannot change a result unnoticed. Each case is the JSON one command printed when the file
under ``tests/data/golden/`` was written; the comparison is recursive:

* every key of the golden object must still be there (new keys may be added);
* strings, booleans and None must be equal; numbers must agree to ``RTOL`` relative
  (reduced model: round-off only) or ``FEM_RTOL`` (FEM verbs: the Newton tolerance,
  rtol 1e-8 on the residual, bounds the change of a converged state to ~1e-6);
* timings, versions, paths and solver statistics are skipped (``VOLATILE``).

Regenerate after an intended change of results with
``python tests/studies/test_golden.py --update`` and say in the commit why the numbers moved.
"""
from __future__ import annotations

import contextlib
import io
import json
import math
import sys
from pathlib import Path

import pytest

from conftest import CI_MESH_ARGS

GOLDEN = Path(__file__).resolve().parents[1] / "data" / "golden"
ROOT = Path(__file__).resolve().parents[2]
RTOL = 1e-9
FEM_RTOL = 2e-5
#: keys whose values depend on the machine, the clock or the package versions
VOLATILE = {"wall_seconds", "build_seconds", "assembly_seconds", "solve_seconds", "seconds",
            "stats", "solver", "versions", "provenance", "elapsed_s", "files", "out",
            "code_version", "python", "time_s", "cache", "path", "newton_iterations",
            "cutbacks", "contact_updates", "cache_file", "wall_time_s", "data"}

#: name -> (argv, tolerance); CI-sized meshes, each case a few seconds
CASES = {
    "curve_theta": (["curve", "--theta-deg", "0:90:15"], RTOL),
    "curve_pressure": (["curve", "--pressure-mpa", "0:0.8:0.2"], RTOL),
    "grasp_paper180": (["grasp", "--pressure-mpa", "1.7", "--theta-deg", "45", "--mass-kg", "2",
                        "--weights", "paper180", "--normalise"], RTOL),
    "control_angle": (["control", "--theta-ref-deg", "50", "--mass-kg", "2", "--mode", "angle",
                       "--t-end-s", "6"], 1e-7),
    "fit_bending": (["fit", "--data", str(ROOT / "studies" / "data" / "example_bending.csv"),
                     "--params", "V0_mm3,mu_sf_MPa"], 1e-6),
    "verify_uniaxial": (["verify", "--case", "uniaxial", "--case", "tube"], FEM_RTOL),
    "reservoir": (["reservoir"], FEM_RTOL),
    "bend_ci_mesh": (["bend", "--pressure-mpa", "0.4,0.8", "--mesher", "gmsh",
                      *CI_MESH_ARGS, "--peak-mpa", "0"], FEM_RTOL),
}


def run_json(argv: list[str]) -> dict:
    """Run ``softhand ARGV --json`` in-process; the parsed stdout."""
    from softhand.studies.cli.main import main

    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        code = main([*argv, "--json"])
    assert code == 0, f"softhand {' '.join(argv)} exited {code}"
    return json.loads(out.getvalue())


def compare(golden, new, rtol: float, where: str = "") -> list[str]:
    """Differences between ``golden`` and ``new`` as readable lines (empty: the same)."""
    if isinstance(golden, dict):
        if not isinstance(new, dict):
            return [f"{where}: was an object, now {type(new).__name__}"]
        diffs = []
        for key, value in golden.items():
            if key in VOLATILE or key.endswith(("seconds", "time_s")):
                continue
            if key not in new:
                diffs.append(f"{where}/{key}: missing")
            else:
                diffs += compare(value, new[key], rtol, f"{where}/{key}")
        return diffs
    if isinstance(golden, list):
        if not isinstance(new, list) or len(new) != len(golden):
            return [f"{where}: list of {len(golden)} became {new!r:.80}"]
        return [d for k, (g, n) in enumerate(zip(golden, new)) for d in compare(g, n, rtol, f"{where}[{k}]")]
    if isinstance(golden, (int, float)) and not isinstance(golden, bool):
        if isinstance(new, bool) or not isinstance(new, (int, float)):
            return [f"{where}: {golden!r} became {new!r}"]
        if math.isclose(golden, new, rel_tol=rtol, abs_tol=rtol * 1e-3):
            return []
        return [f"{where}: {golden!r} became {new!r} (rtol {rtol:g})"]
    return [] if golden == new else [f"{where}: {golden!r} became {new!r}"]


@pytest.mark.parametrize("name", sorted(CASES))
def test_json_output_unchanged(name):
    argv, rtol = CASES[name]
    golden = json.loads((GOLDEN / f"{name}.json").read_text())
    diffs = compare(golden, run_json(argv), rtol)
    assert not diffs, f"softhand {' '.join(argv)} --json changed:\n" + "\n".join(diffs[:20])


def test_compare_sees_a_change():
    """The comparison itself: a moved number, a missing key and a new key."""
    golden = {"rows": [{"theta_deg": 20.0, "name": "a"}], "wall_seconds": 1.0}
    assert compare(golden, {"rows": [{"theta_deg": 20.0, "name": "a", "new": 1}]}, 1e-9) == []
    assert compare(golden, {"rows": [{"theta_deg": 20.0 * (1 + 1e-6), "name": "a"}]}, 1e-9)
    assert compare(golden, {"rows": [{"name": "a"}]}, 1e-9) == ["/rows[0]/theta_deg: missing"]


if __name__ == "__main__":
    if sys.argv[1:] != ["--update"]:
        sys.exit("usage: python tests/studies/test_golden.py --update")
    GOLDEN.mkdir(parents=True, exist_ok=True)
    for name, (argv, _) in CASES.items():
        (GOLDEN / f"{name}.json").write_text(json.dumps(run_json(argv), indent=1) + "\n")
        print("wrote", name)
