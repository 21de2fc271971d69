"""Factorisation reuse: quasi-Newton on an old factor, the solvers' factor/apply, the fallback."""
import os
import warnings

import numpy as np
import pytest
import scipy.sparse as sp
import skfem as fe

from softhand.fem import linsolve
from softhand.fem.assembly import Restriction
from softhand.fem.linsolve import make_solver
from softhand.fem.loads import FollowerPressure
from softhand.fem.materials import NeoHookean
from softhand.fem.newton import NewtonOptions
from softhand.fem.newton_path import PathOptions, solve_path
from softhand.fem.newton_steps import add_pair, bfgs_direction
from softhand.fem.solid import Solid


def inflated_block():
    """A Neo-Hookean block clamped on one face, follower pressure on the opposite one."""
    mesh = fe.MeshTet.init_tensor(*(np.linspace(0, 1, 3),) * 3).with_defaults()
    solid = Solid(mesh, NeoHookean(1.0, 100.0))
    red = Restriction(solid.ndofs, solid.free_dofs(solid.dofs("left")))
    load = FollowerPressure(solid, "right")

    def fun_t(x, t):
        u = red.expand(x)
        R, data = solid.residual_tangent_data(u)
        return (red.vector(R + load.residual(u, 0.4 * t)),
                red.restrict(solid.scatter.csr(data + load.tangent_data(u, 0.4 * t))))
    return fun_t, len(red.keep)


def test_quasi_newton_on_old_factors_reaches_the_same_path_with_fewer_factorisations():
    fun_t, n = inflated_block()
    runs = {}
    for mode in ("always", "adaptive"):
        solver = make_solver()
        opts = PathOptions(steps=4, newton=NewtonOptions(rtol=1e-10, refactor=mode, contraction=0.1))
        res = solve_path(fun_t, np.zeros(n), opts, solver=solver,
                         residual_t=lambda x, t: fun_t(x, t)[0])
        assert res.t[-1] == 1.0 and res.factorizations == solver.n_factorizations
        runs[mode] = res
    full, quasi = runs["always"], runs["adaptive"]
    R0 = np.linalg.norm(fun_t(np.zeros(n), 1.0)[0])
    for x in (full.x[-1], quasi.x[-1]):  # both converged to the tolerance at the end of the path
        assert np.linalg.norm(fun_t(x, 1.0)[0]) <= 1e-10 * R0 + 1e-10
    # the same solution to the accuracy the residual tolerance implies (well-conditioned block)
    assert np.linalg.norm(quasi.x[-1] - full.x[-1]) <= 1e-7 * np.linalg.norm(full.x[-1])
    assert quasi.factorizations < full.factorizations
    assert full.factorizations == full.total_iterations  # Newton: one per iteration (the predictor's too)


@pytest.mark.parametrize("forcing", [1e-2, None])
def test_solves_with_the_stored_factor_ask_only_the_accuracy_newton_needs(forcing):
    """The predictor on a stored factor and the quasi-Newton directions pass a tolerance to the
    solver, as the Newton systems do (a mixed-precision factor is then refined only that far);
    forcing=None asks every solve to be exact."""
    fun_t, n = inflated_block()
    solver, asked = make_solver(), {"apply": [], "solve": []}
    apply, solve = solver.apply, solver.solve
    solver.apply = lambda b, rtol=None: asked["apply"].append(rtol) or apply(b, rtol=rtol)
    solver.solve = lambda K, b, rtol=None: asked["solve"].append(rtol) or solve(K, b, rtol=rtol)
    opts = PathOptions(steps=4, newton=NewtonOptions(rtol=1e-10, refactor="adaptive", contraction=0.5,
                                                     forcing=forcing))
    res = solve_path(fun_t, np.zeros(n), opts, solver=solver, residual_t=lambda x, t: fun_t(x, t)[0])
    assert res.t[-1] == 1.0
    # solve() factorises and applies the new factor: every other apply used a stored factor
    assert len(asked["apply"]) > len(asked["solve"]) > 0
    if forcing is None:
        assert set(asked["apply"]) == {None}
    else:  # exact only where a predictor factorised K(x0) itself (the first step: no factor yet)
        assert asked["apply"].count(None) == asked["solve"].count(None) >= 1
        assert all(0 < r <= forcing for r in asked["apply"] if r is not None)


