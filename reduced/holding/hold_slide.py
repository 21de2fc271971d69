r"""The object sliding along the pull in the fast hold: where the pads first slip is not where the hand lets go.

The limit analysis of :mod:`softhand.reduced.holding.hold_lp` keeps the fingers at their grasp, so its
limit lam(0) is the pull at which the pads start to slip: the object starts to move. Moved by y
along the pull, the object meets fingers that have closed on it there (the cavity pressure keeps
them closing: :func:`softhand.reduced.holding.hold_fast.close_hand` at the moved pose) and their limit
lam(y) is another. A ball held below its widest section wedges into the fingers as it slides,
pushing them open, and lam grows with y; a ball held above it, or a box by its top edges, slips
out, and lam falls. Followed quasi-statically, a pull lam moves the object to the least y at
which lam(y) >= lam; the hand lets go at the **first local maximum** of lam(y): beyond it the
object finds no equilibrium near where it is (the FEM hold's limit, where its next load step no
longer converges). Under its own weight alone (lam = 0) the object rests at the least y with
lam(y) >= 0, or falls if lam(y) < 0 up to the first maximum. As in the FEM hold, an object that
slides more than a quarter of its size (half of :func:`softhand.reduced.holding.object_geometry.size_radius`)
from where it rests has slipped out: the holding limit is the most pull it bore on the way, kept
over WEDGE_MM of slide before that point (a crease at the point itself is past where the hand
lets go, not a pull it bore).

:func:`follow` walks y from 0 in steps of :data:`FIRST_STEP` doubling up to :data:`LARGEST_STEP`
while lam grows, then narrows the maximum's bracket by golden sections to :data:`Y_TOL`; where
lam does not grow over the first step (the usual case: an object held above its widest section,
a box by its edges, a flat lam) it costs one evaluation more than the limit at the grasp. The
first step is short, so that a fall right from the grasp is seen as one (a ball touching next to
a hinge, whose pull falls before the ball passes onto the next pad, is let go at the grasp). The object's
centre moves along the pull; a box turned about the pull's axis also turns as it slides, as the
limit analysis's mechanism turns it (:mod:`softhand.reduced.holding.hold_turn`). Past y = 0, lam(y) is the
least pull borne over [y, y + :data:`WEDGE_MM`]: where the object passes the crease between two pads, the
rigid pads of the limit analysis squeeze it between both for a fraction of a millimetre, and the
pull they bear there jumps by 20-35 % and falls back, a little below where it was, for a fraction of a
millimetre more (measured on a 150 mm ball wedging into the fingers); the whole-hand FEM, whose
fingers give, passes these creases. So the walk goes on where the pull rises or falls for less
than WEDGE_MM of slide. Units: mm, N.
"""
from __future__ import annotations

import math
from typing import Callable, NamedTuple

#: first step of the walk along the pull [mm]
FIRST_STEP = 0.1
#: the walk's largest step [mm]
LARGEST_STEP = 8.0
#: the maximum (and the resting place) are located to this [mm]
Y_TOL = 0.5
#: lam must grow by this share of the load borne to count as growing
GROWTH = 1e-6
#: a pull borne over less slide than this [mm] is not where the hand lets go (module doc)
WEDGE_MM = 1.0
#: an object that never comes to rest is followed at most this many slip-out lengths
LONGEST = 4.0
#: golden ratio's conjugate
_G = 0.5 * (math.sqrt(5.0) - 1.0)


class Slide(NamedTuple):
    """The path of the object along the pull."""

    y_limit: float          #: slide where the hand lets go [mm] (the state bearing the holding limit)
    limit: object           #: the evaluation there (its lam is the holding limit)
    y_rest: float | None    #: where the object rests under its weight [mm]; None: it falls
    rest: object            #: the evaluation there (None if it falls)
    evaluations: int        #: lam(y) evaluated this many times (y = 0 included)
    slipped_out: bool       #: the pull still grew where the object had slid ``slip_out_mm`` from its rest


