"""A mesh that is a rectangular box is held as the box primitive is: detected from its volume and
its oriented bounding box, then met by the pads by separating axes in both hold models."""
import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from softhand.fem.hand.hold_body import body_of
from softhand.reduced.holding import hold, hold_fast, object_mesh, objects
from softhand.reduced.holding.hand_layout import place_object
from softhand.reduced.vocabulary.design import HandDesign


def _stl(mesh, path):
    mesh.export(path)
    return str(path)


@pytest.mark.parametrize("extents, turn", [((180.0, 180.0, 180.0), None), ((60.0, 100.0, 40.0), (0.3, 0.5, -0.2)),
                                           ((200.0, 4.0, 100.0), (1.0, 0.0, 0.0))])
def test_a_box_written_as_a_mesh_is_found_with_its_edges_and_axes(tmp_path, extents, turn):
    box = trimesh.creation.box(extents=extents)
    R = np.eye(3) if turn is None else Rotation.from_rotvec(turn).as_matrix()
    box.apply_transform(np.block([[R, np.array([[5.0], [-3.0], [7.0]])], [np.zeros((1, 3)), np.ones((1, 1))]]))
    half, A, centre = object_mesh.read_mesh(_stl(box, tmp_path / "box.stl")).cuboid
    order = np.argsort(half)
    np.testing.assert_allclose(half[order], np.sort(extents) / 2.0, atol=1e-5)   # STL stores float32
    np.testing.assert_allclose(np.abs(A.T @ R)[order][:, np.argsort(extents)], np.eye(3), atol=1e-6)
    np.testing.assert_allclose(A.T @ A, np.eye(3), atol=1e-12)
    assert np.linalg.det(A) == pytest.approx(1.0)
    np.testing.assert_allclose(centre, 0.0, atol=1e-4)   # the vertices are centred at the centre of mass


def test_other_solids_are_not_boxes(tmp_path):
    corner_cut = trimesh.convex.convex_hull(np.array([[x, y, z] for x in (-50, 50) for y in (-40, 40) for z in (-30, 30)]
                                                     + [[45, 40, 30]], float)[1:])  # one corner cut off
    for k, solid in enumerate((trimesh.creation.icosphere(subdivisions=2, radius=50.0),
                               trimesh.creation.cylinder(radius=40.0, height=80.0, sections=6), corner_cut)):
        assert object_mesh.read_mesh(_stl(solid, tmp_path / f"solid{k}.stl")).cuboid is None


@pytest.fixture(scope="module")
def cube_stl(tmp_path_factory):
    return _stl(trimesh.creation.box(extents=(180.0, 180.0, 180.0)), tmp_path_factory.mktemp("cube") / "cube.stl")


@pytest.mark.parametrize("rotation", [(0.0, 0.0, 0.0), (0.0, 15.0, 0.0)])
def test_a_box_mesh_is_held_as_the_box_is(cube_stl, rotation):
    """The fast hold of a 180 mm cube read from an STL, square and turned 15 deg about the palm's axis
    (where it slides 13 mm and turns): the primitive's limit, slide and turn, to round-off. (Met by
    its distance grid, the turned cube was let go: its edges rounded over a grid step.)"""
    d = HandDesign()
    results = [hold.solve_hold(d, objects.GraspObject(rotation_deg=rotation, mass_kg=0.5, friction=0.5, **shape),
                               P_cavity_MPa=1.2)
               for shape in ({"shape": "mesh", "file": cube_stl}, {"shape": "box", "size_mm": (180.0,) * 3})]
    mesh, box = results
    assert mesh.held and box.held
    assert mesh.holding_limit_N == pytest.approx(box.holding_limit_N, rel=1e-9, abs=1e-9)
    assert mesh.extra["slide_mm"] == pytest.approx(box.extra["slide_mm"], abs=1e-9)
    np.testing.assert_allclose(mesh.rotation_deg, box.rotation_deg, atol=1e-9)


def test_the_fems_body_of_a_box_mesh_is_the_box(cube_stl):
    d = hold_fast.finger_design(HandDesign())
    mesh = objects.GraspObject(shape="mesh", file=cube_stl, rotation_deg=(10.0, 20.0, 30.0), mass_kg=0.5)
    prim = objects.GraspObject(shape="box", size_mm=(180.0,) * 3, rotation_deg=(10.0, 20.0, 30.0), mass_kg=0.5)
    a, b = body_of(mesh, d), body_of(prim, d)
    assert a.shape == "box"
    x = place_object(prim, d).centre + np.random.default_rng(1).normal(scale=120.0, size=(200, 3))
    (da, na), (db, nb) = a.signed_distance(x), b.signed_distance(x)
    np.testing.assert_allclose(da, db, atol=1e-9)
    np.testing.assert_allclose(na, nb, atol=1e-9)
