"""softhand.reduced.calibrated.grasp_hold: the one-solve grasp (F_v or pump pressure given) against the
bracketing root finder on grasp_fem.grasp_state, and the state it finds is grasp_state's."""
import math

import numpy as np
import pytest

from softhand.reduced.calibrated import (finger_hinges, grasp_fem, grasp_hold, grasp_hold_end, grasp_hold_fast, grasp_hold_solve,
                                         hinge_space, hinge_table)
from softhand.reduced.equations import hand, kinematics
from softhand.reduced.vocabulary.design import HandDesign

PAPER = finger_hinges.fem_finger(HandDesign(reservoir_model="fem"))
#: (design, diameter, mass, F_v [N], pump pressure [MPa]): pad 2 (the paper's task), pad 3 after a
#: long close (small object, long finger, short lever), the tip link (large object, thick wall);
#: the task's 2 m g / n and a pump pressure near it, where one pad touches
CASES = [
    (PAPER, 180.0, 2.0, 9.80665, 0.6),
    (PAPER.replace(a=4.5, b=4.5, d=12.0, V0=16226.0, l0=185.7,
                   hinge_s=tuple(s * 185.7 / PAPER.l0 for s in PAPER.hinge_s)), 140.0, 0.5, 2.4516625, 1.39),
    (PAPER.replace(a=4.5, b=5.69, d=18.0, R=29.3, V0=30000.0), 240.0, 3.0, 14.709975, 1.0),
]

def _same_hold(a, b):
    """Two Holds of the same state: P_cavity, P_pump, F_v, theta to Newton's / brentq's 1e-13."""
    for x, y in zip(a[:4], b[:4]):
        assert x == pytest.approx(y, rel=1e-10, abs=1e-12)


def _count_states(monkeypatch) -> list:
    """The calls of grasp_fem.grasp_state from now on (the list grows as they come)."""
    calls, state = [], grasp_fem.grasp_state
    monkeypatch.setattr(grasp_fem, "grasp_state", lambda *a, **k: calls.append(a) or state(*a, **k))
    return calls


@pytest.mark.parametrize("design, diameter, mass, F_v, P_pump", CASES)
@pytest.mark.parametrize("target", ["F_v", "P_pump"])
def test_fast_path_equals_the_slow_path(design, diameter, mass, F_v, P_pump, target):
    value = F_v if target == "F_v" else P_pump
    fast = grasp_hold_fast.fast_hold(design, diameter, mass, target, value)
    slow = grasp_hold.slow_hold(design, diameter, mass, target, value)
    assert fast is not None and fast.fast and not slow.fast
    assert fast.link == slow.link
    # both solve the same equations: Newton to 1e-13 of the unknowns, brentq to 1e-13 MPa
    _same_hold(fast, slow)


@pytest.mark.parametrize("design, diameter, mass, F_v, P_pump", CASES)
def test_the_fast_state_is_grasp_states_at_its_pressure(design, diameter, mass, F_v, P_pump):
    h = grasp_hold_fast.fast_hold(design, diameter, mass, "F_v", 0.8 * F_v)
    s = grasp_fem.grasp_state(design, diameter, h.P_cavity, mass)
    assert s.link == h.link
    assert s.F_v == pytest.approx(0.8 * F_v, rel=1e-9)
    assert s.theta == pytest.approx(h.theta, rel=1e-9)
    # the pump pressure: the cavity's less the reservoir's at the bend (eq. (27) less eq. (28))
    p_r = float(hand.pressure(h.theta, design, reservoir=False) - hand.pressure(h.theta, design))
    assert h.P_pump == pytest.approx(h.P_cavity - p_r, rel=1e-12)


def test_pump_pressure_and_force_are_inverse():
    """F_v at the pump pressure that holds F_v is that F_v; without reservoir P_pump = P_cavity."""
    held = grasp_hold.hold(PAPER, 180.0, 2.0, "F_v", 7.5)
    back = grasp_hold.hold(PAPER, 180.0, 2.0, "P_pump", held.P_pump)
    assert back.F_v == pytest.approx(7.5, rel=1e-10)
    bare = grasp_hold.hold(PAPER, 180.0, 2.0, "F_v", 7.5, reservoir=False)
    assert bare.P_pump == bare.P_cavity == pytest.approx(held.P_cavity, rel=1e-10)


