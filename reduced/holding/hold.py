r"""The fast hold, posed as a user asks it: does the hand hold this object at this pressure, how
much more can it take along a pull, and what pump pressure holds it with a margin.

:func:`solve_hold` runs the path of the FEM hold in the fast model: close at the cavity pressure
(:func:`softhand.reduced.holding.hold_fast.close_hand`), let go (the object's weight: the admissible state nearest
the closing forces, :func:`softhand.reduced.holding.hold_lp.weight_state`; an object whose weight the pads do
not bear where it was grasped first settles under it, sliding down and turning, whatever the pull;
one the closing forces twist more than friction carries turns first, :func:`softhand.reduced.holding.hold_turn.let_go`), pull along a direction until no
admissible state is left (:func:`softhand.reduced.holding.hold_lp.holding_limit`), the object sliding along the
pull where the fingers closing on it there hold it more (:mod:`softhand.reduced.holding.hold_slide`: the
holding limit is the first maximum along that slide; a pull towards the palm is not followed: pushed
into the hand, the object meets the palm, which is not a contact of this model, and fingers pushed
open past straight, where the hinge tables do not reach). It returns the common
:class:`softhand.reduced.holding.hold_result.HoldResult` (model ``"reduced"``); the object's displacement
is where it rests under its own weight, and its rotation the turn its slide there gave it
(:mod:`softhand.reduced.holding.hold_turn`).

:func:`least_pressure` answers the inverse question: the least pump pressure (and its cavity
pressure) at which the holding limit along the pull reaches the margin asked -- the object's
weight times ``margin`` in all (``margin = 2``: a pull of one more weight), or a pull of
``pull_N`` beyond the weight -- found on a grid of pump pressures up to the pump's limit and
bisected; or :class:`NotHeldError` saying why no pressure within the limit does.
Pressures: P_cavity_MPa is the fingers' oil pressure, P_pump_MPa the pump's (the cavity's less
the reservoir's, which falls as the fingers take its oil). Units: N, mm, MPa, kg.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation

from softhand.reduced.equations import hand
from softhand.reduced.holding import hold_fast, hold_finger, hold_lp, hold_slide, hold_turn
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.holding.hand_layout import place_object
from softhand.reduced.holding.hold_result import SLIP, STICK, Contact, HoldResult, LoadStep
from softhand.reduced.holding.object_geometry import Placed, size_radius
from softhand.reduced.holding.objects import GraspObject

#: the default pull: straight down (more weight)
DOWN = (0.0, 1.0, 0.0)
#: pump pressures on the inverse question's grid
PRESSURE_GRID = 24
#: the inverse question's answer is bisected to this [MPa]
PRESSURE_TOL = 1e-4


def pull_unit(pull, field: str = "--pull") -> np.ndarray:
    """The pull direction as a unit vector (3,); InputError for a zero, non-finite or wrong-sized one."""
    numbers = isinstance(pull, (list, tuple, np.ndarray)) and len(pull) == 3 and all(
        isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, (bool, np.bool_)) for x in pull)
    v = np.asarray(pull, float).ravel() if numbers else None
    if v is None or not np.all(np.isfinite(v)):
        raise InputError(field, pull, "must be three numbers x,y,z (hand frame, y down)")
    top = float(np.abs(v).max())
    if not top > 1e-12:
        raise InputError(field, [float(x) for x in v], "must not have zero length (a direction x,y,z; y down)")
    v = v / top  # (the length of 1e308,1e308,0 overflows)
    return v / float(np.linalg.norm(v))


def contact_set(closed: hold_fast.Closed, design: HandDesign) -> hold_lp.ContactSet:
    """The touching pads of the closed hand and its fingers' hinges (moments, stiffness) for the LP."""
    rows = [(i, int(k)) for i, s in enumerate(closed.fingers)
            for k in np.flatnonzero((s.N > 0.0) | (s.geometry.gap <= hold_finger.TOUCH)) if k > 0]
    C, n_s = len(rows), design.n_s
    J = np.zeros((design.n * n_s, C, 3))
    for c, (i, k) in enumerate(rows):
        J[i * n_s:(i + 1) * n_s, c] = closed.fingers[i].geometry.dx[k]
    q = np.array([s.q for s in closed.fingers])
    take = lambda f: np.array([f(closed.fingers[i], k) for i, k in rows], float).reshape(C, -1) if C \
        else np.zeros((0, 3))  # noqa: E731
    return hold_lp.ContactSet(
        finger=np.array([i for i, _ in rows], int), link=np.array([k for _, k in rows], int),
        point=take(lambda s, k: s.geometry.point[k]), normal=take(lambda s, k: s.geometry.normal[k]),
        closing_N=take(lambda s, k: s.N[k])[:, 0] if C else np.zeros(0), J=J,
        moment=np.concatenate([s.moments for s in closed.fingers]),
        stiffness=hold_finger.hinge_stiffness(q, closed.P_cavity, design).ravel())


