"""Newton: quadratic convergence on a hyperelastic problem, line search where plain Newton
diverges, a diverging or stalled solve given up, cut-back and the last converged state on
failure; the linear solvers."""
import numpy as np
import pytest
import scipy.sparse as sp
import skfem as fe

from softhand.fem.assembly import Restriction
from softhand.fem.linsolve import available, make_solver
from softhand.fem.loads import FollowerPressure
from softhand.fem.materials import NeoHookean
from softhand.fem.newton import NewtonOptions, NotConverged, newton
from softhand.fem.newton_path import PathOptions, solve_path
from softhand.fem.solid import Solid


def scalar_system(f, df):
    return lambda x: (np.array([f(x[0])]), sp.csr_matrix([[df(x[0])]]))


ATAN = scalar_system(np.arctan, lambda x: 1.0 / (1.0 + x * x))


def test_line_search_converges_where_plain_newton_diverges():
    # arctan(x) = 0 from x0 = 2: plain Newton overshoots to ever larger |x|
    with pytest.raises(NotConverged) as err:
        newton(ATAN, [2.0], NewtonOptions(line_search=False, max_iter=10))
    # |x| grows each step until the iterations run out or the tangent 1/(1+x^2) underflows
    assert len(err.value.history) >= 5 and err.value.history[-1] > err.value.history[0]
    r = newton(ATAN, [2.0])
    assert abs(r.x[0]) < 2e-8 and min(r.steps) < 1.0  # |x| ~ |R| <= rtol |R0|


def test_residual_only_trials_give_the_same_iterates_with_one_tangent_per_iteration():
    calls = {"fun": 0, "residual": 0}

    def fun(x):
        calls["fun"] += 1
        return ATAN(x)

    def residual(x):
        calls["residual"] += 1
        return np.arctan(x)

    plain = newton(ATAN, [2.0])
    r = newton(fun, [2.0], residual=residual)
    assert r.history == plain.history and r.steps == plain.steps and min(r.steps) < 1.0
    # a tangent per step taken (at x0 and each accepted iterate but the converged one)
    assert calls["fun"] == r.iterations == r.factorizations
    assert calls["residual"] > r.iterations  # rejected trials cost residuals only
    calls["fun"] = 0
    given = newton(fun, [2.0], residual=residual, direction=[-1.0])  # e.g. a load-step predictor
    assert calls["fun"] == given.iterations - 1 == given.factorizations  # none at x0 either


CUBE_ROOT = scalar_system(np.cbrt, lambda x: 1.0 / (3.0 * np.cbrt(x) ** 2))


def test_a_diverging_solve_is_given_up_when_its_residual_grows_past_diverge():
    # cbrt(x) = 0 from x0 = 1: full Newton steps give x_k+1 = -2 x_k, ||R|| x 2^(1/3) per step
    opts = NewtonOptions(line_search=False, max_iter=50)
    with pytest.raises(NotConverged) as plain:
        newton(CUBE_ROOT, [1.0], opts)
    assert len(plain.value.history) == 51  # without the test: all of max_iter
    with pytest.raises(NotConverged, match="diverging") as err:
        newton(CUBE_ROOT, [1.0], NewtonOptions(line_search=False, max_iter=50, diverge=10.0))
    h = err.value.history  # measured from the first step's residual, not the start's
    assert h[-1] > 10.0 * min(h[1:]) and h[-2] <= 10.0 * min(h[1:-1])  # the first iterate past 10x
    assert len(h) == 2 + int(np.ceil(np.log(10.0) / np.log(2.0 ** (1 / 3))))  # 11 steps, not 50
    r = newton(CUBE_ROOT, [1.0], NewtonOptions(diverge=10.0))  # a converging solve is not stopped
    assert abs(r.x[0]) < 1e-20
    with pytest.raises(ValueError, match="diverge"):
        NewtonOptions(diverge=1.0)


CYCLE = scalar_system(lambda x: x ** 3 - 2 * x + 2, lambda x: 3 * x ** 2 - 2)