def test_hold_falls_back_to_the_slow_path(monkeypatch):
    expected = grasp_hold_fast.fast_hold(PAPER, 180.0, 2.0, "F_v", 9.80665)
    monkeypatch.setattr(grasp_hold_fast, "fast_hold", lambda *a, **k: None)
    h = grasp_hold.hold(PAPER, 180.0, 2.0, "F_v", 9.80665)
    assert not h.fast and h.P_pump == pytest.approx(expected.P_pump, rel=1e-10)


def test_the_equations_at_a_batch_are_those_of_each_state():
    """_residuals vectorised over states: a batch gives, row by row, the single states' values."""
    depth = 104.14135964771822
    Z = np.array([[0.02, 0.03, 0.04, 5.0, 0.7], [0.03, 0.02, 0.05, 8.0, 0.9]])
    args = (2, depth, 90.0, 2.0 * PAPER.g / PAPER.n, "F_v", 9.0, PAPER, True)
    batch, F = grasp_hold_solve._residuals(Z, *args)
    for i in range(2):
        one, F1 = grasp_hold_solve._residuals(Z[i:i + 1], *args)
        np.testing.assert_allclose(batch[i], one[0], rtol=1e-14)
    # the moment of hinge 1 against grasp_fem's own hinge moment and lever (pad 2 at its closest point)
    q = np.array([0.02, 0.03, 0.04, 0.04, 0.04])
    _, grad, Tq, *_ = grasp_fem._load(q, (0.0, depth), 2, 2.0 * PAPER.g / PAPER.n, PAPER)
    M = finger_hinges.hinge_moments(q, 0.7, PAPER)
    assert batch[0, 0] == pytest.approx(M[0] - 5.0 * grad[0] - Tq[0], rel=1e-12)
    assert math.isfinite(F[0])


def test_a_force_one_pad_cannot_give_is_refused_at_the_end_of_one_pad(monkeypatch):
    """20 kg on the paper's hand: F_v = 2 m g / n = 98 N is more than pad 3 gives before a second
    pad touches (~75 N at ~2.9 MPa). The bracket halved its step at that end, evaluating the
    same failing pressures again (21 equilibria); now the end is solved for, and the refusal
    names it: the cavity pressure where grasp_state stops having a state (bisection on that; to
    the message's six digits), and F_v there."""
    from softhand.reduced.vocabulary.errors import InputError

    state = grasp_fem.grasp_state
    calls = _count_states(monkeypatch)
    with pytest.raises(InputError, match="not reached by the finger on one pad") as info:
        grasp_hold.slow_hold(PAPER, 180.0, 20.0, "F_v", 98.0665)
    assert len(calls) <= 15
    message = str(info.value)
    end = float(message.split("up to the cavity pressure ")[1].split(" MPa")[0])
    edge = _existence_edge(PAPER, 180.0, 20.0, 2.0, 4.0)
    assert end == pytest.approx(edge, abs=1e-5)
    F_v = state(PAPER, 180.0, edge, 20.0).F_v
    assert F_v < 98.0665 and f"F_v {F_v:.4g} N" in message


#: a big object held at the tip of a short, stiff finger with a small reservoir: the pump's 3.5 MPa
#: are ~3.4 MPa above the contact pressure
TIP_HOLD = PAPER.replace(a=4.1, b=4.3, d=17.0, R=19.5, t=1.5, V0=2200.0, tie_width=7.6, l0=154.0,
                         hinge_s=tuple(s * 154.0 / PAPER.l0 for s in PAPER.hinge_s))


