"""What a first-time designer reads: caveats next to numbers, notes that are not errors.

eq. (25)'s F_v beside the grasp FEM's with the reason it is off; the paper's Table II columns
only beside the paper's hand; a design that changes the number of fingers but not the
reservoir told so; the design file's names in Python too; an automatic mesh retry said as
a note; ``material fit --plot`` drawing every mode of the data.
"""
from __future__ import annotations

import math
import subprocess
import sys
import warnings
from argparse import Namespace

import numpy as np
import pytest

from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.design_files import load_design
from softhand.reduced.vocabulary.errors import InputError, MeshRejected, Note
from softhand.studies.cli.main import main


def test_eq25_far_from_the_fem_is_printed_with_why():
    """Within 10 % of the FEM's F_v: no note; beyond it, the ratio and the touching link."""
    from softhand.studies.weights_rows import NOTE_RTOL, reduced_note

    d = HandDesign()
    N = np.array([0.0, 0.0, 3.2, 0.0, 0.0, 0.0])  # the object on link 2 of 5
    assert reduced_note(4.33, 4.0, N, d) is None and NOTE_RTOL == 0.1
    assert reduced_note(None, 4.0, N, d) is None  # eq. (25) has no answer (J_x w = 0)
    note = reduced_note(93.4, 4.0, N, d)
    assert "touches link 2 of 5" in note and f"{93.4 / 4.0:.3g} x the FEM's" in note and "F_v_fem_N" in note


def test_control_shows_the_papers_columns_for_the_papers_hand_only(tmp_path, capsys):
    argv = ["control", "--theta-ref-deg", "40", "--mass-kg", "0.8", "--t-end-s", "6"]
    assert main(argv) == 0
    assert "paper_F_v_kgf" in capsys.readouterr().out
    own = tmp_path / "own.toml"
    own.write_text("l0_mm = 150.0\na_mm = 3.5\n")
    assert main([*argv, "--design", str(own)]) == 0
    out = capsys.readouterr().out
    assert "Table II" in out and "paper_" not in out


def test_a_design_with_fewer_fingers_is_told_the_reservoir_is_not_its_own(tmp_path, capsys):
    path = tmp_path / "three.toml"
    path.write_text("n = 3\n")
    with pytest.warns(Note, match="n = 3 fingers share the reservoir sized for 4"):
        load_design(path)
    path.write_text("n = 3\nV0_mm3 = 13350.0\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error", Note)
        load_design(path)  # sized: nothing to say
    path.write_text("n = 3\n")  # the command line, as a user sees it (pytest records warnings)
    run = subprocess.run([sys.executable, "-m", "softhand.studies.cli.main", "curve", "--theta-deg", "30",
                          "--design", str(path)], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and run.stderr.count("\n") == 1
    assert run.stderr.startswith("softhand curve: note: three.toml: n = 3") and "warning" not in run.stderr


def test_replace_takes_the_design_files_names_with_its_rules():
    paper = HandDesign()
    a = paper.replace(a_mm=3.5, l0_mm=150.0, theta0_deg=10.0)
    assert (a.a, a.l0, a.theta0) == (3.5, 150.0, pytest.approx(math.radians(10.0)))
    assert a.hinge_s == pytest.approx([s * 150.0 / 180.0 for s in paper.hinge_s])  # scaled as in a file
    assert paper.replace(a=3.5) == paper.replace(a_mm=3.5)
    with pytest.raises(InputError, match="a_mm"):
        paper.replace(a_mm=-1.0)


def test_a_proof_mesh_retried_on_a_finer_one_is_a_note(monkeypatch, capsys):
    from softhand.studies.design import proof, proof_sizes, workflow

    calls = []

    def prove(ev, task, options, out=None, progress=None, tick=None):
        calls.append(options.mesh_size_mm)
        if options.mesh_size_mm == 10.0:
            raise MeshRejected("gmsh mesh_size=10", "has 2 curved elements that fold over themselves")
        progress("free bend FEM")
        return {"ok": True}

    monkeypatch.setattr(proof, "prove", prove)
    monkeypatch.setattr(proof_sizes, "proof_meshes", lambda design, size: [10.0, 6.0])
    task = Namespace(mesh_size=10.0, dP=0.05, edge_ratio=1.0)
    said = []
    fem = workflow.prove_on_meshes(Namespace(design=None), task, None, None, said.append)
    assert calls == [10.0, 6.0] and fem["ok"] and fem["failed_meshes"][0]["mesh_size_mm"] == 10.0
    assert said[0].startswith("note: the 10 mm finger mesh did not serve") and "6 mm mesh instead" in said[0]
    assert not any("failed" in s or "error" in s for s in said)


def test_material_fit_plot_draws_every_mode_of_the_data(tmp_path, monkeypatch, capsys):
    from softhand.studies.io import files

    saved, save = [], files.save_figure
    monkeypatch.setattr(files, "save_figure", lambda fig, path, **kw: (saved.append(fig), save(fig, path, **kw))[1])
    data = tmp_path / "rubber.csv"
    data.write_text("mode,stretch,stress_MPa\nuniaxial,1.2,0.4\nuniaxial,1.5,0.8\nuniaxial,2.0,1.2\n"
                    "equibiaxial,1.2,0.8\nequibiaxial,1.5,1.5\npure-shear,1.3,0.6\npure-shear,1.6,1.0\n"
                    "uniaxial,0.8,-0.5\n")
    path = tmp_path / "fit.png"
    assert main(["material", "fit", "--data", str(data), "--model", "neo-hookean", "--plot", str(path)]) == 0
    assert f"softhand material fit: wrote {path}" in capsys.readouterr().err
    ax = saved[-1].axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    for mode in ("uniaxial", "equibiaxial", "pure-shear"):
        assert f"{mode} data" in labels and any(t.startswith(f"{mode} fit") for t in labels)
    uniaxial_fit = next(line for line in ax.get_lines() if line.get_label().startswith("uniaxial fit"))
    assert min(uniaxial_fit.get_xdata()) == pytest.approx(0.8)  # the compression point is covered


def test_weights_prints_eq25s_force_under_its_caveat(monkeypatch, capsys):
    """The one-diameter table: F_v_reduced_N beside F_v_fem_N, and the line that says why it is
    off; ``--json`` carries the same words as ``F_v_reduced_note``."""
    from types import SimpleNamespace

    from softhand.studies import weights
    from softhand.studies.weights_rows import reduced_note

    N = [0.0, 0.0, 3.2, 0.0, 0.0, 0.0]
    row = {"diameter_mm": 240.0, "F_v_fem_N": 4.751, "F_v_reduced_N": 87.21, "contact_force_N": N,
           "F_v_reduced_note": reduced_note(87.21, 4.751, np.array(N), HandDesign())}
    monkeypatch.setattr(weights, "run_case", lambda case, **kw: SimpleNamespace(summary=lambda: dict(row)))
    assert main(["weights", "--diameter-mm", "240"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[-1] == f"# F_v_reduced_N: {row['F_v_reduced_note']}" and "18.4 x the FEM's" in out[-1]
    assert not any(line.startswith("F_v_reduced_note") for line in out)
