"""Rigid pads vs an analytic object: gap geometry, derivatives, penalty / augmented Lagrangian.

The convergence tests use the rigid chain alone with hinge springs standing in for the tube
(a 5-unknown problem solved by Newton here), so they run in milliseconds.
"""
import math
from pathlib import Path

import numpy as np
import pytest

from softhand.fem.constraints import PlanarChain
from softhand.fem.contact import Circle, Pads, contact_load, gaps, normal_forces

D_PLATE = 15.0
ENDS = (0.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0)
CHAIN = PlanarChain(np.c_[ENDS[1:-1], np.full(5, D_PLATE)])
PADS = Pads(CHAIN, ENDS, D_PLATE)
STEP = 1e-6  # central differences: truncation ~ STEP^2 * |g'''| ~ 1e-8, rounding ~ 1e-16 * 200 / STEP


def central_difference(fun, q, step=STEP):
    return np.stack([(fun(q + step * e) - fun(q - step * e)) / (2 * step) for e in np.eye(len(q))],
                    axis=-1)


def test_gap_of_the_straight_chain_is_the_distance_to_the_pad_line_or_its_ends():
    circle = Circle((75.0, D_PLATE + 50.0 + 3.0), 50.0)  # 3 mm above link 2's pad
    g = gaps(PADS, circle, np.zeros(5)).g
    assert g[2] == pytest.approx(3.0, abs=1e-12)
    for k in (0, 1, 3, 4, 5):  # the closest point is the pad end nearer x = 75
        end = ENDS[k + 1] if k < 2 else ENDS[k]
        assert g[k] == pytest.approx(math.hypot(75.0 - end, 53.0) - 50.0, abs=1e-12)


def test_gap_of_a_rotated_link_is_the_distance_to_its_rotated_line():
    q = np.array([0.0, 0.0, 0.3, 0.0, 0.0])  # hinge 3 at (90, d) turns links 3..5
    p = np.array([90.0, D_PLATE])
    t, n = np.array([math.cos(0.3), math.sin(0.3)]), np.array([-math.sin(0.3), math.cos(0.3)])
    C = p + 45.0 * t + 70.0 * n  # 45 mm along link 3..5's line: link 4 (30..60 mm from hinge 3)
    g = gaps(PADS, Circle(tuple(C), 60.0), q)
    assert g.g[4] == pytest.approx(10.0, abs=1e-12)
    np.testing.assert_allclose(g.nu[4], n, atol=1e-14)
    np.testing.assert_allclose(g.tangent[4], t, atol=1e-14)


def test_a_pad_facing_away_has_no_contact():
    g = gaps(PADS, Circle((75.0, D_PLATE - 80.0), 50.0), np.zeros(5)).g
    assert np.all(np.isinf(g))


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_gap_derivatives_match_finite_differences(seed):
    rng = np.random.default_rng(seed)
    q = rng.uniform(0.0, 0.4, 5)
    circle = Circle((100.0, 120.0), 90.0)
    gp = gaps(PADS, circle, q)
    ok = np.isfinite(gp.g)
    grad_fd = central_difference(lambda x: gaps(PADS, circle, x).g, q)
    hess_fd = central_difference(lambda x: gaps(PADS, circle, x).grad, q)
    np.testing.assert_allclose(gp.grad[ok], grad_fd[ok], atol=1e-6)   # |grad| ~ 100 mm
    np.testing.assert_allclose(gp.hess[ok], hess_fd[ok], atol=1e-5)   # rounding 2e-8 * 100


def test_both_face_and_corner_contacts_are_covered():
    """The FD test above sees faces (projection inside the pad) and corners (at an end)."""
    q = np.random.default_rng(0).uniform(0.0, 0.4, 5)
    gp = gaps(PADS, Circle((100.0, 120.0), 90.0), q)
    s = np.einsum("ki,ki->k", gp.X - np.c_[ENDS[:-1], np.full(6, D_PLATE)], [[1.0, 0.0]] * 6)
    inside = (s > 1e-9) & (s < np.diff(ENDS) - 1e-9)
    assert inside.any() and (~inside).any()


