"""The fast hold model: its special cases and closed forms, residuals and cones."""
import math

import numpy as np
import pytest

from scipy.optimize import minimize

from softhand.reduced.calibrated import finger_hinges, grasp_fem
from softhand.reduced.equations import contact, hand
from softhand.reduced.holding import hold, hold_fast, hold_lp, objects
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.holding.hand_layout import place_object

G = 9.80665


@pytest.mark.parametrize("diameter, P", [(180.0, 0.6), (180.0, 1.5), (240.0, 0.9), (200.0, 2.0)])
def test_one_finger_grasp_is_the_special_case(diameter, P, monkeypatch):
    """A frictionless sphere centred under the hand, the hold's fingers given the one-finger grasp's
    hinges (the blocked-hinge table, uncoupled, closing with equal hinges): each finger's closing
    state is the one-finger grasp's (frictionless circle in its bending plane, its own geometry) --
    hinge angles to 1e-10 rad, the normal force to 1e-8 relative (both Newton tolerances), on the
    same pad."""
    monkeypatch.setattr(finger_hinges, "coupled_moments", finger_hinges.hinge_moments)
    monkeypatch.setattr(finger_hinges, "coupled_energy", finger_hinges.hinge_energy)
    monkeypatch.setattr(finger_hinges, "coupled_stiffness", _table_stiffness)
    monkeypatch.setattr(finger_hinges, "coupled_free_angles", lambda P, d: np.full(
        d.n_s, float(hand.bend_angle(P, d, reservoir=False)) / d.n_s))
    d = hold_fast.finger_design(HandDesign())
    obj = objects.GraspObject(diameter_mm=diameter)
    closed = hold_fast.close_hand(P, place_object(obj, d), d)
    ref = grasp_fem.grasp_state(d, diameter, P, 0.0)
    for s in closed.fingers:
        assert np.allclose(s.q, ref.q, rtol=0, atol=1e-10)
        assert int(np.argmax(s.N)) == ref.link
        assert s.N[ref.link] == pytest.approx(ref.N, rel=1e-8)
    assert closed.symmetric


def _table_stiffness(q, P, design):
    q = np.asarray(q, float)
    M = finger_hinges.hinge_moments(np.stack([q + 1e-6, q - 1e-6]), P, design)
    return (M[0] - M[1]) / 2e-6


@pytest.mark.parametrize("diameter, P", [(180.0, 0.9), (240.0, 1.4), (150.0, 1.7)])
def test_closing_on_coupled_hinges_is_the_least_energy_with_no_pad_inside(diameter, P):
    """The hold's own fingers (hinges coupled through the tube): a finger closing on a centred
    sphere takes the least coupled energy with every pad outside the circle, found here by SLSQP
    over the one-finger grasp's geometry (reduced.equations.contact, not the hold's pads), to 1e-6
    rad; the coupled moments are that energy's gradient."""
    d = hold_fast.finger_design(HandDesign())
    closed = hold_fast.close_hand(P, place_object(objects.GraspObject(diameter_mm=diameter), d), d)
    s = closed.fingers[0]
    centre, r = (0.0, contact.object_depth(diameter, d)), 0.5 * diameter
    q0 = finger_hinges.coupled_free_angles(P, d)
    h = 1e-6
    fd = [(finger_hinges.coupled_energy(s.q + h * e, P, d) - finger_hinges.coupled_energy(s.q - h * e, P, d)) / (2 * h)
          for e in np.eye(d.n_s)]
    np.testing.assert_allclose(finger_hinges.coupled_moments(s.q, P, d), fd, rtol=1e-6, atol=1e-4)
    sol = minimize(lambda q: finger_hinges.coupled_energy(q, P, d), 0.5 * q0, method="SLSQP",
                   jac=lambda q: finger_hinges.coupled_moments(q, P, d),
                   constraints=[{"type": "ineq", "fun": lambda q: np.nan_to_num(
                       contact.pad_gaps(q, centre, r, d)[1:], posinf=1e3)}],
                   bounds=[(-0.1, 0.3)] * d.n_s, options={"ftol": 1e-10, "maxiter": 200})
    # SLSQP may end on "positive directional derivative" at the optimum (the energy's quadrature
    # round-off); where it ends is what is checked
    np.testing.assert_allclose(sol.x, s.q, rtol=0, atol=1e-6)
    assert np.min(contact.pad_gaps(s.q, centre, r, d)) > -1e-8
    assert float(np.max(s.N)) > 0.0