def test_a_pump_pressure_far_above_contact_is_found_by_the_fast_path():
    """Newton starts at the pump's pressure (plus the reservoir's at contact), not just past
    contact, from where it failed (the slow path's 14 equilibria then): the same state as the
    slow path."""
    fast = grasp_hold_fast.fast_hold(TIP_HOLD, 230.0, 3.5, "P_pump", 3.5)
    slow = grasp_hold.slow_hold(TIP_HOLD, 230.0, 3.5, "P_pump", 3.5)
    assert fast is not None and fast.link == slow.link == 5
    _same_hold(fast, slow)


def test_both_paths_stop_where_the_free_finger_has_no_pressure():
    """Above the free finger's pressure at its largest bend (4.0 MPa here) the FEM-calibrated curve
    has no state for grasp_state: the slow path refuses, and the fast path, whose equations go
    on, gives no answer there either (it gave F_v = 93 N at 4.5 MPa)."""
    from softhand.reduced.vocabulary.errors import InputError

    top = grasp_hold_solve.largest_pressure(TIP_HOLD)
    assert 3.9 < top < 4.1
    with pytest.raises(InputError):
        grasp_fem.grasp_state(TIP_HOLD, 230.0, top + 0.1, 3.5)
    assert grasp_hold_fast.fast_hold(TIP_HOLD, 230.0, 3.5, "P_pump", 4.5) is None
    with pytest.raises(InputError, match="not reached"):
        grasp_hold.hold(TIP_HOLD, 230.0, 3.5, "P_pump", 4.5)


def test_a_fast_iterate_outside_the_models_does_not_end_the_hold(monkeypatch):
    """A small reservoir: a Newton iterate on the first pad takes more oil than the reservoir
    holds (InputError from the reservoir model), which ended the design's evaluation; now that
    pad gives no answer and the next one, which holds the object, does: the slow path's state."""
    from softhand.reduced.vocabulary.errors import InputError

    design = PAPER.replace(a=5.2, b=5.3, d=17.9, R=27.5, t=1.1, V0=5600.0, tie_width=14.1, l0=180.0)
    raised, newton = [], grasp_hold_solve._newton

    def watched(*args, **kwargs):
        try:
            return newton(*args, **kwargs)
        except InputError as err:
            raised.append(err)
            raise

    monkeypatch.setattr(grasp_hold_solve, "_newton", watched)
    held = grasp_hold_fast.fast_hold(design, 230.0, 3.5, "P_pump", 3.5)
    assert raised and held is not None and held.link == 5
    slow = grasp_hold.slow_hold(design, 230.0, 3.5, "P_pump", 3.5)
    _same_hold(held, slow)


def _found_on_a_later_pad(monkeypatch, design, diameter, mass, P_pump, link):
    """fast_hold's answer at P_pump on pad ``link`` (not the first face): checked by one
    grasp_state, and the slow path's state."""
    calls = _count_states(monkeypatch)
    held = grasp_hold_fast.fast_hold(design, diameter, mass, "P_pump", P_pump)
    assert held is not None and held.link == link and len(calls) == 1
    _same_hold(held, grasp_hold.slow_hold(design, diameter, mass, "P_pump", P_pump))
    return held


def test_a_pump_pressure_that_presses_a_later_pad_is_found_on_it(monkeypatch):
    """The paper's hand touches the 180 mm object with pad 2 and holds it with pad 3 at 2 MPa: the
    first pad's solve fails, pad 3's is checked by one grasp_state (the slow path's 190 ms were
    spent on every such design of a margin task) and is the slow path's answer."""
    held = _found_on_a_later_pad(monkeypatch, PAPER, 180.0, 1.0, 2.0, link=3)
    assert held.P_pump == pytest.approx(2.0, rel=1e-12)


def test_a_force_on_a_later_pad_is_the_slow_paths_root(monkeypatch):
    """F_v = 30 N on the paper's hand at 180 mm, 1 kg: pad 3 presses with it, pad 2 touched
    first. F_v drops where the touching pad changes and may be reached twice, so a later pad's
    root is kept only if F_v is below 30 N at every point of the slow path's grid below it
    (here 5 states, then its check): the slow path's state, 60 states fewer."""
    calls = _count_states(monkeypatch)
    fast = grasp_hold_fast.fast_hold(PAPER, 180.0, 1.0, "F_v", 30.0)
    assert fast is not None and fast.link == 3 and len(calls) <= 8
    slow = grasp_hold.slow_hold(PAPER, 180.0, 1.0, "F_v", 30.0)
    assert slow.link == 3 and len(calls) > 20
    _same_hold(fast, slow)