def _contacts(cs: hold_lp.ContactSet, state: hold_lp.LimitState | None, held: bool) -> tuple:
    out = []
    for c in range(len(cs.finger)):
        N = float(state.normal_N[c]) if state is not None else float(cs.closing_N[c])
        F = state.friction[c] if state is not None else np.zeros(3)
        size = float(np.linalg.norm(F))
        if N <= 0.0 and size <= 0.0 and state is not None:
            continue
        slip = bool(state.slip[c]) if state is not None else not held
        out.append(Contact(int(cs.finger[c]), int(cs.link[c]), N, size, SLIP if slip else STICK,
                           tuple(cs.point[c].tolist()), tuple(cs.normal[c].tolist()),
                           tuple((F / size).tolist()) if size > 0 else ()))
    return tuple(out)


def solve_hold(design: HandDesign, obj: GraspObject, *, P_cavity_MPa: float, pull_direction=DOWN,
               finger_model: str = "fem", reservoir: bool = True, placed: Placed | None = None,
               closed: hold_fast.Closed | None = None, enough_N: float = math.inf,
               slide_hands: dict | None = None) -> HoldResult:
    """The hold at cavity pressure P [MPa] (module doc): close, let go, pull along the direction,
    the object sliding along it as far as the pull takes it (:mod:`softhand.reduced.holding.hold_slide`);
    the slide is followed only until the pull borne reaches ``enough_N`` (the limit is then at least that).
    ``slide_hands``: the hands closed along the slide, by slide [mm], kept between calls that share
    the pressure, the object's shape and pose and the pull (a map over mass fills it once)."""
    d = hold_fast.finger_design(design, finger_model)
    pull = pull_unit(pull_direction, "pull_direction")
    placed = place_object(obj, d) if placed is None else placed
    closed = hold_fast.close_hand(float(P_cavity_MPa), placed, d, reservoir_on=reservoir) if closed is None else closed
    weight = obj.mass_kg * d.g
    size = float(np.max(np.ptp(placed.surface(resolution=8)[0], axis=0)))

    hands = {} if slide_hands is None else slide_hands  # by pose: its centre and rotation, bit for bit
    pose_key = lambda p: (p.centre.tobytes(), p.R.tobytes())  # noqa: E731
    hands[pose_key(placed)] = closed

    def hand_at(moved):
        """The hand closed on the object at pose ``moved``; None where the object has moved into the open
        fingers (they have let it through)."""
        key = pose_key(moved)
        if key not in hands:
            near = hands[min(hands, key=lambda k: float(np.linalg.norm(np.frombuffer(k[0]) - moved.centre)))]
            try:
                hands[key] = hold_fast.close_hand(closed.P_cavity, moved, d, reservoir_on=reservoir, near=near)
            except InputError:
                hands[key] = None
        return hands[key]

    def slide(start, along, settle, enough):
        """(the slide from pose ``start`` along the unit vector ``along``, its path, its start's evaluation)."""
        def rate(y, moved):  # the object's turn per mm of slide at this pose (hold_turn)
            hand = hand_at(moved)
            return np.zeros(3) if hand is None else hold_turn.turn_rate(
                contact_set(hand, d), moved.centre, weight, along, obj.friction, size_mm=size)

        path_of = hold_turn.Path(start, along, None if obj.shape == "sphere" else rate)

        def at(y):
            """(lam, (placed, closed, contact set, limit state)) with the object moved y [mm] along."""
            if y > 0.0 and along[1] < 0.0:  # pushed towards the palm: not followed (module doc)
                return -math.inf, None
            moved = path_of.at(y)
            hand = hand_at(moved)
            if hand is None:
                return -math.inf, None
            cs = contact_set(hand, d)
            lim = hold_lp.holding_limit(cs, moved.centre, weight, along, obj.friction, size_mm=size)
            return (lim.pull_N if lim is not None else -math.inf), (moved, hand, cs, lim)

        first = at(0.0)
        return hold_slide.follow(at, first, weight_N=weight, slip_out_mm=0.5 * size_radius(obj), enough_N=enough,
                                 settle=settle), path_of, first

    def borne(moved):  # the pull the pads bear at this pose beyond the weight (-inf: none)
        hand = hand_at(moved)
        lim = None if hand is None else hold_lp.holding_limit(contact_set(hand, d), moved.centre, weight, DOWN,
                                                              obj.friction, size_mm=size)
        return -math.inf if lim is None else lim.pull_N

    start = placed if obj.shape == "sphere" else hold_turn.let_go(placed, contact_set(closed, d), obj.friction,
                                                                  size, DOWN, borne)
    path, _, first = slide(start, np.array(DOWN), True, enough_N if pull[1] >= 1.0 - 1e-12 else 0.0)
    evaluations = path.evaluations
    if pull[1] < 1.0 - 1e-12 and path.y_rest is not None:  # let go, then pulled from where it rests
        path, _, first = slide(path.rest[0], pull, False, enough_N)
        evaluations += path.evaluations
    moved, closed_rest, cs, _ = path.rest if path.rest is not None else first[1]
    _, _, cs_limit, limit = path.limit if path.limit is not None else first[1]
    rest = hold_lp.weight_state(cs, moved.centre, weight, obj.friction, size_mm=size) \
        if path.y_rest is not None else None
    held = rest is not None and limit is not None and limit.pull_N >= -1e-9 * max(weight, 1.0)
    holding = max(limit.pull_N, 0.0) if held else 0.0
    notes = []
    if not len(cs.finger):
        notes.append("no pad touches the object at this pressure")
    elif not held:
        notes.append("the pads cannot carry the object's weight (friction and the fingers' hinge moments)")
    if held and path.slipped_out:
        notes.append(f"past this pull the object slides more than {0.5 * size_radius(obj):.3g} mm (a quarter of its "
                     f"size) from where it rests: slipped out")
    if held and limit.pull_N >= hold_lp.MAX_PULL:
        notes.append(f"the pull is bounded only by the search's {hold_lp.MAX_PULL:g} N")
    residual = max(float(np.max([s.residual for s in closed.fingers])), 0.0)
    at_rest = moved if held else placed
    at_limit = path.limit[0] if held else placed

    def shift(pose):  # the object's displacement [mm] from its placement
        return tuple((pose.centre - placed.centre).tolist())

    def turn(pose):  # its turn from its placement: x-y-z Euler angles [deg], as the FEM hold reports it
        return tuple(np.degrees(Rotation.from_matrix(pose.R @ placed.R.T).as_euler("xyz")).tolist())

    steps = (LoadStep("close", closed.P_cavity, 0.0, bool(len(cs.finger)), contacts=len(cs.finger),
                      extra={"hinge_residual": residual}),
             LoadStep("release", closed.P_cavity, 0.0, held, displacement_mm=shift(at_rest),
                      rotation_deg=turn(at_rest),
                      contacts=len(_contacts(cs, rest, held)) if held else 0,
                      extra={"equilibrium_residual": rest.residual if rest is not None else math.nan}),
             LoadStep("pull", closed.P_cavity, holding, held, displacement_mm=shift(at_limit),
                      rotation_deg=turn(at_limit),
                      contacts=len(_contacts(cs_limit, limit, held)) if held else 0,
                      extra={"equilibrium_residual": limit.residual if limit is not None else math.nan}))
    return HoldResult(
        model="reduced", held=held, holding_limit_N=float(holding), pull_direction=tuple(pull.tolist()),
        contacts=_contacts(cs, rest if held else None, held), P_cavity_MPa=float(closed.P_cavity),
        P_pump_MPa=float((closed_rest if held else closed).P_pump), mass_kg=obj.mass_kg, friction=obj.friction,
        object=obj.to_dict(), steps=steps, symmetric=closed.symmetric, notes=tuple(notes),
        displacement_mm=shift(at_rest), rotation_deg=turn(at_rest),
        extra={"finger_model": d.finger_model, "hinge_residual": residual,
               "limit_contacts": [c._asdict() if hasattr(c, "_asdict") else c.__dict__
                                  for c in _contacts(cs_limit, limit, held)] if held else [],
               "friction_polygon": hold_lp.GENERATORS, "object_centre_mm": placed.centre.tolist(),
               "limit_pull_N": float(limit.pull_N) if limit is not None else None,
               "first_slip_pull_N": float(first[0]) if math.isfinite(first[0]) else None,
               "slide_mm": float(path.y_limit), "slide_evaluations": evaluations})


