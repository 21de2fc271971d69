r"""The whole hand holding a rigid object with friction, in the FEM: close, let go, pull.

Every finger of the layout is the finger FEM (:mod:`softhand.fem.hand.finger`, the half model in its
own bending plane) on the one hydraulic circuit (the same cavity pressure). Its links' pads
are rigid plates (:mod:`softhand.fem.hand.hold_geometry`) pressing on a rigid object, a free body
under gravity, the pads' forces and an external pull, with Coulomb friction
(:mod:`softhand.fem.hand.hold_contact`).

Scheme (staggered, with the fingers condensed). The object couples the fingers only
through the contact forces, and pads and object are rigid, so a finger enters the contact
problem only through its hinge angles: its condensed response :math:`Q^{int}_f(q)`, the
generalised force that holds its links at q, linearised at its last FEM state with the exact
condensed stiffness (:mod:`softhand.fem.hand.hold_finger`). A load step:

1. each finger's FEM moves to the step's pressure under its last contact forces;
2. the small contact problem (hinge angles of every solved finger, the object's free pose
   components; Newton + Uzawa, friction cone and gaps to tolerance) is solved on the
   linearised fingers;
3. each finger's FEM is solved under the contact forces found, which puts its linearisation
   on the true response; 2-3 repeat until every finger's FEM hinge angles equal the contact
   problem's to ``q_tol`` -- then the contact forces, the object's equilibrium and every
   finger's FEM equilibrium hold together (a Newton iteration on the fingers' responses:
   it converges quadratically).

The path: the hand comes down over the object (the placement of :mod:`softhand.fem.hand.grasp`:
its top ``palm_gap`` below the palm, or the open fingers ``clearance`` from it), the
pressure rises to the grasp pressure in ``close_steps`` while the object's support holds
it (pose fixed), gravity is switched on and the support removed (pose free), then a pull
along ``pull_direction`` grows -- increments grow 1.5x after a converged step and halve
after a failed one -- until no equilibrium is found (the contact problem or a finger fails,
or the object slides farther than ``max_slide`` from where it was let go). The holding
limit is the largest pull converged, resolved to ``pull_resolution``.

Symmetry: when the object is invariant under the rotations about the palm axis that map
fingers onto fingers, sits on that axis and is pulled along it, one finger per orbit is
solved (its images carry the same state rotated) and only the object's translation and
rotation about the axis are unknowns. Otherwise every finger is solved, with all six.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from softhand.fem.hand.finger import FingerModel, FingerOptions
from softhand.fem.hand.grasp import GraspOptions
from softhand.fem.hand.hold_contact import (ContactHistory, ContactOptions, Fingers, Problem,
                                            solve_contact)
from softhand.fem.hand.hold_finger import HeldFinger
from softhand.fem.hand.hold_geometry import PadSet, Pose, default_layout, pad_contacts, rot_y
from softhand.fem.newton import NotConverged
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.holding.hand_layout import pad_width


@dataclass(frozen=True)
class HoldOptions:
    """Discretisation, contact and path of the FEM hold."""

    finger: FingerOptions = field(default_factory=FingerOptions)
    contact: ContactOptions = field(default_factory=ContactOptions)
    placement: GraspOptions = field(default_factory=GraspOptions)  #: palm_gap, clearance, pad_offset
    pad_width: float | None = None   #: pad width across the finger [mm]; None: the design's
    close_steps: int = 4             #: pressure steps from 0 to the grasp pressure
    pull_step: float | None = None   #: first pull increment [N]; None: half the weight, at least 1 N
    pull_resolution: float = 0.02    #: the holding limit's resolution, relative to it (>= 0.1 N)
    max_pull: float = 2000.0         #: stop pulling there: held beyond it [N]
    max_slide: float | None = None   #: slipped out beyond this slide after release [mm]; None: D / 4
    q_tol: float = 1e-8              #: FEM vs contact hinge angles at convergence [rad]
    max_stagger: int = 30            #: contact/FEM iterations per load step
    symmetry: bool = True            #: solve one finger per symmetry orbit where the case allows
    #: solve a placement without the hand's symmetry (all six pose components free). Not yet
    #: validated: a 180 mm sphere 1.5 mm off the palm axis came out not held where the centred
    #: one holds, so :func:`solve_hold` refuses such a placement unless this is set
    asymmetric: bool = False
    min_weight_step: float = 1 / 16  #: not held when letting go of this share of the weight fails
    pull_floor: float = 0.1          #: the holding limit's resolution is at least this [N]

    def __post_init__(self):
        if not self.close_steps >= 1:
            raise InputError("close_steps", self.close_steps, "must be >= 1")
        if not self.q_tol > 0:
            raise InputError("q_tol", self.q_tol, "must be positive [rad]")


class NoEquilibrium(RuntimeError):
    """The object slipped out: no equilibrium at this load."""


def symmetry_orbits(body, frames, pull_direction, tol: float = 1e-9):
    """[(solved finger, [its images])]: fingers whose rotation about the palm axis maps the
    object onto itself, when the object is centred on the axis and pulled along it; else
    every finger alone."""
    alone = [(j, [j]) for j in range(len(frames))]
    c = np.asarray(body.centre, dtype=float)
    e = np.asarray(pull_direction, dtype=float)
    if abs(c[0]) > tol or abs(c[2]) > tol or np.linalg.norm(np.cross(e, [0.0, 1.0, 0.0])) > tol:
        return alone
    rng = np.random.default_rng(0)
    probe = c + body.radius * rng.uniform(-1.5, 1.5, (200, 3))
    d0 = body.signed_distance(probe)[0]
    orbits, seen = [], set()
    for j, fj in enumerate(frames):
        if j in seen:
            continue
        images = []
        for k, fk in enumerate(frames):
            R = rot_y(fk.azimuth - fj.azimuth)
            if k not in seen and np.allclose(body.signed_distance(c + (probe - c) @ R.T)[0], d0, atol=1e-9):
                images.append(k)
        seen.update(images)
        orbits.append((j, images))
    return orbits


@dataclass
class StepRecord:
    """One converged load step (physical forces, hand frame)."""

    stage: str            #: "close", "release" or "pull"
    P: float              #: cavity pressure [MPa]
    pull_N: float         #: external pull beyond the weight [N]
    gravity: float        #: share of the object's weight acting (0: held by its support)
    pose: np.ndarray      #: (6,) translation [mm] and rotation vector [rad] from the placement
    contacts: list        #: per pad of every finger: dict (finger, link, normal_N, friction_N, state, ...)
    residual_N: float     #: object equilibrium residual (free components) [N, N mm]
    cone: float           #: max ``|T|`` / (mu N) over touching pads (<= 1)
    penetration_mm: float  #: max penetration of a touching pad
    stick_slip_mm: float  #: max slip of a sticking pad within the step
    q_mismatch: float     #: max ``|q_FEM - q_contact|`` [rad]
    fem_residual: float   #: max finger FEM residual norm [N mm]
    iterations: int       #: contact/FEM (stagger) iterations
    states: list = field(repr=False, default_factory=list)  #: the solved fingers' FEM states y


class HoldModel:
    """The hand (design, layout), the placed object and the state along the path."""

    def __init__(self, design: HandDesign, body, *, options: HoldOptions = HoldOptions(),
                 layout=None, pull_direction=(0.0, 1.0, 0.0), finger_model: FingerModel | None = None):
        self.design, self.body, self.options = design, body, options
        e = np.asarray(pull_direction, dtype=float)
        if e.shape != (3,) or not np.linalg.norm(e) > 0:
            raise InputError("pull_direction", pull_direction, "must be a nonzero 3-vector")
        self.pull_direction = e / np.linalg.norm(e)
        self.frames = tuple(layout or default_layout(design.n))
        self.model = finger_model or FingerModel(design, options.finger)
        chain = self.model.chain
        width = options.pad_width or pad_width(design)
        self.pads = PadSet(chain, (0.0, *design.hinge_s, design.l0),
                           design.d + options.placement.pad_offset, width, design)
        orbits = symmetry_orbits(body, self.frames, self.pull_direction) if options.symmetry \
            else [(j, [j]) for j in range(len(self.frames))]
        self.orbits = orbits
        self.symmetric = len(orbits) < len(self.frames)
        #: pose components solved once the support is released: y translation and rotation
        #: about y when symmetric, else all six
        self.free = np.array([1, 4]) if self.symmetric else np.arange(6)
        self.fingers = [HeldFinger(self.model) for _ in orbits]
        self.pose = np.zeros(6)
        self.P = 0.0
        scale = design.mu_sf * design.a ** 2 * design.l0
        self.scale = scale
        self.cs = None
        self.weight = body.mass_kg * design.g
        self._check_open()

    @property
    def n_solved(self) -> int:
        return len(self.orbits)

    def _frames(self):
        return [self.frames[j] for j, _ in self.orbits]

    def _check_open(self):
        pc = pad_contacts(self.body, Pose(self.body.centre), self._frames(), [self.pads] * self.n_solved,
                          [np.zeros(self.design.n_s)] * self.n_solved)
        if np.min(pc.g) < 0.0:
            raise InputError("offset_mm", tuple(self.body.centre), "the object overlaps the open fingers; "
                             "place it lower or further from the fingers")

    def history(self) -> ContactHistory:
        """The contact history at the start of a step: multipliers and anchors of the last state."""
        pose = Pose(self.body.centre, self.pose)
        frames, qs = self._frames(), [f.q for f in self.fingers]
        if self.cs is None:
            pc = pad_contacts(self.body, pose, frames, [self.pads] * self.n_solved, qs)
            m = len(pc.g)
            lam_N, lam_T, x, X, zeta, g, n = np.zeros(m), np.zeros((m, 3)), pc.x, pc.X, pc.zeta, pc.g, pc.normal
        else:
            cs = self.cs
            lam_N, lam_T, x, X, zeta, g, n = cs.N, cs.T, cs.x, cs.X, cs.zeta, cs.g, cs.normal
        xo = x - np.where(np.isfinite(g), g, 0.0)[:, None] * n
        return ContactHistory(lam_N.copy(), lam_T.copy(), X.copy(), zeta.copy(), pose.to_body(xo), x.copy(), xo)

    def _fingers_view(self) -> Fingers:
        return Fingers(self._frames(), [self.pads] * self.n_solved,
                       np.array([len(images) for _, images in self.orbits], dtype=float),
                       [f.q for f in self.fingers], [f.Q.copy() for f in self.fingers], [f.S for f in self.fingers])

    def step(self, P: float, *, gravity: bool, pull: float, stage: str) -> StepRecord:
        """One load step to (P, gravity, pull); the state is kept only if it converges
        (NotConverged or :class:`NoEquilibrium` leave the last state)."""
        saved = ([f.copy_state() for f in self.fingers], self.pose.copy(), self.P, self.cs)
        try:
            return self._step(P, gravity, pull, stage)
        except (NotConverged, NoEquilibrium, np.linalg.LinAlgError):
            states, self.pose, self.P, self.cs = saved
            for f, s in zip(self.fingers, states):
                f.restore(s)
            raise

    def _step(self, P, gravity, pull, stage) -> StepRecord:
        o = self.options
        hist = self.history()
        steps = 1 if self.cs is not None or P == self.P else 2
        for f in self.fingers:
            f.solve(P, f.Q, steps=steps)
        self.P = P
        free = self.free if gravity else np.zeros(0, dtype=int)
        load = np.zeros(6)
        load[:3] = self.weight * float(gravity) * np.array([0.0, 1.0, 0.0]) + pull * self.pull_direction
        if len(free):
            self._settle(load, hist)
        x = np.concatenate([f.q for f in self.fingers] + [self.pose[free]])
        for it in range(1, o.max_stagger + 1):
            problem = Problem(self.body, self._fingers_view(), self.pose.copy(), free, load, hist, self.scale)
            x, cs, updates, its, R = solve_contact(problem, x, o.contact)
            qs, pose = problem.unpack(x)
            if self._slid(pose):
                raise NoEquilibrium(f"the object slid more than {self._slide_limit():.3g} mm: slipped out")
            for f, Qc in zip(self.fingers, cs.Q):
                f.solve(P, Qc, stiffness=it > 2)  # S of the step's start, renewed if it is slow
            mismatch = max(float(np.max(np.abs(f.q - q))) for f, q in zip(self.fingers, qs))
            if mismatch <= o.q_tol:
                p = self.pose.copy()
                p[free] = x[len(x) - len(free):]
                self.pose, self.cs = p, cs
                return self._record(stage, P, pull, gravity, cs, problem, R, mismatch, it)
            x = np.concatenate([f.q for f in self.fingers] + [x[len(x) - len(free):]])
        raise NotConverged(f"contact and fingers disagree by {mismatch:.3g} rad after {o.max_stagger} "
                           "iterations", [], x)

    def _settle(self, load, hist) -> None:
        """An object that no pad touches falls along the load until the first pad touches it
        (bisection on the gap, fingers held); :class:`NoEquilibrium` if none within max_slide."""
        frames, qs, pads = self._frames(), [f.q for f in self.fingers], [self.pads] * self.n_solved
        gap = lambda s: float(np.min(pad_contacts(  # noqa: E731
            self.body, Pose(self.body.centre, self.pose + np.r_[s * e, 0.0, 0.0, 0.0]), frames, pads, qs).g))
        if not np.linalg.norm(load[:3]) > 0:
            return
        pc = pad_contacts(self.body, Pose(self.body.centre, self.pose), frames, pads, qs)
        with np.errstate(invalid="ignore"):
            if np.any(np.isfinite(pc.g) & (hist.lam_N - self.options.contact.penalty * pc.g > 0)):
                return
        e = np.zeros(3)
        e[self.free[self.free < 3]] = load[:3][self.free[self.free < 3]]
        e /= np.linalg.norm(e)
        if gap(0.0) <= 0.0:
            return
        limit = self._slide_limit()
        if gap(limit) > 0.0:
            raise NoEquilibrium(f"no pad under the object: it falls more than {limit:.3g} mm")
        a, b = 0.0, limit
        while b - a > 1e-9 * limit:
            m = 0.5 * (a + b)
            a, b = (m, b) if gap(m) > 0.0 else (a, m)
        self.pose[:3] += a * e

    def _slide_limit(self) -> float:
        return self.options.max_slide if self.options.max_slide is not None else 0.5 * self.body.radius

    def _slid(self, pose) -> bool:
        return bool(np.linalg.norm(pose.t - getattr(self, "released", pose.t)) > self._slide_limit())

    def _record(self, stage, P, pull, gravity, cs, problem, R, mismatch, it) -> StepRecord:
        touching = cs.N > 0
        mu = self.body.friction
        T = np.linalg.norm(cs.T, axis=1)
        cone = float(np.max(T[touching] / (mu * cs.N[touching]), initial=0.0)) if mu > 0 else \
            float(np.max(T, initial=0.0))
        return StepRecord(
            stage, float(P), float(pull), float(gravity), self.pose.copy(), self.contacts(cs),
            float(np.linalg.norm(R[len(R) - len(problem.free):])) if len(problem.free) else 0.0, cone,
            float(np.max(-cs.g[touching], initial=0.0)),
            float(np.max(np.linalg.norm(cs.slip[cs.stick], axis=1), initial=0.0)), float(mismatch),
            max(f.residual_norm() for f in self.fingers), it, [f.y.copy() for f in self.fingers])

    def contacts(self, cs) -> list:
        """Every finger's pads (images of a solved finger rotated about the palm axis)."""
        rows, n = [], self.pads.n_links
        for i, (j, images) in enumerate(self.orbits):
            for k in images:
                R = rot_y(self.frames[k].azimuth - self.frames[j].azimuth)
                for link in range(n):
                    r = i * n + link
                    N = float(cs.N[r])
                    rows.append({"finger": int(k), "link": int(link), "normal_N": N,
                                 "friction_N": float(np.linalg.norm(cs.T[r])),
                                 "state": ("stick" if cs.stick[r] else "slip") if N > 0 else "open",
                                 "gap_mm": float(cs.g[r]) if np.isfinite(cs.g[r]) else None,
                                 "point_mm": (R @ cs.x[r]).tolist(),
                                 "normal_force_N": (R @ (N * cs.normal[r])).tolist(),
                                 "friction_force_N": (R @ cs.T[r]).tolist()})
        return rows


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
    share, d_share = 0.0, 1.0  # of the weight: let go at once, in smaller parts if that fails
    while share < 1.0:
        try:
            steps.append(model.step(P, gravity=min(share + d_share, 1.0), pull=0.0, stage="release"))
            tick(steps[-1])
            share = min(share + d_share, 1.0)
        except (NotConverged, NoEquilibrium) as err:
            d_share *= 0.5
            if d_share < o.min_weight_step:
                why = str(err).split("; residual history")[0]
                return HoldPath(model, steps, False, 0.0, True, f"held {share:.0%} of its weight at "
                                f"most ({why})", time.perf_counter() - t0)
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


