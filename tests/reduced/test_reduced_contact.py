"""softhand.reduced.equations.contact: pad gaps and placement against the grasp FEM's own geometry (fem.contact,
another frame and code), gap gradients against finite differences, contact angle, rolling w."""

import numpy as np
import pytest

from softhand.fem.constraints import PlanarChain
from softhand.fem.contact import Circle, gaps
from softhand.fem.hand.grasp import GraspOptions, default_depth, pads_of, to_finger_frame
from softhand.reduced.equations import contact, kinematics
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError

DESIGN = HandDesign()


def _fem_pads(design):
    return pads_of(PlanarChain(np.c_[design.hinge_s, np.full(design.n_s, design.d)]), design, GraspOptions())


@pytest.mark.parametrize("diameter", [100.0, 180.0, 240.0, 300.0])
def test_object_depth_is_the_grasp_fems_placement(diameter):
    fem = default_depth(_fem_pads(DESIGN), DESIGN, diameter, GraspOptions())
    assert contact.object_depth(diameter, DESIGN) == pytest.approx(fem, abs=1e-6)  # brentq xtol 1e-9


def test_pad_gaps_match_fem_contact_at_random_hinge_angles():
    rng = np.random.default_rng(3)
    pads = _fem_pads(DESIGN)
    for _ in range(5):
        q = rng.uniform(-0.05, 0.4, DESIGN.n_s)
        centre = (rng.uniform(-20, 20), rng.uniform(60, 160))
        fem = gaps(pads, Circle(tuple(to_finger_frame(centre, DESIGN)), 40.0), q).g
        ours = contact.pad_gaps(q, centre, 40.0, DESIGN)
        assert np.array_equal(np.isinf(fem), np.isinf(ours))
        finite = np.isfinite(fem)
        np.testing.assert_allclose(ours[finite], fem[finite], rtol=0, atol=1e-9)


def test_gap_gradient_against_finite_differences():
    q, centre = np.array([0.02, 0.05, 0.1, 0.08, 0.12]), (0.0, 100.0)
    h = 1e-6
    for link in range(DESIGN.n_s + 1):
        fd = [(contact.pad_gaps(q + h * e, centre, 80.0, DESIGN)[link]
               - contact.pad_gaps(q - h * e, centre, 80.0, DESIGN)[link]) / (2 * h) for e in np.eye(5)]
        # central differences: O(h^2) ~ 1e-10 times the curvature, round-off ~1e-16 / h * 100 mm
        np.testing.assert_allclose(contact.pad_gap_gradient(q, centre, link, DESIGN), fd, atol=1e-6)


def test_contact_angle_is_the_first_touch():
    depth = contact.object_depth(180.0, DESIGN)
    theta, link = contact.contact_angle(180.0, DESIGN)
    uniform = np.full(5, 0.2)
    gap = lambda th: np.min(contact.pad_gaps(kinematics.hinge_angles(th, uniform), (0.0, depth), 90.0, DESIGN))  # noqa: E731
    assert abs(gap(theta)) < 1e-9                    # the zero, to the interpolation's accuracy
    assert np.all([gap(th) > 0 for th in np.linspace(0.0, theta - 1e-6, 200)])  # none earlier
    assert link == 2                                 # the grasp FEM: the 180 mm object touches link 2


def test_contact_angle_refuses_objects_out_of_reach():
    with pytest.raises(InputError, match="diameter_mm"):
        contact.contact_angle(180.0, DESIGN, depth=400.0)   # far below the finger tips
    with pytest.raises(InputError, match="overlaps"):
        contact.contact_angle(180.0, DESIGN, depth=60.0)    # through the open fingers


def test_rolling_weights_keep_the_pad_on_the_object():
    theta, link = contact.contact_angle(180.0, DESIGN)
    q = kinematics.hinge_angles(theta, np.full(5, 0.2))
    w = contact.rolling_weights(q, 180.0, link, DESIGN)
    grad = contact.pad_gap_gradient(q, (0.0, contact.object_depth(180.0, DESIGN)), link, DESIGN)
    assert w.sum() == pytest.approx(1.0, abs=1e-12)                  # eq. (23)
    assert grad @ w == pytest.approx(0.0, abs=1e-9)                  # rolls, no penetration
    np.testing.assert_allclose(w[link:], w[-1], rtol=1e-12)          # free hinges share equally
    # against the grasp FEM's w at 180 mm, 2 kg, 0.8 MPa (docs/grasp.md):
    # (-0.056, 0.128, 0.317, 0.307, 0.305); the FEM's tube is not equally stiff at every hinge
    np.testing.assert_allclose(w, [-0.056, 0.128, 0.317, 0.307, 0.305], atol=0.025)
