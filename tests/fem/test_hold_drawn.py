"""The FEM hold's pull drawn by displacement (``pull_control = "displacement"``, coarse CI mesh): the
spring's pull is the object's equilibrium load, two pads pinching a box hold the friction's 2 mu N,
and a sphere's drawn pull peaks where the stepped force finds no more equilibrium."""
import math
from dataclasses import replace

import pytest

from softhand.fem.hand.finger import FingerModel, FingerOptions
from softhand.fem.hand.hold import run_hold
from softhand.fem.hand.hold_body import Body, body_of
from softhand.fem.hand.hold_geometry import FingerFrame
from softhand.fem.hand.hold_model import HoldModel
from softhand.fem.hand.hold_options import HoldOptions
from softhand.reduced.holding.objects import parse_object
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError

DESIGN = HandDesign()
CI = FingerOptions(mesher="gmsh", mesh_size=10.0)  # the coarsest finger mesh (as test_hold_fem.py)
DRAWN = dict(pull_control="displacement")


@pytest.fixture(scope="module")
def finger():
    return FingerModel(DESIGN, CI)


def _load_on_pads(record) -> float:
    """The object's push on the pads along the pull (down, +y), summed over every finger's pads (the
    rows' forces are the object's on the pad)."""
    return sum(c["normal_force_N"][1] + c["friction_force_N"][1] for c in record.contacts)


@pytest.mark.slow
def test_two_pads_pinching_a_box_drawn_hold_two_mu_N(finger):
    """Two facing fingertips on a box's vertical faces: drawn down, the pull rises while the pads
    stick and stays at 2 mu N less the weight once both slip -- the first maximum, resolved to
    pull_resolution (closed form, as the stepped force's test in test_hold_fem.py)."""
    mu = 0.5
    box = Body("box", (0.0, 130.0, 0.0), (150.0, 140.0, 40.0), mass_kg=0.005, friction=mu)
    model = HoldModel(DESIGN, box, layout=[FingerFrame(0.0), FingerFrame(math.pi)], finger_model=finger,
                      options=HoldOptions(close_steps=3, pull_step=0.02, pull_floor=0.002, **DRAWN))
    path = run_hold(model, 1.2)
    assert path.held and path.limit_reached
    pulls = [s for s in path.steps if s.stage == "pull"]
    peak = max(pulls, key=lambda s: s.pull_N)
    assert peak.pull_N == path.holding_limit_N
    N = sum(c["normal_N"] for c in peak.contacts if c["normal_N"] > 0)
    load = model.weight + path.holding_limit_N
    tol = model.options.contact.rtol * model.scale  # the object's equilibrium, to Newton's tolerance
    assert load <= mu * N + tol
    assert load >= mu * N - max(model.options.pull_resolution * path.holding_limit_N, 0.002) - 1e-9
    assert all(c["state"] == "slip" for c in pulls[-1].contacts if c["normal_N"] > 0)  # past it: sliding
    for s in pulls:  # the spring's pull is what the pads bear beyond the weight: the object's equilibrium
        assert _load_on_pads(s) == pytest.approx(model.weight + s.pull_N, abs=tol)


@pytest.mark.slow
def test_a_drawn_sphere_peaks_where_the_stepped_force_stops(finger):
    """The 180 mm sphere of 2 kg (mu 0.8, 0.9 MPa): its pads slip all at once and the pull falls as
    it slides, a limit that does not depend on the path to it. Drawn, the pull's first maximum is
    the stepped force's limit (the largest pull with an equilibrium; two independent paths) to
    within both resolutions; past it the sphere slides and the pull falls (the path kept ends there:
    the steps around the maximum were walked again finer)."""
    obj = replace(parse_object("sphere:180"), mass_kg=2.0, friction=0.8)
    body = body_of(obj, DESIGN)
    stepped = run_hold(HoldModel(DESIGN, body, finger_model=finger, options=HoldOptions()), 0.9)
    model = HoldModel(DESIGN, body, finger_model=finger, options=HoldOptions(**DRAWN))
    drawn = run_hold(model, 0.9)
    assert stepped.held and drawn.held and drawn.limit_reached
    assert drawn.holding_limit_N == pytest.approx(stepped.holding_limit_N, rel=2 * model.options.pull_resolution)
    pulls = [s for s in drawn.steps if s.stage == "pull"]
    peak = max(pulls, key=lambda s: s.pull_N)
    assert pulls[-1].pull_N < peak.pull_N == drawn.holding_limit_N and pulls[-1].pose[1] > peak.pose[1]
    for s in pulls:
        assert s.cone <= 1.0 + 1e-12 and s.q_mismatch <= model.options.q_tol
        assert _load_on_pads(s) == pytest.approx(model.weight + s.pull_N, abs=model.options.contact.rtol * model.scale)


@pytest.mark.parametrize("field, value", [("pull_control", "speed"), ("drive_stiffness", 0.0),
                                          ("drive_step", -1.0)])
def test_drawn_options_are_checked(field, value):
    with pytest.raises(InputError, match=field):
        HoldOptions(**{field: value})
