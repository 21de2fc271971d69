"""Meshes: gmsh geometry -> .msh -> scikit-fem with named groups; the cache; bad files."""
from pathlib import Path

import numpy as np
import pytest
import skfem

from softhand.meshes import cache, gmsh_io
from softhand.meshes.convert import read_mesh
from softhand.meshes.tube import Tube, tube_mesh
from softhand.reduced.vocabulary.errors import InputError


@pytest.fixture(autouse=True)
def private_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SOFTHAND_CACHE", str(tmp_path / "cache"))


def measure(mesh, facets=None):
    """Volume of the mesh, or area of the given boundary facets (isoparametric geometry)."""
    elem = type(mesh).elem()
    basis = (skfem.CellBasis(mesh, elem) if facets is None
             else skfem.FacetBasis(mesh, elem, facets=facets))
    return skfem.Functional(lambda w: 1.0 + 0.0 * w.x[0]).assemble(basis)


@pytest.mark.parametrize("sector, fraction", [("full", 1.0), ("half", 0.5), ("quarter", 0.25)])
def test_tube_groups_measure_the_closed_form(sector, fraction):
    ri, ro, length, cap = 4.0, 9.0, 6.0, 1.5
    mesh = tube_mesh(Tube(ri, ro, length, cap=cap, sector=sector), size=2.0)
    assert isinstance(mesh, skfem.MeshTet2)
    expected_groups = {"full": 4, "half": 5, "quarter": 6}[sector]
    assert len(mesh.boundaries) == expected_groups and set(mesh.subdomains) == {"wall"}
    # quadratic (curved) facets: a circle of radius r with chords h is matched to O((h/r)^4)
    rtol = 2e-3
    inner = fraction * (2 * np.pi * ri * length + np.pi * ri ** 2)
    outer = fraction * 2 * np.pi * ro * (length + cap)
    annulus = fraction * np.pi * (ro ** 2 - ri ** 2)
    volume = annulus * length + fraction * np.pi * ro ** 2 * cap
    assert measure(mesh, mesh.boundaries["inner"]) == pytest.approx(inner, rel=rtol)
    assert measure(mesh, mesh.boundaries["outer"]) == pytest.approx(outer, rel=rtol)
    assert measure(mesh, mesh.boundaries["base"]) == pytest.approx(annulus, rel=rtol)
    assert measure(mesh, mesh.boundaries["tip"]) == pytest.approx(fraction * np.pi * ro ** 2, rel=rtol)
    assert measure(mesh) == pytest.approx(volume, rel=rtol)
    if sector != "full":
        assert np.allclose(mesh.p[1, mesh.facets[:, mesh.boundaries["symmetry"]]], 0.0)


def test_refine_splits_every_tetrahedron_into_eight_on_the_curved_surfaces():
    tube = Tube(4.0, 9.0, 6.0, cap=1.5, sector="half")
    coarse, fine = (tube_mesh(tube, size=3.0, refine=n) for n in (0, 1))
    assert fine.t.shape[1] == 8 * coarse.t.shape[1]
    assert set(fine.boundaries) == set(coarse.boundaries)
    for name, r in (("inner", 4.0), ("outer", 9.0)):  # new vertices lie on the cylinders
        p = fine.p[:, np.unique(fine.facets[:, fine.boundaries[name]])]
        on_wall = p[2] < 6.0 - 1e-9 if name == "inner" else slice(None)  # not the cap face
        assert np.allclose(np.hypot(p[0], p[1])[on_wall], r, atol=1e-9)
    # the same solid, described better: the outer area's error falls by ~2^4 (curved P2 facets)
    exact = 0.5 * 2 * np.pi * 9.0 * 7.5
    errors = [abs(measure(m, m.boundaries["outer"]) - exact) for m in (coarse, fine)]
    assert errors[1] < errors[0] / 8


def test_linear_order_gives_straight_tetrahedra():
    mesh = tube_mesh(Tube(4.0, 9.0, 3.0, sector="quarter"), size=2.0, order=1)
    assert type(mesh) is skfem.MeshTet1 and "inner" in mesh.boundaries


