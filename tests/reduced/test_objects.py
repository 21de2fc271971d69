"""Objects, the hand layout and the hold result: closed forms, bad input, round trips."""
import math

import numpy as np
import pytest

from softhand.reduced.equations import contact
from softhand.reduced.holding import hand_layout, object_geometry, object_mesh, objects
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.design_files import design_from_dict
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.holding.hold_result import Contact, HoldResult, LoadStep, result_from_json

trimesh = pytest.importorskip("trimesh")


def test_short_forms_and_legacy_table():
    assert objects.object_from_short("sphere:150").diameter_mm == 150.0
    c = objects.object_from_short("cylinder:120x200")
    assert (c.shape, c.diameter_mm, c.length_mm) == ("cylinder", 120.0, 200.0)
    assert objects.object_from_short("box:80x60x100").size_mm == (80.0, 60.0, 100.0)
    legacy = objects.object_from_table({"diameter_mm": 180.0, "mass_kg": 2.0})
    assert (legacy.shape, legacy.diameter_mm, legacy.mass_kg) == ("sphere", 180.0, 2.0)


@pytest.mark.parametrize("table, field", [
    ({"shape": "sphere", "diameter_mm": 100, "friction": -0.1}, "friction"),
    ({"shape": "box", "diameter_mm": 100}, "diameter_mm"),
    ({"shape": "cone", "diameter_mm": 100}, "shape"),
    ({"shape": "cylinder", "diameter_mm": 100}, "length_mm"),
    ({"diameter_mm": 100, "colour": "red"}, "colour"),
    ({"shape": "capsule", "diameter_mm": 100, "length_mm": 50}, "length_mm"),
    ({"shape": "box", "size_mm": [1, 2]}, "size_mm"),
    ({"shape": "box", "size_mm": [1e-300, 10, 10]}, "size_mm"),       # below a millimetre: a unit slip
    ({"shape": "cylinder", "diameter_mm": 180, "length_mm": 0.5}, "length_mm"),
])
def test_bad_tables_name_the_field(table, field):
    with pytest.raises(InputError) as exc:
        objects.object_from_table(table)
    assert field in exc.value.field


def test_primitive_distances_closed_form():
    """Signed distances of the primitives at points whose distance is known by hand."""
    p = np.array([[0, 0, 0], [100, 0, 0], [0, 130, 0], [50, 120, 0]], float)
    box = objects.GraspObject(shape="box", size_mm=(80, 60, 100))
    assert np.allclose(object_geometry.local_sdf(box, p), [-30, 60, 100, math.hypot(10, 90)])
    cyl = objects.GraspObject(shape="cylinder", diameter_mm=100, length_mm=200)
    assert np.allclose(object_geometry.local_sdf(cyl, p), [-50, 50, 30, math.hypot(0, 20)])
    cap = objects.GraspObject(shape="capsule", diameter_mm=100, length_mm=200)
    assert np.allclose(object_geometry.local_sdf(cap, p), [-50, 50, 130 - 100, math.hypot(50, 70) - 50])


