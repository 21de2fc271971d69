"""The object sliding along the pull in the fast hold: the walk against known curves lam(y), and
the fast model's slide against a dense scan of its own limit along the pull."""
import math
from dataclasses import replace

import numpy as np
import pytest

from softhand.reduced.holding import hold, hold_fast, hold_lp, hold_slide, objects
from softhand.reduced.holding.hand_layout import place_object
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.design_files import design_from_dict


def _walk(curve, *, weight=5.0, slip_out=100.0, enough=math.inf):
    calls = []

    def at(y):
        calls.append(y)
        return float(curve(y)), y

    return hold_slide.follow(at, at(0.0), weight_N=weight, slip_out_mm=slip_out, enough_N=enough), calls


def test_a_falling_limit_is_the_limit_at_the_grasp_in_two_evaluations():
    s, calls = _walk(lambda y: 5.0 - y)
    assert (s.y_limit, s.y_rest, s.evaluations) == (0.0, 0.0, 2)


def test_a_flat_limit_does_not_walk():
    s, _ = _walk(lambda y: 2.0)
    assert s.y_limit == 0.0 and s.evaluations == 2


def test_the_peak_and_the_resting_place_of_a_smooth_wedge():
    """lam = 3 - (y - 20)^2 / 40: slips under its weight (lam(0) = -7), rests where lam = 0
    (y = 20 - sqrt(120)), lets go at the peak."""
    curve = lambda y: 3.0 - (y - 20.0) ** 2 / 40.0  # noqa: E731
    s, _ = _walk(curve)
    assert curve(s.limit) == pytest.approx(3.0, abs=0.01)
    assert abs(s.y_limit - 20.0) <= 1.0
    assert s.y_rest == pytest.approx(20.0 - math.sqrt(120.0), abs=hold_slide.Y_TOL)
    assert curve(s.rest) >= 0.0


def test_the_first_of_two_peaks():
    """Peaks of 2 at y = 10 and of 5 at y = 40 with a valley of -1 between: the hand lets go at
    the first (past it the object finds no equilibrium near)."""
    curve = lambda y: np.interp(y, [0, 10, 25, 40, 60], [0.5, 2.0, -1.0, 5.0, 0.0])  # noqa: E731
    s, _ = _walk(curve)
    assert curve(s.limit) == pytest.approx(2.0, abs=0.1)


def test_a_crease_shorter_than_the_wedge_length_is_passed():
    """A rising pull with a crease at 14.75-15.25 mm (a jump of 2 N, then 0.1 N below the trend
    for 0.5 mm), peaking at 40 mm: the walk, wherever its steps land, passes the crease."""
    def curve(y):
        trend = y / 8.0 if y <= 40.0 else 5.0 - (y - 40.0) / 4.0
        if 14.75 <= y <= 15.0:
            return trend + 2.0
        if 15.0 < y <= 15.5:
            return trend - 0.1
        return trend
    for shift in np.linspace(0.0, 1.0, 9):
        s, _ = _walk(lambda y, k=shift: curve(y + k) - curve(k))
        assert s.y_limit + shift == pytest.approx(40.0, abs=1.0)


def test_an_object_that_slides_a_quarter_of_its_size_from_its_rest_has_slipped_out():
    """lam = y - 3 rising without end, slip-out length 20 mm: it rests at 3 mm and slips out at
    23 mm; the holding limit is the pull kept over the last millimetre before, 19 N at 22 mm."""
    s, _ = _walk(lambda y: y - 3.0, slip_out=20.0)
    assert s.slipped_out and s.y_rest == pytest.approx(3.0, abs=hold_slide.Y_TOL)
    assert s.y_limit == pytest.approx(s.y_rest + 20.0 - hold_slide.WEDGE_MM)


@pytest.mark.parametrize("at", [0.0, 0.2, 0.5, 1.0])
def test_a_crease_at_the_slip_out_point_does_not_send_the_limit_back_to_the_first_slip(at):
    """A ball wedging as it slides (lam = 5 + y / 4 from the grasp, where it rests) meets a crease
    where it has slid its slip-out length, 37.5 mm, or just before: the pull falls to 4 N for
    0.3 mm and jumps past the trend after it. It slips out there; the limit is the pull borne over
    the slide before, ~14 N, not the first slip's 5 N (the crease is where the hand lets go, not
    a pull it bore: before, the last millimetre's least pull, the crease's, fell below the first
    slip and the limit went back to it)."""
    def curve(y):
        if 37.5 - at <= y <= 37.8 - at:
            return 4.0
        return 5.0 + y / 4.0 + (3.0 if y > 37.8 - at else 0.0)
    s, _ = _walk(curve, slip_out=37.5)
    assert s.slipped_out and s.y_rest == 0.0
    assert 12.0 <= curve(s.y_limit) <= 5.0 + 37.5 / 4.0  # the walk's payload is y