def follow(at: Callable[[float], tuple], first, *, weight_N: float, slip_out_mm: float,
           enough_N: float = math.inf, settle: bool = True) -> Slide:
    """The slide of module doc: ``at(y)`` is (lam(y), evaluation) for the object moved y [mm] along
    the pull (lam = -inf where no pad holds it), ``first`` that pair at y = 0. An object that has
    slid ``slip_out_mm`` from where it rests has slipped out (the FEM hold's rule: a quarter of its
    size); the walk also stops once the pull borne reaches ``enough_N`` (then a lower bound).
    ``settle``: an object whose weight the pads do not bear at y = 0 slides along the walk to rest
    (the pull is along gravity); else it falls."""
    scale = max(abs(weight_N), 1.0)
    seen = {0.0: first}
    if not settle and not first[0] >= 0.0:
        return Slide(0.0, first[1], None, None, 1, False)

    def raw(y):
        if y not in seen:
            seen[y] = at(y)
        return seen[y][0]

    def lam(y):  # the pull borne at y and kept for WEDGE_MM more of the slide
        return raw(y) if y == 0.0 else min(raw(y), raw(y + WEDGE_MM))

    def above(y, value):
        if not math.isfinite(value):  # no admissible state there: any state is better
            return math.isfinite(raw(y))
        return raw(y) > value + GROWTH * (scale + abs(value))

    def crossing(lo, hi):  # lam(lo) < 0 <= lam(hi): where the object comes to rest
        while hi - lo > Y_TOL:
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if lam(mid) < 0.0 else (lo, mid)
        return hi

    y_rest = 0.0 if raw(0.0) >= 0.0 else None
    bound = slip_out_mm if y_rest is not None else LONGEST * slip_out_mm
    y_best, y_before, h, y = 0.0, 0.0, FIRST_STEP, 0.0
    walked = [0.0]  # the walk's points
    while raw(y_best) < enough_N and y_best < bound:
        y = min(y_best + h, bound)
        # on while lam grows; a rise or a fall that does not last WEDGE_MM of slide is a crease
        if not (above(y, raw(y_best)) or (y_best > 0.0 and above(y, lam(y_best)))
                or (y > WEDGE_MM and above(y + WEDGE_MM, lam(y_best)))):
            break
        y_before, y_best, h = y_best, y, min(2.0 * h, LARGEST_STEP)
        walked.append(y)
        if y_rest is None and lam(y_best) >= 0.0:
            y_rest = crossing(y_before, y_best)
            bound = min(y_rest + slip_out_mm, LONGEST * slip_out_mm)
    slipped_out = y_best >= bound and y_rest is not None
    if slipped_out and bound - WEDGE_MM > y_rest:
        # the most pull kept over WEDGE_MM of slide before it slips out: at its last WEDGE_MM, or
        # where the walk saw more (a crease at the slip-out point itself is past where it lets go)
        before = [y for y in walked if y_rest <= y <= bound - WEDGE_MM][-1:]
        y_best = max(before + [bound - WEDGE_MM], key=lam)
    if 0.0 < y_best < y and raw(y_best) < enough_N and not slipped_out:
        a, b = y_before, y  # golden sections on [y_before, y] around y_best
        while b - a > Y_TOL:
            c = b - _G * (b - a) if y_best - a > b - y_best else a + _G * (b - a)
            left, right = (c, y_best) if c < y_best else (y_best, c)
            a, b, y_best = (a, right, left) if lam(left) >= lam(right) else (left, b, right)
    if y_best > 0.0 and lam(y_best) < raw(0.0):  # a crease's neighbours bear less than the grasp
        y_best = 0.0
    if y_best > 0.0 and raw(y_best + WEDGE_MM) < raw(y_best):
        y_best += WEDGE_MM  # the state that bears lam(y_best)
    return Slide(y_best, seen[y_best][1], y_rest, seen[y_rest][1] if y_rest is not None else None, len(seen),
                 slipped_out)