def _pinch(N_cap: float, mu: float, *, along=0.0, K=(1000.0,)):
    """Two flat pads on opposite faces x = +-20 of a box centred at the origin, each on its own
    finger, closed with N_cap. A finger's hinges (stiffness K) push its pad along -n (J = -n: the
    gap rate -1); its last hinge also moves the pad by ``along`` along +y per radian, so the pad's
    friction loads that hinge."""
    normal = np.array([[1.0, 0, 0], [-1.0, 0, 0]])     # the box's outward normals at the pads
    point = 20.0 * normal
    h = len(K)
    J = np.zeros((2 * h, 2, 3))
    for c in range(2):
        J[c * h:(c + 1) * h, c] = -normal[c]
        J[(c + 1) * h - 1, c, 1] = along
    return hold_lp.ContactSet(np.array([0, 1]), np.array([1, 1]), point, normal, np.array([N_cap, N_cap]), J,
                              np.full(2 * h, -N_cap), np.tile(np.asarray(K, float), 2))


@pytest.mark.parametrize("mu", [0.0, 0.3, 0.8])
def test_two_flat_pads_pinching_a_box_hold_two_mu_N(mu):
    """Coulomb: the largest load along the pads is 2 mu N (N each pad's normal force, reported):
    the pull beyond a weight W is 2 mu N - W, exactly (the polygon has a side along the load)."""
    cs, W = _pinch(10.0, mu), 1.0
    lim = hold_lp.holding_limit(cs, np.zeros(3), W, (0, 1, 0), mu)
    if mu == 0.0:
        assert lim.pull_N == pytest.approx(-W)   # frictionless flat pads carry no weight: only a push cancelling it
        return
    assert np.allclose(lim.normal_N, 10.0)
    assert lim.pull_N + W == pytest.approx(2.0 * mu * float(np.mean(lim.normal_N)), rel=1e-9)
    assert np.all(lim.slip)


@pytest.mark.parametrize("along", [0.5, -0.5])
def test_a_pads_friction_on_elastic_hinges_changes_its_normal_force_by_their_compliance(along):
    """A finger of two hinges (K_a = 1000, K_b = 3000 N mm/rad) pressing one pad; the pad's friction
    (mu N against the pull along +y) loads hinge b alone, by s = ``along`` per unit. The pad stays on
    the box: K_a da = N* - N, K_b db = N* - N + s mu N, da + db = 0, so N = N* / (1 - s mu w) with
    w = (1/K_b) / (1/K_a + 1/K_b) = 1/4, the compliance-weighted share of the hinge it loads (a rigid
    hinge a would keep N*, a rigid b would let it go to N* / (1 - s mu)). The pull beyond W is 2 mu N - W."""
    mu, W, N_star = 0.8, 1.0, 10.0
    cs = _pinch(N_star, mu, along=along, K=(1000.0, 3000.0))
    lim = hold_lp.holding_limit(cs, np.zeros(3), W, (0, 1, 0), mu)
    N = N_star / (1.0 - along * mu * 0.25)
    assert np.allclose(lim.normal_N, N, rtol=1e-9)
    assert lim.pull_N == pytest.approx(2.0 * mu * N - W, rel=1e-9)


def test_pinch_off_axis_pull_within_the_polygon_bound():
    """A load oblique to the polygon's sides: the friction it allows lies between the inscribed
    polygon's bound cos(pi/16) and the cone's (the closed form sqrt((2 mu N)^2 - W^2))."""
    cs, W, mu = _pinch(10.0, 0.5), 3.0, 0.5
    lim = hold_lp.holding_limit(cs, np.zeros(3), W, (0, 0, 1), mu)
    exact = math.sqrt((2 * mu * 10.0) ** 2 - W ** 2)
    assert exact * math.cos(math.pi / hold_lp.GENERATORS) - 1e-9 <= lim.pull_N <= exact + 1e-9


