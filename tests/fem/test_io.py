"""VTK output: fields of a homogeneous deformation against closed forms; files; series."""
import meshio
import numpy as np
import pytest
import skfem

from softhand.fem.io import VtkSeries, solid_output, state_fields, write_state
from softhand.fem.materials import Fibers, NeoHookean
from softhand.fem.solid import Solid

F0 = np.array([[1.2, 0.1, 0.0], [0.0, 0.9, 0.05], [0.0, 0.0, 0.95]])


@pytest.fixture(scope="module")
def box():
    mesh = skfem.MeshTet2.from_mesh(skfem.MeshTet.init_tensor(*[np.linspace(0, 1, 3)] * 3))
    basis = skfem.Basis(mesh, skfem.ElementVector(skfem.ElementTetP2()))
    u = basis.project(lambda x: np.einsum("ij,j...->i...", F0 - np.eye(3), x))
    return mesh, basis, u


def cauchy(law, F):
    return law.stress(F) @ F.T / np.linalg.det(F)


def test_homogeneous_fields_match_closed_forms(box):
    mesh, basis, u = box
    law = NeoHookean(1.15) + Fibers(50.0, np.array([1.0, 1.0, 0.0]))
    point, cell = state_fields(basis, u, law)
    sigma = cauchy(law, F0)
    s = sigma - np.trace(sigma) / 3 * np.eye(3)
    # P2 reproduces the linear displacement exactly: only round-off (~1e-12 of kappa (J-1))
    for data in (point, cell):
        assert np.allclose(data["cauchy_stress_MPa"], sigma.ravel(), rtol=0, atol=1e-9)
        assert np.allclose(data["von_mises_MPa"], np.sqrt(1.5 * np.sum(s * s)), atol=1e-9)
        assert np.allclose(data["J"], np.linalg.det(F0), atol=1e-12)
        assert np.allclose(data["principal_stretches"],
                           np.sqrt(np.linalg.eigvalsh(F0.T @ F0))[::-1], atol=1e-12)
        assert np.allclose(data["fiber_stretch"], np.linalg.norm(F0 @ [1, 1, 0]) / np.sqrt(2))
    assert point["displacement_mm"].shape == (basis.N // 3, 3)
    # J_bar = J for a homogeneous state: the mean-dilatation stress is the same
    point_bar, _ = state_fields(basis, u, law, J_bar=np.full(mesh.nelements, np.linalg.det(F0)))
    assert np.allclose(point_bar["cauchy_stress_MPa"], sigma.ravel(), atol=1e-9)


def test_vtu_has_quadratic_cells_and_extra_data(box, tmp_path):
    mesh, basis, u = box
    path = write_state(tmp_path / "s.vtu", basis, u, NeoHookean(1.0),
                       point_data={"x": mesh.p[0]}, cell_data={"id": np.arange(mesh.nelements)})
    back = meshio.read(path)
    assert list(back.cells_dict) == ["tetra10"] and len(back.points) == basis.N // 3
    assert np.allclose(back.points, basis.doflocs[:, ::3].T)
    # vertex data extended to edge midpoints by averaging: exact for x on straight edges
    assert np.allclose(back.point_data["x"], back.points[:, 0])
    assert np.array_equal(back.cell_data["id"][0], np.arange(mesh.nelements))
    assert [p.name for p in tmp_path.iterdir()] == ["s.vtu"]  # no temporary left behind


def test_series_lists_every_step(box, tmp_path):
    mesh, basis, u = box
    series = VtkSeries(tmp_path / "run.pvd")
    for t in (0.0, 0.5, 1.0):
        series.write(t, basis, t * u, NeoHookean(1.0))
    text = (tmp_path / "run.pvd").read_text()
    assert text.count("<DataSet") == 3 and 'file="run_0002.vtu"' in text
    last = meshio.read(tmp_path / "run_0002.vtu")
    assert np.allclose(last.point_data["displacement_mm"], u.reshape(-1, 3))


def test_solid_output_uses_the_mean_dilatation_pressure(box):
    mesh, basis, u = box
    law = NeoHookean(1.15, kappa=1150.0)
    solid = Solid(mesh, law)
    args = solid_output(solid, u)
    assert np.allclose(args["J_bar"], np.linalg.det(F0))
    point, _ = state_fields(args["basis"], u, law, J_bar=args["J_bar"])
    assert np.allclose(point["cauchy_stress_MPa"], cauchy(law, F0).ravel(), atol=1e-9)