def potential(q, circle, penalty, lam):
    """Augmented-Lagrangian contact potential sum <lam - eps g>^2 / (2 eps)."""
    return float(np.sum(normal_forces(gaps(PADS, circle, q).g, penalty, lam) ** 2) / (2 * penalty))


def test_contact_force_is_minus_the_gradient_of_its_potential_and_dQ_its_derivative():
    rng = np.random.default_rng(4)
    q = rng.uniform(0.0, 0.4, 5)
    circle, lam = Circle((100.0, 120.0), 90.0), np.abs(rng.normal(size=6)) * 3
    L = contact_load(gaps(PADS, circle, q), 100.0, lam)
    assert (L.N > 0).sum() >= 2
    dPi = central_difference(lambda x: np.array(potential(x, circle, 100.0, lam)), q, 1e-7)
    np.testing.assert_allclose(L.Q, -dPi, rtol=1e-6, atol=1e-4)  # rounding 1e-16 * Pi / 1e-7
    shares = rng.uniform(size=6)
    load = lambda x: contact_load(gaps(PADS, circle, x), 100.0, lam, weight=5.0,  # noqa: E731
                                  shares=shares / shares.sum())
    dQ_fd = central_difference(lambda x: load(x).Q, q)
    np.testing.assert_allclose(load(q).dQ, dQ_fd, atol=1e-4 * np.abs(dQ_fd).max())


def test_weight_share_acts_along_the_pads():
    q = np.array([0.1, 0.1, 0.2, 0.1, 0.1])
    gp = gaps(PADS, Circle((100.0, 120.0), 90.0), q)
    shares = np.array([0, 0, 0.25, 0, 0, 0.75])
    L = contact_load(gp, 100.0, np.zeros(6), weight=8.0, shares=shares)
    np.testing.assert_allclose(L.forces + L.N[:, None] * gp.nu, 8.0 * shares[:, None] * gp.tangent)


# ---------------------------------------------------------------- a rigid stand-in finger
K_HINGE = 2000.0  # hinge springs [N mm/rad], about the tube's bending stiffness (docs/grasp.md)
MOMENT = 150.0    # pressure moment on every hinge [N mm] (P a^2 pi d at ~0.2 MPa)
OBJECT = Circle((75.0, D_PLATE + 45.0 + 2.0), 45.0)  # 2 mm above the straight chain's link 2


def equilibrium(penalty, lam=np.zeros(6), q0=np.zeros(5)):
    """Hinge springs + pressure moment + contact: K q - M - Q(q) = 0 by Newton."""
    q = np.array(q0, dtype=float)
    for _ in range(100):
        L = contact_load(gaps(PADS, OBJECT, q), penalty, lam)
        r = K_HINGE * q - MOMENT - L.Q
        if np.linalg.norm(r) < 1e-10 * MOMENT:
            return q, L
        q = q - np.linalg.solve(K_HINGE * np.eye(5) - L.dQ, r)
    raise AssertionError("the stand-in did not converge")


def uzawa(penalty, tol=1e-10):
    lam, q = np.zeros(6), np.zeros(5)
    for update in range(50):
        q, L = equilibrium(penalty, lam, q)
        g = gaps(PADS, OBJECT, q).g
        if np.max(-g[L.N > 0], initial=0.0) < tol:
            return q, L, update
        lam = L.N
    raise AssertionError("Uzawa did not converge")