def test_support_point_is_the_surfaces_extreme_point():
    """The closed-form point deepest along -u of each primitive against a brute-force minimum
    of X . u over its tessellated surface (exact for the box's corners, to the rim's sampling
    for the cylinder), on the surface (distance 0); where that set is a face, the point of it
    nearest the reference."""
    rng = np.random.default_rng(3)
    u = rng.normal(size=(40, 3))
    ref = rng.normal(scale=30.0, size=(40, 3))
    for obj in (objects.GraspObject(shape="box", size_mm=(80, 60, 100)),
                objects.GraspObject(shape="cylinder", diameter_mm=100, length_mm=200),
                objects.GraspObject(shape="capsule", diameter_mm=100, length_mm=200),
                objects.GraspObject(shape="sphere", diameter_mm=90)):
        S = object_geometry.support_point(obj.shape, object_geometry.dimensions(obj), u, ref)
        pts, _ = object_geometry.surface(obj, resolution=2048)
        brute = np.min(pts @ u.T, axis=0)
        h = np.einsum("ki,ki->k", S, u)
        assert np.all(h <= brute + 1e-9) and np.allclose(h, brute, rtol=0, atol=1e-4 * 100), obj.shape
        assert np.allclose(object_geometry.local_sdf(obj, S), 0.0, atol=1e-9), obj.shape
    face = object_geometry.support_point("box", (80, 60, 100), [[0.0, 1.0, 0.0]], [[10.0, 0.0, 70.0]])
    assert np.allclose(face, [[10.0, -30.0, 50.0]])          # the -y face's point nearest the reference
    cap = object_geometry.support_point("cylinder", (100, 200), [[0.0, -1.0, 0.0]], [[80.0, 0.0, 0.0]])
    assert np.allclose(cap, [[50.0, 100.0, 0.0]])            # the +y end disc, clamped to its rim
    assert object_geometry.support_point("mesh", (), u, ref) is None


def test_rotation_and_normal():
    """A box turned 90 deg about z swaps its x and y edges; the normal is the face's."""
    box = objects.GraspObject(shape="box", size_mm=(80, 20, 20), rotation_deg=(0, 0, 90))
    placed = object_geometry.place(box, (0, 50, 0))
    assert placed.sdf(np.array([0, 50 - 41, 0])) == pytest.approx(1.0)
    assert np.allclose(placed.normal(np.array([0, 50 - 41, 0])), [0, -1, 0], atol=1e-9)


def test_sphere_placement_and_gaps_are_the_one_finger_grasps():
    """A centred sphere: every finger's pad gaps equal the planar ones of reduced.contact."""
    d = HandDesign()
    placed = hand_layout.place_object(objects.object_from_short("sphere:180"), d)
    depth = contact.object_depth(180.0, d)
    assert placed.centre[1] == depth
    q = np.tile(np.linspace(0.05, 0.3, d.n_s), (d.n, 1))
    gaps = hand_layout.pad_distance(placed, hand_layout.pads(q, d)).gap
    planar = contact.pad_gaps(q[0], (0.0, depth), 90.0, d)
    assert np.allclose(gaps, planar[None, :], rtol=0, atol=1e-9)


def test_sampled_pad_distance_is_close_to_exact_for_a_cylinder():
    """A vertical cylinder seen by the fingers: the pads' gaps from the sampled search against a
    dense search (20 001 points) of the pad's centre line, which is where a centred cylinder
    is nearest; the closed-form distance is checked above. Bound 1e-3 mm: the parabola's
    O(h^3) error at h = 1/32 of a 30 mm link on a 50 mm radius."""
    d = HandDesign()
    cyl = objects.object_from_short("cylinder:100x300")
    placed = object_geometry.place(cyl, (0, 170, 0))
    q = np.tile(np.full(d.n_s, 0.15), (d.n, 1))
    p = hand_layout.pads(q, d)
    pd = hand_layout.pad_distance(placed, p)
    s = np.linspace(-1, 1, 20001)[:, None] * p.half[:, 0]
    pts = p.centre[:, None] + s[None, ..., None] * p.along[:, None]
    dense = placed.sdf(pts).min(axis=1)
    assert np.all(np.isfinite(pd.gap))
    assert np.allclose(pd.gap, dense, atol=1e-3)


def test_layout_default_is_even_and_key_round_trips():
    d = HandDesign()
    assert np.allclose(np.degrees(hand_layout.azimuths(d)), [0, 90, 180, 270])
    assert "finger_azimuths_deg" not in d.to_dict()   # old designs keep their hash
    three = design_from_dict({"n": 3, "finger_azimuths_deg": [0, 100, 200], "pad_width_mm": 12})
    assert np.allclose(np.degrees(three.finger_azimuths), [0, 100, 200])
    assert design_from_dict(three.to_dict()) == three
    assert hand_layout.pad_width(d) == 18.0 and hand_layout.pad_width(three) == 12.0
    with pytest.raises(InputError, match="finger_azimuths_deg"):
        design_from_dict({"n": 3, "finger_azimuths_deg": [0, 0, 200]})
    frames = hand_layout.finger_frames(d)
    assert np.allclose(frames.e_out[1], [0, 0, -1]) and np.allclose(frames.e_normal[0], [0, 0, 1])


