"""The rigid planar chain and its multi-point constraint: kinematics, derivatives, loads."""
import numpy as np
import pytest
import scipy.sparse as sp
from scipy.optimize import brentq

from softhand.fem.constraints import ChainConstraint, PlanarChain

HINGES = np.c_[[30.0, 60.0, 90.0, 120.0, 150.0], np.full(5, 15.0)]
CHAIN = PlanarChain(HINGES)
RNG = np.random.default_rng(5)
Q0 = RNG.normal(scale=0.4, size=5)
LINKS = np.repeat(np.arange(6), 4)
POINTS = np.c_[30.0 * LINKS + RNG.uniform(0, 30, LINKS.size), RNG.uniform(-9, 9, LINKS.size)]
STEP = 1e-6  # central differences: truncation ~ STEP^2 |x'''| ~ 1e-10 mm, rounding ~ 1e-16 x/STEP


def central_difference(fun, q, step=STEP):
    """d fun / d q by central differences, the q-axis last."""
    return np.stack([(fun(q + step * e) - fun(q - step * e)) / (2 * step)
                     for e in np.eye(len(q))], axis=-1)


def test_point_map_derivatives_match_finite_differences():
    _, J, H = CHAIN.point_map(Q0, LINKS, POINTS)
    J_fd = central_difference(lambda q: CHAIN.point_map(q, LINKS, POINTS)[0], Q0)
    H_fd = central_difference(lambda q: CHAIN.point_map(q, LINKS, POINTS)[1], Q0)
    scale = np.abs(POINTS).max()
    np.testing.assert_allclose(J, J_fd, atol=1e-7 * scale)  # rounding 1e-16 * 180 / 1e-6 ~ 2e-8
    np.testing.assert_allclose(H, H_fd, atol=1e-7 * scale)
    np.testing.assert_allclose(H, np.swapaxes(H, 2, 3), atol=0)  # second derivatives commute


def test_links_move_rigidly_and_stay_joined_at_the_hinges():
    x, _, _ = CHAIN.point_map(Q0, LINKS, POINTS)
    for k in range(6):
        on = LINKS == k
        dist = lambda p: np.linalg.norm(p[on][:, None] - p[on][None], axis=-1)  # noqa: E731
        np.testing.assert_allclose(dist(x), dist(POINTS), atol=1e-12)
    # hinge i is a point of both link i-1 and link i
    left = CHAIN.point_map(Q0, np.arange(5), HINGES)[0]
    right = CHAIN.point_map(Q0, np.arange(1, 6), HINGES)[0]
    np.testing.assert_allclose(left, right, atol=1e-12)
    np.testing.assert_allclose(left, CHAIN.hinge_positions(Q0), atol=1e-12)
    assert CHAIN.link_angles(Q0)[-1] == pytest.approx(Q0.sum())  # theta = sum of hinge angles


def test_uniform_hinge_angles_put_the_hinges_on_a_circle():
    """Equal links and equal angles: the hinges lie on a circle of radius L / (2 sin(q/2))."""
    q = np.full(5, 0.2)
    p = CHAIN.hinge_positions(q)
    chords = np.linalg.norm(np.diff(p, axis=0), axis=1)
    np.testing.assert_allclose(chords, 30.0, rtol=1e-14)
    turn = np.diff(np.unwrap(np.arctan2(*np.diff(p, axis=0).T[::-1])))
    np.testing.assert_allclose(turn, 0.2, rtol=1e-12)


def test_point_load_is_the_moment_about_each_hinge():
    f = RNG.normal(size=(LINKS.size, 2))
    Q, _ = CHAIN.point_load(Q0, LINKS, POINTS, f)
    x, _, _ = CHAIN.point_map(Q0, LINKS, POINTS)
    p = CHAIN.hinge_positions(Q0)
    arm = x[:, None, :] - p[None]                              # (m, n_s, 2)
    moment = arm[..., 0] * f[:, None, 1] - arm[..., 1] * f[:, None, 0]
    expected = np.sum(moment * (np.arange(5)[None] < LINKS[:, None]), axis=0)
    np.testing.assert_allclose(Q, expected, rtol=1e-12, atol=1e-12)
    # a pure moment on link k loads hinges 1..k
    np.testing.assert_allclose(CHAIN.moment_load([3], [2.0]), [2.0, 2.0, 2.0, 0.0, 0.0])


