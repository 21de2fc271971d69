r"""FEM-informed grasping force: the finger in equilibrium against the object where it touches.

Eq. (25) charges all the pressure work beyond the free curve to a force at the finger's
*tip*, moving with the tip along w. The grasp FEM's finger touches the object with one
link's pad, often far from the tip, and rolls on it; this model keeps what the FEM knows
and drops the tip assumption:

* **The finger, hinge by hinge** (:mod:`softhand.reduced.calibrated.finger_hinges`): each hinge's
  moment M_j(theta_hat_j; P) from the finger FEM locked at its hinges (a blocked-hinge table), no
  coupling between hinges. Without it, the free finger's W_f and Q split equally over the hinges,
  the contact force of a finger held by the object low on it comes out 50 % too large.
* **The contact where it is** (:mod:`softhand.reduced.equations.contact`, the grasp FEM's geometry): the
  object's force on pad k at its closest point x*, F = -N nu + T t_k (normal force N along
  the outward normal -nu, the weight share T = m g / n along the link, as in the grasp FEM).
* **Virtual work hinge by hinge** (eq. (1) with every hinge free, not only along w):

  .. math:: \frac{\partial E}{\partial\hat\theta_j} = F\cdot\frac{\partial x^*}{\partial\hat\theta_j}
            \quad (j = 1..n_s), \qquad g_k(\hat\theta) = 0.

  Hinges beyond the touching link carry no load: they bend as the free finger's. The n_s
  equations and the gap fix the k proximal hinge angles and N. Where no pad settles alone,
  the object sits in the crease of pads k and k + 1 (a gap and an N each, the weight shared
  in proportion to N): the state between the two pads' own, continuous with the distal one's.

F_v is the FEM's: the resultant F projected on the tip link's outward normal (eq. (29)).
Two ways to pose a grasp: :func:`grasp_state` at a placement (depth; default the grasp
FEM's), theta follows; :func:`grasp_state_at_angle` at a bend theta, the depth that gives it
follows (the Fig. 8 states). :func:`vertical_force` is the one function to call.
P is the finger's cavity pressure. Units: mm, N, MPa, rad.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from scipy.optimize import brentq, root

from softhand.reduced.calibrated.finger_hinges import fem_finger, hinge_moments
from softhand.reduced.equations import contact, hand, kinematics
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError

#: a pad other than the touching one penetrating by more than this [mm] moves the contact there
PENETRATION = 1e-6
#: the equilibrium's tolerance (scipy hybr, relative on the unknowns)
_XTOL = 1e-10


class GraspState(NamedTuple):
    """One equilibrium of the finger against the object (physical forces, hand frame)."""

    P: float            #: cavity pressure [MPa]
    depth: float        #: object centre below the palm [mm]
    q: np.ndarray       #: hinge angles theta_hat (n_s,) [rad]
    link: int           #: touching pad (0 base .. n_s tip); -1: no contact
    N: float            #: normal force of the object on the pad [N]
    point: np.ndarray   #: contact point x* (2,) [mm]
    F: np.ndarray       #: force of the object on the finger (2,), x out, y down [N]
    F_v: float          #: F . n_out of the tip link (29) [N]
    #: in a crease (the object on pads link and link + 1 at once): (N [N], x* (2,) [mm]) of pad
    #: link + 1, whose force F includes; None on one pad
    crease: tuple | None = None

    @property
    def theta(self) -> float:
        return float(np.sum(self.q))


def _load(q, centre, link: int, weight: float, design: HandDesign, corner: bool = False):
    """(centre distance, dg/dq, generalised weight force (n_s,), x*, nu, tangent) of pad ``link``
    (``corner``: touching with its far end, the hinge it shares with the next pad)."""
    xs, nu, dx = contact.pad_motion(q, centre, link, design, end=corner)
    alpha = kinematics.link_angles(q, design)[link]
    t = np.array([-math.sin(alpha), math.cos(alpha)])
    rho = float(np.linalg.norm(np.asarray(centre) - xs))  # the caller subtracts the radius
    return rho, -dx @ nu, weight * (dx @ t), xs, nu, t


def _state(P, depth, q, link, N, weight, design, corner=False) -> GraspState:
    """The state with pad ``link`` (its far end if ``corner``) pressed by N; N a pair in a crease
    (pads link and link + 1; the weight shared in proportion to N)."""
    if link < 0:
        return GraspState(P, depth, q, -1, 0.0, np.full(2, np.nan), np.zeros(2), 0.0)
    Ns = np.atleast_1d(np.asarray(N, float))
    share = Ns / Ns.sum() if len(Ns) > 1 else np.ones(1)
    at = [_load(q, (0.0, depth), k, 1.0, design, corner)[3:] for k in range(link, link + len(Ns))]  # (x*, nu, t)
    F = sum(-Nk * nu + weight * sk * t for Nk, sk, (_, nu, t) in zip(Ns, share, at))
    alpha = q.sum() - design.theta0
    return GraspState(P, depth, q, link, float(Ns[0]), at[0][0], F, float(F @ [math.cos(alpha), math.sin(alpha)]),
                      (float(Ns[1]), at[1][0]) if len(Ns) > 1 else None)


def _solve_link(P, depth, radius, link, weight, q0, design, corner=False, crease=False):
    """Hinges 1..link and N with pad ``link`` (its far end if ``corner``) on the object, distal hinges
    as q0's; ``crease``: pads link and link + 1 (hinges 1..link + 1, N a pair; the weight shared by N)."""
    centre, k, m = (0.0, depth), link + crease, 1 + crease  # k held hinges, m contacts

    def terms(q):  # per contact (rho, dg/dq, unit weight's generalised force)
        return [_load(q, centre, link + i, 1.0, design, corner)[:3] for i in range(m)]

    def residual(x):
        q, N = np.concatenate([x[:k], q0[k:]]), x[k:]
        share = weight * (N / N.sum() if crease and N.sum() != 0.0 else np.ones(m))
        at = terms(q)
        f = hinge_moments(q, P, design) - sum(Ni * grad + wi * Tq for (_, grad, Tq), Ni, wi in zip(at, N, share))
        return np.concatenate([f[:k], [rho - radius for rho, *_ in at]])

    _, grad, Tq = terms(q0)[0]
    M = (hinge_moments(q0, P, design) - weight * Tq)[:k]
    N0 = max(float(M @ grad[:k]) / max(float(grad[:k] @ grad[:k]), 1e-12), 0.0)
    x0 = np.concatenate([q0[:k], [N0] if m == 1 else [0.5 * N0, 0.5 * N0]])
    sol = root(residual, x0, method="hybr", options={"xtol": _XTOL})
    if not sol.success:  # hybr stalls where the table's kinks meet a poor start: Levenberg-Marquardt
        sol = root(residual, x0, method="lm", options={"xtol": _XTOL, "ftol": _XTOL})
    if not sol.success or np.max(np.abs(residual(sol.x)) / [*np.maximum(np.abs(M), 1.0), *[1.0] * m]) > 1e-7:
        raise InputError("pressure_MPa", P, f"no equilibrium with pad {link}{' and the next' * crease} on the "
                                            f"object (depth {depth:.4g} mm): {sol.message}")
    return np.concatenate([sol.x[:k], q0[k:]]), (float(sol.x[k]) if m == 1 else sol.x[k:])