def test_a_pump_pressure_beyond_the_one_pad_region_is_refused_at_once(monkeypatch):
    """The paper's hand at a 4 MPa pump on 180 mm: a second pad touches near 3 MPa. The answer's
    cavity pressure is at least the pump's (the reservoir's pressure is not negative), where one
    pad no longer holds the object alone: refused after that one equilibrium (the bracket
    halved down to the edge, ~0.5 s). A scan of the one-pad states confirms: none reaches 4 MPa."""
    from softhand.reduced.vocabulary.errors import InputError

    state = grasp_fem.grasp_state
    calls = _count_states(monkeypatch)
    with pytest.raises(InputError, match="second pad touches below the cavity pressure 4 MPa"):
        grasp_hold.slow_hold(PAPER, 180.0, 1.0, "P_pump", 4.0)
    assert len(calls) == 1
    reached = []
    for P in np.arange(0.4, 4.0, 0.05):
        try:
            s = state(PAPER, 180.0, P, 1.0)
        except InputError:
            break
        reached.append(P - float(grasp_hold_solve.reservoir_pressure(s.theta, PAPER)))
    assert 1.5 < len(reached) * 0.05 and max(reached) < 4.0


def _existence_edge(design, diameter, mass, lo, hi, tol=1e-8):
    """The cavity pressure where grasp_state stops having a state, by plain bisection on whether it
    has one (lo: it has, hi: it has not)."""
    from softhand.reduced.vocabulary.errors import InputError

    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        try:
            grasp_fem.grasp_state(design, diameter, mid, mass)
            lo = mid
        except InputError:
            hi = mid
    return lo


def test_the_one_pad_model_ends_where_a_second_pad_touches(monkeypatch):
    """The paper's hand at a 4 MPa pump on 180 mm (refused above): at_pump gives the grasp where
    one pad stops holding the object alone, the state grasp_state has there, with another pad
    just touching the object, at the pressure a bisection on grasp_state's having a state finds;
    the scan-and-bisect route (the fast route's solve switched off) gives the same end."""
    held = grasp_hold.at_pump(PAPER, 180.0, 1.0, 4.0)
    assert held.edge == grasp_hold_solve.ONE_PAD_END and held.P_pump < 4.0 and held.fast
    # grasp_state admits 1e-6 mm of another pad in the object: ~1e-7 MPa past the exact end
    edge = _existence_edge(PAPER, 180.0, 1.0, 2.0, 4.0)
    assert held.P_cavity == pytest.approx(edge, abs=2e-7)
    s = grasp_fem.grasp_state(PAPER, 180.0, held.P_cavity, 1.0)
    assert s.link == held.link and s.F_v == pytest.approx(held.F_v, rel=1e-9)
    gaps = grasp_hold.contact.pad_gaps(s.q, (0.0, s.depth), 90.0, finger_hinges.fem_finger(PAPER))
    gaps[s.link] = np.inf
    assert np.min(np.abs(gaps)) < 1e-8  # the second pad, at the object
    assert held.P_pump == pytest.approx(held.P_cavity - float(grasp_hold_solve.reservoir_pressure(s.theta, PAPER)))
    slow = grasp_hold_end.one_pad_end(PAPER, 180.0, 1.0)  # no pump pressure to start from: the scan
    assert slow.edge == held.edge and slow.P_cavity == pytest.approx(held.P_cavity, abs=1e-12)
    monkeypatch.setattr(grasp_hold_end, "_end_on_pad", lambda *a, **k: None)
    bisected = grasp_hold.at_pump(PAPER, 180.0, 1.0, 4.0)
    assert not bisected.fast and bisected.P_cavity == pytest.approx(edge, abs=1e-8)
    assert bisected.F_v == pytest.approx(held.F_v, rel=1e-6)


