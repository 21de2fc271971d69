"""The hyperelastic solid: derivatives by finite differences, the sparse pattern against
scikit-fem's own assembly, homogeneous tension against the closed form, and the
locking-free plane-strain tube against the incompressible closed form."""
import numpy as np
import pytest
import skfem as fe
from scipy.integrate import quad
from scipy.optimize import brentq
from skfem.models.elasticity import linear_elasticity

from softhand.fem import kinematics as kin
from softhand.fem.assembly import Restriction
from softhand.fem.linsolve import make_solver
from softhand.fem.loads import FollowerPressure
from softhand.fem.materials import CompressibleNeoHookean, Fibers, NeoHookean
from softhand.fem.newton import NewtonOptions
from softhand.fem.newton_path import PathOptions, solve_path
from softhand.fem.mixed import MixedNewton
from softhand.fem.solid import Solid

RNG = np.random.default_rng(3)


def box(n=(2, 2, 3), size=(1.0, 1.0, 2.0)):
    return fe.MeshTet.init_tensor(*(np.linspace(0, s, k + 1) for k, s in zip(n, size))).with_defaults()


@pytest.mark.parametrize("formulation", ["mean_dilatation", "displacement"])
def test_residual_and_tangent_are_derivatives(formulation):
    mesh = box()
    law = NeoHookean(1.0, 40.0) + Fibers(30.0, RNG.standard_normal((3, mesh.t.shape[1])))
    solid = Solid(mesh, law, formulation=formulation, chunk=17)  # several chunks
    # 5 % dilation + noise: every fiber stretched (lam ~ 1.05), away from the kink at lam = 1
    u = 0.05 * solid.dof_locations.T.ravel() + 0.005 * RNG.standard_normal(solid.ndofs)
    R, K = solid.residual_tangent(u)
    d, h = RNG.standard_normal(solid.ndofs), 1e-6
    dE = (solid.energy(u + h * d) - solid.energy(u - h * d)) / (2 * h)
    dR = (solid.residual(u + h * d) - solid.residual(u - h * d)) / (2 * h)
    # central differences: O(h^2) truncation, round-off ~1e-16 |E| / h
    assert dE == pytest.approx(R @ d, rel=1e-7)
    np.testing.assert_allclose(K @ d, dR, atol=1e-7 * np.abs(K @ d).max())
    assert abs(K - K.T).max() < 1e-12 * abs(K).max()  # hyperelastic: symmetric
    np.testing.assert_allclose(solid.residual(u), R)


def test_a_solid_with_another_bulk_modulus_is_that_solid_built_anew():
    """with_bulk_modulus shares the mesh and quadrature and changes only the volume energy: its
    energy, residual and tangent are those of the solid built from scratch with that kappa,
    and the original keeps its own."""
    mesh = box()
    fibers = Fibers(30.0, RNG.standard_normal((3, mesh.t.shape[1])))
    stiff = Solid(mesh, NeoHookean(1.0, 1000.0) + fibers, chunk=17)
    u = 0.05 * stiff.dof_locations.T.ravel() + 0.005 * RNG.standard_normal(stiff.ndofs)
    before = stiff.residual_tangent(u)
    soft, fresh = stiff.with_bulk_modulus(40.0), Solid(mesh, NeoHookean(1.0, 40.0) + fibers, chunk=17)
    (R, K), (R0, K0) = soft.residual_tangent(u), fresh.residual_tangent(u)
    np.testing.assert_allclose(R, R0, rtol=1e-12, atol=1e-12 * np.abs(R0).max())
    assert abs(K - K0).max() <= 1e-12 * abs(K0).max()
    assert soft.energy(u) == pytest.approx(fresh.energy(u), rel=1e-13)
    R1, K1 = stiff.residual_tangent(u)
    np.testing.assert_array_equal(R1, before[0])
    assert abs(K1 - before[1]).max() == 0.0
    with pytest.raises(ValueError, match="mean-dilatation"):
        Solid(mesh, NeoHookean(1.0, 40.0), formulation="displacement").with_bulk_modulus(10.0)


def test_tangent_at_rest_is_scikit_fem_linear_elasticity():
    """An independent assembly (scikit-fem BilinearForm, COO -> CSR) of the same operator."""
    mesh = box((2, 3, 2))
    lam, mu = 3.0, 1.15
    solid = Solid(mesh, CompressibleNeoHookean(mu, lam))
    vb = fe.Basis(mesh, fe.ElementVector(fe.ElementTetP2()), intorder=2)
    K_ref = fe.asm(linear_elasticity(lam, mu), vb)
    assert abs(solid.tangent(np.zeros(solid.ndofs)) - K_ref).max() < 1e-13 * abs(K_ref).max()
    assert np.array_equal(solid.dofs("left"), np.sort(vb.get_dofs("left").all()))