def test_object_that_does_not_fit_or_sits_in_the_palm():
    d = HandDesign()
    with pytest.raises(InputError, match="does not fit"):
        hand_layout.place_object(objects.object_from_short("box:400x50x400"), d)
    with pytest.raises(InputError, match="palm"):
        hand_layout.place_object(objects.GraspObject(diameter_mm=100, offset_mm=(0, -30, 0)), d)


def _write(mesh, path):
    mesh.export(path)
    return str(path)


def test_mesh_reading_distance_and_checks(tmp_path):
    """An icosphere STL: its distance matches the sphere's to the facets' sag plus the grid's
    error; an open mesh and a self-intersecting one are refused in one line."""
    ball = trimesh.creation.icosphere(subdivisions=4, radius=60.0)
    obj = objects.object_from_table({"shape": "mesh", "file": "ball.stl", "mass_kg": 1.0},
                                    base_dir=_write(ball, tmp_path / "ball.stl").rsplit("/", 1)[0])
    pts = np.array([[40, 0, 0], [80, 0, 0], [0, 0, 70], [30, 30, 30], [0, 61, 0]], float)
    exact = np.linalg.norm(pts, axis=1) - 60.0
    # sag of a facet on r = 60: ~0.07 mm (measured +0.05 ... +0.07: the facets lie inside the
    # sphere); the cubic B-spline of the 3.1 mm grid adds less than 0.01 mm near the surface
    assert np.allclose(object_geometry.local_sdf(obj, pts), exact + 0.05, atol=0.03)
    open_mesh = ball.copy()
    open_mesh.update_faces(np.arange(len(ball.faces) - 1))
    with pytest.raises(InputError, match="not closed"):
        object_mesh.read_mesh(_write(open_mesh, tmp_path / "open.stl"))
    two = trimesh.util.concatenate([ball, ball.copy().apply_translation([23.7, 11.3, 5.1])])
    with pytest.raises(InputError, match="intersects itself"):
        object_mesh.read_mesh(_write(two, tmp_path / "two.stl"))
    apart = trimesh.util.concatenate([ball, ball.copy().apply_translation([300, 0, 0])])
    assert object_mesh.self_intersection(apart.vertices, apart.faces) is None
    with pytest.raises(InputError, match="2 separate closed surfaces"):
        object_mesh.read_mesh(_write(apart, tmp_path / "apart.stl"))
    with pytest.raises(InputError, match="was it written in m"):
        object_mesh.read_mesh(_write(ball.copy().apply_scale(1e-3), tmp_path / "metres.stl"))
    (tmp_path / "folder.stl").mkdir()
    with pytest.raises(InputError, match="is not a regular file"):
        object_mesh.read_mesh(str(tmp_path / "folder.stl"))


