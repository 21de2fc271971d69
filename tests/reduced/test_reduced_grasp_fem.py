"""softhand.reduced.calibrated.grasp_fem: the energy's gradient by differences, the lever law on one link in
closed form, virtual work of the contact force by differences of positions, the angle mode,
and agreement with stored grasp FEM states (tests/data/grasp_fem_states.json)."""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from softhand.reduced.equations import contact, grasp, hand, kinematics
from softhand.reduced.calibrated import finger_hinges, grasp_fem
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.cli.main import main

DESIGN = finger_hinges.fem_finger(HandDesign())
STATES = json.loads((Path(__file__).resolve().parents[1] / "data" / "grasp_fem_states.json").read_text())


def test_hinge_moments_are_the_gradient_of_the_hinge_energy():
    q, h = np.radians([1.0, 3.0, 5.0, -2.0, 8.0]), 1e-6
    fd = [(finger_hinges.hinge_energy(q + h * e, 0.7, DESIGN) - finger_hinges.hinge_energy(q - h * e, 0.7, DESIGN))
          / (2 * h) for e in np.eye(DESIGN.n_s)]
    np.testing.assert_allclose(finger_hinges.hinge_moments(q, 0.7, DESIGN), fd, rtol=1e-6, atol=1e-5)


def test_without_contact_every_hinge_bends_as_the_free_finger():
    s = grasp_fem.grasp_state(DESIGN, 180.0, 0.8, depth_mm=400.0)  # far below the finger
    free = float(hand.bend_angle(0.8, DESIGN, reservoir=False))
    assert s.link == -1 and s.F_v == 0.0
    assert s.theta == pytest.approx(free, rel=1e-12)
    np.testing.assert_allclose(finger_hinges.hinge_moments(s.q, 0.8, DESIGN), 0.0, atol=1e-6)


def test_a_large_object_touched_near_the_tip_stops_the_finger_at_every_pressure():
    """A 260 mm object touches pad 5 at a 1.3 deg bend; from 2.6 MPa on the free finger would
    have bent past it (89 deg and more) and clears it, which it cannot do: the pad keeps
    pressing, F_v growing with P (it was reported as no contact, F_v = 0)."""
    D, mass = 260.0, 1.0
    theta_c, _ = contact.contact_angle(D, DESIGN)
    P = np.linspace(float(hand.finger_pressure(theta_c, DESIGN)) + 0.05,
                    float(hand.finger_pressure(math.radians(170.0), DESIGN)), 12)
    free = [grasp_fem.grasp_state(DESIGN, D, p, 0.0, depth_mm=contact.object_depth(D, DESIGN)) for p in P]
    swept = [float(np.min(contact.pad_gaps(np.full(DESIGN.n_s, hand.bend_angle(p, DESIGN, reservoir=False)
                                                    / DESIGN.n_s), (0.0, s.depth), 0.5 * D, DESIGN))) > 0
             for p, s in zip(P, free)]
    assert swept[-1] and not swept[0]  # the case: the free finger clears the object at the top
    states = [grasp_fem.grasp_state(DESIGN, D, p, mass) for p in P]
    assert all(s.link == 5 for s in states)
    assert np.all(np.diff([s.F_v for s in states]) > 0) and states[0].F_v > 0
    assert all(s.theta < math.radians(20.0) for s in states)  # held far below the free bend


def test_one_link_contact_is_the_lever_law():
    """Pad 1 touches (160 mm object at depth 70 mm): only hinge 1 is held; the pad is tangent to
    the circle, closed form for its angle, and N s = -M_1 with s the distance from hinge 1."""
    D, depth, P = 160.0, 70.0, 1.0
    s = grasp_fem.grasp_state(DESIGN, D, P, depth_mm=depth)
    assert s.link == 1
    p1 = kinematics.joint_positions(np.zeros(DESIGN.n_s), DESIGN)[1]   # hinge 1 does not move
    v, R = np.array([0.0, depth]) - p1, 0.5 * D
    # inward distance of the centre from the pad's line = R: -(v_x cos a + v_y sin a) = R
    phi = math.atan2(v[1], v[0])
    alphas = phi + np.array([1.0, -1.0]) * math.acos(-R / np.hypot(*v))
    alpha = alphas[np.argmin(np.abs(alphas + DESIGN.theta0))]
    assert s.q[0] == pytest.approx(alpha + DESIGN.theta0, abs=1e-9)
    n_out = np.array([math.cos(alpha), math.sin(alpha)])
    x = np.array([0.0, depth]) + R * n_out
    lever = (x - p1) @ [-math.sin(alpha), math.cos(alpha)]
    np.testing.assert_allclose(s.point, x, atol=1e-7)
    M1 = finger_hinges.hinge_moments(s.q, P, DESIGN)[0]
    assert s.N == pytest.approx(-M1 / lever, rel=1e-8)
    tip = s.q.sum() - DESIGN.theta0
    assert s.F_v == pytest.approx(s.N * math.cos(tip - alpha), rel=1e-8)


