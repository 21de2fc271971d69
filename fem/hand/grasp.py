r"""The grasp FEM: the finger FEM of :mod:`softhand.fem.hand.finger` closing on a rigid object.

The object (diameter D) is centred on the hand's axis, at depth ``depth`` below the palm
(the hand frame of :mod:`softhand.reduced.equations.kinematics`: x outward, y down, the finger base on the
hinge plate at (``base_offset``, 0)). By default (:func:`default_depth`) the hand comes
down over the object until the object's top is ``palm_gap`` below the palm, or -- for
objects too big to pass between the open fingers -- until the open fingers' pads are
``clearance`` from its surface. The fingers then close under the cavity pressure P.

Contact: frictionless, rigid link pads against the analytic object (:mod:`softhand.fem.contact`),
augmented Lagrangian with Uzawa updates until the largest ``|gap|`` of a loaded pad is below
``gap_tol`` (its own convergence check: gap at convergence vs penalty); the penalty grows
tenfold whenever an update does not cut that gap by 4 (two nearly dependent contacts,
e.g. both sides of a hinge, make plain Uzawa slow). The object's
weight share m g / n (eq. (24)) acts tangentially on the touching pads, split by their
normal forces. The mesh is the half tube (symmetry plane z = 0), so the model's links
carry half of every physical load: the generalised forces passed to the finger are
half those of :func:`softhand.fem.contact.contact_load`; the forces reported are physical.

Weight vector (eqs. (21)-(23)): w = (q(P + dP) - q(P)) / sum(q(P + dP) - q(P)), the
virtual displacement of the hinge angles between two converged contact states, so
sum(w) = 1 by construction.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import brentq

from softhand.fem.constraints import PlanarChain
from softhand.fem.contact import Circle, Pads, contact_load, gaps
from softhand.fem.hand.finger import FingerModel
from softhand.fem.hand.frame import hand_frame, to_finger_frame
from softhand.fem.linsolve import make_solver
from softhand.fem.newton import NewtonOptions, NotConverged
from softhand.fem.newton_path import PathOptions, solve_path
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError


@dataclass(frozen=True)
class GraspOptions:
    """Placement of the object and the contact treatment."""

    palm_gap: float = 10.0    #: object top below the palm, when it fits between the open fingers [mm]
    clearance: float = 2.0    #: else: gap between the open fingers' pads and the object [mm]
    pad_offset: float = 0.0   #: grasping face beyond the hinge axes' line, towards the object [mm]
    penalty: float = 100.0    #: contact penalty to start with [N/mm]
    max_penalty: float = 1e6  #: the penalty grows x10 while the penetration stagnates, up to this [N/mm]
    gap_tol: float = 1e-4     #: stop the Uzawa updates when every penetration is below [mm]
    share_tol: float = 1e-3   #: ... and the weight shares changed less than this
    max_updates: int = 20     #: Uzawa updates before giving up
    steps: int = 2            #: initial load steps from P = 0
    #: a load step whose residual grows 100-fold is cut back at once, not after max_iter
    #: factorisations: at 1.2 MPa, 120-180 mm, the first step's two failed tries took 33-41
    #: of a solve's 88-104 factorisations (``softhand weights --diameter-mm D --pressure-mpa 1.2``)
    newton: NewtonOptions = field(default_factory=lambda: NewtonOptions(rtol=1e-9, diverge=100.0, stall=8))

    def __post_init__(self):
        for name in ("penalty", "gap_tol", "share_tol"):
            if not getattr(self, name) > 0:
                raise InputError(name, getattr(self, name), "must be a positive number")
        if not self.clearance >= 0 or not self.palm_gap >= 0:
            raise InputError("clearance", (self.palm_gap, self.clearance), "must be >= 0 [mm]")


def pads_of(finger_chain, design: HandDesign, options: GraspOptions) -> Pads:
    """The links' grasping faces: the hinge plate line y = d (+ pad_offset), base to tip."""
    return Pads(finger_chain, (0.0, *design.hinge_s, design.l0), design.d + options.pad_offset)


