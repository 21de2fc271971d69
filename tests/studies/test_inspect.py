"""softhand inspect: a picture that is not blank, the field's range and peak, bad input."""
import numpy as np
import pytest
import skfem
from matplotlib.image import imread

from softhand.fem.io import VtkSeries
from softhand.fem.materials import NeoHookean
from softhand.studies.cli.main import main
from softhand.studies.io.render import inspect


@pytest.fixture(scope="module")
def series(tmp_path_factory):
    """A bar twisted by an increasing angle: von Mises grows away from the axis."""
    mesh = skfem.MeshTet2.from_mesh(skfem.MeshTet.init_tensor(
        np.linspace(-1, 1, 4), np.linspace(-1, 1, 4), np.linspace(0, 6, 7)))
    basis = skfem.Basis(mesh, skfem.ElementVector(skfem.ElementTetP2()))
    path = tmp_path_factory.mktemp("vtk") / "twist.pvd"
    out = VtkSeries(path)
    for k, angle in enumerate((0.0, 0.05, 0.1)):
        def twist(x, a=angle):
            c, s = np.cos(a * x[2]), np.sin(a * x[2])
            return np.array([c * x[0] - s * x[1] - x[0], s * x[0] + c * x[1] - x[1], 0 * x[2]])
        out.write(k, basis, basis.project(twist), NeoHookean(1.0, kappa=100.0))
    return path


def test_png_is_not_blank_and_range_is_reported(series, tmp_path):
    png = tmp_path / "pic.png"
    summary = inspect(series, field="von_mises_MPa", out=png)
    image = imread(png)[..., :3]
    assert image.shape[0] > 100 and image.std() > 0.05  # a blank picture has std 0
    assert summary.step == 2 and summary.n_steps == 3
    # the twist's shear grows with the distance from the axis: peak on a corner edge
    assert np.hypot(*summary.peak_at[:2]) == pytest.approx(np.sqrt(2), rel=1e-6)
    assert summary.maximum > summary.minimum >= 0


def test_cli_prints_range_and_writes_default_png(series, capsys):
    assert main(["inspect", str(series), "--step", "1", "--field", "principal_stretches[0]"]) == 0
    out = capsys.readouterr().out
    assert "principal_stretches[0]" in out and "max" in out
    png = series.parent / "twist_step1_principal_stretches_0.png"
    assert png.is_file()
    argv = ["inspect", str(series), "--step", "0", "--field", "principal_stretches[0]"]
    mine = series.parent / "twist_step0_principal_stretches_0.png"
    mine.write_bytes(b"the user's picture")  # the default name of step 0: a file of the user's
    assert main(argv) == 2 and mine.read_bytes() == b"the user's picture"
    assert "--out" in capsys.readouterr().err
    mine.unlink()
    assert main(argv) == 0 and main(argv) == 0  # its own picture: replaced


@pytest.mark.parametrize("argv, word", [
    (["--field", "nope"], "nope"),
    (["--step", "3"], "--step"),
    (["--field", "J[2]"], "J"),
])
def test_bad_field_or_step_is_one_line_exit_2(series, capsys, argv, word):
    assert main(["inspect", str(series), *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and word in err


@pytest.mark.parametrize("content", ["not a mesh\n", '<?xml version="1.0"?>\n<VTKFile type="U'])
def test_bad_file_is_one_line_exit_2(tmp_path, capsys, content):
    bad = tmp_path / "bad.vtu"
    bad.write_text(content)
    for path in (bad, tmp_path / "missing.vtu", tmp_path / "x.txt"):
        assert main(["inspect", str(path)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and str(path.name) in err


@pytest.mark.parametrize("n, view, turns", [
    (4, None, [0.0, 180.0]), (4, "side", [0.0, 180.0]), (3, "side", [0.0]), (5, None, [0.0]),
    (3, "iso", [0.0, 120.0, 240.0]), (4, "top", [0.0, 90.0, 180.0, 270.0]), (1, "side", [0.0])])
def test_the_side_view_draws_only_the_fingers_in_the_bending_plane(n, view, turns):
    """Seen along the bending plane's normal, a finger turned out of that plane lies across the
    object: the side view draws the modelled finger and the one opposite it (n even) only."""
    from softhand.studies.io.render_style import finger_turns

    assert finger_turns(n, view) == pytest.approx(turns)


@pytest.mark.parametrize("key, shown", [("P_cavity_MPa", "P_cavity = 1.014 MPa"),
                                        ("p_reservoir_MPa", "p_reservoir = 0.05127 MPa"),
                                        ("pressure_MPa", "P = 0.8 MPa")])
def test_a_pictures_title_names_its_pressure(key, shown):
    """A finger's or grasp's scene carries its cavity pressure, the sheet's its own: the title
    says which (a file written before the names, ``pressure_MPa``, is shown as P)."""
    import pyvista as pv

    from softhand.studies.io.render_style import title_of

    block = pv.PolyData(np.zeros((1, 3)))
    block.field_data[key] = [{"P_cavity_MPa": 1.014, "p_reservoir_MPa": 0.05127, "pressure_MPa": 0.8}[key]]
    assert shown in title_of("grasp.pvd", [block], 0, 1)