def test_dead_tip_force_on_a_spring_hinged_link_matches_the_closed_form():
    """One link of length L on a torsion spring k, dead force F normal to the undeformed link:
    k q = F L cos q. Newton with point_load's tangent converges quadratically."""
    chain = PlanarChain([[0.0, 0.0]])
    k, F, L = 1e3, 30.0, 50.0
    q = np.zeros(1)
    history = []
    for _ in range(20):
        Q, dQ = chain.point_load(q, [1], [[L, 0.0]], [[0.0, F]])
        r = k * q - Q
        history.append(abs(r[0]))
        if history[-1] < 1e-10 * k:
            break
        q = q - np.linalg.solve(k * np.eye(1) - dQ, r)
    exact = brentq(lambda t: k * t - F * L * np.cos(t), 0.0, np.pi / 2)
    assert q[0] == pytest.approx(exact, rel=1e-10)                # the Newton tolerance
    assert len(history) <= 6 and history[-2] < 1e-2 * history[-3] ** 1.5  # quadratic


def _random_constraint(n_nodes=40):
    """A vector of n_nodes * 3 + 5 DOFs; the first 24 nodes follow links, half of them tied."""
    m = LINKS.size
    nodes = np.arange(3 * m).reshape(m, 3)
    fixed = np.array([3 * n_nodes - 1, 3 * n_nodes + 2])      # one displacement, one 'pressure'
    return ChainConstraint(CHAIN, 3 * n_nodes + 5, nodes, LINKS, POINTS,
                           np.arange(m) % 2 == 0, fixed)


def test_reduced_residual_and_tangent_are_derivatives_of_the_reduced_energy():
    """E(u) = u.K.u/2 - f.u + sum u^4/4 on u = T(y): r = dE/dy and K_r = dr/dy (FD)."""
    c = _random_constraint()
    n = c.n_dofs
    A = sp.random(n, n, density=0.1, random_state=1)
    K0 = (A @ A.T + sp.eye(n)).tocsr()
    f = RNG.normal(size=n)
    energy = lambda u: 0.5 * u @ (K0 @ u) - f @ u + 0.25 * np.sum(u**4)  # noqa: E731
    residual = lambda u: K0 @ u - f + u**3                                # noqa: E731
    tangent = lambda u: K0 + sp.diags(3 * u**2)                           # noqa: E731
    y = RNG.normal(scale=0.3, size=c.n_reduced)
    u = c.expand(y)
    r, Kr = c.reduce(y, residual(u), tangent(u))
    r_fd = central_difference(lambda z: np.array(energy(c.expand(z))), y)
    K_fd = central_difference(lambda z: c.reduce(z, residual(c.expand(z))), y)
    np.testing.assert_allclose(r, r_fd, rtol=1e-6, atol=1e-6 * np.abs(r).max())
    np.testing.assert_allclose(Kr.toarray(), K_fd, rtol=1e-6, atol=1e-6 * np.abs(K_fd).max())
    assert np.all(u[c.fixed] == 0.0)


def test_operator_pattern_does_not_depend_on_the_state():
    c = _random_constraint()
    B0, B1 = c.operator(c.zero()), c.operator(RNG.normal(size=c.n_reduced))
    assert np.array_equal(B0.indptr, B1.indptr) and np.array_equal(B0.indices, B1.indices)