def _crease(P, depth, radius, k, weight, q0, design) -> GraspState | None:
    """Pads k and k + 1 both pressing the object; None where no such state is (no equilibrium,
    an N not positive, another pad in the object)."""
    try:
        q, N = _solve_link(P, depth, radius, k, weight, q0, design, crease=True)
    except InputError:
        return None
    others = np.delete(contact.pad_gaps(q, (0.0, depth), radius, design), [k, k + 1])
    return _state(P, depth, q, k, N, weight, design) if np.all(N > 0.0) and np.min(others) >= -PENETRATION else None


def grasp_state(design: HandDesign, diameter_mm: float, P: float, mass_kg: float = 0.0, *,
                depth_mm: float | None = None) -> GraspState:
    """The finger at cavity pressure P [MPa] closing on the object (diameter [mm], mass [kg])
    at depth [mm] (default: the grasp FEM's placement, :func:`softhand.reduced.equations.contact.object_depth`)."""
    design = fem_finger(design)
    depth = contact.object_depth(diameter_mm, design) if depth_mm is None else float(depth_mm)
    radius, weight = 0.5 * float(diameter_mm), float(mass_kg) * design.g / design.n
    q_free = np.full(design.n_s, float(hand.bend_angle(P, design, reservoir=False)) / design.n_s)
    # the free finger clear of the object has not reached it yet (or never does) -- or, bent past
    # the angle where it first touches, it has swept through it, which the object stops
    clear = np.min(contact.pad_gaps(q_free, (0.0, depth), radius, design)) >= 0.0
    try:
        theta_c, link = contact.contact_angle(diameter_mm, design, depth=depth)
    except InputError:
        if clear:  # it does not reach the object
            return _state(P, depth, q_free, -1, 0.0, weight, design)
        raise
    if clear and float(np.sum(q_free)) < theta_c:
        return _state(P, depth, q_free, -1, 0.0, weight, design)
    q0 = np.concatenate([np.full(link, theta_c / design.n_s), q_free[link:]])
    corner, seen, creases = False, set(), {}
    for _ in range(design.n_s + 2):
        if link == 0:
            raise InputError("diameter_mm", diameter_mm, "touches the base link, which cannot press")
        q, N = _solve_link(P, depth, radius, link, weight, q0, design, corner)
        gaps = contact.pad_gaps(q, (0.0, depth), radius, design)
        seen.add(link)
        gaps[link + (1 if corner else 0)] = gaps[link] = np.inf
        if np.min(gaps) >= -PENETRATION:
            if N < 0.0:  # the pad would pull on the object: it does not touch
                return _state(P, depth, q_free, -1, 0.0, weight, design)
            return _state(P, depth, q, link, N, weight, design, corner)
        nxt = int(np.argmin(gaps))
        if nxt in seen and abs(nxt - link) == 1 and not corner:  # both sides of a hinge: its corner
            link, corner = min(nxt, link), True
            creases.setdefault(link, np.concatenate([q[:link], q_free[link:]]))
        else:
            link, corner = nxt, False
        q0 = np.concatenate([q[:link], q_free[link:]])
    for k, start in creases.items():  # no state on one pad: the object in the crease of two
        if (both := _crease(P, depth, radius, k, weight, start, design)) is not None:
            return both
    raise InputError("diameter_mm", diameter_mm, "the contact settles on no pad and in no crease")


