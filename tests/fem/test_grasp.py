"""The grasp FEM (coarse CI mesh): placement, contact convergence, virtual work, w; the weights CLI."""
import json
import math

import numpy as np
import pytest

from softhand.fem.contact import gaps
from softhand.fem.hand.finger import FingerModel, FingerOptions
from softhand.fem.hand.grasp import GraspModel, GraspOptions, default_depth, pads_of, weight_vector
from softhand.fem.linsolve import make_solver
from softhand.fem.newton import NewtonOptions, newton
from softhand.reduced.vocabulary.design import HandDesign
from softhand.studies.cli.main import main
from softhand.studies.weights import interpolate
from conftest import COARSEST_FINGER

DESIGN = HandDesign()
P, DP = 0.45, 0.05  # MPa; the fingers touch the 180 mm object from 0.3 MPa on (FEM, CI mesh)


@pytest.fixture(scope="module")
def grasp180():
    model = GraspModel(FingerModel(DESIGN, FingerOptions(**COARSEST_FINGER)), 180.0)  # docs/grasp.md: w on it vs finer
    a = model.solve(P)
    return model, a, model.solve(P + DP, start=a), model.solve(P + DP / 2, start=a)


def test_default_depth_against_the_open_finger_geometry():
    from softhand.fem.constraints import PlanarChain

    opts = GraspOptions()
    pads = pads_of(PlanarChain(np.c_[DESIGN.hinge_s, np.full(DESIGN.n_s, DESIGN.d)]), DESIGN, opts)
    c, s = math.cos(DESIGN.theta0), math.sin(DESIGN.theta0)
    # 180 mm: lowered until the open pad line (through the base point (base_offset, 0),
    # along (sin theta0, cos theta0)) is `clearance` from the object's surface
    expect = (90.0 + opts.clearance - DESIGN.base_offset * c) / s
    assert default_depth(pads, DESIGN, 180.0, opts) == pytest.approx(expect, abs=1e-6)
    # 120 mm passes between the open fingers: its top is palm_gap below the palm
    assert default_depth(pads, DESIGN, 120.0, opts) == pytest.approx(60.0 + opts.palm_gap)


def test_contact_converged_and_only_where_touching(grasp180):
    model, a, b, _ = grasp180
    for s in (a, b):
        assert s.N.sum() > 1.0                                   # the finger presses
        assert np.max(-s.gap[s.N > 0]) <= model.options.gap_tol  # AL stop criterion
        assert np.all(s.gap[s.N == 0] > -model.options.gap_tol)  # no hidden penetration
    assert b.N.sum() > a.N.sum()                                 # more pressure, more force


def _whole_finger_energy(model, y, q, P):
    """min over the tube of 2 (W - P V) with the hinge angles held at q (the half model x 2)."""
    f = model.finger
    n_f = len(f.constraint.free)

    def fun(x):
        r, K = f.residual_tangent(np.concatenate((x, q)), P)
        return r[:n_f], K[:n_f, :n_f]

    d = DESIGN
    res = newton(fun, y[:n_f], NewtonOptions(rtol=1e-12, atol=1e-12), solver=make_solver(symmetric=True),
                 scale=d.mu_sf * d.a ** 2 * d.l0)
    y_q = np.concatenate((res.x, q))
    return 2.0 * (f.energy(y_q) - P * f.cavity.volume(f.constraint.expand(y_q)))  # rubber + windings


def test_contact_forces_and_pressure_satisfy_the_virtual_work_balance(grasp180):
    """Independent energy route: dE/dq of the finger's reduced potential E(q) = min_u 2 (W - P V),
    by central differences of energies only, equals the contact's generalised force."""
    model, a, _, _ = grasp180
    Q = np.einsum("k,kj->j", a.N, gaps(model.pads, model.circle, a.q).grad)  # physical, m = 0
    h = 2e-5  # rad; truncation h^2 E''' ~ 1e-6 N mm, rounding 1e-16 E / h ~ 1e-8 N mm
    dE = np.array([(_whole_finger_energy(model, a.y, a.q + h * e, P)
                    - _whole_finger_energy(model, a.y, a.q - h * e, P)) / (2 * h) for e in np.eye(5)])
    np.testing.assert_allclose(dE, Q, rtol=1e-4, atol=1e-4 * np.abs(Q).max())


def test_w_sums_to_one_and_is_stable_under_halving_dP(grasp180):
    _, a, b, c = grasp180
    w, w_half = weight_vector(a, b), weight_vector(a, c)
    assert w.sum() == pytest.approx(1.0, abs=1e-12)
    # a one-sided difference: w(dP) - w(0) = O(dP); halving dP moves w by about half that.
    # Band 0.02 per entry: measured 1.2e-3 on this mesh at 0.45 MPa (docs/grasp.md)
    np.testing.assert_allclose(w, w_half, atol=0.02)