def cavity_pressure(P_pump: float, placed: Placed, design: HandDesign, *, finger_model: str = "fem",
                    reservoir: bool = True) -> float:
    """The cavity pressure [MPa] at which the hand closed on the object has pump pressure P_pump."""
    if not reservoir:
        return float(P_pump)
    d = hold_fast.finger_design(design, finger_model)
    f = lambda P: hold_fast.close_hand(P, placed, d).P_pump - P_pump  # noqa: E731
    top = float(hand.pressure_span(d, reservoir=False)[1])
    # secant: P_pump(P_cavity) has a slope near 1 (the reservoir's pressure changes slowly with the oil)
    x0, x1 = float(P_pump), float(P_pump) + 0.1
    f0, f1 = f(x0), f(x1)
    for _ in range(12):
        if abs(f1) < 1e-10 or f1 == f0:
            break
        x0, x1, f0 = x1, min(x1 - f1 * (x1 - x0) / (f1 - f0), top), f1
        f1 = f(x1)
    if abs(f1) < 1e-9:
        return float(x1)
    lo, hi = float(P_pump), float(P_pump) + 0.5
    while f(hi) < 0.0:
        lo, hi = hi, hi + 0.5
        if hi > top:
            raise InputError("pressure_MPa", P_pump, f"needs a cavity pressure above the finger model's "
                             f"highest, {top:.4g} MPa")
    return float(brentq(f, lo, hi, xtol=1e-10))