def rectangle(model, params, size):
    """A 2D r-z strip with named edges, as the axisymmetric models use."""
    occ = model.occ
    occ.addRectangle(0, 0, 0, params["width"], params["height"])
    occ.synchronize()
    for _, tag in model.getEntities(1):
        x0, y0, _, x1, y1, _ = model.getBoundingBox(1, tag)
        name = "axis" if x1 < 1e-6 else "bottom" if y1 < 1e-6 else "other"  # OCC boxes pad 1e-7
        model.addPhysicalGroup(1, [tag], name=f"{name}{tag}" if name == "other" else name)


@pytest.mark.parametrize("order, kind", [(1, skfem.MeshTri1), (2, skfem.MeshTri2)])
def test_2d_geometry_gives_triangles_with_named_edges(order, kind):
    mesh = cache.load_mesh(rectangle, {"width": 3.0, "height": 1.0}, size=0.5, order=order)
    assert type(mesh) is kind and set(mesh.subdomains) == {"domain"}
    assert measure(mesh) == pytest.approx(3.0, rel=1e-12)  # straight edges: exact
    assert measure(mesh, mesh.boundaries["bottom"]) == pytest.approx(3.0, rel=1e-12)
    assert np.allclose(mesh.p[0, mesh.facets[:, mesh.boundaries["axis"]]], 0.0)


def test_python_signal_handlers_still_run_after_gmsh_meshed(tmp_path):
    """gmsh's library installs its own C-level handlers: a SIGTERM after meshing killed the
    process instead of running the CLI's handler (the clean-up of a stopped run)."""
    import subprocess
    import sys

    code = (
        "import os, signal, sys\n"
        "sys.path.insert(0, {tests!r})\n"
        "from test_meshes import rectangle\n"
        "from softhand.meshes.gmsh_io import generate_msh\n"
        "hits = []\n"
        "signal.signal(signal.SIGTERM, lambda *a: hits.append('TERM'))\n"
        "signal.signal(signal.SIGINT, lambda *a: hits.append('INT'))\n"
        "generate_msh(rectangle, {{'width': 3.0, 'height': 1.0}}, 'r.msh', size=1.0)\n"
        "os.kill(os.getpid(), signal.SIGTERM)\n"
        "os.kill(os.getpid(), signal.SIGINT)\n"
        "print(','.join(hits))\n"
    ).format(tests=str(Path(__file__).parent))
    proc = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and proc.stdout.strip() == "TERM,INT", (proc.returncode, proc.stderr)


def test_cache_generates_each_mesh_once(monkeypatch):
    tube = Tube(4.0, 9.0, 2.0, sector="quarter")
    first = cache.cached_msh(tube_geometry_fn(), tube, size=3.0)

    def forbidden(*args, **kwargs):
        raise AssertionError("gmsh called for a cached mesh")

    monkeypatch.setattr(cache, "generate_msh", forbidden)
    assert cache.cached_msh(tube_geometry_fn(), tube, size=3.0) == first
    with pytest.raises(AssertionError):  # another size is another mesh
        cache.cached_msh(tube_geometry_fn(), tube, size=2.5)
    key = cache.mesh_key(tube_geometry_fn(), tube, size=3.0, order=2)
    assert key != cache.mesh_key(tube_geometry_fn(), Tube(4.0, 9.0, 2.5, sector="quarter"),
                                 size=3.0, order=2)
    assert first.parent == cache.cache_dir()


def tube_geometry_fn():
    from softhand.meshes.tube import tube_geometry
    return tube_geometry