def _open_gap(pads: Pads, design: HandDesign, diameter: float, depth: float) -> float:
    """Smallest gap [mm] between the open finger's pads and the object centred at depth."""
    centre = to_finger_frame([0.0, depth], design)
    return float(np.min(gaps(pads, Circle(tuple(centre), 0.5 * diameter), np.zeros(design.n_s)).g))


def check_placement(design: HandDesign, diameter: float, depth: float,
                    options: GraspOptions | None = None, *, pads: Pads | None = None) -> None:
    """InputError if the object (diameter [mm]) centred at depth [mm] overlaps the open
    finger's pads (default: those of the design's link chain as :class:`softhand.fem.hand.finger.FingerModel`
    builds it, no mesh, so it is checked before any meshing or FEM)."""
    top, reach = depth - 0.5 * diameter, float(np.sum(design.link_lengths))
    if top < 0.0:
        raise InputError("depth_mm", depth, f"puts the object (diameter {diameter:g} mm) above the palm; its "
                                            f"centre goes at least {0.5 * diameter:g} mm below it")
    if top >= reach:
        raise InputError("depth_mm", depth, f"puts the object's top {top:g} mm below the palm, beyond the "
                                            f"finger's reach ({reach:g} mm, pointing straight down)")
    if pads is None:
        chain = PlanarChain(np.c_[design.hinge_s, np.full(design.n_s, design.d)])
        pads = pads_of(chain, design, options or GraspOptions())
    if _open_gap(pads, design, diameter, depth) < 0.0:
        raise InputError("depth_mm", depth, f"the object (diameter {diameter:g} mm) overlaps the open "
                                            "finger at this depth; place it deeper")


def default_depth(pads: Pads, design: HandDesign, diameter: float, options: GraspOptions) -> float:
    """Depth of the object's centre below the palm [mm]: its top ``palm_gap`` below the palm,
    lowered until the open fingers clear it by ``clearance`` (the gap grows with depth)."""
    depth = 0.5 * diameter + options.palm_gap
    fun = lambda y: _open_gap(pads, design, diameter, y) - options.clearance  # noqa: E731
    if fun(depth) >= 0.0:
        return depth
    hi = depth + diameter + 2.0 * design.l0
    if fun(hi) < 0.0:
        raise InputError("diameter_mm", diameter, "the object does not clear the open fingers")
    return float(brentq(fun, depth, hi, xtol=1e-9))


@dataclass
class GraspState:
    """A converged contact state (physical forces; hand frame where stated)."""

    P: float                #: cavity pressure [MPa]
    q: np.ndarray           #: hinge angles theta_hat_i [rad]
    N: np.ndarray           #: normal force of the object on each link's pad, base..tip [N]
    gap: np.ndarray         #: gap of each pad [mm] (inf: facing away)
    F: np.ndarray           #: resultant force of the object on the finger, hand frame (x out, y down) [N]
    F_v: float              #: F . n_out of the tip link: the normal force of eq. (29) [N]
    updates: int            #: Uzawa (augmented Lagrangian) updates
    iterations: int         #: Newton iterations
    penalty: float          #: the contact penalty at convergence [N/mm]
    y: np.ndarray = field(repr=False, default=None)
    factorizations: int = 0  #: tangents factorised (fewer than iterations with refactor="adaptive")

    @property
    def theta(self) -> float:
        return float(np.sum(self.q))