def test_a_surface_that_encloses_a_region_twice_is_refused():
    """Two cubes overlapping along coplanar faces (no edge crosses a face): the surface's own
    volume counts the overlap twice, the solid its distance bounds once; a box, a thin plate, a
    torus and a fine ball pass with their count's error well inside the tolerance."""
    cube = trimesh.creation.box(extents=[100.0, 100.0, 100.0])
    both = trimesh.util.concatenate([cube, cube.copy().apply_translation([30.0, 0.0, 0.0])])
    assert object_mesh.self_intersection(both.vertices, both.faces) is None  # what the volumes catch

    def check(mesh):
        V = np.asarray(mesh.vertices - mesh.center_mass)
        lo, hi = V.min(axis=0), V.max(axis=0)
        step = float(np.max(hi - lo)) / (object_mesh.MESH_GRID - 1)
        axes = [np.arange(lo[i] - 3 * step, hi[i] + 3.5 * step, step) for i in range(3)]
        points = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
        distance = object_mesh.mesh_sdf(V, mesh.faces, points)
        object_mesh.check_encloses_once(float(mesh.volume), float(mesh.area), distance, step, "file", "x.stl")

    with pytest.raises(InputError, match="overlaps itself"):
        check(both)
    for fine in (cube, trimesh.creation.box(extents=[200.0, 4.0, 100.0]), trimesh.creation.torus(60.0, 20.0),
                 trimesh.creation.icosphere(subdivisions=4, radius=60.0)):
        check(fine)


def test_a_mesh_support_point_is_its_extreme_vertex_and_a_box_mesh_the_box(tmp_path):
    """The mesh's point deepest along -u: for a box written as an STL, the primitive box's
    support point (closed form) in any direction, on ties (a face or an edge facing u) the
    point of the tied face or edge nearest the reference, as the primitive's; none (NaN) for an
    icosphere, whose facets fold by less than FOLD_DEG: a smooth surface, met by its distance."""
    box = trimesh.creation.box(extents=[60.0, 100.0, 40.0])
    obj = objects.object_from_table({"shape": "mesh", "file": "box.stl", "mass_kg": 1.0, "rotation_deg": [10, 20, 30]},
                                    base_dir=_write(box, tmp_path / "box.stl").rsplit("/", 1)[0])
    prim = objects.object_from_table({"shape": "box", "size_mm": [60.0, 100.0, 40.0], "mass_kg": 1.0,
                                      "rotation_deg": [10, 20, 30]})
    mesh, solid = object_geometry.place(obj, [1.0, 150.0, -2.0]), object_geometry.place(prim, [1.0, 150.0, -2.0])
    rng = np.random.default_rng(3)
    faces = np.eye(3)[[0, 1, 2, 0, 1, 2]] * np.repeat([1.0, -1.0], 3)[:, None]       # a face against u
    edges = np.array([[1.0, 1.0, 0.0], [0.0, -1.0, 1.0], [1.0, 0.0, -1.0]]) / math.sqrt(2.0)  # an edge
    u = np.concatenate([rng.normal(size=(20, 3)), faces, edges]) @ mesh.R.T            # hand frame
    ref = mesh.centre + rng.normal(scale=30.0, size=(len(u), 3))
    np.testing.assert_allclose(mesh.support(u, ref), solid.support(u, ref), atol=1e-9)
    ball = trimesh.creation.icosphere(subdivisions=3, radius=50.0)
    m = object_mesh.read_mesh(_write(ball, tmp_path / "ball.stl"))
    u = np.concatenate([rng.normal(size=(50, 3)), np.eye(3), -np.eye(3)])  # axes: ties on its facets
    assert not m.folds.any() and object_mesh.fold_vertices(box.vertices, box.faces).all()
    assert np.isnan(object_mesh.mesh_support(m, u, np.zeros_like(u), np.full(len(u), 1e-9))).all()


def test_result_json_round_trip():
    r = HoldResult(model="reduced", held=True, holding_limit_N=12.5, pull_direction=(0, 1, 0),
                   contacts=(Contact(0, 3, 10.0, 2.0, "stick"),), P_cavity_MPa=0.8, P_pump_MPa=0.7,
                   steps=(LoadStep("close", 0.8, 0.0, True),))
    data = r.to_json()
    assert set(data) >= {"model", "held", "holding_limit_N", "pull_direction", "contacts",
                         "P_cavity_MPa", "P_pump_MPa", "displacement_mm", "rotation_deg", "steps"}
    assert data["contacts"][0]["state"] == "stick"
    assert result_from_json(data) == r