def test_a_cycling_solve_is_given_up_after_stall_iterations_without_progress():
    # x^3 - 2x + 2 = 0 from x0 = 0: full Newton steps cycle 0, 1, 0, 1, ... (||R|| 2, 1, 2, 1, ...)
    opts = NewtonOptions(line_search=False, max_iter=30)
    with pytest.raises(NotConverged) as plain:
        newton(CYCLE, [0.0], opts)
    assert plain.value.history[:5] == [2.0, 1.0, 2.0, 1.0, 2.0] and len(plain.value.history) == 31
    for k in (1, 3, 6):
        with pytest.raises(NotConverged, match="stalled") as err:
            newton(CYCLE, [0.0], NewtonOptions(line_search=False, max_iter=30, stall=k))
        # the best ||R|| (1, after the first step) is not beaten by 10 % in the k iterations after it
        assert len(err.value.history) == k + 2
    r = newton(ATAN, [2.0], NewtonOptions(stall=1))  # a converging solve is not stopped
    assert abs(r.x[0]) < 2e-8
    with pytest.raises(ValueError, match="stall"):
        NewtonOptions(stall=0)


def test_cut_back_and_last_converged_state():
    """arctan(x) = 2 t has a solution only for t < pi/4: the path stops just before it."""
    def fun_t(x, t):
        R, K = ATAN(x)
        return R - 2 * t, K
    opts = PathOptions(steps=2, min_dt=1e-3, newton=NewtonOptions(max_iter=8))
    with pytest.raises(NotConverged) as err:
        solve_path(fun_t, [0.0], opts)
    t_last, x_last = err.value.last_converged
    assert np.pi / 4 - 0.01 < t_last < np.pi / 4
    assert np.arctan(x_last[0]) == pytest.approx(2 * t_last, abs=1e-8)


def test_cut_back_recovers_a_hard_step():
    def fun_t(x, t):  # x^3 + x = 30 t: a full step from 0 needs several iterations
        return np.array([x[0] ** 3 + x[0] - 30 * t]), sp.csr_matrix([[3 * x[0] ** 2 + 1]])
    # plain Newton (a line search solves this 1D problem exactly along its line)
    opts = PathOptions(steps=1, newton=NewtonOptions(max_iter=3, line_search=False))
    res = solve_path(fun_t, [0.0], opts)
    assert res.cutbacks >= 1 and res.t[-1] == 1.0
    assert res.x[-1][0] ** 3 + res.x[-1][0] == pytest.approx(30.0, rel=2e-8)  # rtol 1e-8 of |R0| <= 30


def inflated_block(n: int):
    """(unknowns, fun) of a Neo-Hookean unit cube on n^3 P2 tets' grid, clamped on the left,
    0.3 MPa follower pressure on the right."""
    mesh = fe.MeshTet.init_tensor(*(np.linspace(0, 1, n + 1),) * 3).with_defaults()
    solid = Solid(mesh, NeoHookean(1.0, 100.0))
    red = Restriction(solid.ndofs, solid.free_dofs(solid.dofs("left")))
    load = FollowerPressure(solid, "right")

    def fun(x):
        u = red.expand(x)
        R, data = solid.residual_tangent_data(u)
        return red.vector(R + load.residual(u, 0.3)), red.restrict(solid.scatter.csr(data + load.tangent_data(u, 0.3)))

    return len(red.keep), fun


def test_quadratic_convergence_on_inflated_block():
    n, fun = inflated_block(2)
    r = newton(fun, np.zeros(n), NewtonOptions(rtol=1e-12, atol=0.0, xtol=0.0))
    h = np.array(r.history)
    # the last steps: log r_{k+1} ~ 2 log r_k + c  (order 2, before round-off at ~1e-14 |R0|)
    tail = h[(h < 1e-1 * h[0]) & (h > 1e-12 * h[0])]
    assert len(tail) >= 3
    order = np.polyfit(np.log(tail[:-1]), np.log(tail[1:]), 1)[0]
    assert order > 1.8, f"observed order {order:.2f}, history {h}"


def test_restriction_equals_slicing():
    rng = np.random.default_rng(4)
    K = sp.random(50, 50, density=0.2, random_state=3, format="csr")
    keep = np.sort(rng.choice(50, 30, replace=False))
    red = Restriction(50, keep)
    for _ in range(2):  # second call: cached index map
        assert abs(red.restrict(K) - K[keep][:, keep]).max() == 0.0
        K.data *= 2.0
    x = rng.standard_normal(30)
    assert np.array_equal(red.vector(red.expand(x, 5.0)), x) and red.expand(x, 5.0).sum() == pytest.approx(x.sum() + 100)


