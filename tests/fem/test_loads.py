"""Follower pressure and cavity volume: exact volumes under affine maps, derivatives by
finite differences, pressure load = p dV/du on a closed cavity, and volume control
against pressure control."""
import numpy as np
import pytest
import skfem as fe

from softhand.fem.assembly import Restriction
from softhand.fem.linsolve import make_solver
from softhand.fem.loads import CavityVolume, FollowerPressure, dead_load, volume_control
from softhand.fem.materials import NeoHookean
from softhand.fem.newton import newton
from softhand.fem.solid import Solid

RNG = np.random.default_rng(7)


def block_with_hole(lo, hi):
    """3 x 3 x 3 unit cubes in [0, 3]^3 without the cubes inside the box [lo, hi]; the
    boundary facets of the hole (excluding any on the plane x = 0) are named 'cavity'."""
    lo, hi = np.array(lo, dtype=float)[:, None], np.array(hi, dtype=float)[:, None]
    m = fe.MeshTet.init_tensor(*(np.linspace(0, 3, 4),) * 3)
    c = m.p[:, m.t].mean(axis=1)
    m = m.remove_elements(np.flatnonzero(np.all((c > lo) & (c < hi), axis=0)))
    mid = m.p[:, m.facets].mean(axis=1)
    inside = np.all((mid >= lo - 1e-9) & (mid <= hi + 1e-9), axis=0)
    b = m.boundary_facets()
    return m.with_boundaries({"cavity": b[inside[b] & ~np.isclose(mid[0, b], 0.0)]})


@pytest.fixture(scope="module")
def closed():
    mesh = block_with_hole((1, 1, 1), (2, 2, 2))
    solid = Solid(mesh, NeoHookean(1.0, 20.0))
    return solid, CavityVolume(solid, "cavity")


@pytest.fixture(scope="module")
def half():
    mesh = block_with_hole((0, 1, 1), (1, 2, 2))  # the hole is open to the plane x = 0
    solid = Solid(mesh, NeoHookean(1.0, 20.0))
    return solid, CavityVolume(solid, "cavity", symmetry_normal=0)


def affine(solid, E):
    return (E @ solid.dof_locations).T.ravel()


def test_volume_under_affine_maps_is_det_F(closed, half):
    E = np.array([[0.2, 0.1, -0.05], [0.03, -0.1, 0.2], [0.1, 0.0, 0.3]])
    solid, cav = closed
    assert cav.volume(np.zeros(solid.ndofs)) == pytest.approx(1.0, rel=1e-13)
    assert cav.volume(affine(solid, E)) == pytest.approx(np.linalg.det(np.eye(3) + E), rel=1e-12)
    E[0, 1:] = 0.0  # keep the symmetry plane x = 0 in place
    solid, cav = half
    assert cav.volume(np.zeros(solid.ndofs)) == pytest.approx(1.0, rel=1e-13)
    assert cav.volume(affine(solid, E)) == pytest.approx(np.linalg.det(np.eye(3) + E), rel=1e-12)


@pytest.mark.parametrize("which", ["closed", "half"])
def test_volume_gradient_and_hessian_by_finite_differences(which, request):
    solid, cav = request.getfixturevalue(which)
    u = 0.05 * RNG.standard_normal(solid.ndofs)
    d, h = RNG.standard_normal(solid.ndofs), 1e-6
    g, H = cav.gradient(u), cav.hessian(u)
    # central differences: O(h^2) truncation of a quartic polynomial in u, round-off ~1e-16/h
    assert (cav.volume(u + h * d) - cav.volume(u - h * d)) / (2 * h) == pytest.approx(g @ d, rel=1e-7)
    dg = (cav.gradient(u + h * d) - cav.gradient(u - h * d)) / (2 * h)
    np.testing.assert_allclose(H @ d, dg, atol=1e-8 * np.abs(dg).max())
    assert abs(H - H.T).max() < 1e-14 * abs(H).max()


def test_follower_pressure_is_p_times_volume_gradient_and_its_stiffness_by_fd(closed, half):
    solid, cav = closed
    load = FollowerPressure(solid, "cavity")
    u = 0.05 * RNG.standard_normal(solid.ndofs)
    # two formulas: -f_ext = p int cof(F) N phi dA  vs  f_ext = p dV/du (closed cavity)
    np.testing.assert_allclose(load.residual(u, 0.7), -0.7 * cav.gradient(u), atol=1e-13)
    solid, _ = half
    load = FollowerPressure(solid, "cavity")  # an open surface: unsymmetric load stiffness
    u = 0.05 * RNG.standard_normal(solid.ndofs)
    d, h = RNG.standard_normal(solid.ndofs), 1e-6
    K = load.tangent(u, 0.7)
    dR = (load.residual(u + h * d, 0.7) - load.residual(u - h * d, 0.7)) / (2 * h)
    np.testing.assert_allclose(K @ d, dR, atol=1e-8 * np.abs(dR).max())
    assert abs(K - K.T).max() > 1e-3 * abs(K).max()


def test_dead_pressure_on_a_closed_surface_has_no_net_force(closed):
    solid, _ = closed
    f = dead_load(solid, "cavity", pressure=0.4)
    assert np.abs(f.reshape(-1, 3).sum(axis=0)).max() < 1e-14
    # virtual work of the uniform dilation u = X: p dV = p * 3 V0 (divergence theorem)
    assert f @ affine(solid, np.eye(3)) == pytest.approx(3 * 0.4 * 1.0, rel=1e-13)


def test_volume_control_agrees_with_pressure_control(closed):
    solid, cav = closed
    fixed = solid.dofs(solid.mesh.facets_satisfying(lambda x: np.isclose(x[0], 0.0)))
    free = solid.free_dofs(fixed)
    V_target = 1.3
    red = Restriction(solid.ndofs + 1, np.append(free, solid.ndofs))

    def bordered(z):
        u, p = red.expand(z)[:-1], z[-1]
        R, K = solid.residual_tangent(u)
        Rb, Kb = volume_control(R, K, p, cav, u, V_target)
        return red.vector(Rb), red.restrict(Kb)

    r = newton(bordered, np.zeros(len(free) + 1), solver=make_solver(symmetric=True))
    u_v, p_v = red.expand(r.x)[:-1], r.x[-1]
    assert cav.volume(u_v) == pytest.approx(V_target, rel=1e-9)
    # the same state under follower pressure p_v (an independent residual)
    load, red_u = FollowerPressure(solid, "cavity"), Restriction(solid.ndofs, free)

    def pressure_control(x):
        u = red_u.expand(x)
        R, data = solid.residual_tangent_data(u)
        return red_u.vector(R + load.residual(u, p_v)), red_u.restrict(
            solid.scatter.csr(data + load.tangent_data(u, p_v)))

    r2 = newton(pressure_control, red_u.vector(u_v))
    assert r2.iterations <= 1  # already in equilibrium (to the Newton tolerance)
    assert p_v > 0 and cav.volume(red_u.expand(r2.x)) == pytest.approx(V_target, rel=1e-8)
