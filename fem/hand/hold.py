r"""The whole hand holding a rigid object with friction, in the FEM: close, let go, pull.

Every finger of the layout is the finger FEM (:mod:`softhand.fem.hand.finger`, the half model in its
own bending plane) on the one hydraulic circuit (the same cavity pressure). Its links' pads
are rigid plates (:mod:`softhand.fem.hand.hold_geometry`) pressing on a rigid object, a free body
under gravity, the pads' forces and an external pull, with Coulomb friction
(:mod:`softhand.fem.hand.hold_contact`).

The load step (the staggered scheme, the fingers condensed) is
:class:`softhand.fem.hand.hold_model.HoldModel`'s; the options and the symmetry a placement must
have are in :mod:`softhand.fem.hand.hold_options`. Here: the path and the hold's answer.

The path: the hand comes down over the object (the placement of :mod:`softhand.fem.hand.grasp`:
its top ``palm_gap`` below the palm, or the open fingers ``clearance`` from it), the
pressure rises to the grasp pressure in ``close_steps`` while the object's support holds
it (pose fixed), gravity is switched on and the support removed (pose free), then a pull
along ``pull_direction`` grows -- increments grow 1.5x after a converged step and halve
after a failed one -- until no equilibrium is found (the contact problem or a finger fails,
or the object slides farther than ``max_slide`` from where it was let go). The holding
limit is the largest pull converged, resolved to ``pull_resolution``.

That limit depends on how the pull is stepped where friction gives way: a large step can land on
a state where every pad slips and nothing larger converges, or carry the object over a pose where
the fingers would have caught it. With ``pull_control = "displacement"`` the pull is drawn instead:
the far end of a stiff spring on the object (a load cell) moves along the pull in steps that keep
each step's change of pull and slide small, the pull borne is the spring's force, and the holding
limit is the first maximum of that force along the slide (as the fast model's,
:mod:`softhand.reduced.holding.hold_slide`), the steps around it walked again finer to
``pull_resolution``.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import NamedTuple

from softhand.fem.hand.hold_geometry import Pose
from softhand.fem.hand.hold_model import HoldModel, NoEquilibrium
from softhand.fem.hand.hold_options import HoldOptions, check_hold
from softhand.fem.newton import NotConverged
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError


@dataclass
class HoldPath:
    """The converged steps of a hold and its answer."""

    model: HoldModel
    steps: list                 #: StepRecord, in order
    held: bool                  #: holds under its own weight
    holding_limit_N: float      #: largest pull held beyond the weight, along pull_direction [N]
    limit_reached: bool         #: False when max_pull was reached still holding
    failure: str = ""           #: why the next pull increment found no equilibrium
    wall_seconds: float = 0.0


def run_hold(model: HoldModel, P: float, *, progress=None) -> HoldPath:
    """Close to cavity pressure P [MPa], release, pull to the holding limit."""
    if not P > 0:
        raise InputError("P_cavity_MPa", P, "must be a positive pressure [MPa]")
    t0, o, steps = time.perf_counter(), model.options, []
    tick = progress or (lambda record: None)
    P_k, dP = 0.0, P / o.close_steps
    while P_k < P:  # close; a step that fails is halved, down to a sixteenth
        try:
            steps.append(model.step(min(P_k + dP, P), gravity=0.0, pull=0.0, stage="close"))
            tick(steps[-1])
            P_k = min(P_k + dP, P)
        except NotConverged:
            dP *= 0.5
            if dP < P / (16 * o.close_steps):
                raise
    model.released = Pose(model.body.centre, model.pose).t.copy()
    # of the weight: let go at once, the release followed as a path where it finds no equilibrium near
    # the grasp; where the hand is symmetric, in smaller parts if that fails (the largest share held is
    # reported, each part a plain step)
    share, d_share = 0.0, 1.0
    while share < 1.0:
        try:
            steps.append(model.step(P, gravity=min(share + d_share, 1.0), pull=0.0, stage="release",
                                    path=d_share == 1.0))
            tick(steps[-1])
            share = min(share + d_share, 1.0)
        except (NotConverged, NoEquilibrium) as err:
            why = str(err).split("; residual history")[0]
            if not model.symmetric:  # the release was followed as a path (HoldModel._relax)
                return HoldPath(model, steps, False, 0.0, True, f"not held when let go of {share + d_share:.0%} "
                                f"of its weight ({why})", time.perf_counter() - t0)
            d_share *= 0.5
            if d_share < o.min_weight_step:
                return HoldPath(model, steps, False, 0.0, True, f"held {share:.0%} of its weight at "
                                f"most ({why})", time.perf_counter() - t0)
    if o.pull_control == "displacement":
        return _drawn(model, P, steps, tick, t0)
    F, failure = 0.0, ""
    dF = o.pull_step or max(0.5 * model.weight, 1.0)
    while F < o.max_pull:
        if dF < max(o.pull_resolution * F, o.pull_floor):
            return HoldPath(model, steps, True, F, True, failure, time.perf_counter() - t0)
        try:
            steps.append(model.step(P, gravity=True, pull=F + dF, stage="pull"))
            tick(steps[-1])
            F, dF = F + dF, 1.5 * dF
        except (NotConverged, NoEquilibrium) as err:
            failure, dF = str(err).split("; residual history")[0], 0.5 * dF
    return HoldPath(model, steps, True, F, False, "", time.perf_counter() - t0)


class _Drawn(NamedTuple):
    s: float        #: where the spring's far end is, along the pull from where the object was let go [mm]
    F: float        #: the spring's pull [N]
    u: float        #: the object's slide along the pull from there [mm]
    state: tuple    #: the model's state (``HoldModel.save``)


def _drawn(model: HoldModel, P: float, steps: list, tick, t0: float) -> HoldPath:
    """The pull drawn by displacement (``pull_control = "displacement"``): the far end of a stiff spring
    on the object moves along the pull; the pull borne is the spring's force. The holding limit is the
    first maximum of that pull along the slide: the largest pull borne before it has fallen more than
    ``pull_resolution`` below it ``drive_past_peak`` further on, or the object slips out or finds no
    equilibrium (a pull that stays within the resolution of its maximum, an object sliding at a constant
    pull, is followed on: it can rise again as the object wedges). The steps around that maximum are
    walked again four times finer until its neighbours are within ``pull_resolution`` of it; where the
    finer walk finds no equilibrium short of a maximum the coarser one reached (the object's edge
    meeting the next pad between two of its steps), the coarser walk is kept and the answer says so."""
    o, e = model.options, model.pull_direction
    dF_max = o.pull_step or max(0.5 * model.weight, 1.0)
    u = float(e @ (model.pose[:3] - model.released))
    walk, first = [_Drawn(u, 0.0, u, model.save())], len(steps)  # walk[i > 0] is steps[first + i - 1]
    # the first move: drive_step, or less where the spring alone would pull more than a pull step
    ds = min(o.drive_step, dF_max / o.drive_stiffness)
    cap, end, failure, out, finer = math.inf, math.inf, "", False, 0
    coarse = None  # (walk, steps) before the last walk again around a maximum
    while True:
        best = max(range(len(walk)), key=lambda i: (walk[i].F, -i))  # the first largest
        last = walk[-1]
        if last.F > o.max_pull:
            return HoldPath(model, steps, True, last.F, False, "", time.perf_counter() - t0)
        if last.s >= end and best == len(walk) - 1:  # still rising past the bracket walked again: walk on
            end = cap = math.inf
        tol = max(o.pull_resolution * walk[best].F, o.pull_floor)
        if out or (failure and ds < min(o.drive_step, cap) / 64) or last.s >= end \
                or (last.u - walk[best].u >= o.drive_past_peak and last.F < walk[best].F - tol):
            if coarse is not None and last.s < end and walk[best].F < max(w.F for w in coarse[0]) - tol:
                # the finer walk found no equilibrium where the coarser one went on: keep that one's
                walk, steps[:] = coarse
                model.restore(walk[-1].state)
                best = max(range(len(walk)), key=lambda i: (walk[i].F, -i))
                failure = f"the maximum's neighbourhood walked again finer found no equilibrium ({failure})"
                return HoldPath(model, steps, True, walk[best].F, True, failure, time.perf_counter() - t0)
            near = [walk[i].F for i in (best - 1, best + 1) if 0 <= i < len(walk)]
            if best == 0 or finer >= 4 or all(walk[best].F - F <= tol for F in near):
                return HoldPath(model, steps, True, walk[best].F, True, failure, time.perf_counter() - t0)
            # walk the bracket around the maximum again, finer
            finer, failure, out, coarse = finer + 1, "", False, (list(walk), list(steps))
            end = walk[best + 1].s if best + 1 < len(walk) else 2 * walk[best].s - walk[best - 1].s
            cap = ds = (end - walk[best - 1].s) / 8
            model.restore(walk[best - 1].state)
            del steps[first + best - 1:]
            walk = walk[:best]
            continue
        try:
            record = model.step(P, gravity=True, pull=0.0, stage="pull", drive=last.s + ds)
        except (NotConverged, NoEquilibrium) as err:
            failure, out = str(err).split("; residual history")[0], isinstance(err, NoEquilibrium)
            ds *= 0.5
            continue
        tick(record)
        steps.append(record)
        u = float(e @ (model.pose[:3] - model.released))
        walk.append(_Drawn(last.s + ds, record.pull_N, u, model.save()))
        failure = ""
        # a step changes the pull by at most a pull step or a quarter of the pull, and slides drive_max_slide
        r = max(abs(walk[-1].F - last.F) / max(dF_max, 0.25 * abs(last.F)),
                abs(walk[-1].u - last.u) / o.drive_max_slide)
        ds = min(cap, ds * min(1.5, 1.0 / r if r > 0 else 1.5))


def solve_hold(design: HandDesign, obj, *, P_cavity_MPa: float, pull_direction=(0.0, 1.0, 0.0),
               options: HoldOptions = HoldOptions(), progress=None, keep_path: bool = False,
               P_pump_MPa: float = math.nan, path_progress=None):
    """The FEM hold of ``obj`` (a :class:`softhand.reduced.holding.objects.GraspObject`, placed by its table) at
    cavity pressure P_cavity_MPa: the common :class:`softhand.reduced.holding.hold_result.HoldResult` (P_pump_MPa
    only reported); ``progress(record)`` after every converged load step, ``path_progress(k, support_N)``
    after every step of a followed path (``HoldModel._relax``); with ``keep_path``
    also the :class:`HoldPath` (for :func:`softhand.fem.hand.hold_output.write_hold`)."""
    from softhand.fem.hand.hold_output import to_result

    body, layout = check_hold(design, obj, pull_direction)
    model = HoldModel(design, body, options=options, layout=layout, pull_direction=pull_direction)
    model.on_path_step = path_progress
    path = run_hold(model, float(P_cavity_MPa), progress=progress)
    result = replace(to_result(path, obj=obj), P_pump_MPa=float(P_pump_MPa))
    return (result, path) if keep_path else result