def test_the_contact_does_no_virtual_work_along_w(grasp180):
    """Why eq. (25) cannot return the FEM's contact force (docs/grasp.md): along the FEM's w
    the touching pad rolls on the rigid object, so the contact's virtual work
    N dg/dq . w vanishes (to the gap tolerance / dtheta), while eq. (25) charges a tip force
    with the tip's virtual displacement J_x w (tens of mm/rad)."""
    model, a, b, _ = grasp180
    w = weight_vector(a, b)
    grad = gaps(model.pads, model.circle, a.q).grad[a.N > 0]
    dtheta = b.theta - a.theta
    bound = 2 * model.options.gap_tol / dtheta + 1e-3 * np.abs(grad).max()  # gaps + second order
    assert np.all(np.abs(grad @ w) < bound)
    assert np.abs(grad).max() > 10.0  # mm/rad: the same pad's lever is not small


# ---------------------------------------------------------------- study and CLI (no FEM)
def test_interpolated_w_sums_to_one_and_hits_the_table():
    D = [150.0, 180.0, 210.0]
    W = [[0.2, 0.2, 0.2, 0.2, 0.2], [-0.1, 0.1, 0.4, 0.3, 0.3], [-0.2, 0.0, 0.1, 0.3, 0.8]]
    assert interpolate(D, W, 180.0) == pytest.approx(W[1])
    assert interpolate(D, W, 195.0).sum() == pytest.approx(1.0)
    with pytest.raises(Exception, match="diameter_mm"):
        interpolate(D, W, 300.0)


def test_weights_cli_caches_by_input(tmp_path, monkeypatch, capsys):
    import softhand.studies.weights as sw

    calls = []

    def fake_compute(case, out=None, progress=None):
        calls.append(case)
        return {"diameter_mm": case.diameter_mm, "w": [0.2] * 5, "w_sum": 1.0, "theta_deg": 40.0,
                "F_v_fem_N": 3.0, "mesh_size_mm": case.mesh_size_mm, "ndofs": 10}

    monkeypatch.setenv("SOFTHAND_CACHE", str(tmp_path))
    monkeypatch.setattr(sw, "compute", fake_compute)
    argv = ["weights", "--diameter-mm", "200", "--json"]
    cached = []
    for args in (argv, argv, argv + ["--mass-kg", "2"]):
        assert main(args) == 0
        cached.append(json.loads(capsys.readouterr().out)["cached"])
    assert cached == [False, True, False] and len(calls) == 2  # a new input runs again
    assert len(list((tmp_path / "weights").glob("*.json"))) == 2


