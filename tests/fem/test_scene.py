"""The VTK scene of a finger: blocks, the links against the hinge angles, the mirror image;
softhand inspect on it: off-screen pictures, fields, views, animations, bad input."""
import importlib.util
import math

import numpy as np
import pytest
from matplotlib.image import imread

from softhand.fem.hand.finger import FingerModel, FingerOptions
from softhand.fem.io import SceneSeries
from softhand.fem.hand.scene import finger_scene, link_boxes, to_hand
from softhand.reduced.vocabulary.design import HandDesign
from softhand.studies.cli.main import main
from softhand.studies.io.render import animate, describe, inspect, load_scene
from conftest import COARSEST_FINGER

DESIGN = HandDesign()
Q = np.array([0.1, 0.25, 0.15, 0.05, 0.3])  # rad, distinct per hinge so a mix-up shows


@pytest.fixture(scope="module")
def finger():
    return FingerModel(DESIGN, FingerOptions(**COARSEST_FINGER))


@pytest.fixture(scope="module")
def series(finger, tmp_path_factory):
    """Two kinematic states (free displacements 0, hinge angles Q/2 and Q) as a scene series."""
    path = tmp_path_factory.mktemp("scene") / "finger.pvd"
    out = SceneSeries(path)
    for k, P in enumerate((0.4, 0.8)):
        y = finger.constraint.zero()
        y[len(finger.constraint.free):] = Q * (k + 1) / 2
        out.write(P, *finger_scene(finger, y, P))
    return path


def test_blocks_have_the_right_names_counts_and_units(finger, series):
    scene, step, n = load_scene(series)
    n_s = DESIGN.n_s
    assert (step, n) == (1, 2)
    assert scene.keys() == ["tube", *[f"link_{k}" for k in range(n_s + 1)],
                            *[f"hinge_{k}" for k in range(1, n_s + 1)]]
    tube = scene["tube"]
    nodes = finger.vector_basis().N // 3
    assert tube.n_points == 2 * nodes and tube.n_cells == 2 * finger.mesh.nelements
    assert np.bincount(tube.cell_data["mirrored"]).tolist() == [finger.mesh.nelements] * 2
    assert {"displacement_mm", "von_mises_MPa", "cauchy_stress_MPa", "principal_stretches",
            "rubber_stretch"} <= set(tube.point_data)
    assert float(tube.field_data["P_cavity_MPa"][0]) == 0.8
    assert all(scene[f"link_{k}"].n_points == 8 for k in range(n_s + 1))


def test_mirror_image_reflects_points_and_displacements(series):
    tube = load_scene(series)[0]["tube"]
    n = tube.n_points // 2
    X, u = np.asarray(tube.points), np.asarray(tube.point_data["displacement_mm"])
    np.testing.assert_allclose(X[n:], X[:n] * [1, 1, -1], atol=1e-9)
    np.testing.assert_allclose(u[n:], u[:n] * [1, 1, -1], atol=1e-9)
    assert X[:n, 2].min() >= -1e-9  # the computed half is z >= 0


def test_links_in_the_vtk_turn_by_the_hinge_angles(series):
    scene = load_scene(series)[0]
    edge = np.array([scene[f"link_{k}"].points[1] - scene[f"link_{k}"].points[0] for k in range(DESIGN.n_s + 1)])
    angles = np.unwrap(np.arctan2(edge[:, 1], edge[:, 0]))
    np.testing.assert_allclose(np.diff(angles), Q, atol=1e-12)  # hinge i turns link i by q_i
    # the base link along the finger axis: theta0 from the downward vertical, outward (x)
    assert angles[0] == pytest.approx(math.pi / 2 - DESIGN.theta0, abs=1e-12)
    hinge_centres = np.array([scene[f"hinge_{k}"].points[0] for k in range(1, DESIGN.n_s + 1)])
    corners = np.array([scene[f"link_{k}"].points[2] for k in range(DESIGN.n_s + 1)])
    # each hinge pin sits at the grasping-face corner of the links it joins
    gap = np.linalg.norm(hinge_centres[:, :2] - corners[:-1, :2], axis=1)
    assert np.all(gap < 1.0 + 1e-9)


