"""The object turning as it slides in the fast hold: the mechanism's rotation against the LP's own
dual values where they are unique, symmetric grasps that do not turn, and the path's integration
against closed forms (first order in the step)."""
import math

import numpy as np
import pytest
from scipy.optimize import linprog
from scipy.spatial.transform import Rotation

from softhand.reduced.holding import hold, hold_fast, hold_lp, hold_turn, objects
from softhand.reduced.holding.hand_layout import place_object
from softhand.reduced.vocabulary.design import HandDesign

DOWN = np.array([0.0, 1.0, 0.0])


def _grasp(obj, P):
    d = hold_fast.finger_design(HandDesign())
    placed = place_object(obj, d)
    closed = hold_fast.close_hand(P, placed, d)
    size = float(np.max(np.ptp(placed.surface(resolution=8)[0], axis=0)))
    return placed, hold.contact_set(closed, d), obj.mass_kg * d.g, size


def _dual_rate(cs, centre, weight, mu):
    """omega from HiGHS's dual values of the object's six equations (the mechanism's velocities),
    per unit velocity along the pull: an independent route to the same rate where they are unique."""
    gens = hold_lp.tangent_generators(cs.normal, DOWN)
    A_eq, b_eq, A_ub, b_ub, Q = hold_lp._system(cs, centre, weight, DOWN, mu, gens)
    c = np.zeros(A_eq.shape[1])
    c[-1] = -1.0
    bounds = hold_lp._bounds(len(cs.finger), gens.shape[1], Q, (-weight - 1.0, hold_lp.MAX_PULL))
    sol = linprog(c, A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=b_eq, bounds=bounds, method="highs")
    duals = sol.eqlin.marginals[:6]
    return duals[3:] / (duals[:3] @ DOWN)


def test_a_turned_cube_turns_back_at_the_rate_of_the_lps_duals():
    """The 180 mm cube turned 15 deg about the palm's axis (0.5 kg, mu 0.5, 1.2 MPa): its pads press
    the faces off their centre lines; the mechanism turns it back towards square, about the palm's
    axis alone, at the rate the LP's dual values give (unique here) -- and as the FEM hold's cube
    turns (-0.44 deg at rest, -8.8 deg at its limit)."""
    obj = objects.GraspObject(shape="box", size_mm=(180.0,) * 3, rotation_deg=(0.0, 15.0, 0.0), mass_kg=0.5,
                              friction=0.5)
    placed, cs, weight, size = _grasp(obj, 1.2)
    omega = hold_turn.turn_rate(cs, placed.centre, weight, DOWN, obj.friction, size_mm=size)
    dual = _dual_rate(cs, placed.centre, weight, obj.friction)
    assert omega[1] < -np.radians(0.5)                    # back towards square, > 0.5 deg/mm
    assert omega[1] == pytest.approx(dual[1], rel=1e-6)
    assert np.allclose(omega[[0, 2]], 0.0, atol=1e-12)


@pytest.mark.parametrize("obj", [
    objects.GraspObject(shape="box", size_mm=(180.0,) * 3, mass_kg=0.5, friction=0.5),
    objects.GraspObject(shape="cylinder", diameter_mm=180.0, length_mm=180.0, mass_kg=2.0, friction=0.8),
    objects.GraspObject(diameter_mm=180.0, mass_kg=2.0, friction=0.8),
])
def test_a_symmetric_grasp_does_not_turn(obj):
    """A grasp whose limit is even in an applied moment does not turn, about any axis (the LP's dual
    values, one vertex of a face of them, turned these three by 0.1-0.95 deg/mm with this HiGHS:
    module doc)."""
    placed, cs, weight, size = _grasp(obj, 0.9)
    omega = hold_turn.turn_rate(cs, placed.centre, weight, DOWN, obj.friction, size_mm=size,
                                axes=np.eye(3))
    assert np.allclose(omega, 0.0, atol=1e-9)


def test_a_constant_rate_turns_the_object_exactly():
    """rate = const: the knots compose rotations about one axis, R(y) = exp(omega y) R0 exactly."""
    obj = objects.GraspObject(shape="box", size_mm=(100.0, 80.0, 60.0), rotation_deg=(10.0, 20.0, 30.0))
    placed = place_object(obj, HandDesign())
    omega = np.radians([0.3, -1.0, 0.5])
    path = hold_turn.Path(placed, DOWN, lambda y, p: omega)
    for y in (0.0, 0.7, 13.0, 40.0):
        at = path.at(y)
        assert np.allclose(at.R, Rotation.from_rotvec(omega * y).as_matrix() @ placed.R, atol=1e-12)
        assert np.allclose(at.centre, placed.centre + y * DOWN, atol=1e-12)


def test_a_rate_that_eases_as_the_object_turns_converges_at_first_order():
    """omega = -k psi about y (the object turning back to square, slower as it gets there):
    psi(y) = psi0 exp(-k y); the explicit Euler steps of TURN_STEP at most approach it at first
    order in the step, within the step's turn."""
    obj = objects.GraspObject(shape="box", size_mm=(100.0,) * 3, rotation_deg=(0.0, 15.0, 0.0))
    placed = place_object(obj, HandDesign())
    k, y = 0.05, 30.0

    def psi_of(p):
        return Rotation.from_matrix(p.R).as_rotvec()[1]

    exact = np.radians(15.0) * math.exp(-k * y)
    errors = []
    for step_deg in (1.0, 0.5, 0.25):
        old = hold_turn.TURN_STEP
        hold_turn.TURN_STEP = np.radians(step_deg)
        try:
            path = hold_turn.Path(placed, DOWN, lambda y, p: np.array([0.0, -k * psi_of(p), 0.0]))
            errors.append(abs(psi_of(path.at(y)) - exact))
        finally:
            hold_turn.TURN_STEP = old
    assert errors[0] < np.radians(1.0)
    assert errors[1] / errors[0] == pytest.approx(0.5, abs=0.08)
    assert errors[2] / errors[1] == pytest.approx(0.5, abs=0.08)