@pytest.mark.parametrize("argv, field", [
    (["weights", "--diameter-mm", "-180"], "--diameter-mm"),
    (["weights", "--diameter-mm", "180", "--mass-kg", "-1"], "--mass-kg"),
    (["weights", "--diameter-mm", "180", "--pressure-mpa", "0"], "--pressure-mpa"),
    (["weights", "--diameter-mm", "180", "--pressure-mpa", "5.5"], "--pressure-mpa"),
    (["weights", "--diameter-mm", "180", "--mesh-size-mm", "x"], "--mesh-size-mm"),
])
def test_weights_bad_input_is_one_line_exit_2(argv, field, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and field in err


def test_weights_takes_the_pump_pressures_design_tasks_allow():
    """Design tasks allow pumps up to 5 MPa; the grasp FEM is asked up to the same (it was cut
    at 3 MPa, so a design for a 4 MPa pump could not be checked at its limit)."""
    from softhand.studies.cli.verbs import weights

    assert weights._scalar("4.5", "--pressure-mpa") == 4.5  # 5.5: refused, above


def test_vtk_series_of_the_contact_states(grasp180, tmp_path):
    import meshio

    from softhand.studies.weights import write_vtk

    model, a, b, _ = grasp180
    write_vtk(tmp_path, model, (a, b))
    assert (tmp_path / "grasp.pvd").read_text().count("<DataSet") == 2
    mesh = meshio.read(tmp_path / "grasp" / "grasp_0001" / "tube.vtu")
    u = mesh.point_data["displacement_mm"]
    assert u.shape[1] == 3 and np.isfinite(u).all() and np.abs(u).max() > 1.0  # mm: the finger moved
    assert mesh.field_data["P_cavity_MPa"][0] == b.P


def test_scene_of_a_contact_state_holds_the_object_and_the_pad_forces(grasp180, tmp_path):
    """The object's sphere (radius D/2 around the hand axis at the model's depth), the pad
    forces (normal part along the line from the centre = N of the FEM state), the links
    turned by the state's hinge angles."""
    from softhand.studies.io.render import load_scene
    from softhand.studies.weights import write_vtk

    model, a, _, _ = grasp180
    write_vtk(tmp_path, model, (a,))
    scene = load_scene(tmp_path / "grasp.pvd")[0]
    assert {"object", "contact_forces"} <= set(scene.keys())
    centre = np.array([0.0, model.depth, 0.0])
    radius = np.linalg.norm(np.asarray(scene["object"].points) - centre, axis=1)
    np.testing.assert_allclose(radius, 0.5 * model.diameter, rtol=1e-12)
    forces = scene["contact_forces"]
    assert forces.n_points == DESIGN.n_s + 1
    away = np.asarray(forces.points) - centre
    normal = np.einsum("ki,ki->k", forces.point_data["force_N"], away / np.linalg.norm(away, axis=1)[:, None])
    np.testing.assert_allclose(normal, a.N, atol=1e-9 * a.N.max())
    touching = a.N > 0  # the touching pads lie on the sphere (gap below the contact tolerance)
    np.testing.assert_allclose(np.linalg.norm(away[touching], axis=1), 0.5 * model.diameter,
                               atol=model.options.gap_tol)
    edge = np.array([scene[f"link_{k}"].points[1] - scene[f"link_{k}"].points[0] for k in range(DESIGN.n_s + 1)])
    np.testing.assert_allclose(np.diff(np.unwrap(np.arctan2(edge[:, 1], edge[:, 0]))), a.q, atol=1e-12)


def test_grasp_cli_takes_w_from_the_fem_or_the_paper_by_name(tmp_path, monkeypatch, capsys):
    import softhand.studies.weights as sw

    w_fem = [-0.1, 0.1, 0.3, 0.3, 0.4]
    monkeypatch.setenv("SOFTHAND_CACHE", str(tmp_path))
    monkeypatch.setattr(sw, "compute", lambda case: {"w": w_fem, "diameter_mm": case.diameter_mm})
    base = ["grasp", "--pressure-mpa", "1", "--theta-deg", "40", "--mass-kg", "2", "--json"]
    assert main(base + ["--diameter-mm", "200"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["w"] == pytest.approx(w_fem) and out["w_source"].startswith("FEM: D = 200 mm")
    assert main(base + ["--weights", "paper240"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["w"] == pytest.approx([-0.2, 0.0, 0.1, 0.3, 0.8]) and out["w_source"].startswith("paper")
    # where the grasp FEM's own F_v says eq. (25) with its w is off, the F_v printed comes with why
    far = {"w": w_fem, "diameter_mm": 210.0, "P_cavity_MPa": 0.8, "theta_deg": 30.0, "F_v_fem_N": 4.0,
           "F_v_reduced_N": 93.4, "contact_force_N": [0.0, 0.0, 3.9, 0.0, 0.0, 0.0]}
    monkeypatch.setattr(sw, "compute", lambda case: far)
    assert main(base + ["--diameter-mm", "210"]) == 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("softhand grasp: warning: at the grasp FEM's own state")
    assert "touches link 2 of 5" in err and "23.4 x the FEM's" in err and "--model fem" in err


@pytest.mark.parametrize("forces, warned", [([0.0] * 6, True), ([0.0, 0.0, 0.0, 0.0, 0.0, 1.5], False)])
def test_w_of_a_finger_that_does_not_touch_the_object_is_said_to_be_no_grasps(forces, warned, tmp_path,
                                                                             monkeypatch, capsys):
    """The 60 mm object at 0.8 MPa: the grasp FEM's finger bends 20.5 deg and touches nothing (its
    w is the free bend's); the reduced model's finger reaches it only at 167 deg, 3.59 MPa (the
    paper's finger, eqs. (28) and the pad geometry): the warning says both."""
    import softhand.studies.weights as sw

    def fake_compute(case, out=None, progress=None):
        return {"diameter_mm": case.diameter_mm, "depth_mm": 40.0, "w": [0.2] * 5, "w_sum": 1.0,
                "theta_deg": 20.54, "F_v_fem_N": 0.0, "contact_force_N": forces,
                "mesh_size_mm": case.mesh_size_mm, "ndofs": 10}

    monkeypatch.setenv("SOFTHAND_CACHE", str(tmp_path))
    monkeypatch.setattr(sw, "compute", fake_compute)
    assert main(["weights", "--diameter-mm", "60", "--json"]) == 0
    err = capsys.readouterr().err
    said = "softhand: warning: the finger does not touch the 60 mm object at 0.8 MPa (theta 20.5 deg"
    assert (said in err) == warned
    if warned:
        assert "touches it at theta 167 deg (cavity pressure 3.59 MPa)" in err


@pytest.mark.parametrize("diameter", [180.0, 240.0])  # objects the open fingers reach at depth 0
def test_the_placement_check_needs_no_mesh_and_agrees_with_the_default_depth(diameter):
    """The open finger's pads from the design's link chain alone: the default depth (the object
    clear of the pads by the clearance) passes, and a depth a hair shallower than where the
    gap closes is refused."""
    from scipy.optimize import brentq

    from softhand.fem.constraints import PlanarChain
    from softhand.fem.hand.grasp import _open_gap, check_placement
    from softhand.reduced.vocabulary.errors import InputError

    d, options = HandDesign(), GraspOptions()
    pads = pads_of(PlanarChain(np.c_[d.hinge_s, np.full(d.n_s, d.d)]), d, options)
    depth = default_depth(pads, d, diameter, options)
    check_placement(d, diameter, depth)
    assert _open_gap(pads, d, diameter, 0.0) < 0.0 < _open_gap(pads, d, diameter, depth)
    touching = brentq(lambda y: _open_gap(pads, d, diameter, y), 0.0, depth, xtol=1e-12)
    check_placement(d, diameter, touching + 1e-6)
    with pytest.raises(InputError, match="overlaps the open finger"):
        check_placement(d, diameter, touching - 1e-6)