class NotHeldError(InputError):
    """No pressure within the pump's limit holds the object with the margin asked."""


class Least(NamedTuple):
    P_pump_MPa: float
    P_cavity_MPa: float
    result: HoldResult
    required_N: float       #: the holding limit asked along the pull [N]


def least_pressure(design: HandDesign, obj: GraspObject, *, max_pump_MPa: float, margin: float = 1.0,
                   pull_N: float | None = None, pull_direction=DOWN, finger_model: str = "fem",
                   reservoir: bool = True, progress=None) -> Least:
    """The least pump pressure (<= max_pump_MPa) whose hold meets the margin (module doc)."""
    d = hold_fast.finger_design(design, finger_model)
    placed = place_object(obj, d)
    weight = obj.mass_kg * d.g
    required = float(pull_N) if pull_N is not None else (margin - 1.0) * weight
    lo_pump = float(hand.pressure(0.0, d, reservoir)) if reservoir else 0.0
    grid = np.linspace(max(lo_pump, 0.0), max_pump_MPa, PRESSURE_GRID)

    def at(P_pump):
        Pc = cavity_pressure(P_pump, placed, d, reservoir=reservoir)
        return solve_hold(d, obj, P_cavity_MPa=Pc, pull_direction=pull_direction, placed=placed)

    def ok(r):
        return r.held and r.holding_limit_N >= required

    prev, best = None, None
    for n, P in enumerate(grid):
        r = at(P)
        if progress is not None:
            progress(n + 1, len(grid))
        if ok(r):
            if prev is None:
                return Least(P, r.P_cavity_MPa, r, required)
            lo, hi, best = prev, P, r
            while hi - lo > PRESSURE_TOL:
                mid = 0.5 * (lo + hi)
                rm = at(mid)
                lo, hi, best = (lo, mid, rm) if ok(rm) else (mid, hi, best)
            return Least(hi, best.P_cavity_MPa, best, required)
        prev, best = P, r
    why = best.notes[0] if best is not None and best.notes else \
        f"its holding limit there is {best.holding_limit_N:.4g} N"
    raise NotHeldError("--max-pump-mpa", max_pump_MPa,
                       f"no pump pressure up to it holds the {obj.describe()} ({obj.mass_kg:g} kg, mu = "
                       f"{obj.friction:g}) with a holding limit of {required:.4g} N along the pull: at "
                       f"{max_pump_MPa:g} MPa {why}")
