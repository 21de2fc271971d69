r"""One load step of the whole-hand FEM hold (:mod:`softhand.fem.hand.hold` follows the path): the
hand, the placed object and the state along the path, stepped by the contact problem and the
fingers' FEM in turn.

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

Letting go (stage "release") of an object placed without the hand's symmetry can need the
object to slide far from where its support held it: closed on an object held off the palm
axis, one finger pushes harder than its opposite, and the unbalanced push must be taken up
by pads that slip; a box turned about the palm's axis (symmetric or not) is twisted by its pads
more than friction carries and must turn. No equilibrium is then near the last state, and one load step's Newton
does not find one (its corrections grow to millimetres along the slipping pads' zero
stiffness). Such a step is followed as a path (``HoldModel._relax``): the object moves
against a viscous support that fades from step to step, each step anchoring friction where
the last ended, until the support carries less than ``relax_force`` of the load and the
step without it converges -- or the object slides farther than the slide limit: it slipped out.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from softhand.fem.hand.finger import FingerModel
from softhand.fem.hand.hold_contact import ContactHistory, Fingers, Problem, solve_contact
from softhand.fem.hand.hold_finger import HeldFinger
from softhand.fem.hand.hold_geometry import PadSet, Pose, contact_rows, default_layout, pad_contacts
from softhand.fem.hand.hold_options import HoldOptions, symmetry_orbits
from softhand.fem.newton import NotConverged
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.holding.hand_layout import pad_width


class NoEquilibrium(RuntimeError):
    """The object slipped out: no equilibrium at this load."""


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
    relaxed: int = 0      #: relaxation steps the object slid through to this state (0: none needed)


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
        #: called after each step of a followed path (``HoldModel._relax``) with (step, support force [N])
        self.on_path_step = None
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

    def step(self, P: float, *, gravity: bool, pull: float, stage: str, path: bool = False,
             drive: float | None = None) -> StepRecord:
        """One load step to (P, gravity, pull); the state is kept only if it converges
        (NotConverged or :class:`NoEquilibrium` leave the last state). A release step that finds no
        equilibrium near the last state is followed as a path (``HoldModel._relax``) where the hand is not
        symmetric, or with ``path``. ``drive`` [mm]: the pull is a spring of ``options.drive_stiffness``
        [N/mm] along the pull direction whose far end is ``drive`` along it from where the object was let go
        (``pull`` is then ignored, and the record's pull is the spring's force)."""
        saved = self.save()
        try:
            return self._step(P, gravity, pull, stage, drive=drive)
        except (NotConverged, NoEquilibrium, np.linalg.LinAlgError) as err:
            self.restore(saved)
            if stage != "release" or (self.symmetric and not path) or not self.options.relax_steps \
                    or isinstance(err, NoEquilibrium):
                raise
        try:
            return self._relax(P, gravity, pull, stage)
        except (NotConverged, NoEquilibrium, np.linalg.LinAlgError):
            self.restore(saved)
            raise

    def save(self):
        """The state along the path (the fingers' FEM states, pose, pressure, contact state)."""
        return [f.copy_state() for f in self.fingers], self.pose.copy(), self.P, self.cs

    def restore(self, saved) -> None:
        """Back to a state of :meth:`save`."""
        states, pose, self.P, self.cs = saved
        self.pose = pose.copy()
        for f, s in zip(self.fingers, states):
            f.restore(s)

    def _relax(self, P, gravity, pull, stage) -> StepRecord:
        """The load step as a path where it finds no equilibrium near the last state: the object
        moves against a viscous support c (p - p_last) that fades step by step, each step
        anchoring friction where the last ended (the slide followed in increments), until the
        support's force is below ``relax_force`` of the load and the step without it converges.
        NoEquilibrium where the object slides farther than the slide limit: it slipped out.
        While the support's force decays (to below half its last), c halves and the step
        without it is tried; while it does not (the object sliding on), c quarters."""
        r = self.body.radius
        load = np.linalg.norm(self.weight * gravity * np.array([0.0, 1.0, 0.0]) + pull * self.pull_direction)
        c = 2.0 * self.weight * np.r_[1.0, 1.0, 1.0, r * r, r * r, r * r]  # [N/mm, N mm/rad]
        last = np.inf
        for k in range(self.options.relax_steps):
            p0 = self.pose.copy()
            try:
                self._step(P, gravity, pull, stage, damping=c)
            except (NotConverged, np.linalg.LinAlgError):
                c = 4.0 * c
                continue
            support = float(np.linalg.norm(c[:3] * (self.pose - p0)[:3]))
            if self.on_path_step is not None:
                self.on_path_step(k, support)
            settling, last = support < 0.5 * last, support
            if settling and support <= self.options.relax_force * load:
                saved = self.save()
                try:
                    record = self._step(P, gravity, pull, stage)
                    record.relaxed = k + 1
                    return record
                except (NotConverged, np.linalg.LinAlgError):
                    self.restore(saved)
            c = (0.5 if settling else 0.25) * c
        raise NotConverged(f"no equilibrium after {self.options.relax_steps} relaxation steps", [], self.pose)

    def _step(self, P, gravity, pull, stage, damping=None, drive=None) -> StepRecord:
        o = self.options
        spring = None
        if drive is not None:
            spring, pull = (o.drive_stiffness, self.pull_direction, self.released + drive * self.pull_direction), 0.0
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
        cs = None
        for it in range(1, o.max_stagger + 1):
            problem = Problem(self.body, self._fingers_view(), self.pose.copy(), free, load, hist, self.scale,
                              damping, spring)
            x, cs, updates, its, R = solve_contact(problem, x, o.contact, warm=cs if it > 1 else None)
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
                if spring is not None:  # the spring's force along the pull
                    pull = spring[0] * float(spring[1] @ (spring[2] - p[:3]))
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
            stage, float(P), float(pull), float(gravity), self.pose.copy(),
            contact_rows(self.orbits, self.frames, self.pads.n_links, cs),
            float(np.linalg.norm(R[len(R) - len(problem.free):])) if len(problem.free) else 0.0, cone,
            float(np.max(-cs.g[touching], initial=0.0)),
            float(np.max(np.linalg.norm(cs.slip[cs.stick], axis=1), initial=0.0)), float(mismatch),
            max(f.residual_norm() for f in self.fingers), it, [f.y.copy() for f in self.fingers])
