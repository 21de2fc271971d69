"""The drawn pull's walk (``run_hold`` with ``pull_control = "displacement"``) on objects whose pads bear
a prescribed pull R(u) at slide u: where it finds the holding limit -- the first maximum of R,
past a dip shorter than ``drive_past_peak`` or within ``pull_resolution``, not past a real fall --,
and what it does where no equilibrium is found. The walk sees only what a load step returns (the
spring's force at the slide where k (s - u) = R(u)), as it sees the whole-hand FEM's."""
import math
from types import SimpleNamespace

import numpy as np
from scipy.optimize import brentq

from softhand.fem.hand.hold import run_hold
from softhand.fem.hand.hold_model import NoEquilibrium
from softhand.fem.hand.hold_options import HoldOptions
from softhand.fem.newton import NotConverged

OPTIONS = HoldOptions(pull_control="displacement")
K = OPTIONS.drive_stiffness


class Pads:
    """A stand-in for :class:`softhand.fem.hand.hold_model.HoldModel`: the object slides along y, its pads
    bear R(u) [N] at slide u [mm]; no equilibrium where ``stuck(u)``, slipped out beyond ``slip_out``."""

    def __init__(self, R, *, stuck=lambda u: False, slip_out=45.0, weight=4.9):
        self.R, self.stuck, self.slip_out, self.weight = R, stuck, slip_out, weight
        self.options, self.pull_direction = OPTIONS, np.array([0.0, 1.0, 0.0])
        self.body, self.symmetric, self.pose, self.P = SimpleNamespace(centre=np.zeros(3)), True, np.zeros(6), 0.0

    def save(self):
        return self.pose.copy(), self.P

    def restore(self, saved):
        self.pose, self.P = saved[0].copy(), saved[1]

    def step(self, P, *, gravity, pull, stage, path=False, drive=None):
        self.P = P
        if drive is None:
            return SimpleNamespace(stage=stage, pull_N=0.0, pose=self.pose.copy())
        # the spring k (s - u) against the pads' R(u): one root, the spring stiffer than any fall of R
        u = brentq(lambda u: K * (drive - u) - self.R(u), -1e3, drive + 1e-9, xtol=1e-12)
        if self.stuck(u):
            raise NotConverged("no equilibrium found", [], None)
        if u > self.slip_out:
            raise NoEquilibrium("the object slid more than the slide limit: slipped out")
        self.pose = np.r_[0.0, u, 0.0, 0.0, 0.0, 0.0]
        return SimpleNamespace(stage=stage, pull_N=K * (drive - u), pose=self.pose.copy())


def ramp(*points):
    """R(u): piecewise linear through (u, R) points, 0 before the first, flat after the last."""
    u, R = np.array(points, dtype=float).T
    return lambda x: float(np.interp(x, u, R, left=0.0, right=R[-1]))


def _limit(pads) -> float:
    path = run_hold(pads, 1.0)
    assert path.held and path.limit_reached
    return path


def test_a_peak_then_a_fall_is_found_to_the_resolution():
    """Sticking to 10 N at 0.2 mm, then the pads give way and the pull falls: 10 N."""
    path = _limit(Pads(ramp((0.0, 0.0), (0.2, 10.0), (5.0, 0.5))))
    assert 10.0 * (1 - OPTIONS.pull_resolution) <= path.holding_limit_N <= 10.0 + 1e-9


def test_a_dip_shorter_than_the_past_peak_slide_is_passed():
    """10 N at 0.2 mm, 9 N at 0.5 mm, then the object wedges: 14 N at 1.0 mm before the fall.
    The dip lasts 0.5 mm of slide: a crease passed, not where the hand lets go."""
    path = _limit(Pads(ramp((0.0, 0.0), (0.2, 10.0), (0.5, 9.0), (1.0, 14.0), (6.0, 1.0))))
    assert 14.0 * (1 - OPTIONS.pull_resolution) <= path.holding_limit_N <= 14.0 + 1e-9


def test_a_fall_longer_than_the_past_peak_slide_ends_the_hold():
    """10 N at 0.2 mm, down to 5 N at 1.7 mm, up to 20 N at 6 mm: the hand lets go at 10 N."""
    path = _limit(Pads(ramp((0.0, 0.0), (0.2, 10.0), (1.7, 5.0), (6.0, 20.0), (9.0, 1.0))))
    assert 10.0 * (1 - OPTIONS.pull_resolution) <= path.holding_limit_N <= 10.0 + 1e-9
    assert max(s.pose[1] for s in path.steps) < 6.0


def test_a_pull_within_the_resolution_of_its_maximum_is_followed_on():
    """Sliding at 10 N (within 0.1 %) from 0.2 to 3 mm, then caught: 12 N at 4 mm."""
    path = _limit(Pads(ramp((0.0, 0.0), (0.2, 10.0), (3.0, 9.99), (4.0, 12.0), (8.0, 2.0))))
    assert 12.0 * (1 - OPTIONS.pull_resolution) <= path.holding_limit_N <= 12.0 + 1e-9


def test_a_pull_rising_until_it_slips_out_is_the_most_it_bore():
    """The pull grows as the object slides until it has slid out (10 mm here): the most borne."""
    R = ramp((0.0, 0.0), (0.2, 5.0), (20.0, 15.0))
    path = _limit(Pads(R, slip_out=10.0))
    assert R(10.0) * (1 - OPTIONS.pull_resolution) <= path.holding_limit_N <= R(10.0) + 1e-9


def test_where_a_finer_walk_finds_no_equilibrium_the_coarser_walk_is_kept():
    """Sliding at 3 N to 2 mm, where the next pads catch it (8 N, falling after), with no equilibrium
    found in the last 0.1 mm before (as the FEM's contact problem can stall there). The coarse walk
    steps over that band onto the catch; walked again finer it meets the band: the coarse walk is
    kept -- the object caught, its largest pull found -- and the answer says the maximum is unresolved."""
    R = lambda u: 0.0 if u < 0 else (min(30.0 * u, 3.0) if u < 2.0 else max(8.0 - 2.0 * (u - 2.0), 0.0))  # noqa: E731
    path = _limit(Pads(R, stuck=lambda u: 1.9 < u < 2.0))
    pulls = [s for s in path.steps if s.stage == "pull"]
    assert 3.5 < path.holding_limit_N <= 8.0 + 1e-9
    assert path.holding_limit_N == max(s.pull_N for s in pulls) and max(s.pose[1] for s in pulls) > 2.0
    assert "walked again finer found no equilibrium" in path.failure


def test_a_hold_that_never_lets_go_stops_at_the_largest_pull_tried():
    path = run_hold(Pads(ramp((0.0, 0.0), (1.0, 3000.0))), 1.0)
    assert path.held and not path.limit_reached and path.holding_limit_N > OPTIONS.max_pull
    assert len([s for s in path.steps if s.stage == "pull"]) < 60  # a quarter of the pull per step, at most
    assert math.isfinite(path.holding_limit_N)