def solve_hold(design: HandDesign, obj, *, P_cavity_MPa: float, pull_direction=(0.0, 1.0, 0.0),
               options: HoldOptions = HoldOptions(), progress=None, keep_path: bool = False,
               P_pump_MPa: float = math.nan):
    """The FEM hold of ``obj`` (a :class:`softhand.reduced.holding.objects.GraspObject`, placed by its table) at
    cavity pressure P_cavity_MPa: the common :class:`softhand.reduced.holding.hold_result.HoldResult` (P_pump_MPa
    only reported); ``progress(record)`` after every converged load step; with ``keep_path``
    also the :class:`HoldPath` (for :func:`softhand.fem.hand.hold_output.write_hold`)."""
    from softhand.fem.hand.hold_output import to_result

    body, layout = check_hold(design, obj, pull_direction, options)
    model = HoldModel(design, body, options=options, layout=layout, pull_direction=pull_direction)
    path = run_hold(model, float(P_cavity_MPa), progress=progress)
    result = replace(to_result(path, obj=obj), P_pump_MPa=float(P_pump_MPa))
    return (result, path) if keep_path else result


def check_hold(design: HandDesign, obj, pull_direction=(0.0, 1.0, 0.0), options: HoldOptions = HoldOptions()):
    """(placed body, finger frames) of ``obj`` on the design's hand, after
    :func:`check_placement`: what :func:`solve_hold` refuses, found before any FEM model."""
    from softhand.fem.hand.hold_body import body_of
    from softhand.fem.hand.hold_geometry import FingerFrame
    from softhand.reduced.holding.hand_layout import azimuths

    body = body_of(obj, design)
    layout = tuple(FingerFrame(float(a)) for a in azimuths(design))
    check_placement(body, layout, pull_direction, options, obj)
    return body, layout


def check_placement(body, layout, pull_direction, options: HoldOptions, obj) -> None:
    """InputError unless the placed object and the pull are symmetric to the hand's fingers
    (or ``options.asymmetric``): the FEM hold is validated there only. Cheap: no FEM model."""
    e = np.asarray(pull_direction, dtype=float)
    if e.shape != (3,) or not np.linalg.norm(e) > 0:
        raise InputError("pull_direction", pull_direction, "must be a nonzero 3-vector")
    symmetric = len(symmetry_orbits(body, layout, e / np.linalg.norm(e))) < len(layout)
    if not symmetric and not options.asymmetric:
        raise InputError("object", f"{obj.shape} at offset_mm {list(obj.offset_mm)}, rotation_deg "
                         f"{list(obj.rotation_deg)}, pull {[float(v) for v in pull_direction]}",
                         "the whole-hand FEM hold is validated where the object and the pull are "
                         "symmetric to the hand's fingers (centred on the palm axis, pulled along it); "
                         "for this placement use --model reduced")