def _check_state(result, weight):
    """The object's equilibrium from the reported contacts alone, and every contact's cone."""
    F = np.zeros(3)
    centre = np.asarray(result.extra["object_centre_mm"])
    M = np.zeros(3)
    for c in result.contacts:
        f = -c.normal_N * np.asarray(c.normal) + (c.friction_N * np.asarray(c.friction_dir) if c.friction_dir else 0)
        F += f
        M += np.cross(np.asarray(c.point_mm) - centre, f)
        assert c.friction_N <= result.friction * c.normal_N * (1 + 1e-9) + 1e-9
    F += np.array([0, weight, 0])
    # HiGHS' primal feasibility tolerance 1e-7 on forces of ~10 N
    assert np.max(np.abs(F)) < 1e-6 and np.max(np.abs(M)) < 1e-4


def test_caged_frictionless_sphere_holds_by_geometry_and_drops_when_open_above():
    """Frictionless: a sphere the tip pads touch below its equator holds with the holding limit
    of geometry alone, sum_c N*_c (-n_c . e_y) - m g (each finger's hinges bound its pad's force by
    the closing force N*); where the pads touch above the equator, nothing holds it."""
    d = HandDesign()
    caged = objects.GraspObject(diameter_mm=150.0, mass_kg=0.5, friction=0.0, offset_mm=(0, 40, 0))
    r = hold.solve_hold(d, caged, P_cavity_MPa=2.0)
    assert r.held
    closed = hold_fast.close_hand(2.0, place_object(caged, hold_fast.finger_design(d)), hold_fast.finger_design(d))
    cs = hold.contact_set(closed, hold_fast.finger_design(d))
    assert np.all(cs.normal[:, 1] > 0)   # below the equator: the object's normals point down
    geometric = float(np.sum(cs.closing_N * cs.normal[:, 1])) - 0.5 * G
    assert r.holding_limit_N == pytest.approx(geometric, rel=1e-7)
    _check_state(r, 0.5 * G)
    above = objects.GraspObject(diameter_mm=180.0, mass_kg=0.5, friction=0.0)
    r2 = hold.solve_hold(d, above, P_cavity_MPa=1.5)
    assert r2.contacts and all(np.asarray(c.normal)[1] < 0 for c in r2.contacts)
    assert not r2.held and r2.holding_limit_N == 0.0


def test_friction_hold_residual_cones_and_monotone_in_mu():
    d = HandDesign()
    limits = []
    for mu in (0.5, 0.8, 1.2):
        r = hold.solve_hold(d, objects.GraspObject(diameter_mm=180.0, mass_kg=0.5, friction=mu), P_cavity_MPa=1.5)
        assert r.held
        _check_state(r, 0.5 * G)
        assert r.steps[2].extra["equilibrium_residual"] < 1e-6
        limits.append(r.holding_limit_N)
    assert limits[0] < limits[1] < limits[2]


def test_symmetry_shortcut_equals_solving_every_finger(monkeypatch):
    """A square box turned 45 deg about the palm's axis is seen alike by the four fingers at 90 deg:
    found symmetric, one finger solved; solving all four gives the same hold (to the Newton
    tolerance). A box of unequal sides is not symmetric and every finger is solved."""
    from softhand.reduced.holding import hand_layout

    d = HandDesign()
    box = objects.GraspObject(shape="box", size_mm=(110, 110, 110), mass_kg=0.3, friction=0.5, rotation_deg=(0, 45, 0))
    r = hold.solve_hold(d, box, P_cavity_MPa=1.5)
    assert r.symmetric and r.held
    _check_state(r, 0.3 * G)
    monkeypatch.setattr(hand_layout, "symmetric", lambda placed, design: False)
    full = hold.solve_hold(d, box, P_cavity_MPa=1.5)
    assert not full.symmetric
    assert full.holding_limit_N == pytest.approx(r.holding_limit_N, rel=1e-7)
    monkeypatch.undo()
    odd = objects.GraspObject(shape="box", size_mm=(120, 110, 100), mass_kg=0.3, friction=0.5, rotation_deg=(0, 30, 0))
    r_odd = hold.solve_hold(d, odd, P_cavity_MPa=1.5)
    assert not r_odd.symmetric
    if r_odd.held:
        _check_state(r_odd, 0.3 * G)