@pytest.mark.parametrize("diameter, P, mass", [(180.0, 0.8, 2.0), (210.0, 1.0, 0.0), (240.0, 1.25, 6.0)])
def test_the_contact_force_does_the_energys_virtual_work(diameter, P, mass):
    """dE = F . dx for every virtual hinge motion, x the pad's material point at the contact,
    both sides by central differences (kinematics only, not the contact code)."""
    s = grasp_fem.grasp_state(DESIGN, diameter, P, mass)
    assert s.link >= 1
    joints = kinematics.joint_positions(s.q, DESIGN)
    along = float(np.linalg.norm(s.point - joints[s.link]))

    def point(q):
        a = kinematics.link_angles(q, DESIGN)[s.link]
        return kinematics.joint_positions(q, DESIGN)[s.link] + along * np.array([-math.sin(a), math.cos(a)])

    h = 1e-6
    for dq in np.random.default_rng(5).normal(size=(4, DESIGN.n_s)):
        dE = (finger_hinges.hinge_energy(s.q + h * dq, P, DESIGN) - finger_hinges.hinge_energy(s.q - h * dq, P, DESIGN)) / (2 * h)
        dW = s.F @ (point(s.q + h * dq) - point(s.q - h * dq)) / (2 * h)
        assert dE == pytest.approx(dW, rel=1e-5, abs=1e-3)


#: a design an optimiser proposed whose 150 mm, 1 kg ball passes from pad 3 to pad 4 between
#: cavity pressures of about 1.6775 and 1.6800 MPa through the crease between them
CREASE = finger_hinges.fem_finger(HandDesign(a=6.0, d=13.59, l0=162.49,
                                         hinge_s=tuple(np.array(HandDesign().hinge_s) * 162.49 / 180.0)))


def test_an_object_in_the_crease_of_two_pads_does_the_energys_virtual_work():
    """Where neither pad alone settles, the ball sits in the crease of pads 3 and 4: both gaps
    closed, both N positive, and dE = F_3 . dx_3 + F_4 . dx_4 for every virtual hinge motion,
    each pad's force rebuilt from its point's geometry (normal towards the centre, the weight
    shared in proportion to N along the link), by central differences."""
    P, mass, D = 1.6785, 1.0, 150.0
    s = grasp_fem.grasp_state(CREASE, D, P, mass)
    assert s.link == 3 and s.crease is not None and s.N > 0.0 and s.crease[0] > 0.0
    centre = np.array([0.0, s.depth])
    gaps = contact.pad_gaps(s.q, centre, 0.5 * D, CREASE)
    np.testing.assert_allclose(gaps[3:5], 0.0, atol=1e-7)
    assert np.min(np.delete(gaps, [3, 4])) > 0.0
    weight = mass * CREASE.g / CREASE.n
    pads = [(3, s.N, s.point), (4, s.crease[0], s.crease[1])]
    joints, angles = kinematics.joint_positions(s.q, CREASE), kinematics.link_angles(s.q, CREASE)
    forces, alongs = [], []
    for k, N, x in pads:
        nu = (centre - x) / np.linalg.norm(centre - x)
        t = np.array([-math.sin(angles[k]), math.cos(angles[k])])
        forces.append(-N * nu + weight * N / (s.N + s.crease[0]) * t)
        alongs.append(float(np.linalg.norm(x - joints[k])))
    np.testing.assert_allclose(forces[0] + forces[1], s.F, rtol=1e-9)
    at = grasp_fem.grasp_state_at_angle(CREASE, D, P, s.theta, mass)  # the same state by its bend
    assert at.crease is not None and at.depth == pytest.approx(s.depth, abs=1e-6)

    def point(q, k, along):
        a = kinematics.link_angles(q, CREASE)[k]
        return kinematics.joint_positions(q, CREASE)[k] + along * np.array([-math.sin(a), math.cos(a)])

    h = 1e-6
    for dq in np.random.default_rng(7).normal(size=(4, CREASE.n_s)):
        dE = (finger_hinges.hinge_energy(s.q + h * dq, P, CREASE) - finger_hinges.hinge_energy(s.q - h * dq, P, CREASE)) / (2 * h)
        dW = sum(F @ (point(s.q + h * dq, k, a) - point(s.q - h * dq, k, a)) / (2 * h)
                 for F, (k, _, _), a in zip(forces, pads, alongs))
        assert dE == pytest.approx(dW, rel=1e-5, abs=1e-3)