def uniaxial_closed_form(lam, mu, kappa):
    """Lateral stretch l2 and nominal stress P11 of NH (isochoric + kappa/2 (J-1)^2) in uniaxial
    tension, from P22 = 0 written out by hand: mu J^{-2/3} (l2^2 - I1/3) + kappa (J - 1) J = 0."""
    def p22_times_l2(l2):
        J, I1 = lam * l2 * l2, lam * lam + 2 * l2 * l2
        return mu * J ** (-2 / 3) * (l2 * l2 - I1 / 3) + kappa * (J - 1) * J
    l2 = brentq(p22_times_l2, 0.3, 1.0, xtol=1e-15, rtol=1e-15)
    J, I1 = lam * l2 * l2, lam * lam + 2 * l2 * l2
    return l2, (mu * J ** (-2 / 3) * (lam * lam - I1 / 3) + kappa * (J - 1) * J) / lam


@pytest.mark.parametrize("formulation, kappa", [("mean_dilatation", 1150.0), ("mean_dilatation", 11.5),
                                                ("displacement", 11.5)])
def test_homogeneous_uniaxial_tension_matches_closed_form(formulation, kappa):
    mesh = box((2, 2, 2), (1.0, 1.0, 1.0))
    mu, lam = 1.15, 1.5
    solid = Solid(mesh, NeoHookean(mu, kappa), formulation=formulation)
    x = solid.dof_locations
    s = np.arange(x.shape[1])
    right = 3 * s[np.isclose(x[0], 1.0)]
    fixed = np.concatenate([3 * s[np.isclose(x[0], 0)], right, 3 * s[np.isclose(x[1], 0)] + 1,
                            3 * s[np.isclose(x[2], 0)] + 2])
    red = Restriction(solid.ndofs, solid.free_dofs(fixed))
    u_d = np.zeros(solid.ndofs)

    def fun_t(xf, t):
        u_d[right] = t * (lam - 1.0)
        R, K = solid.residual_tangent(red.expand(xf, u_d))
        return red.vector(R), red.restrict(K)

    opts = PathOptions(steps=2, newton=NewtonOptions(rtol=1e-12, atol=1e-13))
    res = solve_path(fun_t, np.zeros(len(red.keep)), opts, solver=make_solver(symmetric=True))
    u_d[right] = lam - 1.0
    u = red.expand(res.x[-1], u_d)
    l2, P11 = uniaxial_closed_form(lam, mu, kappa)
    corner = np.flatnonzero(np.all(np.isclose(x, 1.0), axis=0))[0]
    force = solid.residual(u)[right].sum()  # reaction on the face x = 1, reference area 1
    # homogeneous state: the P2 (and P2-P0) spaces contain it exactly -> solver tolerance
    assert 1.0 + u[3 * corner + 1] == pytest.approx(l2, rel=1e-10)
    assert force == pytest.approx(P11, rel=1e-9)


# -- plane-strain thick-walled tube: locking-free check ----------------------------------
A, B, MU, P = 4.0, 9.0, 1.15, 0.6  # inner / outer radius [mm], shear modulus, pressure [MPa]


def quarter_tube(nr, nt):
    """Quarter annulus A < r < B, one element thick in z, quadratic (curved) geometry."""
    m = fe.MeshTet.init_tensor(np.linspace(A, B, nr + 1), np.linspace(0, np.pi / 2, nt + 1),
                               np.array([0.0, 1.0]))
    bnd = {"inner": m.facets_satisfying(lambda x: np.isclose(x[0], A)),
           "theta0": m.facets_satisfying(lambda x: np.isclose(x[1], 0)),
           "theta90": m.facets_satisfying(lambda x: np.isclose(x[1], np.pi / 2))}
    r, th, z = fe.MeshTet2.from_mesh(m).doflocs
    return fe.MeshTet2(doflocs=np.array([r * np.cos(th), r * np.sin(th), z]), t=m.t, _boundaries=bnd)


def pressure_closed_form(a):
    """Incompressible NH tube in plane strain: p = int_a^b mu (l^2 - l^-2) / r dr, l = r/R,
    R^2 = r^2 - (a^2 - A^2) (radial equilibrium; Ogden, Non-linear elastic deformations, 5.3)."""
    c = a * a - A * A
    b = np.sqrt(B * B + c)
    return quad(lambda r: MU * (r * r / (r * r - c) - (r * r - c) / (r * r)) / r, a, b,
                epsabs=1e-14, epsrel=1e-13)[0]