def test_zero_pull_is_refused():
    with pytest.raises(InputError, match="zero length"):
        hold.pull_unit((0, 0, 0))


def test_box_corner_contact_does_not_depend_on_the_pad_sampling(monkeypatch):
    """A box's top corner on a pad: the corner is a feature point, so the closing force and the
    holding limit are the same with a coarse and a fine sampling of the pads (to the Newton tolerance)."""
    from softhand.reduced.holding import hand_layout

    d = hold_fast.finger_design(HandDesign())
    box = objects.GraspObject(shape="box", size_mm=(110, 110, 110), mass_kg=0.3, rotation_deg=(0, 45, 0))
    limits = []
    for samples in ((17, 3), (65, 9)):
        monkeypatch.setattr(hand_layout, "PAD_SAMPLES", samples)
        limits.append(hold.solve_hold(d, box, P_cavity_MPa=1.5).holding_limit_N)
    assert limits[0] == pytest.approx(limits[1], rel=1e-8)


@pytest.mark.parametrize("text", ["box:180x180x180", "cylinder:180x180"])
def test_pads_on_a_top_edge_touch_it_in_their_own_planes_as_the_fem_does(text):
    """The 180 mm cube's top edges and the upright cylinder's rim under the four fingers: each
    finger's pad meets the edge at the object's point deepest through the pad (the FEM hold's
    rule): in the finger's own plane, on the edge, and the four contacts the quarter turns of
    one another. (A sampled contact sat 8.4 mm across the pad on the cube, and 2.2 mm on two
    of the cylinder's four, twisting the object the LP then had to hold.)"""
    from softhand.reduced.holding import hand_layout

    d = hold_fast.finger_design(HandDesign())
    placed = place_object(objects.parse_object(text), d)
    cs = hold.contact_set(hold_fast.close_hand(0.9, placed, d), d)
    assert len(cs.finger) == 4 and sorted(cs.finger) == [0, 1, 2, 3]
    frames = hand_layout.finger_frames(d)
    rel = cs.point - placed.centre
    for c, i in enumerate(cs.finger):
        across = np.cross(frames.e_out[i], frames.e_down[i])
        assert abs(rel[c] @ across) < 1e-9                                   # in the finger's plane
        assert rel[c] @ frames.e_out[i] == pytest.approx(90.0, abs=1e-9)      # on the side's plane
        assert rel[c][1] == pytest.approx(-90.0, abs=1e-6)                    # at the top
    turn = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])  # a quarter turn about y
    order = np.argsort(cs.finger)
    for a, b in zip(order[:-1], order[1:]):
        assert np.allclose(np.abs(rel[b]), np.abs(rel[a] @ turn.T), atol=1e-6)
        assert cs.closing_N[b] == pytest.approx(cs.closing_N[a], rel=1e-9)


def test_mesh_object_holds_as_the_sphere_it_approximates(tmp_path):
    """A triangulated sphere (icosphere, 2562 vertices, r = 90 mm) read from STL against the 180 mm
    sphere: the holding limit within 3 % (the facets lie up to 0.05 mm inside the sphere, the
    distance grid's step 4.7 mm: measured 1.6 %; with 642 vertices, 7 %)."""
    trimesh = pytest.importorskip("trimesh")
    trimesh.creation.icosphere(subdivisions=4, radius=90.0).export(tmp_path / "ball.stl")
    mesh = objects.object_from_table({"shape": "mesh", "file": "ball.stl", "mass_kg": 0.5}, base_dir=tmp_path)
    d = HandDesign()
    rm = hold.solve_hold(d, mesh, P_cavity_MPa=1.5)
    rs = hold.solve_hold(d, objects.GraspObject(diameter_mm=180.0, mass_kg=0.5), P_cavity_MPa=1.5)
    assert rm.held and rs.held
    assert rm.holding_limit_N == pytest.approx(rs.holding_limit_N, rel=0.03)
