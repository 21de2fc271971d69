r"""Frictional contact of rigid pads on a rigid free object, with the fingers condensed.

Unknowns: the hinge angles :math:`q_f` of every solved finger and the object's free pose
components p. Each finger enters through its condensed response at the cavity pressure,
the physical generalised force its links need to be held at q (:mod:`softhand.fem.hand.hold_finger`),
linearised at its last FEM state: :math:`Q^{int}_f(q) = Q_f + S_f (q - q_f)`.

Contact of pad i (gap :math:`g_i`, object's outward normal :math:`n_i` at the pad's
closest point :math:`x_i`, :mod:`softhand.fem.hand.hold_geometry`), augmented Lagrangian with
Coulomb friction (Simo and Laursen 1992; Alart and Curnier's return map):

.. math:: N_i = \langle \lambda_{N,i} - \epsilon_N g_i \rangle,\qquad
          T^*_i = P_i\lambda_{T,i} - \epsilon_T P_i s_i,\qquad
          T_i = T^*_i \min(1, \mu N_i / |T^*_i|),

with :math:`P_i = I - n_i n_i^T` and :math:`s_i` the slip of the step: the displacement
of the pad's material point anchored at the step's start relative to the object's material
point anchored there. The object pushes the pad with :math:`F_i = N_i n_i + T_i`, the pad
pushes the object with :math:`-F_i`. A finger's generalised force is
:math:`Q_{c,f} = \sum_{i \in f} J_i^T E_f^T F_i` (in-plane part, :math:`E_f` its plane's
basis, :math:`J_i` the link point's Jacobian at the pad point): out-of-plane components are
reacted by the hinges. Equations:

.. math:: Q^{int}_f(q_f) - Q_{c,f}(q, p) = 0, \qquad
          \sum_f m_f \sum_{i\in f} W_i(-F_i) + (m g + F_{pull}) e = 0 \text{ (free components)},

:math:`m_f` the multiplicity of a finger standing for its symmetric images. Newton
(:func:`softhand.fem.newton.newton`) with a central-difference Jacobian (the system is small), the
multipliers fixed; Uzawa updates :math:`\lambda \leftarrow (N, T)` until every touching pad's
penetration is below ``gap_tol`` and every sticking pad's slip below ``slip_tol``; the
friction cone :math:`|T| \le \mu N` holds by construction (the return map).
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sp

from softhand.fem.hand.hold_geometry import Pose, pad_contacts, pad_points
from softhand.fem.hand.hold_options import ContactOptions
from softhand.fem.linsolve import make_solver
from softhand.fem.newton import NewtonOptions, NotConverged, newton


@dataclass
class ContactHistory:
    """What a contact carries from one load step to the next (one row per pad)."""

    lam_N: np.ndarray  #: (m,) normal multipliers [N]
    lam_T: np.ndarray  #: (m, 3) tangential multipliers (force on the pad) [N]
    X: np.ndarray      #: (m, 2) pad anchors, finger frame reference [mm]
    zeta: np.ndarray   #: (m,) pad anchors' distance from the bending plane [mm]
    Xo: np.ndarray     #: (m, 3) object anchors, placed body frame [mm]
    xp0: np.ndarray    #: (m, 3) pad anchors at the step's start, hand frame [mm]
    xo0: np.ndarray    #: (m, 3) object anchors at the step's start, hand frame [mm]


@dataclass
class Fingers:
    """The solved fingers as the contact problem sees them (lists over fingers)."""

    frames: list       #: :class:`softhand.fem.hand.hold_geometry.FingerFrame`
    padsets: list      #: :class:`softhand.fem.hand.hold_geometry.PadSet`
    mult: np.ndarray   #: how many fingers each stands for
    q0: list           #: hinge angles of the last FEM state [rad]
    Q0: list           #: physical generalised forces applied there [N mm]
    S: list            #: condensed stiffness there, physical [N mm/rad]

    @property
    def n_s(self) -> int:
        return self.padsets[0].chain.n_s

    def split(self, x) -> list:
        n = self.n_s
        return [x[i * n:(i + 1) * n] for i in range(len(self.frames))]


@dataclass
class ContactState:
    """Forces at (q, pose): per pad rows, finger by finger."""

    g: np.ndarray
    N: np.ndarray
    T: np.ndarray          #: (m, 3) friction force on the pad [N]
    normal: np.ndarray     #: (m, 3)
    x: np.ndarray          #: (m, 3) contact points on the pads [mm]
    X: np.ndarray
    zeta: np.ndarray
    slip: np.ndarray       #: (m, 3) tangential slip of the step [mm]
    stick: np.ndarray      #: (m,) bool
    Q: list = field(default_factory=list)  #: generalised force on each finger [N mm]
    wrench: np.ndarray = None  #: (6,) force and moment of the pads on the object (one of each finger) [N, N mm]
    parts: np.ndarray = None   #: (fingers, 6) each solved finger's share of the wrench [N, N mm]
    attempt: int = 0           #: the Newton tangent that converged (:func:`solve_contact`)
    penalty: tuple = (0.0, 0.0)  #: the penalties (eps_N, eps_T) it converged with [N/mm]


def evaluate(body, fingers: Fingers, qs, pose: Pose, hist: ContactHistory, eps_N: float,
             eps_T: float, keep=None, stuck=None) -> ContactState:
    """Contact forces, generalised forces and the object's wrench at (qs, pose); ``keep``
    (bool per pad): pads whose normal force is not clamped at 0 (for the Newton tangent only);
    ``stuck`` (default ``keep``): pads whose friction is not clamped to the cone there."""
    pc = pad_contacts(body, pose, fingers.frames, fingers.padsets, qs)
    n = pc.normal
    with np.errstate(invalid="ignore"):
        trial = hist.lam_N - eps_N * pc.g
        N = np.where(np.isfinite(pc.g), np.maximum(trial, 0.0), 0.0)
        if keep is not None:
            N = np.where(keep & np.isfinite(pc.g), trial, N)
    xp, xo = pad_points(fingers.frames, fingers.padsets, qs, hist.X, hist.zeta), pose.to_hand(hist.Xo)
    s = (xp - hist.xp0) - (xo - hist.xo0)
    proj = lambda v: v - np.einsum("ki,ki->k", v, n)[:, None] * n  # noqa: E731
    s_T = proj(s)
    trial = proj(hist.lam_T) - eps_T * s_T
    size = np.linalg.norm(trial, axis=1)
    cap = body.friction * N
    stick = size <= cap
    T = np.where(stick[:, None], trial, trial * (cap / np.where(size > 0, size, 1.0))[:, None])
    stuck = keep if stuck is None else stuck
    if stuck is not None and body.friction > 0:  # the tangent sticks these pads (a stick predictor)
        T = np.where(stuck[:, None], trial, T)
    T = np.where((N > 0)[:, None] | (keep[:, None] if keep is not None else False), T, 0.0)
    F = N[:, None] * n + T
    Q, i = [], 0
    for frame, pads, q in zip(fingers.frames, fingers.padsets, qs):
        m = pads.n_links
        f2 = F[i:i + m] @ frame.matrix(pads.design)              # in-plane components
        _, J, _ = pads.chain.point_map(q, np.arange(m), pc.X[i:i + m], order=1)
        Q.append(np.einsum("maj,ma->j", J, f2))
        i += m
    mult = np.repeat(fingers.mult, [p.n_links for p in fingers.padsets])
    per_pad = -mult[:, None] * np.hstack([F, np.cross(pc.x - pose.centre, F)])
    parts = np.add.reduceat(per_pad, np.cumsum([0] + [p.n_links for p in fingers.padsets[:-1]]), axis=0)
    return ContactState(pc.g, N, T, n, pc.x, pc.X, pc.zeta, s_T, stick & (N > 0), Q,
                        parts.sum(axis=0), parts=parts)


@dataclass
class Problem:
    """The condensed hold at one load: fingers, object, external load and free pose components."""

    body: object
    fingers: Fingers
    pose0: np.ndarray      #: (6,) the pose the free components start from (the fixed ones stay)
    free: np.ndarray       #: indices into the pose's 6 components that are unknowns
    load: np.ndarray       #: (6,) external wrench on the object about its centre [N, N mm]
    hist: ContactHistory
    scale: float           #: force scale for the tolerance [N mm]
    #: (6,) viscous support on the object's pose, c (p - pose0) [N/mm, N mm/rad]: a relaxation
    #: step (:meth:`softhand.fem.hand.hold_model.HoldModel.step`); None: none
    damping: np.ndarray | None = None
    #: the pull applied through a stiff spring (a load cell whose far end is moved): (k [N/mm],
    #: e (3,), a (3,)), the force k e.(a - t) e on the object at translation t; None: none
    drive: tuple | None = None

    def unpack(self, x):
        n = len(self.fingers.frames) * self.fingers.n_s
        p = self.pose0.copy()
        p[self.free] = x[n:]
        return self.fingers.split(x[:n]), Pose(self.body.centre, p)

    def residual(self, x, eps_N, eps_T, keep=None, stuck=None):
        qs, pose = self.unpack(x)
        cs = evaluate(self.body, self.fingers, qs, pose, self.hist, eps_N, eps_T, keep, stuck)
        f = self.fingers
        R = [Q0 + S @ (q - q0) - Qc for Q0, S, q, q0, Qc in zip(f.Q0, f.S, qs, f.q0, cs.Q)]
        F = cs.wrench + self.load
        if self.damping is not None:
            F = F - self.damping * (np.r_[pose.t, pose.r] - self.pose0)
        if self.drive is not None:
            k, e, a = self.drive
            F[:3] += k * float(e @ (a - pose.t)) * e
        R.append(F[self.free])
        return np.concatenate(R), cs


def _kept_open(problem: Problem, x, eps_N: float, eps_T: float, options: ContactOptions) -> bool:
    """Whether a pad at x is open (no normal force) yet within keep_gap of touching."""
    g = problem.residual(x, eps_N, eps_T)[1].g
    with np.errstate(invalid="ignore"):
        trial = problem.hist.lam_N - eps_N * g
        return bool(np.any(np.isfinite(g) & (trial <= 0.0) & (trial > -eps_N * options.keep_gap)))


def _jacobian(problem: Problem, x, steps, eps_N, eps_T, kept, stuck) -> np.ndarray:
    """The residual's Jacobian by central differences, with the tangent's kept and stuck pads.
    A finger's hinge angles move only its own pads: the j-th hinge of every finger is
    perturbed at once (a colouring), its columns taken from each finger's own rows and its
    share of the object's wrench -- 2 (n_s + free) evaluations instead of 2 (fingers n_s + free)."""
    fingers = problem.fingers
    n_f, n_s = len(fingers.frames), fingers.n_s
    n_q = n_f * n_s
    K = np.zeros((len(x), len(x)))
    for j in range(n_s):
        cols = np.arange(n_f) * n_s + j
        e = np.zeros(len(x))
        e[cols] = steps[cols]
        Rp, cp = problem.residual(x + e, eps_N, eps_T, kept, stuck)
        Rm, cm = problem.residual(x - e, eps_N, eps_T, kept, stuck)
        for f, col in enumerate(cols):
            rows = slice(f * n_s, (f + 1) * n_s)
            K[rows, col] = (Rp[rows] - Rm[rows]) / (2 * steps[col])
            K[n_q:, col] = (cp.parts[f] - cm.parts[f])[problem.free] / (2 * steps[col])
    for col in range(n_q, len(x)):
        e = np.zeros(len(x))
        e[col] = steps[col]
        K[:, col] = (problem.residual(x + e, eps_N, eps_T, kept, stuck)[0]
                     - problem.residual(x - e, eps_N, eps_T, kept, stuck)[0]) / (2 * steps[col])
    return K