def test_failed_generation_leaves_nothing(tmp_path):
    def broken(model, params, size):
        model.occ.addBox(0, 0, 0, 1, 1, 1)
        raise RuntimeError("geometry bug")

    with pytest.raises(RuntimeError):
        gmsh_io.generate_msh(broken, {}, tmp_path / "m.msh", size=1.0)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("content", ["hello\n", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"])
def test_a_file_that_is_not_a_mesh_is_one_line_input_error(tmp_path, content):
    path = tmp_path / "bad.msh"
    path.write_text(content)
    with pytest.raises(InputError) as err:
        read_mesh(path)
    assert "\n" not in str(err.value) and "bad.msh" in str(err.value)
    with pytest.raises(InputError):
        read_mesh(tmp_path / "missing.msh")


# -- the layered finger mesh (meshes.finger.layered_tube_mesh) --------------------------------
def layered(refine=0, **kw):
    from softhand.meshes.finger import FingerTube, layered_tube_mesh
    tube = FingerTube(4.0, 5.0, 180.0, 5.0, ((10.0, 20.0), (40.0, 50.0), (70.0, 80.0)))
    opts = dict(n_phi=4, layer_first=0.2, layer_ratio=2.0, axial_size=5.0, refine=refine) | kw
    return tube, layered_tube_mesh(tube, **opts)


def facet_measure(mesh, name):
    from softhand.fem.mapping import facet_basis
    return float(facet_basis(mesh, skfem.ElementTetP2(), facets=mesh.boundaries[name], intorder=4).dx.sum())


@pytest.mark.parametrize("refine", [0, 1])
def test_layered_mesh_measures_the_closed_form(refine):
    """Volume, cavity and ring areas of the half tube against their closed forms (the P2
    curved geometry is exact up to its interpolation error, 4th order in the sector angle); every
    element right-handed everywhere; every boundary facet in exactly one group."""
    tube, mesh = layered(refine)
    a, ro, cav = tube.a, tube.a + tube.b, tube.length - tube.cap
    tol = 1e-3 / 16 ** refine  # P2 arcs of 45 / 2**refine deg: 4th order in the sector angle
    basis = skfem.Basis(mesh, skfem.ElementTetP2(), intorder=5)  # positive weights
    assert basis.dx.min() > 0
    volume = np.pi / 2 * ((ro ** 2 - a ** 2) * cav + ro ** 2 * tube.cap)
    assert basis.dx.sum() == pytest.approx(volume, rel=tol)
    assert facet_measure(mesh, "cavity") == pytest.approx(np.pi * a * cav + np.pi * a ** 2 / 2, rel=tol)
    for k in range(3):
        assert facet_measure(mesh, f"tie{k}") == pytest.approx(np.pi * ro * 10.0, rel=tol)
    assert facet_measure(mesh, "base") == pytest.approx(np.pi / 2 * (ro ** 2 - a ** 2), rel=tol)
    assert facet_measure(mesh, "tip") == pytest.approx(np.pi / 2 * ro ** 2, rel=tol)
    assert facet_measure(mesh, "symmetry") == pytest.approx(2 * tube.b * cav + 2 * ro * tube.cap, rel=1e-9)


def test_layered_refinement_is_nested_with_eight_times_the_wall_elements():
    """Halving every spacing splits each wall element into 8 (the cap's core, a polar grid
    around the axis, into more); the fine mesh's vertices include every coarse P2 node."""
    tube, coarse = layered(0)
    _, fine = layered(1)
    def wall(m):
        return np.sum(m.p[0, m.t].mean(axis=0) < tube.length - tube.cap)
    assert wall(fine) == 8 * wall(coarse)
    # every coarse P2 node (vertices and curved mid-edge nodes) is a vertex of the fine mesh
    ours = {tuple(v) for v in np.round(fine.p.T, 9)}
    assert all(tuple(v) in ours for v in np.round(coarse.doflocs.T, 9))


def test_layered_wall_layers_grow_geometrically_and_fill_the_wall():
    from softhand.meshes.finger import layered_radii
    r = layered_radii(4.0, 5.0, 0.2, 2.0)
    t = np.diff(r)
    assert r[0] == 4.0 and r[-1] == pytest.approx(9.0) and np.allclose(t[1:] / t[:-1], 2.0)


def test_robust_facet_map_equals_scikit_fem_where_both_work():
    """On a curved mesh scikit-fem can map, the better-started inverse gives the same facet
    quadrature (points, weights, normals); on the thin layered elements it also converges."""
    from softhand.fem.mapping import facet_basis
    mesh = skfem.MeshTet2.init_ball()
    ours = facet_basis(mesh, skfem.ElementTetP2(), intorder=4)
    theirs = skfem.FacetBasis(mesh, skfem.ElementTetP2(), intorder=4)
    np.testing.assert_allclose(ours.dx, theirs.dx, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(ours.normals.value, theirs.normals.value, atol=1e-10)
    _, thin = layered(axial_size=20.0)
    with pytest.raises(Exception, match="Newton"):
        skfem.FacetBasis(thin, skfem.ElementTetP2(), facets=thin.boundaries["cavity"], intorder=4)


@pytest.mark.parametrize("s", [0.5, 0.3, 0.1, -0.2, -0.3, -0.6])
def test_a_fold_is_found_where_the_quadratic_edge_map_says(s):
    """One P2 tetrahedron whose midside node of edge (0, 1) sits at s along the edge: along it
    x(xi) = xi (2 xi - 1) + 4 xi (1 - xi) s, so det J = dx/dxi is 4 s - 1 at vertex 0 and 3 - 4 s
    at vertex 1 (the other directions straight), linear between. It is folded, for
    folded_elements, where (4 s - 1) / (3 - 4 s) < -FOLD_DEPTH (s < -1/4 for 0.5)."""
    from softhand.fem.mapping import FOLD_DEPTH, folded_elements

    mesh = skfem.MeshTet2.from_mesh(skfem.MeshTet.init_refdom())
    nodes = mesh.doflocs.copy()
    assert np.allclose(nodes[:, 4], [0.5, 0.0, 0.0])  # skfem's first edge node: edge (0, 1)
    nodes[0, 4] = s
    folded = (4 * s - 1) / (3 - 4 * s) < -FOLD_DEPTH
    assert folded_elements(skfem.MeshTet2(nodes, mesh.t)).tolist() == ([0] if folded else [])


def test_a_finger_mesh_with_folded_elements_is_refused_before_its_fem():
    """gmsh 10 mm graded to 5 mm at the ring edges: positive det J at every quadrature point,
    folded between them; its FEM 'converged' to a ballooned tube (theta 7.9 deg, stretch 3.1 at
    0.05 MPa; the uniform 10 mm mesh gives 1.1 deg). The uniform 4 mm mesh, with slivers of
    negative det J at a few vertices and the right bend (docs/finger.md), is kept."""
    from softhand.fem.hand.finger import FingerModel, FingerOptions
    from softhand.reduced.vocabulary.design import HandDesign
    from softhand.reduced.vocabulary.errors import MeshRejected

    with pytest.raises(InputError, match="fold over themselves") as info:
        FingerModel(HandDesign(), FingerOptions(mesher="gmsh", mesh_size=10.0, edge_ratio=0.5, mesh_refine=0))
    assert info.value.field == "mesh" and isinstance(info.value, MeshRejected)
    FingerModel(HandDesign(), FingerOptions(mesher="gmsh", mesh_size=4.0, edge_ratio=1.0, mesh_refine=0))


@pytest.mark.parametrize("kw", [{}, {"refine": 1}, {"n_phi": 3, "axial_size": 5.0},
                                {"layer_first": 1.0, "layer_ratio": 1.0, "core_rings": 2}])
def test_layered_tets_counts_the_layered_mesh_without_building_it(kw):
    from softhand.meshes.finger import layered_tets, layered_tube_mesh

    tube, _ = layered(0)
    args = {"n_phi": 4, "layer_first": 0.2, "layer_ratio": 2.0, "axial_size": 2.5, **kw}
    assert layered_tets(tube, **args) == layered_tube_mesh(tube, **args).t.shape[1]


def _thin_walled():
    from softhand.reduced.vocabulary.design import HandDesign

    return HandDesign(a=6.0, b=3.0, d=10.0, l0=200.0)


@pytest.mark.parametrize("design, options", [
    ("paper", {}),
    ("paper", {"mesher": "gmsh", "mesh_size": 4.0}),
    ("thin", {"mesher": "gmsh", "mesh_size": 4.0}),
    ("thin", {"n_phi": 3, "axial_size": 5.0}),
])
def test_least_unknowns_is_a_lower_bound_of_the_finger_fem(design, options):
    """The size check's estimate, taken before meshing, never exceeds the FEM's unknowns (it
    refuses only meshes at least that large); the layered one is within 25 %."""
    from softhand.fem.hand.finger import FingerModel, FingerOptions
    from softhand.fem.hand.finger_options import least_unknowns
    from softhand.reduced.vocabulary.design import HandDesign

    design = HandDesign() if design == "paper" else _thin_walled()
    model = FingerModel(design, FingerOptions(**options))
    least = least_unknowns(model.tube, model.options)
    assert least <= model.ndofs
    if model.options.mesher == "layered":
        assert model.ndofs <= 1.25 * least


def test_a_mesh_too_large_for_the_memory_is_refused_before_meshing(monkeypatch):
    """By the measured peak memory (14.9 GB at 553 820 unknowns, growing as n^(4/3)): 1 GB holds
    about 73 000 unknowns, so the 2 mm gmsh finger (>= 46 000) passes and one refinement of the
    layered mesh (>= 277 000) does not; nothing is meshed (gmsh is not called)."""
    from softhand.fem.hand import finger_options as fo
    from softhand.fem.hand.finger import FingerModel, FingerOptions
    from softhand.fem.hand.finger_options import finger_tube
    from softhand.reduced.vocabulary.design import HandDesign
    from softhand.reduced.vocabulary.errors import MeshRejected

    assert fo.most_unknowns(fo.MEASURED_PEAK_BYTES) == fo.MEASURED_UNKNOWNS
    assert fo.most_unknowns(1e9) == pytest.approx(553_820 / 14.9 ** 0.75, abs=1)
    design = HandDesign()
    small, large = FingerOptions(mesher="gmsh", mesh_size=2.0), FingerOptions(mesh_refine=1)
    fo.check_size(finger_tube(design, small), small, memory=1e9)
    with pytest.raises(MeshRejected, match="at least 277,632 unknowns; 1 GiB of memory"):
        fo.check_size(finger_tube(design, large), large, memory=1e9)
    monkeypatch.setattr(fo, "memory_bytes", lambda: 1e9)
    monkeypatch.setattr(fo, "build_mesh", lambda *a: pytest.fail("meshed"))
    with pytest.raises(MeshRejected, match="choose a coarser mesh"):
        FingerModel(design, large)


#: the manifest of an earlier bend run that wrote result.json (docs/outputs.md)
EARLIER = '{"run": "earlier", "outputs": ["result.json"]}'


@pytest.mark.parametrize("files, argv, field", [
    ({"t.toml": "[object]\ndiameter_mm = 180.0\nmass_kg = 2.0\n[pump]\nmax_pressure_MPa = 2.0\n"
                "[free]\na_mm = [3.5, 4.5]\n[fem]\nmesh_size_mm = 0.6\n"},
     ["design", "--task", "t.toml", "--no-progress"], "fem.mesh_size_mm = 0.6"),
    ({"t.toml": "[object]\ndiameter_mm = 180.0\nmass_kg = 2.0\n[pump]\nmax_pressure_MPa = 2.0\n"
                "[free]\na_mm = [3.5, 4.5]\n"},
     ["design", "--task", "t.toml", "--no-progress", "--mesh-size-mm", "0.5"], "--mesh-size-mm = 0.5"),
    ({"s.toml": "lhs = 2\nmesh_size_mm = 0.5\n[space]\na_mm = [3.0, 6.0]\nb_mm = [3.0, 7.0]\n"
                "d_mm = [10.0, 20.0]\nl0_mm = [120.0, 200.0]\ntie_width_mm = [5.0, 15.0]\n"},
     ["calibrate", "finger", "--space", "s.toml", "--out", "t.csv", "--no-progress"], "s.toml: mesh_size_mm = 0.5"),
    ({"o/result.json": "{}", "o/.softhand-outputs.json": EARLIER},  # the last run's result, kept
     ["bend", "--mesh-size-mm", "0.6", "--out", "o"], "mesh = 'gmsh mesh_size=0.6"),
    ({"o/result.json": "{}", "o/.softhand-outputs.json": EARLIER},  # a mesh refused for folded elements keeps it too
     ["bend", "--mesh-size-mm", "12", "--edge-ratio", "0.5", "--out", "o"], "fold over themselves"),
])
def test_a_refused_mesh_is_one_line_before_any_work_and_touches_no_output(files, argv, field, tmp_path,
                                                                         monkeypatch, capsys):
    """On a 24 GiB machine: the design task's proof mesh (checked on the box's smallest finger
    before the optimiser runs), a design space's mesh and a bend mesh: exit 2, one line naming
    the field (no progress bar drawn first), nothing written or cleared (nor by a bend mesh
    refused for its folded elements)."""
    from softhand.fem.hand import finger_options as fo
    from softhand.studies.cli.main import main

    monkeypatch.setattr(fo, "memory_bytes", lambda: 24 * 2 ** 30)
    monkeypatch.chdir(tmp_path)
    for name, text in files.items():
        (tmp_path / name).parent.mkdir(exist_ok=True)
        (tmp_path / name).write_text(text)
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert err.startswith("softhand ") and err.count("\n") == 1 and field in err and "mesh" in err
    assert out == ""
    written = [p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file()]
    assert sorted(str(p) for p in written if p.parts[0] != "cache") == sorted(files)


def test_a_study_whose_finger_mesh_does_not_fit_is_refused_when_read(tmp_path, monkeypatch, capsys):
    """A finger_bend study on 0.25 mm slices (347k unknowns at least for the paper's finger) on a
    4 GiB machine: one line naming the case's field, exit 2, before any case runs; on 24 GiB the
    same study loads."""
    from softhand.fem.hand import finger_options as fo
    from softhand.studies.batch.studyfile import load_study
    from softhand.studies.cli.main import main

    study = tmp_path / "s.toml"
    study.write_text('kind = "finger_bend"\n[params]\ntheta_target_deg = 64.0\np_max_mpa = 2.0\n'
                     'p_step_mpa = 0.5\npressures_mpa = [0.2]\naxial_size_mm = 0.25\n[sweep]\na_mm = [4.0]\n')
    monkeypatch.setattr(fo, "memory_bytes", lambda: 24 * 2 ** 30)
    load_study(study)
    monkeypatch.setattr(fo, "memory_bytes", lambda: 4 * 2 ** 30)
    monkeypatch.chdir(tmp_path)
    assert main(["study", "run", str(study), "--no-progress"]) == 2
    out, err = capsys.readouterr()
    assert err.count("\n") == 1 and "axial_size_mm = 0.25" in err and "at least 346,560 unknowns" in err
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["s.toml"]


def test_the_memory_is_the_containers_limit_where_it_is_lower(tmp_path, monkeypatch):
    from softhand.fem.hand import finger_options as fo

    machine = fo.memory_bytes()
    (tmp_path / "v2").write_text("max\n")
    (tmp_path / "v1").write_text(f"{2 ** 30}\n")
    monkeypatch.setattr(fo, "CGROUP_LIMITS", (str(tmp_path / "v2"), str(tmp_path / "missing")))
    assert fo.memory_bytes() == machine  # no limit
    monkeypatch.setattr(fo, "CGROUP_LIMITS", (str(tmp_path / "v2"), str(tmp_path / "v1")))
    assert fo.memory_bytes() == min(machine, 2 ** 30)


def test_without_a_home_folder_the_cache_goes_to_the_temporary_folder(monkeypatch):
    """HOME unset and a user id the password file does not know (a container run as another
    user): Path.home() raises; HOME set empty would put the cache at the root's /.cache."""
    import tempfile

    monkeypatch.delenv("SOFTHAND_CACHE", raising=False)
    monkeypatch.delenv("HOME", raising=False)

    def no_home():
        raise RuntimeError("Could not determine home directory.")

    monkeypatch.setattr(Path, "home", staticmethod(no_home))
    assert cache.cache_dir().parent.parent == Path(tempfile.gettempdir())
    monkeypatch.setenv("HOME", "")
    assert cache.cache_dir().parent.parent == Path(tempfile.gettempdir())
    monkeypatch.setenv("SOFTHAND_CACHE", "/elsewhere")
    assert cache.cache_dir() == Path("/elsewhere/meshes")