def grasp_state_at_angle(design: HandDesign, diameter_mm: float, P: float, theta: float,
                         mass_kg: float = 0.0) -> GraspState:
    """The finger at cavity pressure P [MPa] held at bend theta [rad] by the object: the
    object's depth is the one at which the equilibrium bends the finger by theta. At or
    beyond the free bend theta_free(P) the finger does not press (F_v = 0, link -1)."""
    design = fem_finger(design)
    theta_free = float(hand.bend_angle(P, design, reservoir=False))
    radius = 0.5 * float(diameter_mm)
    lo = max(contact.object_depth(diameter_mm, design, palm_gap=0.0, clearance=1e-3), radius)
    hi = lo + 2.0 * design.l0 + diameter_mm
    if theta >= theta_free:
        q = np.full(design.n_s, theta_free / design.n_s)
        return _state(P, hi, q, -1, 0.0, 0.0, design)
    at = lambda y: grasp_state(design, diameter_mm, P, mass_kg, depth_mm=y)  # noqa: E731
    f = lambda y: at(y).theta - theta  # noqa: E731
    y0 = float(np.clip(contact.object_depth(diameter_mm, design), lo, hi))
    f0, step = f(y0), 1.0
    while f0 != 0.0:  # the root nearest the default placement: theta(depth) need not be monotone
        a, b = max(lo, y0 - step), min(hi, y0 + step)
        bracket = next(((x, y0) if x < y0 else (y0, x) for x in (a, b) if f(x) * f0 <= 0.0), None)
        if bracket is not None:
            return at(brentq(f, *bracket, xtol=1e-10))
        if a == lo and b == hi:
            raise InputError("theta_deg", round(math.degrees(theta), 6),
                             f"no placement of the object holds this finger there at P_cavity = {P:.4g} MPa "
                             f"(from its highest placement it bends {math.degrees(at(lo).theta):.4g} deg)")
        step *= 2.0
    return at(y0)


def vertical_force(design: HandDesign, diameter_mm: float, P, theta=None, mass_kg: float = 0.0, *,
                   depth_mm: float | None = None):
    """F_v [N] (29) of one finger grasping the object (diameter [mm], mass [kg]) at cavity
    pressure P [MPa]: at bend theta [rad] if given (the depth follows, :func:`grasp_state_at_angle`),
    else at the placement depth_mm (default: the grasp FEM's, :func:`grasp_state`). P and
    theta broadcast; a float for scalars. 0 where the finger does not touch."""
    P, theta = np.broadcast_arrays(np.asarray(P, float), np.asarray(np.nan if theta is None else theta, float))
    out = np.empty(P.shape)
    for i in np.ndindex(P.shape):  # one small root solve per state
        if np.isnan(theta[i]):
            out[i] = grasp_state(design, diameter_mm, float(P[i]), mass_kg, depth_mm=depth_mm).F_v
        else:
            out[i] = grasp_state_at_angle(design, diameter_mm, float(P[i]), float(theta[i]), mass_kg).F_v
    return float(out) if out.ndim == 0 else out