def test_enough_stops_the_walk_and_nothing_to_hold_stops_it_at_once():
    s, calls = _walk(lambda y: y, enough=3.0)
    assert 3.0 <= s.limit <= 6.0 and max(calls) <= 8.0
    s, calls = _walk(lambda y: -math.inf)
    assert s.y_rest is None and max(calls) <= 1.0


def _lam(d, placed, obj, P, y):
    moved = replace(placed, centre=placed.centre + np.array([0.0, y, 0.0]))
    cs = hold.contact_set(hold_fast.close_hand(P, moved, d), d)
    lim = hold_lp.holding_limit(cs, moved.centre, obj.mass_kg * d.g, (0.0, 1.0, 0.0), obj.friction, size_mm=150.0)
    return lim.pull_N if lim is not None else -math.inf


def test_a_ball_held_below_its_widest_section_wedges_as_it_slides():
    """The paper's hand (calibrated finger) on a 150 mm ball at 1.7 MPa: the pads touch below the
    equator, so sliding down opens the fingers and the pull they bear grows. Where the pads first
    slip it does not hold its weight; it slides to where the pull borne is the weight (bisected on
    a dense scan, 0.25 mm), and from there it is pulled a quarter of its size, 37.5 mm, and slips
    out: the holding limit is the pull borne there (the dense scan's, creases -- pulls not kept
    over the wedge length -- left out), within 1 %."""
    d = hold_fast.finger_design(HandDesign())
    obj = objects.GraspObject(diameter_mm=150.0, mass_kg=0.5, friction=0.8)
    r = hold.solve_hold(d, obj, P_cavity_MPa=1.7)
    assert r.held and r.extra["first_slip_pull_N"] < 0.0 < r.holding_limit_N
    placed = place_object(obj, d)
    ys = np.arange(0.0, 60.0, 0.25)
    lam = np.array([_lam(d, placed, obj, 1.7, y) for y in ys])
    kept = np.minimum(lam, np.interp(ys + hold_slide.WEDGE_MM, ys, lam, right=-np.inf))
    rest = ys[np.argmax(kept >= 0.0)]
    assert r.displacement_mm[1] == pytest.approx(rest, abs=0.25 + hold_slide.Y_TOL)
    assert 36.5 - hold_slide.Y_TOL <= r.extra["slide_mm"] - r.displacement_mm[1] <= 37.5 + hold_slide.Y_TOL
    assert r.holding_limit_N == pytest.approx(np.interp(r.displacement_mm[1] + 36.5, ys, kept), rel=0.01)
    assert any("slipped out" in n for n in r.notes)


@pytest.mark.parametrize("P", [0.9, 1.2])
def test_a_ball_held_above_its_widest_section_does_not_slide(P):
    """The paper's 180 mm sphere: pads above the equator, the pull borne falls as it starts to
    slide, so the limit is where the pads first slip and the object rests where it was grasped.
    At 1.2 MPa the pads touch next to a hinge: 0.5 mm down the ball passes onto the next pad and
    holds more there, but the pull falls first (the FEM hold stops there too: 11.34 N, its next
    pull finds no equilibrium, the ball not having moved)."""
    d = hold_fast.finger_design(HandDesign())
    r = hold.solve_hold(d, objects.GraspObject(diameter_mm=180.0, mass_kg=2.0 if P < 1 else 0.5,
                                               friction=0.8 if P < 1 else 0.5), P_cavity_MPa=P)
    assert r.held and r.holding_limit_N == r.extra["first_slip_pull_N"]
    assert r.extra["slide_mm"] == 0.0 and r.displacement_mm == (0.0, 0.0, 0.0)
    assert r.extra["slide_evaluations"] == 2