def test_assembly_into_the_restricted_pattern_equals_slicing_the_full_tangent():
    mesh = fe.MeshTet.init_tensor(*(np.linspace(0, 1, 4),) * 3).with_defaults()
    solid = Solid(mesh, NeoHookean(1.0, 100.0))
    red = Restriction(solid.ndofs, solid.free_dofs(solid.dofs("left")))
    u = 0.005 * np.random.default_rng(1).standard_normal(solid.ndofs)
    for v in (u, 2 * u):  # second call: the cached restricted positions
        R, K = solid.residual_tangent(v)
        Rr, Kr = solid.residual_tangent(v, restriction=red)
        K_ref = K.tocsc()[red.keep][:, red.keep]
        assert abs(Kr - K_ref).max() <= 1e-14 * abs(K).max() and Kr.shape == K_ref.shape
        assert np.array_equal(Rr, R[red.keep])


@pytest.mark.parametrize("method", available())
@pytest.mark.parametrize("symmetric", [True, False])
def test_linear_solvers_agree_and_reuse_the_analysis(method, symmetric):
    if method == "qdldl" and not symmetric:
        with pytest.raises(ValueError, match="symmetric"):
            make_solver(method, symmetric=False)
        return
    rng = np.random.default_rng(1)
    n = 200
    A = sp.random(n, n, density=0.03, random_state=2, format="csr")
    A = A + A.T + sp.diags(np.linspace(-3, 5, n)) if symmetric else A + sp.diags(np.full(n, 4.0))
    A = A.tocsr()
    solver = make_solver(method, symmetric=symmetric)
    for _ in range(2):
        b = rng.standard_normal(n)
        x = solver.solve(A, b)
        assert np.linalg.norm(A @ x - b) < 1e-10 * np.linalg.norm(b)  # backward-stable direct solve
        A.data *= 1.1  # same pattern, new values
    assert solver.n_analyses == 1 and solver.n_solves == 2 and solver.n_factorizations == 2
    assert solver.name in solver.describe()
    x = solver.apply(b)  # the last factor, kept: A was scaled by 1.1 after it
    assert np.linalg.norm(A @ x - 1.1 * b) < 1e-10 * np.linalg.norm(b)
    assert solver.n_factorizations == 2 and solver.n_solves == 3


def _path_laplacian(n, shift):
    """Graph Laplacian of a path (free ends) + shift I: SPD, cond ~ 4 / shift for small shift."""
    main = np.full(n, 2.0)
    main[[0, -1]] = 1.0
    return sp.diags([-np.ones(n - 1), main + shift, -np.ones(n - 1)], [-1, 0, 1], format="csr")


@pytest.mark.skipif("pardiso" not in available(), reason="PARDISO (pypardiso, MKL) not installed")
def test_mixed_precision_refines_to_double_accuracy_and_falls_back_when_ill_conditioned():
    rng = np.random.default_rng(2)
    b = rng.standard_normal(3000)
    # cond ~ 4e3: each refinement step gains ~ cond * eps_single ~ 1e-4
    K = _path_laplacian(3000, 1e-3)
    mixed, double = make_solver("pardiso", symmetric=True), make_solver("pardiso", symmetric=True,
                                                                          precision="double")
    x, x_ref = mixed.solve(K, b), double.solve(K, b)
    assert np.linalg.norm(K @ x - b) <= 1e-10 * np.linalg.norm(b)  # REFINE_RTOL
    assert np.linalg.norm(x - x_ref) <= 1e-9 * np.linalg.norm(x_ref)  # <= cond * 1e-10 + round-off
    assert mixed.precision == "mixed" and mixed.refinement_steps >= 2 and "mixed" in mixed.describe()
    # cond ~ 4e9 > 1 / eps_single: the single-precision factor cannot converge; double takes over
    K = _path_laplacian(3000, 1e-9)
    x = mixed.solve(K, b)
    assert mixed.precision == "double" and "stalled" in mixed.fallback and mixed.n_analyses == 2
    assert np.linalg.norm(K @ x - b) <= 1e-6 * np.linalg.norm(b)  # backward stable: ~ cond * eps_double


