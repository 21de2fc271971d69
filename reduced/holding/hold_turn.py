r"""The object turning as it slides in the fast hold: the rotation of the limit analysis's mechanism.

Past the pull at which its pads first slip, the object moves along the pull
(:mod:`softhand.reduced.holding.hold_slide`). A ball, an upright cylinder or a box square under
the fingers moves straight; a box turned about the palm's axis also turns: its pads press the
faces off their centre lines, and the twist they put on it is carried by friction until the pads
slip. The limit analysis (:mod:`softhand.reduced.holding.hold_lp`) says how it turns. At the limit
the object moves in the collapse mechanism, its centre at velocity v and turning at the rate
omega, and by the power of the loads on it (the kinematic side of limit analysis) a moment M
applied to the object besides the weight and the pull changes the limit by

.. math:: \frac{\partial\lambda}{\partial M} = -\frac{\omega}{d\cdot v},

so the object turns, per mm of slide along the pull d, at minus the limit's gradient in an applied
moment (:func:`turn_rate`). The LP's dual values are that gradient too, but at the degenerate optimum
of a symmetric grasp they are one vertex of a face of duals (the centred 180 mm ball's turned it
0.95 deg/mm about a tilted axis); the central difference averages the one-sided slopes, so a grasp
whose limit is even in the moment (every symmetric one) does not turn. Where a moment about an axis
finds no admissible state on one side, the pads bear no moment about it and the mechanism leaves
that rotation free: the object is not turned about it. Only the turn about the pull's axis is
followed: about the other axes the gradient is not robust. Measured on the 180 mm cube turned 15
deg, which by its symmetry cannot tilt: 3-7 mm down its slide, pads touching within the contact
tolerance on some fingers and not on others gave it tilt rates of 0.4-0.8 deg/mm.

:class:`Path` follows the pose: the centre moves along the pull (the mechanism's sideways velocity
is not followed), the rotation integrated by explicit Euler steps from knot to knot,
one every :data:`TURN_STEP` of turn at most. A ball (rotating it changes no contact) is not turned.

**Let go with a twist** (:func:`untwist`). Where the pads cannot hold the object in place even
without its weight -- the closing forces twist it about the palm's axis (a box turned about it,
pressed off its faces' centre lines) more than friction carries -- no admissible state exists and
so no mechanism: the object turns first, as the closing forces twist it, until friction carries
what twist is left and the pads bear its weight, where it rests (or, where no turn lets them
bear it, until they first hold it at all; it settles on from there). It is turned in steps of
:data:`TURN_STEP` (the hand closed afresh at each) up to :data:`LARGEST_UNTWIST`, that pose
bisected to :data:`UNTWIST_TOL`. Units: mm, rad, N, N mm.
"""
from __future__ import annotations

import math
from bisect import bisect_right
from dataclasses import replace
from typing import Callable

import numpy as np
from scipy.spatial.transform import Rotation

from softhand.reduced.holding import hold_lp
from softhand.reduced.holding.object_geometry import Placed

#: the largest turn [rad] between two knots of the path
TURN_STEP = np.radians(1.0)
#: the applied moment of the central difference, per (weight [N] x size [mm])
MOMENT_STEP = 1e-3
#: the largest turn [rad] of an object let go with a twist (:func:`untwist`)
LARGEST_UNTWIST = np.radians(45.0)
#: the untwisted pose is bisected to this turn [rad]
UNTWIST_TOL = np.radians(0.05)


def closing_twist(cs: hold_lp.ContactSet, centre, axis) -> float:
    """The closing forces' moment [N mm] on the object about ``axis`` (unit vector) through ``centre``."""
    moments = np.cross(cs.point - np.asarray(centre, float), -cs.closing_N[:, None] * cs.normal)
    return float(np.sum(moments @ np.asarray(axis, float)))


def let_go(placed: Placed, cs: hold_lp.ContactSet, mu: float, size_mm: float, axis,
           pull_at: Callable[[Placed], float]) -> Placed:
    """The pose the object let go turns to before it settles (module doc): :func:`untwist` where the pads
    of the grasp ``cs`` cannot hold it in place without its weight and can once the closing forces'
    twist about ``axis`` is taken off it; else ``placed``."""
    axis = np.asarray(axis, float)
    twist = closing_twist(cs, placed.centre, axis)
    if not len(cs.finger) or hold_lp.holding_limit(cs, placed.centre, 0.0, axis, mu, size_mm=size_mm) is not None \
            or hold_lp.holding_limit(cs, placed.centre, 0.0, axis, mu, size_mm=size_mm, moment=-twist * axis) is None:
        return placed
    return untwist(placed, axis, twist, pull_at)