def solve_tube(mesh, kappa, formulation=None, steps=1):
    """(solid, u) under the pressure P: mixed (u, p) iteration for the mean-dilatation solid."""
    solid = Solid(mesh, NeoHookean(MU, kappa), formulation=formulation)
    fixed = np.concatenate([solid.dofs(None, (2,)), solid.dofs("theta0", (1,)), solid.dofs("theta90", (0,))])
    red = Restriction(solid.ndofs, solid.free_dofs(fixed))
    load = FollowerPressure(solid, "inner")
    mixed = MixedNewton(solid, red.expand)

    def fun_t(x, t):
        u = red.expand(x)
        R, data = solid.residual_tangent_data(u, anchor=mixed.anchor)
        K = solid.scatter.csr(data + load.tangent_data(u, t * P))
        return red.vector(R + load.residual(u, t * P)), red.restrict(K)

    opts = PathOptions(steps=steps, newton=NewtonOptions(merit="finite" if solid.formulation == "mean_dilatation" else "slope"))
    res = solve_path(fun_t, np.zeros(len(red.keep)), opts, solver=make_solver(), on_accept=mixed.accept)
    return solid, red.expand(res.x[-1]), res.total_iterations


def tube_inner_radius(mesh, kappa):
    """Inner radius under P and the Newton iterations (mixed iteration, one load step)."""
    solid, u, iterations = solve_tube(mesh, kappa)
    x = solid.dof_locations
    s = np.flatnonzero(np.isclose(x[0], A) & np.isclose(x[1], 0) & np.isclose(x[2], 0))[0]
    return A + u[3 * s], iterations


def test_plane_strain_tube_is_locking_free():
    a_exact = brentq(lambda a: pressure_closed_form(a) - P, 1.0001 * A, 2 * A, xtol=1e-14)
    mesh = quarter_tube(2, 4)
    ratios = [1e2, 1e3, 1e4, 1e5]
    radii, iterations = zip(*(tube_inner_radius(mesh, k * MU) for k in ratios))
    stretch = np.array(radii) / A
    # the mixed (u, p) Newton iteration: one load step of 0.6 MPa, iterations independent of kappa
    assert max(iterations) <= 6, iterations
    # the criterion: the same answer within 1 % for kappa/mu = 1e2 .. 1e5
    assert np.ptp(stretch) / stretch.mean() < 0.01
    # and it converges to the incompressible closed form: O(mu/kappa) + discretisation
    # (this coarse 2 x 4 mesh: 0.4 % of the radial displacement a - A)
    assert abs(stretch[-1] * A - a_exact) < 0.006 * (a_exact - A)
    assert abs(stretch[-1] - stretch[-2]) < 1e-3 * (stretch[-1] - 1.0)  # kappa-independent limit


def mean_stress_closed_form(r, a):
    """sigma_kk / 3 at current radius r of the incompressible tube with inner radius a:
    sigma_rr from radial equilibrium, sigma_tt = sigma_rr + mu (l^2 - l^-2),
    sigma_zz = sigma_rr + mu (1 - l^-2) (sigma = -q I + mu B, B = diag(l^-2, l^2, 1))."""
    c = a * a - A * A
    srr = -P + quad(lambda rho: MU * (rho * rho / (rho * rho - c) - (rho * rho - c) / (rho * rho)) / rho, a, r)[0]
    l2 = r * r / (r * r - c)
    return srr + (MU * (l2 - 1 / l2) + MU * (1 - 1 / l2)) / 3


def test_plane_strain_tube_pressure_field_has_no_locking_oscillation():
    """Element pressure p_e = U'(Jbar_e) vs the closed-form mean stress; the displacement
    formulation's pressure kappa (J - 1) at the quadrature points oscillates instead."""
    a_exact = brentq(lambda a: pressure_closed_form(a) - P, 1.0001 * A, 2 * A, xtol=1e-14)
    mesh, kappa = quarter_tube(4, 8), 1e4 * MU
    rms = {}
    for formulation in ("mean_dilatation", "displacement"):
        solid, u, _ = solve_tube(mesh, kappa, formulation, steps=1 if formulation == "mean_dilatation" else 8)
        ue = u[solid.scatter.vector_dofs()].reshape(-1, solid.G.shape[2], 3)
        phi = np.stack([np.asarray(solid.sbasis.basis[i][0]) for i in range(solid.G.shape[2])], -1)
        x = np.asarray(solid.sbasis.global_coordinates()) + np.einsum("ena,eqn->aeq", ue, phi)
        exact = np.vectorize(lambda r: mean_stress_closed_form(r, a_exact))(np.hypot(x[0], x[1]))
        if formulation == "mean_dilatation":
            p = solid.element_pressure(u)[:, None]
        else:
            p = kappa * (kin.det(solid.F(u)) - 1.0)
        rms[formulation] = np.sqrt(np.mean((p - exact) ** 2))
    # P0 pressure on a 4 x 8 mesh: O(h) error, a few % of the 0.44 MPa range; no oscillation
    assert rms["mean_dilatation"] < 0.05 * P, rms
    assert rms["displacement"] > 10 * rms["mean_dilatation"], rms