def test_the_crease_state_continues_into_the_distal_pads():
    """As the pressure rises, pad 3's N in the crease falls to zero where pad 4's own state
    begins: the bend and F_v meet there (the one-pad states on either side jump by 2 deg)."""
    P1, P2 = 1.6780, 1.6790
    a, b = (grasp_fem.grasp_state(CREASE, 150.0, P, 1.0) for P in (P1, P2))
    assert a.crease is not None and b.crease is not None and b.N < a.N
    P0 = P1 + (P2 - P1) * a.N / (a.N - b.N)  # where pad 3's N reaches zero (linear to ~1e-4)
    below, above = (grasp_fem.grasp_state(CREASE, 150.0, P, 1.0) for P in (P0 - 2e-6, P0 + 2e-6))
    assert below.crease is not None and below.N < 0.01 and above.link == 4 and above.crease is None
    assert above.theta == pytest.approx(below.theta, abs=1e-5)
    assert above.F_v == pytest.approx(below.F_v, abs=2e-3)
    assert above.N == pytest.approx(below.crease[0], abs=2e-2)


def test_tip_contact_is_eq_25s_virtual_work_balance():
    """The tip corner touching (150 mm object at depth 180 mm): eq. (25)'s balance, the tip force
    through the tip Jacobian (20) of eq. (25) at theta_hat = w theta, holds along the state's
    own w = q / theta, and with the tip Jacobian at the state along any w."""
    P, mass = 1.4, 2.0
    s = grasp_fem.grasp_state(DESIGN, 150.0, P, mass, depth_mm=180.0)
    assert s.link == DESIGN.n_s
    np.testing.assert_allclose(s.point, kinematics.tip_position(s.q, DESIGN), atol=1e-9)
    M = finger_hinges.hinge_moments(s.q, P, DESIGN)
    w = s.q / s.theta
    J_xw, J_yw = grasp.projected_jacobian(s.theta, w, DESIGN)
    assert w @ M == pytest.approx(s.F[0] * J_xw + s.F[1] * J_yw, rel=1e-8)
    J_x, J_y = kinematics.jacobian(s.q, DESIGN)
    for v in np.random.default_rng(2).normal(size=(3, DESIGN.n_s)):
        assert v @ M == pytest.approx(s.F[0] * (J_x @ v) + s.F[1] * (J_y @ v), rel=1e-8, abs=1e-6)


def test_angle_mode_inverts_the_placement():
    s = grasp_fem.grasp_state(DESIGN, 180.0, 0.8, 2.0, depth_mm=110.0)
    t = grasp_fem.grasp_state_at_angle(DESIGN, 180.0, 0.8, s.theta, 2.0)
    assert t.depth == pytest.approx(110.0, abs=1e-6)
    assert t.F_v == pytest.approx(s.F_v, rel=1e-6)
    assert grasp_fem.vertical_force(DESIGN, 180.0, 0.8, s.theta, 2.0) == pytest.approx(s.F_v, rel=1e-6)
    free = float(hand.bend_angle(0.8, DESIGN, reservoir=False))
    assert grasp_fem.vertical_force(DESIGN, 180.0, 0.8, free + 0.01, 2.0) == 0.0  # not pressing


def test_an_angle_the_object_cannot_hold_is_refused():
    with pytest.raises(InputError, match="theta_deg"):
        grasp_fem.grasp_state_at_angle(DESIGN, 240.0, 1.25, math.radians(0.5), 6.0)