class GraspModel:
    """The finger FEM, an object and its contact."""

    def __init__(self, finger: FingerModel, diameter: float, *, mass: float = 0.0,
                 depth: float | None = None, options: GraspOptions = GraspOptions()):
        design = finger.design
        if not diameter > 0:
            raise InputError("diameter_mm", diameter, "must be a positive number")
        if not mass >= 0:
            raise InputError("mass_kg", mass, "must be a number >= 0")
        self.finger, self.design, self.options = finger, design, options
        self.diameter, self.mass = float(diameter), float(mass)
        self.pads = pads_of(finger.chain, design, options)
        self.depth = default_depth(self.pads, design, diameter, options) if depth is None \
            else float(depth)
        check_placement(design, diameter, self.depth, pads=self.pads)
        self.circle = Circle(tuple(to_finger_frame([0.0, self.depth], design)), 0.5 * diameter)
        self.weight = self.mass * design.g / design.n  #: the weight share, eq. (24) [N]
        # one solver for every state of this model: the symbolic analysis is done once. Double
        # precision, as for the free finger (fem.hand.finger_sweep): the single-precision factor
        # of this tangent refines too slowly and fell back after one wasted factorisation.
        # Unsymmetric under a weight: the tangential load is a follower
        self.solver = make_solver(symmetric=self.weight == 0.0, precision="double")

    def load(self, q, multipliers, shares, penalty: float | None = None):
        """Physical contact load at hinge angles q (:class:`softhand.fem.contact.ContactLoad`)."""
        penalty = self.options.penalty if penalty is None else penalty
        return contact_load(gaps(self.pads, self.circle, q), penalty, multipliers,
                            weight=self.weight, shares=shares)

    def state_load(self, state: GraspState):
        """The contact load of a converged state: its normal forces N and weight shares
        (penalty 0 and multipliers N reproduce N exactly), with the forces and their points."""
        shares = state.N / state.N.sum() if state.N.sum() > 0 else np.zeros(len(state.N))
        return contact_load(gaps(self.pads, self.circle, state.q), 0.0, state.N,
                            weight=self.weight, shares=shares)

    def _link_load(self, multipliers, shares, penalty):
        def link_load(q):
            L = self.load(q, multipliers, shares, penalty)
            return 0.5 * L.Q, 0.5 * L.dQ  # the half model carries half the load
        return link_load

    def _path(self, y, P0, P1, multipliers, shares, penalty, solver, steps):
        link_load = self._link_load(multipliers, shares, penalty)
        d = self.design
        scale = d.mu_sf * d.a ** 2 * d.l0
        res = solve_path(lambda x, t: self.finger.residual_tangent(x, P0 + t * (P1 - P0), link_load),
                         y, PathOptions(steps=steps, newton=self.options.newton),
                         solver=solver, scale_t=lambda t: scale,
                         residual_t=lambda x, t: self.finger.residual(x, P0 + t * (P1 - P0), link_load))
        return res.x[-1], res.total_iterations

    def solve(self, P: float, *, start: GraspState | None = None) -> GraspState:
        """The converged contact state at cavity pressure P [MPa], from ``start`` (or P = 0)."""
        n_links = self.pads.n_links
        if start is None:
            y, P0, lam, shares = self.finger.constraint.zero(), 0.0, np.zeros(n_links), np.zeros(n_links)
        else:
            y, P0, lam = start.y, start.P, start.N
            shares = start.N / start.N.sum() if start.N.sum() > 0 else np.zeros(n_links)
        solver, factorizations = self.solver, self.solver.n_factorizations
        its, steps = 0, self.options.steps if start is None else 1
        penalty, last = self.options.penalty if start is None else start.penalty, np.inf
        for update in range(self.options.max_updates + 1):
            try:
                y, n = self._path(y, P0, P, lam, shares, penalty, solver, steps)
            except NotConverged as err:
                t, x = err.last_converged or (0.0, y)
                raise self._failure(f"Newton stopped at P = {P0 + t * (P - P0):.4g} MPa on the way "
                                    f"to {P:.4g} MPa", err, P0 + t * (P - P0), x, lam, shares,
                                    penalty, update, its) from err
            its, P0, steps = its + n, P, 1
            L = self.load(self.finger.constraint.q(y), lam, shares, penalty)
            g = gaps(self.pads, self.circle, self.finger.constraint.q(y)).g
            new_shares = L.N / L.N.sum() if L.N.sum() > 0 else np.zeros(n_links)
            penetration = float(np.max(np.abs(g[(L.N > 0) | (lam > 0)]), initial=0.0))
            if penetration <= self.options.gap_tol and \
                    np.max(np.abs(new_shares - shares)) <= self.options.share_tol:
                return replace(self._state(P, y, L, g, update, its, penalty),
                               factorizations=solver.n_factorizations - factorizations)
            if penetration > 0.25 * last:  # slow Uzawa (near-dependent contacts): stiffen
                penalty = min(10.0 * penalty, self.options.max_penalty)
            lam, shares, last = L.N, new_shares, penetration
        raise self._failure(f"contact: penetration {penetration:.3g} mm at P = {P:.4g} MPa after "
                            f"{self.options.max_updates} augmented-Lagrangian updates",
                            NotConverged("", [], y), P, y, lam, shares, penalty, update, its)

    def _failure(self, message, err, P, y, lam, shares, penalty, updates, its) -> NotConverged:
        """The NotConverged to raise: ``message``, and as ``.state`` the finger's last converged
        configuration y at cavity pressure ``.pressure`` = P under the contact load it had
        (its penetration may exceed gap_tol: Uzawa had not finished), for the caller to save."""
        q = self.finger.constraint.q(y)
        state = self._state(P, y, self.load(q, lam, shares, penalty), gaps(self.pads, self.circle, q).g,
                            updates, its, penalty)
        failure = NotConverged(message, err.history, err.x, err.last_converged)
        failure.pressure, failure.state = float(P), state
        return failure

    def _state(self, P, y, L, g, updates, its, penalty) -> GraspState:
        q = np.array(self.finger.constraint.q(y))
        M, _ = hand_frame(self.design)
        F = L.forces.sum(axis=0)
        n_tip = np.array([-math.sin(q.sum()), math.cos(q.sum())])  # tip pad normal, finger frame
        return GraspState(P=float(P), q=q, N=L.N, gap=g, F=M @ F, F_v=float(-F @ n_tip),
                          updates=updates, iterations=its, penalty=penalty, y=np.array(y))