def test_increment_grows_again_after_a_cut_back():
    """x^3 + x = 30 t with plain Newton: the full step fails, and no step counts as easy
    (easy_iter = 0), so only the steady progress after the cut-back may let it grow."""
    def fun_t(x, t):
        return np.array([x[0] ** 3 + x[0] - 30 * t]), sp.csr_matrix([[3 * x[0] ** 2 + 1]])
    newton_options = NewtonOptions(max_iter=5, line_search=False)
    res = solve_path(fun_t, [0.0], PathOptions(steps=1, easy_iter=0, newton=newton_options))
    dt = np.diff(res.t)
    assert res.cutbacks >= 1 and res.t[-1] == 1.0
    assert dt.max() >= 1.4 * dt[0]  # grown after two converged steps (x 1.5, the last one clipped at t = 1)
    assert res.x[-1][0] ** 3 + res.x[-1][0] == pytest.approx(30.0, rel=2e-8)
    never = solve_path(fun_t, [0.0], PathOptions(steps=1, easy_iter=0, grow_after=10 ** 6, newton=newton_options))
    assert np.allclose(np.diff(never.t), np.diff(never.t)[0])  # without it: the cut-back increment for good
    assert len(never.t) > len(res.t)


def test_one_failure_type_for_load_and_volume_paths():
    """A failed volume path is caught like a failed load path, and carries the same fields."""
    from softhand.fem.volume_path import PathState, VolumeNotConverged

    last = PathState(100.0, 0.01, 1.0, np.arange(3.0))
    with pytest.raises(NotConverged) as err:
        raise VolumeNotConverged("no equilibrium at V = 123 mm^3", [1.0, 0.5], last)
    assert err.value.last is last and err.value.x is last.u
    assert err.value.last_converged == (100.0, last.u) and err.value.history == [1.0, 0.5]
    assert "residual history" in str(err.value)



def test_decrease_merit_takes_the_first_step_whole_then_halves_until_the_merit_drops():
    """arctan(x) = 0 from 1.5: the full Newton step overshoots to |x| = 1.69 > 1.5 (taken whole:
    the first step), the next full step would overshoot further, so it is halved; the caller's
    merit (here |x|, the distance to the root) decides, not ||R||."""
    calls = []

    def merit(x, R):
        calls.append(float(x[0]))
        return abs(float(x[0]))

    # forcing=None: exact Newton steps (an inexact one is the Newton step only to ~1e-8 in single precision)
    r = newton(ATAN, [1.5], NewtonOptions(merit="decrease", forcing=None), merit=merit)
    assert abs(r.x[0]) < 1e-8 and r.steps[0] == 1.0 and min(r.steps[1:]) < 1.0
    x1 = 1.5 - np.arctan(1.5) * (1 + 1.5**2)  # the first, whole Newton step
    assert abs(x1) > 1.5 and calls[1] == pytest.approx(x1, rel=1e-12)


def test_path_lands_on_its_stops_up_and_down_within_the_largest_step():
    """x^3 + x = t through t = 2, 5, 10 from 0, then back down through 5, 1 from 10: every stop
    is a converged state (closed form: the real root of x^3 + x - t), steps <= max_step."""
    fun_t = lambda x, t: (np.array([x[0] ** 3 + x[0] - t]), sp.csr_matrix([[3 * x[0] ** 2 + 1]]))  # noqa: E731
    root = lambda t: float(np.real(np.roots([1, 0, 1, -t])[np.isreal(np.roots([1, 0, 1, -t]))][0]))  # noqa: E731
    opts = PathOptions(first_step=0.1, max_step=1.5, predictor="secant",
                       newton=NewtonOptions(rtol=0.0, atol=1e-12))
    up = solve_path(fun_t, [0.0], opts, stops=(2.0, 5.0, 10.0))
    assert [up.t[k] for k in up.stops] == [2.0, 5.0, 10.0]
    assert np.all(np.diff(up.t) > 0) and np.max(np.diff(up.t)) <= 1.5 + 1e-12 and up.t[1] == 0.1
    for k, t in zip(up.stops, (2.0, 5.0, 10.0)):
        assert up.x[k][0] == pytest.approx(root(t), abs=1e-11)
    down = solve_path(fun_t, up.x[-1], opts, t0=10.0, stops=(5.0, 1.0))
    assert [down.t[k] for k in down.stops] == [5.0, 1.0] and np.all(np.diff(down.t) < 0)
    assert down.x[down.stops[-1]][0] == pytest.approx(root(1.0), abs=1e-11)
    with pytest.raises(ValueError, match="monotonically"):
        solve_path(fun_t, [0.0], opts, stops=(2.0, 1.0))