def test_a_ball_is_not_turned_and_a_turned_cube_rests_turned_back():
    d = HandDesign()
    ball = hold.solve_hold(d, objects.GraspObject(diameter_mm=180.0, mass_kg=0.5, friction=0.8), P_cavity_MPa=0.9)
    assert ball.rotation_deg == (0.0, 0.0, 0.0)
    cube = hold.solve_hold(d, objects.GraspObject(shape="box", size_mm=(180.0,) * 3, rotation_deg=(0.0, 15.0, 0.0),
                                                  mass_kg=0.5, friction=0.5), P_cavity_MPa=1.2)
    assert cube.held
    assert -3.0 < cube.rotation_deg[1] < 0.0      # the FEM's: -0.44 deg at rest
    assert cube.steps[-1].rotation_deg[1] < cube.rotation_deg[1]


def test_the_closing_twist_is_the_moment_of_the_closing_forces():
    """Two pads pressing a box's opposite faces x = +-20 off its centre line by +-5 mm along z, each
    with N = 10: the forces -N n on it twist it by 2 x 5 x 10 = 100 N mm about -y."""
    normal = np.array([[1.0, 0, 0], [-1.0, 0, 0]])
    point = np.array([[20.0, 0, 5.0], [-20.0, 0, -5.0]])
    cs = hold_lp.ContactSet(np.array([0, 1]), np.array([1, 1]), point, normal, np.array([10.0, 10.0]),
                            np.zeros((2, 2, 3)), np.zeros(2), np.ones(2))
    assert hold_turn.closing_twist(cs, np.zeros(3), DOWN) == pytest.approx(-100.0)
    assert hold_turn.closing_twist(cs, np.zeros(3), [1.0, 0, 0]) == pytest.approx(0.0)


@pytest.mark.parametrize("twist, rest_deg", [(-3.0, 2.37), (2.0, 7.9), (-1.0, 30.0)])
def test_untwist_turns_with_the_twist_to_where_the_weight_is_borne(twist, rest_deg):
    """A synthetic hand whose pads bear the weight once the object has turned ``rest_deg`` with the
    twist (the pull borne grows with the turn past it, none admissible before 1 deg): the untwisted
    pose is turned there, about the palm's axis, to the tolerance; the direction is the twist's."""
    placed = place_object(objects.GraspObject(shape="box", size_mm=(150.0, 150.0, 150.0)),
                          hold_fast.finger_design(HandDesign()))
    sign = np.sign(twist)

    def turn_deg(p):  # the pose's turn about y from the placement, in the twist's sense
        return sign * math.degrees(Rotation.from_matrix(p.R @ placed.R.T).as_rotvec()[1])

    def pull_at(p):
        a = turn_deg(p)
        return -math.inf if a < 1.0 else a - rest_deg

    moved = hold_turn.untwist(placed, DOWN, twist, pull_at)
    assert np.allclose(moved.centre, placed.centre)
    assert turn_deg(moved) == pytest.approx(rest_deg, abs=math.degrees(hold_turn.UNTWIST_TOL))
    assert turn_deg(moved) >= rest_deg


def test_untwist_where_the_weight_is_never_borne_turns_to_the_first_hold_or_not_at_all():
    placed = place_object(objects.GraspObject(shape="box", size_mm=(150.0, 150.0, 150.0)),
                          hold_fast.finger_design(HandDesign()))

    def turn_deg(p):
        return -math.degrees(Rotation.from_matrix(p.R @ placed.R.T).as_rotvec()[1])

    moved = hold_turn.untwist(placed, DOWN, -5.0, lambda p: -math.inf if turn_deg(p) < 4.3 else -1.0)
    assert turn_deg(moved) == pytest.approx(4.3, abs=math.degrees(hold_turn.UNTWIST_TOL))
    assert hold_turn.untwist(placed, DOWN, -5.0, lambda p: -math.inf) is placed
    assert hold_turn.untwist(placed, DOWN, 0.0, lambda p: 1.0) is placed


def test_a_box_twisted_more_than_friction_carries_turns_back_when_let_go_and_is_held():
    """Design A's 160 x 110 x 140 mm box turned 25 deg (0.4 kg, mu 0.6, 1.3 MPa): closed on, its pads
    twist it more than friction carries (no admissible state at the grasp, not even without its
    weight). The whole-hand FEM turns it 3 deg back while it lets go and holds 1.78 N
    (studies/data/hold_fem_limits.json); the fast model turns it back 2-4 deg and holds it."""
    from softhand.studies import hold_reference

    data = hold_reference.load()
    case = next(c for c in data["cases"] if c["name"].startswith("design A, box 160 x 110 x 140"))
    design = hold_reference.design_of(case, data["designs"])
    obj = objects.object_from_table(dict(case["object"], mass_kg=case["mass_kg"], friction=case["friction"]),
                                    source="test")
    d = hold_fast.finger_design(design)
    placed = place_object(obj, d)
    cs = hold.contact_set(hold_fast.close_hand(case["P_cavity_MPa"], placed, d), d)
    assert hold_lp.holding_limit(cs, placed.centre, 0.0, DOWN, obj.friction, size_mm=160.0) is None
    r = hold.solve_hold(design, obj, P_cavity_MPa=case["P_cavity_MPa"])
    assert r.held and -4.0 < r.rotation_deg[1] < -2.0
    assert r.holding_limit_N == pytest.approx(case["fem_limit_N"], rel=0.05)