def test_the_one_pad_model_ends_at_the_calibrated_fingers_highest_pressure():
    """A big object held at the tip: one pad holds it up to the free finger's pressure at its
    largest bend (the finger model's highest), below the 4.5 MPa asked: the grasp there."""
    top = grasp_hold_solve.largest_pressure(TIP_HOLD)
    held = grasp_hold.at_pump(TIP_HOLD, 230.0, 3.5, 4.5)
    assert held.edge == grasp_hold_solve.LARGEST_BEND and held.P_cavity == top and held.P_pump < 4.5
    assert held.F_v == grasp_fem.grasp_state(TIP_HOLD, 230.0, top, 3.5).F_v


def test_at_pump_is_hold_where_the_one_pad_model_reaches_the_pump_pressure():
    held = grasp_hold.at_pump(PAPER, 180.0, 1.0, 2.0)
    assert held.edge == "" and held == grasp_hold.hold(PAPER, 180.0, 1.0, "P_pump", 2.0)
    assert held.P_pump == pytest.approx(2.0, rel=1e-12)  # the pump pressure asked, reached


def test_a_pump_pressure_held_at_a_pads_far_end_is_found_by_the_fast_path(monkeypatch):
    """A wide tube on short links (150 mm, 1 kg, a held-out-style margin task near its optimum):
    at 1.5 MPa pad 3 holds the object with its far end, the hinge it shares with pad 4 (both
    pads' faces cut the circle there, as in grasp_state's corner contact). The face solves put
    pad 4 into the object, so every such design went to the slow path (114 ms); the corner's
    solve, checked by one grasp_state, is the slow path's state."""
    design = PAPER.replace(a=6.0, d=13.61, l0=161.32, hinge_s=tuple(s * 161.32 / PAPER.l0 for s in PAPER.hinge_s))
    state = grasp_fem.grasp_state
    held = _found_on_a_later_pad(monkeypatch, design, 150.0, 1.0, 1.5, link=3)
    s = state(design, 150.0, held.P_cavity, 1.0)
    gaps = grasp_hold.contact.pad_gaps(s.q, (0.0, s.depth), 75.0, design)
    assert gaps[3] < -0.1 and gaps[4] < -0.1  # the corner: both faces inside, the hinge on the circle
    assert np.linalg.norm(s.point - kinematics.joint_positions(s.q, design)[4]) < 1e-12


def test_a_reservoir_pressure_below_zero_does_not_hide_the_pump_pressure():
    """A tiny reservoir (V0 = 2000 mm^3) whose tabulated model gives p_r = -4e-6 MPa: the cavity
    pressure of the answer is just below the pump's, where the slow path's bracket started (it
    refused the pump pressure, "not reached up to 8.5 MPa"). It now starts from contact there,
    and finds the fast path's state."""
    design = PAPER.replace(a=4.1956, b=7.0, d=13.3817, R=40.0, t=0.89407, V0=2000.0, tie_width=13.7794,
                           l0=155.3523, hinge_s=tuple(s * 155.3523 / PAPER.l0 for s in PAPER.hinge_s))
    slow = grasp_hold.slow_hold(design, 230.0, 3.5, "P_pump", 3.5)
    assert slow.P_cavity < 3.5 and slow.P_pump == pytest.approx(3.5, abs=1e-12)
    fast = grasp_hold_fast.fast_hold(design, 230.0, 3.5, "P_pump", 3.5)
    _same_hold(fast, slow)


@pytest.fixture
def papers_table(monkeypatch):
    """Every design on the paper's design's hinge table as it is (not carried to its geometry)."""
    fine = hinge_table.read(str(hinge_space.TABLE_FILE))
    monkeypatch.setattr(hinge_space, "design_table", lambda design: fine)
    finger_hinges._energy_cuts.cache_clear()
    yield
    finger_hinges._energy_cuts.cache_clear()