def test_tube_under_each_tie_moves_with_its_link_in_the_vtk(finger, series):
    """Tied nodes' deformed positions (VTK tube) = the rigid motion of the VTK link box."""
    scene = load_scene(series)[0]
    tube = scene["tube"]
    X = np.asarray(tube.points)
    x = X + np.asarray(tube.point_data["displacement_mm"])
    reference = to_hand(link_boxes(finger.chain, np.zeros(DESIGN.n_s), DESIGN).reshape(-1, 3), DESIGN)
    basis = finger.solid.sbasis
    for k in range(1, DESIGN.n_s + 1):
        A, B = reference[8 * k:8 * k + 8, :2], np.asarray(scene[f"link_{k}"].points)[:, :2]
        R, t = _rigid_fit(A, B)
        tied = basis.get_dofs(f"tie{k}").all()
        np.testing.assert_allclose(x[tied, :2], X[tied, :2] @ R.T + t, atol=1e-8)


def _rigid_fit(A, B):
    """Rotation R and shift t with B = A R^T + t (least squares, Kabsch)."""
    a, b = A - A.mean(axis=0), B - B.mean(axis=0)
    U, _, Vt = np.linalg.svd(a.T @ b)
    R = (U @ Vt).T
    return R, B.mean(axis=0) - A.mean(axis=0) @ R.T


def test_offscreen_render_is_not_blank_and_differs_between_fields(series, tmp_path):
    images = {}
    for field in ("von_mises_MPa", "displacement_mm"):
        summary = inspect(series, field=field, out=tmp_path / f"{field}.png")
        images[field] = imread(summary.png)[..., :3]
        assert images[field].std() > 0.05  # a blank picture has std 0
    difference = np.abs(images["von_mises_MPa"] - images["displacement_mm"]).mean()
    assert difference > 0.002, difference
    # a view along the hand's axis differs from the default, normal to the bending plane
    top = imread(inspect(series, field="displacement_mm", view="top", out=tmp_path / "top.png").png)[..., :3]
    assert np.abs(top - images["displacement_mm"]).mean() > 0.002


def test_animation_has_one_frame_per_step(series, tmp_path):
    from PIL import Image

    out = tmp_path / "path.gif"
    animate(series, out)
    with Image.open(out) as gif:
        assert gif.n_frames == 2
        frames = []
        for k in range(2):
            gif.seek(k)
            frames.append(np.asarray(gif.convert("RGB"), dtype=float))
    assert np.abs(frames[0] - frames[1]).mean() > 0.1  # the finger moved between the frames


def test_fields_lists_blocks_and_cli_errors(series, capsys):
    rows = describe(series.parent / "finger" / "finger_0001.vtm")  # one step's scene
    assert {"block": "tube", "field": "von_mises_MPa", "location": "point", "components": 1} in rows
    assert {"block": "link_3", "field": "P_cavity_MPa", "location": "field", "components": 1} in rows
    assert main(["inspect", str(series), "--fields"]) == 0
    assert "displacement_mm" in capsys.readouterr().out
    bad = [(["--view", "up"], "--view"), (["--animate", "x.png"], "--animate")]
    if importlib.util.find_spec("imageio_ffmpeg") is None:  # MP4 is an optional extra
        bad.append((["--animate", "x.mp4"], "imageio-ffmpeg"))
    for argv, word in bad:
        assert main(["inspect", str(series), *argv]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and word in err


def test_default_camera_looks_normal_to_the_bending_plane(series):
    from softhand.studies.io.render import _draw, _plotter

    plotter = _plotter(window_size=(200, 150))
    _draw(plotter, load_scene(series)[0], "J", title="t", view=None, hand=False)
    position, focus, up = plotter.camera_position
    plotter.close()
    direction = np.subtract(position, focus)
    assert abs(direction[2]) == pytest.approx(np.linalg.norm(direction), rel=1e-12)  # along z
    assert up[1] < 0  # the hand frame's y points down: up is -y