def test_penalty_gap_vanishes_as_penalty_grows_and_force_converges():
    penalties = np.array([1e2, 1e3, 1e4, 1e5])
    results = [equilibrium(eps) for eps in penalties]
    pen = np.array([-np.min(gaps(PADS, OBJECT, q).g) for q, _ in results])
    N = np.array([L.N.sum() for _, L in results])
    assert np.all(pen > 0) and N[-1] > 1.0
    rate = np.polyfit(np.log(penalties), np.log(pen), 1)[0]
    assert rate == pytest.approx(-1.0, abs=0.05)          # penetration = N / eps
    _, L_exact, _ = uzawa(1e3)
    err = np.abs(N - L_exact.N.sum())
    assert np.polyfit(np.log(penalties), np.log(err), 1)[0] == pytest.approx(-1.0, abs=0.1)


def test_augmented_lagrangian_reaches_the_rigid_limit_for_any_penalty():
    (q1, L1, n1), (q2, L2, n2) = uzawa(1e2), uzawa(1e4)
    np.testing.assert_allclose(L1.N, L2.N, rtol=1e-6, atol=1e-8)  # gap tolerance 1e-10 mm
    np.testing.assert_allclose(q1, q2, atol=1e-9)
    assert n2 <= n1  # a stiffer penalty needs fewer updates


def test_an_off_axis_release_converges_on_the_slipping_pads_own_tangent():
    """A contact problem replayed from the FEM hold: tests/fem/data/off_axis_release.npz is the
    condensed hold of a 180 mm sphere 1.5 mm off the palm axis (2 kg, mu 0.8, 0.9 MPa, CI mesh,
    every finger and all six pose components solved) with half its weight let go. With every
    kept pad stuck in the Newton tangent, Newton stalled at a constant residual: the sphere
    turning in pads that slip kept the stick stiffness. The slipping pads' own tangent (the
    return map's derivative) converges; the answer is checked as an equilibrium, not a number."""
    from softhand.fem.constraints import PlanarChain
    from softhand.fem.hand.hold_body import Body
    from softhand.fem.hand.hold_contact import ContactHistory, Fingers, Problem, solve_contact
    from softhand.fem.hand.hold_options import ContactOptions
    from softhand.fem.hand.hold_geometry import FingerFrame, PadSet
    from softhand.reduced.vocabulary.design import HandDesign

    d = np.load(Path(__file__).parent / "data" / "off_axis_release.npz")
    body = Body("sphere", tuple(d["body_centre"]), tuple(d["body_size"]), tuple(d["body_axis"]),
                mass_kg=float(d["body_mass_kg"]), friction=float(d["body_friction"]))
    pads = PadSet(PlanarChain(d["hinges"]), tuple(d["ends"]), float(d["pad_y"]), float(d["pad_width"]), HandDesign())
    n = len(d["azimuths"])
    fingers = Fingers([FingerFrame(float(a)) for a in d["azimuths"]], [pads] * n, d["mult"], list(d["q0"]),
                      list(d["Q0"]), list(d["S"]))
    hist = ContactHistory(*(d[f"hist_{k}"] for k in ("lam_N", "lam_T", "X", "zeta", "Xo", "xp0", "xo0")))
    problem = Problem(body, fingers, d["pose0"], d["free"], d["load"], hist, float(d["scale"]))
    options = ContactOptions()
    x, cs, _, _, R = solve_contact(problem, d["x0"], options)
    touching = cs.N > 0
    assert np.linalg.norm(R) <= options.rtol * problem.scale  # hinges of every finger and the object in equilibrium
    assert np.max(-cs.g[touching]) <= options.gap_tol  # no pad in the sphere
    assert np.max(np.linalg.norm(cs.slip[cs.stick], axis=1), initial=0.0) <= options.slip_tol
    assert np.all(np.linalg.norm(cs.T, axis=1) <= body.friction * cs.N * (1 + 1e-12) + 1e-12)  # Coulomb's cone
    assert touching.sum() == n and (~cs.stick[touching]).any()  # every finger touches; some pads slip
    # the object's force balance, summed over the pads: they carry its weight's share let go
    assert np.allclose(cs.wrench[:3], -d["load"][:3], atol=1e-6 * np.abs(d["load"]).max())