def solve_contact(problem: Problem, x0, options: ContactOptions, warm=None):
    """Newton + Uzawa on the condensed hold from x0; returns (x, ContactState, updates, iterations,
    residual at x); raises NotConverged when no equilibrium is found. ``warm``: the ContactState
    of a solve of the same step (the fingers' linearisation since renewed): Uzawa goes on from
    its multipliers and penalties, Newton first tries the tangent that converged there."""
    eps_N, eps_T = options.penalty, options.tangent_penalty
    hist = replace(problem.hist)
    first = 0
    if warm is not None:
        hist.lam_N, hist.lam_T = warm.N.copy(), warm.T.copy()
        (eps_N, eps_T), first = warm.penalty, warm.attempt
    problem = replace(problem, hist=hist)
    x, its, last = np.array(x0, dtype=float), 0, np.inf
    n_q = len(problem.fingers.frames) * problem.fingers.n_s
    steps = np.r_[np.full(n_q, 1e-7), np.where(problem.free < 3, 1e-5, 1e-7)]
    solver = make_solver("superlu")
    tol = options.rtol * problem.scale
    stall = options.stall if problem.damping is None else None

    for update in range(options.max_updates + 1):
        def fun(x, tangent, keep_gap=options.keep_gap):
            R, cs = problem.residual(x, eps_N, eps_T)
            # the tangent keeps pads within keep_gap of touching in contact (a generalised
            # Jacobian): a step that opens a softly held pad is pulled back, not lost
            with np.errstate(invalid="ignore"):
                kept = np.isfinite(cs.g) & (problem.hist.lam_N - eps_N * cs.g > -eps_N * keep_gap)
            # "stick": every kept pad sticks in the tangent (regular when every pad slips at the
            # start of a load reversal); "slip": a pad slipping at x has the return map's own
            # derivative (no stiffness along its slip), else a slipping mode, e.g. an off-axis
            # sphere turning in its pads, keeps the stick stiffness and Newton stalls
            stuck = kept if tangent == "stick" else kept & ~((cs.N > 0) & ~cs.stick)
            K = _jacobian(problem, x, steps, eps_N, eps_T, kept, stuck)
            K[n_q:, n_q:] += 1e-9 * problem.scale * np.eye(len(x) - n_q)  # a free rotation of a frictionless sphere
            return R, sp.csr_matrix(K)

        # full steps first (a softly held pad keeps its gap window); when they cycle between
        # contact states, again from the same start with Armijo backtracking on ||R||; then
        # both again with the slipping pads' own tangent; last, where the failed iterate has an
        # open pad within keep_gap, the residual's own Jacobian (no pad kept: such a pad, kept,
        # can turn the Newton direction into an ascent one, measured on a sphere off the axis)
        attempts = [(t, m, options.keep_gap) for t in ("stick", "slip") for m in ("finite", "residual")]
        attempts.append(("slip", "residual", 0.0))
        # the one that converged last goes first (the slipping pads' tangent, once an off-axis
        # object turns in its pads, converges in 2-5 iterations where the stick tangent fails in 40)
        order = [first] + [k for k in range(len(attempts)) if k != first]
        error = None
        for k in order:
            tangent, merit, keep_gap = attempts[k]
            if keep_gap == 0.0 and error is not None and not _kept_open(problem, error.x, eps_N, eps_T, options):
                continue
            try:
                res = newton(lambda x: fun(x, tangent, keep_gap), x,
                             NewtonOptions(rtol=0.0, atol=tol, max_iter=options.max_iter, merit=merit,
                                           forcing=None, xtol=1e-14, max_backtracks=30, stall=stall),
                             solver=solver, residual=lambda x: problem.residual(x, eps_N, eps_T)[0])
                first, error = k, None
                break
            except NotConverged as err:
                error = err
        if error is not None:
            raise error
        x, its = res.x, its + res.iterations
        cs = problem.residual(x, eps_N, eps_T)[1]
        touching = cs.N > 0
        penetration = float(np.max(-cs.g[touching], initial=0.0))
        slip = float(np.max(np.linalg.norm(cs.slip[cs.stick], axis=1), initial=0.0))
        if penetration <= options.gap_tol and slip <= options.slip_tol:
            cs.attempt, cs.penalty = first, (eps_N, eps_T)
            return x, cs, update, its, problem.residual(x, eps_N, eps_T)[0]
        measure = max(penetration / options.gap_tol, slip / options.slip_tol)
        if measure > 0.25 * last:  # slow Uzawa (near-dependent contacts): stiffen
            eps_N, eps_T = min(10 * eps_N, options.max_penalty), min(10 * eps_T, options.max_penalty)
        last = measure
        hist.lam_N, hist.lam_T = cs.N.copy(), cs.T.copy()
    raise NotConverged(f"contact: penetration {penetration:.3g} mm, stick slip {slip:.3g} mm after "
                       f"{options.max_updates} augmented-Lagrangian updates", [], x)