def test_bfgs_direction_satisfies_the_secant_condition():
    rng = np.random.default_rng(3)
    n = 12
    M = rng.standard_normal((n, n))
    K0, K = np.eye(n) * 3.0, M @ M.T + n * np.eye(n)  # old factor, true (SPD) Hessian
    pairs = []
    for _ in range(3):
        s = rng.standard_normal(n)
        add_pair(pairs, s, K @ s, memory=10)
    apply = lambda r: np.linalg.solve(K0, r)
    s, y, _ = pairs[-1]
    assert np.allclose(-bfgs_direction(y, pairs, apply), s, rtol=1e-10)  # H y_k = s_k
    add_pair(pairs, np.ones(n), -np.ones(n), memory=10)  # negative curvature: not kept
    assert len(pairs) == 3
    for _ in range(10):
        add_pair(pairs, rng.standard_normal(n), rng.standard_normal(n) + 100.0, memory=4)
    assert len(pairs) == 4


def test_qdldl_falls_back_to_superlu_on_a_zero_pivot():
    pytest.importorskip("qdldl")
    A = sp.csr_matrix(np.array([[1e-300, 1.0, 0.0], [1.0, 0.0, 2.0], [0.0, 2.0, 1.0]]))
    solver = make_solver("qdldl", symmetric=True)
    b = np.array([1.0, 2.0, 3.0])
    x = solver.solve(A, b)
    assert np.allclose(A @ x, b, rtol=1e-12) and solver._lu is not None


def test_a_fallback_solver_is_announced_once(monkeypatch):
    monkeypatch.setattr(linsolve, "available", lambda: ["qdldl", "superlu"])
    monkeypatch.setattr(linsolve, "_announced", set())
    pytest.importorskip("qdldl")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        names = [make_solver(symmetric=True).name, make_solver(symmetric=True).name,
                 make_solver(symmetric=False).name]
    assert names == ["qdldl", "qdldl", "superlu"]  # qdldl needs a symmetric matrix
    messages = [str(w.message) for w in caught if issubclass(w.category, RuntimeWarning)]
    assert len(messages) == 2 and "qdldl, about 12x slower" in messages[0] and "superlu" in messages[1]


def test_pardiso_solves_without_refinement_and_to_the_same_accuracy():
    """PARDISO refines a solution only where pivots were perturbed: no refinement solves on a
    well-posed symmetric indefinite matrix, and the relative residual of a direct solve."""
    if "pardiso" not in linsolve.available():
        pytest.skip("MKL PARDISO is not installed here")
    n = 400
    rng = np.random.default_rng(0)
    A = sp.random(n, n, density=0.02, random_state=rng)
    K = (A + A.T + sp.diags(np.where(np.arange(n) % 2, 4.0, -4.0))).tocsr()  # indefinite
    b = rng.standard_normal(n)
    solver = make_solver("pardiso", symmetric=True, precision="double")
    x = solver.solve(K, b)
    assert solver._ps.iparm[6] == 0  # refinement steps performed
    assert np.linalg.norm(K @ x - b) <= 1e-12 * np.linalg.norm(b)


@pytest.mark.skipif("pardiso" not in linsolve.available(), reason="needs MKL PARDISO")
def test_the_mkl_runtime_found_without_a_search_is_the_one_pypardiso_finds(monkeypatch):
    """The shortcut to MKL's runtime (where the wheel puts it) must name the library pypardiso's
    own search of the environment loads, or nothing."""
    import pypardiso

    from softhand.fem.linsolve_pardiso import _wheel_mkl_rt

    monkeypatch.delenv("PYPARDISO_MKL_RT", raising=False)
    found = _wheel_mkl_rt()
    searched = pypardiso.PyPardisoSolver().libmkl._name
    assert found is None or os.path.samefile(found, searched)


def test_a_failed_step_leaves_no_factor_for_the_retry():
    """After a load step fails, the factor is of the failed solve's last iterate, off the path:
    the retry's predictor factorises the tangent at the last converged state instead of
    solving with it (a compliant finger's retry had predicted a 17 rad hinge turn from it)."""
    fun_t, n = inflated_block()
    solver, calls = make_solver(), []
    for name in ("apply", "solve", "forget"):
        method = getattr(solver, name)
        setattr(solver, name, lambda *a, _m=method, _n=name, **k: calls.append(_n) or _m(*a, **k))
    opts = PathOptions(steps=1, newton=NewtonOptions(rtol=1e-10, refactor="adaptive", contraction=0.5, max_iter=8))
    res = solve_path(fun_t, np.zeros(n), opts, solver=solver, residual_t=lambda x, t: fun_t(x, t)[0])
    assert res.t[-1] == 1.0 and res.cutbacks >= 1
    assert calls.count("forget") == res.cutbacks
    after = [calls[i + 1] for i, c in enumerate(calls) if c == "forget"]
    assert after == ["solve"] * res.cutbacks  # a fresh factorisation, not the stored factor