MU = 1.0  #: shear modulus of the stretched box [MPa]


def stretch_box(lam: float, kappa: float, values_known: bool):
    """The unit-cross-section box of length 2 stretched to lam by a prescribed end displacement
    (one mixed-Newton solve from rest); symmetry planes x = 0, y = 0, z = 0 (with_defaults names
    left/bottom/front for x, y, z = 0 and back for z = 2). -> (solid, u, Newton iterations)."""
    from softhand.fem.newton import newton

    mesh = box(n=(1, 1, 2))
    solid = Solid(mesh, NeoHookean(MU, kappa))
    end = solid.dofs("back", (2,))
    fixed = np.unique(np.concatenate([solid.dofs("left", (0,)), solid.dofs("bottom", (1,)),
                                      solid.dofs("front", (2,)), end]))
    u_D = np.zeros(solid.ndofs)
    u_D[end] = (lam - 1.0) * 2.0
    red = Restriction(solid.ndofs, solid.free_dofs(fixed), values=u_D if values_known else 0.0)
    expand = lambda x: red.expand(x, u_D)  # noqa: E731 - the state the residual is taken at
    mixed = MixedNewton(solid, red.expand)  # values_known=False: the anchor misses u_D

    def fun(x):
        return solid.residual_tangent(expand(x), anchor=mixed.anchor, restriction=red)

    x0 = np.zeros(len(red.keep))
    r = newton(fun, x0, NewtonOptions(rtol=1e-10, max_iter=40, merit="finite"),
               solver=make_solver(), on_accept=mixed.accept)
    return solid, expand(r.x), r.history


def test_mixed_newton_with_prescribed_displacements_converges_quadratically():
    """An anchor taken at the full state (prescribed values included) keeps Newton quadratic
    (one step to stretch 1.5 at kappa = 1000 mu, from rest); one that misses them, as ``expand`` with
    zeros for the fixed dofs did, does not converge at all."""
    from softhand.fem.newton import NotConverged

    _, _, history = stretch_box(1.5, 1000.0 * MU, values_known=True)
    h = np.array(history) / history[0]
    assert len(h) <= 13, history                       # from rest, line-searched, one step
    assert h[-1] < 1e-10 and h[-1] < 10 * h[-2] ** 1.8, history  # the last step: quadratic
    with pytest.raises(NotConverged):  # the anchor at u with u_D = 0: Newton wanders off
        stretch_box(1.5, 1000.0 * MU, values_known=False)


def test_reaction_force_and_moment_are_the_uniaxial_closed_form():
    """The support's resultant on the stretched end is P11 A0 (homogeneous uniaxial tension,
    exact in P2), and its moment about the origin is c x F with c the end face's deformed
    centre (a uniform traction has no moment about its centroid)."""
    from softhand.studies.verification.closed_forms import uniaxial_lateral_stretch, uniaxial_nominal_stress

    lam, kappa = 1.5, 1000.0 * MU
    solid, u, _ = stretch_box(lam, kappa, values_known=True)
    force, moment = solid.reaction(u, "back", about=(0.0, 0.0, 0.0))
    F = uniaxial_nominal_stress(lam, MU, kappa) * 1.0  # A0 = 1 x 1 mm^2
    lat = uniaxial_lateral_stretch(lam, MU, kappa)
    np.testing.assert_allclose(force, [0.0, 0.0, F], rtol=1e-7, atol=1e-9)  # Newton rtol 1e-10
    c = np.array([0.5 * lat, 0.5 * lat, 2.0 * lam])
    np.testing.assert_allclose(moment, np.cross(c, [0.0, 0.0, F]), rtol=1e-7, atol=1e-8)
    assert solid.reaction(u, "back")[1] is None