def test_a_pull_towards_the_palm_is_not_followed_and_any_pull_starts_where_the_weight_rests():
    """Pushed up into the hand the object would meet the palm (not a contact) and push the fingers
    open past straight: its limit is where the pads first slip. Under any pull the object is let go
    first, as in the FEM hold: one whose weight the pads do not bear where it was grasped settles
    under it (a 150 mm ball at 1.7 MPa, and a 180 mm cube turned 15 deg, which turns as it settles),
    to where it rests under a pull down, and is pulled from there."""
    d = hold_fast.finger_design(HandDesign())
    up = hold.solve_hold(d, objects.GraspObject(diameter_mm=180.0, mass_kg=0.5, friction=0.8), P_cavity_MPa=0.9,
                         pull_direction=(0.0, -1.0, 0.0))
    assert up.held and up.holding_limit_N == up.extra["first_slip_pull_N"] and up.extra["slide_mm"] == 0.0
    for obj, P in ((objects.GraspObject(diameter_mm=150.0, mass_kg=0.5, friction=0.8), 1.7),
                   (objects.GraspObject(shape="box", size_mm=(180.0,) * 3, rotation_deg=(0.0, 15.0, 0.0),
                                        mass_kg=0.5, friction=0.5), 1.2)):
        down = hold.solve_hold(d, obj, P_cavity_MPa=P)
        assert down.held and down.displacement_mm[1] > 0.0
        for pull in ((1.0, 0.0, 0.0), (0.0, 0.0, -1.0), (1.0, 1.0, 0.0)):
            side = hold.solve_hold(d, obj, P_cavity_MPa=P, pull_direction=pull)
            assert side.held and side.holding_limit_N >= 0.0
            assert side.displacement_mm == down.displacement_mm and side.rotation_deg == down.rotation_deg
            assert side.steps[1].displacement_mm == down.steps[1].displacement_mm
    assert down.rotation_deg[1] < 0.0  # the cube turned back as it settled


def test_a_finger_pressing_with_two_pads_shares_them_by_its_hinges_stiffness():
    """A 160 mm cube under fingers of a 16 mm plate (a 5, b 4, l0 160 mm): each finger presses a
    top edge with link 2 and the face with its tip. At the holding limit the finger's hinges, bent
    by the reported forces from the grasp (K_j dq_j = sum_c (N_c n_c - F_c) . dx_c/dq_j - M_j), keep
    both pads on the cube (gap rates 0, to HiGHS's tolerance); the pads' share is then their
    stiffness's, not the closing one (the friction on the tip loads every hinge)."""
    d = hold_fast.finger_design(design_from_dict({"a_mm": 5.0, "b_mm": 4.0, "d_mm": 16.0, "l0_mm": 160.0,
                                                  "tie_width_mm": 8.0}))
    obj = objects.GraspObject(shape="box", size_mm=(160.0, 160.0, 160.0), mass_kg=0.5, friction=0.5)
    closed = hold_fast.close_hand(1.2, place_object(obj, d), d)
    N0 = closed.fingers[0].N
    assert np.count_nonzero(N0) == 2
    r = hold.solve_hold(d, obj, P_cavity_MPa=1.2, closed=closed)
    assert r.extra["slide_mm"] == 0.0
    cs = hold.contact_set(closed, d)
    n_s = d.n_s
    for f in range(4):
        mine = {c["link"]: c for c in r.extra["limit_contacts"] if c["finger"] == f}
        assert sorted(mine) == sorted(cs.link[cs.finger == f].tolist())
        rows = slice(f * n_s, (f + 1) * n_s)
        Q = np.zeros(n_s)
        for c in np.flatnonzero(cs.finger == f):
            hit = mine[int(cs.link[c])]
            F = hit["friction_N"] * np.asarray(hit["friction_dir"]) if hit["friction_dir"] else np.zeros(3)
            Q += (hit["normal_N"] * cs.normal[c] - F) @ cs.J[rows, c].T
        dq = (Q - cs.moment[rows]) / cs.stiffness[rows]
        for c in np.flatnonzero(cs.finger == f):
            rate = float(np.einsum("ji,i->j", cs.J[rows, c], cs.normal[c]) @ dq)
            assert abs(rate) < 1e-6 * float(np.max(np.abs(cs.J[rows, c])))
        share = mine[2]["normal_N"] / mine[5]["normal_N"]
        assert abs(share / (N0[2] / N0[5]) - 1.0) > 0.01