@dataclass(frozen=True)
class WeightResult:
    """w from two contact states (eqs. (21)-(23))."""

    w: np.ndarray          #: (n_s,) hinge weight vector, sum = 1
    state: GraspState      #: the state at P
    state_dP: GraspState   #: the state at P + dP
    ndofs: int             #: unknowns of the finger FEM
    wall_seconds: float    #: wall time of both solves


def weight_vector(a: GraspState, b: GraspState) -> np.ndarray:
    """w = dq / sum(dq) between two states (eq. (21)); InputError if sum(dq) vanishes."""
    dq = b.q - a.q
    if abs(dq.sum()) < 1e-9:
        raise InputError("pressure_MPa", (a.P, b.P), "the bend angle does not change: w undefined")
    return dq / dq.sum()


def grasp_weights(model: GraspModel, P: float, dP: float, start: GraspState | None = None,
                  on_state=None) -> WeightResult:
    """Contact states at P and P + dP [MPa] and the weight vector between them (the state at P
    continued from ``start``, a converged state nearby, if given); ``on_state`` is called with
    each state as it converges (a progress bar)."""
    if not P > 0 or not dP > 0:
        raise InputError("pressure_MPa", (P, dP), "P and dP must be positive")
    t0 = time.perf_counter()
    a = None
    try:
        a = model.solve(P, start=start)
        if on_state is not None:
            on_state(a)
        b = model.solve(P + dP, start=a)
        if on_state is not None:
            on_state(b)
    except NotConverged as err:  # what was reached, for the caller to save: ``.states``, ``.model``
        err.model = model
        err.states = tuple(s for s in (a, getattr(err, "state", None)) if s is not None)
        raise
    return WeightResult(weight_vector(a, b), a, b, model.finger.ndofs, time.perf_counter() - t0)