@pytest.mark.parametrize("state", STATES["states"], ids=lambda s: s["label"])
def test_agrees_with_the_grasp_fem(state):
    """Same object, placement, cavity pressure and mass as a stored grasp FEM state (the command
    that made it is stored with it): F_v within 10 % or 0.05 kgf, the larger."""
    F_v = grasp_fem.vertical_force(DESIGN, state["diameter_mm"], state["P_cavity_MPa"], mass_kg=state["mass_kg"],
                                   depth_mm=state["depth_mm"])
    assert abs(F_v - state["F_v_fem_N"]) <= max(0.1 * state["F_v_fem_N"], 0.05 * grasp.KGF)


def test_cli_model_fem_without_a_contact_is_one_error_line(capsys):
    """Below the free finger's pressure at that angle the finger does not reach the object: no
    placement lets it press there, said in one line naming the bend it reaches free (not a
    table of zeros with the object far below the palm)."""
    argv = ["grasp", "--pressure-mpa", "0.8", "--theta-deg", "40", "--mass-kg", "1", "--diameter-mm", "180",
            "--model", "fem"]
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "--theta-deg" in err and "bends only to" in err


def test_cli_model_fem_and_its_bad_inputs(capsys):
    argv = ["grasp", "--pressure-mpa", "0.7", "--theta-deg", "15", "--mass-kg", "2"]
    assert main([*argv, "--diameter-mm", "180", "--model", "fem", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["model"] == "fem" and out["contact_link"] == 2
    P_cavity = 0.7 + float(hand.pressure(math.radians(15), DESIGN, reservoir=False)
                           - hand.pressure(math.radians(15), DESIGN))
    assert out["P_cavity_MPa"] == pytest.approx(P_cavity, rel=1e-12)
    assert out["F_v_N"] == pytest.approx(grasp_fem.vertical_force(
        DESIGN, 180.0, P_cavity, math.radians(15), 2.0), rel=1e-9)
    assert main([*argv, "--weights", "paper180", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["model"] == "paper"
    for extra, field in ((["--diameter-mm", "180", "--model", "fe"], "--model"),
                         (["--weights", "paper180", "--model", "fem"], "--model"),
                         (["--diameter-mm", "100", "--model", "fem"], "--theta-deg")):
        assert main([*argv, *extra]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and field in err


@pytest.mark.parametrize("data", STATES["second_pad"], ids=lambda d: d["label"])
def test_the_one_pad_grasp_ends_where_the_grasp_fem_touches_with_a_second_pad(data):
    """The paper's hand on 180 mm at 1 kg: the grasp FEM holds the object with pad 3 alone up to
    2.8 MPa and touches it with the tip pad 5 too from 2.9 MPa on (stored states); the
    low-pressure task's optimum at a 4 MPa pump: pad 3 alone up to 3.55 MPa, the tip pad too
    from 3.6 MPa. The reduced model's end of the one-pad grasp (reduced.calibrated.grasp_hold_end.one_pad_end)
    lies between, on the FEM's holding pad, with the FEM's second pad the one touching, and its
    F_v within 10 % of the FEM's there."""
    from softhand.reduced.calibrated import grasp_hold_end
    from softhand.reduced.vocabulary.design_files import design_from_dict

    design = finger_hinges.fem_finger(design_from_dict(data["design"], DESIGN, source="stored")) \
        if data["design"] else DESIGN
    rows = sorted(data["states"], key=lambda r: r["P_cavity_MPa"])
    one = [r["P_cavity_MPa"] for r in rows if np.count_nonzero(r["contact_force_N"]) == 1]
    two = [r["P_cavity_MPa"] for r in rows if np.count_nonzero(r["contact_force_N"]) == 2]
    assert one and two and max(one) < min(two)
    holding = {int(np.argmax(r["contact_force_N"])) for r in rows}
    second = {i for r in rows for i in np.flatnonzero(r["contact_force_N"]) if i not in holding}
    end = grasp_hold_end.one_pad_end(design, data["diameter_mm"], data["mass_kg"])
    assert max(one) < end.P_cavity < min(two) and {end.link} == holding
    s = grasp_fem.grasp_state(design, data["diameter_mm"], end.P_cavity, data["mass_kg"])
    gaps = contact.pad_gaps(s.q, (0.0, s.depth), 0.5 * data["diameter_mm"], design)
    gaps[end.link] = np.inf
    assert {int(np.argmin(np.abs(gaps)))} == second and np.min(np.abs(gaps)) < 1e-8
    F_fem = np.interp(end.P_cavity, [r["P_cavity_MPa"] for r in rows], [r["F_v_fem_N"] for r in rows])
    assert end.F_v == pytest.approx(F_fem, rel=0.1)