def test_forcing_term_is_eisenstat_walker_within_its_bounds():
    from softhand.fem.newton import forcing_term
    assert forcing_term([1.0], 1e-12, 1e-2, []) == 1e-2                    # first step: the largest
    assert forcing_term([1.0, 0.01], 1e-12, 1e-2, [1e-2]) == pytest.approx(0.9e-4)  # 0.9 (ratio)^2
    assert forcing_term([1.0, 0.9], 1e-12, 1e-2, [1e-2]) == 1e-2             # capped at the largest
    # near the tolerance no solve needs to be more accurate than 0.5 tol / ||R||
    assert forcing_term([1e-3, 1e-9], 1e-10, 1e-2, [1e-4]) == 1e-2            # floor 0.05, capped
    assert forcing_term([1e-3, 1e-9], 1e-13, 1e-2, [1e-4]) == pytest.approx(0.5e-4)  # the floor
    # a large last term may not collapse at once: 0.9 eta_{k-1}^2 = 0.225 > 0.1 stands
    assert forcing_term([1.0, 1e-4], 1e-7, 0.5, [0.5]) == pytest.approx(0.225)


@pytest.mark.skipif("pardiso" not in available(), reason="mixed precision needs PARDISO")
def test_inexact_newton_gives_the_answer_to_tolerance_with_fewer_refinement_steps():
    """Mixed-precision PARDISO refines every exact solve to 1e-10; an inexact Newton step stops
    at the forcing term. Same iterations, the same answer to the tolerance, fewer refinements."""
    n, fun = inflated_block(3)
    out = {}
    for forcing in (None, 1e-2):
        solver = make_solver("pardiso", precision="mixed")
        r = newton(fun, np.zeros(n), NewtonOptions(rtol=1e-10, forcing=forcing), solver=solver)
        out[forcing] = (r, solver.refinement_steps)
    (exact, n_exact), (inexact, n_inexact) = out[None], out[1e-2]
    assert inexact.iterations == exact.iterations and n_inexact < n_exact
    # both meet ||R|| <= 1e-10 ||R0||: their difference is of the size of that residual's error
    scale = np.abs(exact.x).max()
    np.testing.assert_allclose(inexact.x, exact.x, atol=1e-8 * scale)


def test_a_given_first_direction_starts_the_path_and_is_not_reused_after_a_cut_back():
    """x^3 + x = 30 t: the caller's first direction is the step's predictor (no predictor
    evaluated for it); the same converged root as with the path's own predictor; a first
    direction that fails is dropped for the cut-back's retry (the path's own predictor)."""
    calls = []

    def fun_t(x, t):
        calls.append(t)
        return np.array([x[0] ** 3 + x[0] - 30 * t]), sp.csr_matrix([[3 * x[0] ** 2 + 1]])
    opts = PathOptions(steps=1, newton=NewtonOptions(rtol=0.0, atol=1e-12))
    own = solve_path(fun_t, [0.0], opts)
    calls.clear()
    given = solve_path(fun_t, [0.0], opts, first_direction=np.array([30.0]))  # the Euler step from x = 0
    assert 0.0 not in calls  # no predictor at t = 0
    assert given.x[-1][0] == pytest.approx(own.x[-1][0], abs=1e-11)
    plain = PathOptions(steps=1, newton=NewtonOptions(max_iter=3, line_search=False))
    wild = solve_path(fun_t, [0.0], plain, first_direction=np.array([1e6]))  # diverges: cut back
    assert wild.cutbacks >= 1 and wild.x[-1][0] ** 3 + wild.x[-1][0] == pytest.approx(30.0, rel=1e-8)