@pytest.mark.parametrize("a, d, l0", [(6.0, 13.59, 162.49), (5.99558128, 13.5871418, 162.41546091)])
def test_a_pump_pressure_at_a_snap_is_the_state_just_below_it(monkeypatch, papers_table, a, d, l0):
    """Near a held-out-style margin task's optimum (150 mm, 1 kg, 1.5 MPa): where the object held
    by pad 3 slides to the pad's far end, the finger snaps to another state (F_v 16.55 N to 14.65 N)
    and the pump pressure jumps past 1.50235 MPa (by 1.2e-4 MPa): no equilibrium has it. The slow
    path's root finder closes on the jump; the fast path solves for the snap and checks it with
    two states: the same state, to grasp_state's 1e-6 mm tolerance. The root finder lands on
    either side of the jump: it takes the state below, as the fast path. (The snap is the paper's
    hinge table's, as it was measured: carried over the design space, the table moves this
    design's change of pad to 1.66 MPa, through the crease between pads 3 and 4, where both
    touch and the one-contact finger has no state for 2.5e-3 MPa.)"""
    design = PAPER.replace(a=a, d=d, l0=l0, hinge_s=tuple(s * l0 / PAPER.l0 for s in PAPER.hinge_s))
    state = grasp_fem.grasp_state
    calls = _count_states(monkeypatch)
    target = 1.50235
    held = grasp_hold_fast.fast_hold(design, 150.0, 1.0, "P_pump", target)
    assert held is not None and held.link == 3 and len(calls) <= 4
    assert target - 2e-4 < held.P_pump < target
    above = state(design, 150.0, held.P_cavity + 1e-6, 1.0)
    assert above.P - float(grasp_hold_solve.reservoir_pressure(above.theta, design)) > target
    slow = grasp_hold.slow_hold(design, 150.0, 1.0, "P_pump", target)
    assert slow.P_cavity == pytest.approx(held.P_cavity, abs=1e-6)
    assert slow.F_v == pytest.approx(held.F_v, rel=1e-5)


def test_a_later_pads_force_is_the_first_root_where_the_root_finder_took_a_second(papers_table):
    """A held-out-style task's design (200 mm, 3 kg, F_v 17.35 N): on pad 3 F_v rises to 17.35 N
    at 0.940 MPa, drops by 2 N at 0.98 MPa (the contact moves to the pad's far end) and
    reaches 17.35 N again at 1.044 MPa. The root finder's bracket holds both roots (it gave the
    second until the hinge table measured hinges bent backwards; now the first); the fast path's
    pad-3 solve, checked on the root finder's grid, gives the first: F_v stays below the asked
    force on a fine scan up to it. (With the paper's hinge table, as the two roots were found:
    carried over the design space, the table gives this design one root on pad 3, at 1.093 MPa.)"""
    design = PAPER.replace(b=3.13164975, V0=15384.3122, R=20.0, mu_sf=1.5, mu_sr=1.5)
    F_v = 17.3549875
    fast = grasp_hold_fast.fast_hold(design, 200.0, 3.0, "F_v", F_v)
    slow = grasp_hold.slow_hold(design, 200.0, 3.0, "F_v", F_v)
    assert fast is not None and fast.link == slow.link == 3
    assert fast.P_cavity == pytest.approx(0.9405, abs=1e-3)
    assert min(abs(slow.P_cavity - 0.9405), abs(slow.P_cavity - 1.0438)) < 1e-3
    assert grasp_fem.grasp_state(design, 200.0, 1.0438, 3.0).F_v == pytest.approx(F_v, abs=0.02)  # the second root
    theta_c, _ = grasp_hold.contact.contact_angle(200.0, finger_hinges.fem_finger(design))
    P_c = float(grasp_hold.hand.finger_pressure(theta_c, finger_hinges.fem_finger(design)))
    below = [grasp_fem.grasp_state(design, 200.0, P, 3.0).F_v for P in np.arange(P_c + 1e-6, fast.P_cavity, 0.005)]
    assert max(below) < F_v