def untwist(placed: Placed, axis, twist: float, pull_at: Callable[[Placed], float]) -> Placed:
    """The pose the object let go with the closing forces' ``twist`` about ``axis`` (through its centre)
    turns to (module doc): turned with the twist until ``pull_at(pose)`` -- the pull the pads bear there
    beyond the weight, -inf for no admissible state -- is >= 0 (it rests there), or, where no turn up to
    :data:`LARGEST_UNTWIST` gets there, until the pads first hold it at all (it settles on from there);
    ``placed`` itself where no turn does."""
    axis = np.asarray(axis, float) * np.sign(twist)
    if twist == 0.0:
        return placed

    def turned(angle):
        return replace(placed, R=Rotation.from_rotvec(angle * axis).as_matrix() @ placed.R)

    def first(ok, lo, hi):  # bisected: ok(hi), not ok(lo)
        while hi - lo > UNTWIST_TOL:
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if not ok(pull_at(turned(mid))) else (lo, mid)
        return turned(hi)

    angles = np.arange(int(LARGEST_UNTWIST / TURN_STEP) + 1) * TURN_STEP
    pulls = []
    for k, angle in enumerate(angles[1:], start=1):
        pulls.append(pull_at(turned(angle)))
        if pulls[-1] >= 0.0:
            return first(lambda lam: lam >= 0.0, angles[k - 1], angle)
    held = [k for k, lam in enumerate(pulls, start=1) if math.isfinite(lam)]
    return first(math.isfinite, angles[held[0] - 1], angles[held[0]]) if held else placed


def turn_rate(cs: hold_lp.ContactSet, centre, weight_N: float, pull, mu: float, *, size_mm: float,
              axes=None) -> np.ndarray:
    """omega (3,) [rad per mm of slide along ``pull``] of the limit analysis's mechanism (module doc):
    minus the holding limit's central difference in a moment applied about each of ``axes`` (unit
    vectors; default the pull's axis); an axis about which one side has no admissible state is not
    turned about."""
    pull = np.asarray(pull, float)
    axes = [pull] if axes is None else [np.asarray(a, float) for a in axes]
    dM = MOMENT_STEP * max(float(weight_N), 1.0) * float(size_mm)
    omega = np.zeros(3)
    for axis in axes:
        up, down = (hold_lp.holding_limit(cs, centre, weight_N, pull, mu, size_mm=size_mm, moment=s * dM * axis)
                    for s in (1.0, -1.0))
        if up is not None and down is not None:
            omega -= (up.pull_N - down.pull_N) / (2.0 * dM) * axis
    return omega


class Path:
    """The object's pose along the slide: ``at(y)`` is the placement moved y [mm] along the pull and
    turned as the mechanism turns it on the way; ``rate(y, placed)`` gives omega (3,) [rad/mm] at the
    pose after y [mm] (None: the object does not turn, a translation along the pull)."""

    def __init__(self, placed: Placed, pull, rate: Callable[[float, Placed], np.ndarray] | None):
        self._pull = np.asarray(pull, float)
        self._rate = rate
        self._y, self._placed, self._omega = [0.0], [placed], []

    def at(self, y: float) -> Placed:
        """The pose after y [mm] of slide (knots added up to y as needed)."""
        if self._rate is None:
            first = self._placed[0]
            return first if y == 0.0 else replace(first, centre=first.centre + y * self._pull)
        while y > self._y[-1]:
            k = len(self._y) - 1
            speed = float(np.linalg.norm(self._turn(k)))
            step = y - self._y[k] if speed * (y - self._y[k]) <= TURN_STEP else TURN_STEP / speed
            self._placed.append(self._advance(k, step))
            self._y.append(self._y[k] + step)
        k = bisect_right(self._y, y) - 1
        return self._placed[k] if y == self._y[k] else self._advance(k, y - self._y[k])

    def _turn(self, k: int) -> np.ndarray:
        while len(self._omega) <= k:  # the knots' rates, in order
            j = len(self._omega)
            self._omega.append(np.asarray(self._rate(self._y[j], self._placed[j]), float))
        return self._omega[k]

    def _advance(self, k: int, dy: float) -> Placed:
        p = self._placed[k]
        R = Rotation.from_rotvec(self._turn(k) * dy).as_matrix() @ p.R
        return replace(p, centre=p.centre + dy * self._pull, R=R)