def test_force_hessian_equals_the_contraction_with_the_second_derivatives():
    x, _, H = CHAIN.point_map(Q0, LINKS, POINTS)
    f = RNG.normal(size=POINTS.shape)
    np.testing.assert_allclose(CHAIN.force_hessian(Q0, LINKS, x, f), np.einsum("majl,ma->jl", H, f),
                               rtol=1e-12, atol=1e-12 * np.abs(x).max() * np.abs(f).max())


def test_generalised_force_is_the_transposed_jacobian_times_the_forces():
    x, J, _ = CHAIN.point_map(Q0, LINKS, POINTS)
    f = RNG.normal(size=POINTS.shape)
    np.testing.assert_allclose(CHAIN.generalised_force(Q0, LINKS, x, f), np.einsum("maj,ma->j", J, f),
                               rtol=1e-12, atol=1e-12 * np.abs(x).max() * np.abs(f).max())


def test_reduced_residual_alone_equals_the_one_with_the_tangent():
    c = _random_constraint()
    y, R = RNG.normal(size=c.n_reduced), RNG.normal(size=c.n_dofs)
    K = sp.random(c.n_dofs, c.n_dofs, density=0.05, random_state=3, format="csr")
    np.testing.assert_allclose(c.reduce(y, R), c.reduce(y, R, K)[0], rtol=1e-12, atol=1e-12)


def test_reduced_tangent_is_the_triple_product_in_a_fixed_pattern_even_for_unsymmetric_K():
    """T'^T K T' + sum R . T'' against sparse products, with an unsymmetric K whose values
    vanish in places (a sparse product drops those entries; the reduced pattern must not)."""
    c = _random_constraint()
    n, n_f = c.n_dofs, len(c.free)
    A = sp.random(n, n, density=0.1, random_state=2, format="csr") + sp.eye(n, format="csr")
    patterns = []
    for y, zero_some in ((c.zero(), True), (RNG.normal(scale=0.3, size=c.n_reduced), False)):
        K = A.copy()
        K.data = RNG.normal(size=K.nnz) * (RNG.uniform(size=K.nnz) > 0.3 if zero_some else 1.0)
        R = RNG.normal(size=n)
        r, Kr = c.reduce(y, R, K)
        B = c.operator(y)
        _, _, H = CHAIN.point_map(c.q(y), c.links, c.X)
        ref = (B.T @ K @ B).toarray()
        ref[n_f:, n_f:] += np.einsum("majl,ma->jl", H, R[c.nodes[:, :2]])
        np.testing.assert_allclose(Kr.toarray(), ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())
        np.testing.assert_allclose(r, B.T @ R, rtol=1e-12, atol=1e-12 * np.abs(R).max())
        patterns.append((Kr.indptr.copy(), Kr.indices.copy()))
    assert all(np.array_equal(a, b) for a, b in zip(*patterns))


def test_symmetric_reduction_equals_the_triple_product():
    """``symmetric=True`` forms K J_m once and uses it for both off-diagonal blocks: on a
    symmetric K the result must be T'^T K T' + sum R . T'' (the sparse products), and on an
    unsymmetric one it must differ (the flag is a promise about K, not ignored)."""
    c = _random_constraint()
    n, n_f = c.n_dofs, len(c.free)
    A = sp.random(n, n, density=0.1, random_state=3, format="csr")
    K = (A + A.T + sp.eye(n)).tocsr()
    y, R = RNG.normal(scale=0.3, size=c.n_reduced), RNG.normal(size=n)
    r, Kr = c.reduce(y, R, K, symmetric=True)
    B = c.operator(y)
    _, _, H = CHAIN.point_map(c.q(y), c.links, c.X)
    ref = (B.T @ K @ B).toarray()
    ref[n_f:, n_f:] += np.einsum("majl,ma->jl", H, R[c.nodes[:, :2]])
    np.testing.assert_allclose(Kr.toarray(), ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())
    U = K.copy()
    U.data = RNG.normal(size=U.nnz)
    assert not np.allclose(c.reduce(y, R, U, symmetric=True)[1].toarray(), c.reduce(y, R, U)[1].toarray())
