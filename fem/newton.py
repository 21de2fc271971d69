r"""Newton's method with a backtracking line search (the load path that steps it is
:mod:`softhand.fem.newton_path`).

Generic: ``fun(x) -> (R, K)`` with R the residual (n,) and K its Jacobian (sparse,
n x n), for any extended system (Dirichlet-reduced displacements, bordered volume
control, rigid-body reduced coordinates, ...).

Line search (default ``merit="slope"``): the slope
:math:`g(s) = R(x + s\,\Delta x)\cdot\Delta x` is the derivative of the energy along
the Newton direction for a potential problem (hyperelasticity with dead loads or
volume control), and a good indicator otherwise. The full step is taken when the
energy still decreases there (g(1) < 0) or :math:`|g(s)| \le \eta |g(0)|`; when it
overshoots (g(1) > 0) the zero of g is bracketed and found by regula falsi. The
residual norm is a poor merit for slender bodies (a good step can raise
:math:`\|R\|` a lot); ``merit="residual"`` keeps Armijo backtracking on it;
``merit="finite"`` takes full steps (the mixed (u, p) iteration of a nearly
incompressible solid converges in ~4 full steps although its displacement residual
jumps by 1e3 after the first: any merit on it would cut those steps); ``merit="decrease"``
takes a solve's first step whole (from a predicted state) and halves later ones until a
caller's merit (default :math:`\|R\|`; a bordered system weighs its blocks) decreases. A non-finite
residual (inverted element) halves the step. The Jacobian evaluated at an accepted
trial point is reused for the next iteration, so a full step costs one assembly.
Given a cheaper ``residual(x) -> R`` (for the P2 solid a residual costs ~5 % of a
residual + tangent), trial points evaluate only R and the tangent is assembled once, at
the accepted point: a rejected trial then costs a residual, not a full assembly.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from softhand.fem.linsolve import make_solver
from softhand.fem.newton_steps import add_pair, bfgs_direction, factored_size, line_search


MERITS = ("slope", "residual", "finite", "decrease")


@dataclass(frozen=True)
class NewtonOptions:
    rtol: float = 1e-8  #: on ||R||, relative to ``scale`` (default: ||R(x0)||)
    atol: float = 1e-10  #: absolute floor on ||R|| [units of R]
    xtol: float = 1e-10  #: also converged when the Newton correction ||dx|| <= xtol (1 + ||x||)
    max_iter: int = 25  #: Newton iterations per solve
    line_search: bool = True  #: adjust the step length (see ``merit``)
    #: "slope": R(x + s dx).dx -> 0 (energy); "residual": Armijo on ||R||; "finite": full
    #: steps, halved only where R is not finite (the mixed (u, p) iteration, see fem.mixed.MixedNewton)
    #: "decrease": the first step whole, then halving until ``newton``'s ``merit`` decreases
    merit: str = "slope"
    eta: float = 0.5  #: "slope": accept when ``|R(x + s dx).dx|`` <= eta ``|R(x).dx|``
    max_backtracks: int = 6  #: trial steps before taking the last one
    armijo: float = 1e-4  #: "residual": sufficient-decrease constant c
    #: "always": factorise the tangent at every iterate (Newton); "adaptive": quasi-Newton on
    #: the solver's last factorisation (also one left by an earlier solve), see :func:`newton`
    refactor: str = "always"
    contraction: float = 0.1  #: "adaptive": largest ||R_new|| / ||R|| kept on an old factorisation
    memory: int = 10  #: "adaptive": secant pairs of the BFGS update kept
    #: inexact Newton: the largest relative residual ||K dx + R|| / ||R|| a Newton system is
    #: solved to (None: as accurately as the solver can); see :func:`forcing_term`
    forcing: float | None = 1e-2
    #: give up as soon as ||R|| exceeds this multiple of the smallest ||R|| since the first step
    #: (None: only after max_iter); a diverging solve then costs a few iterations, not max_iter
    #: (PETSc's SNES divergence tolerance, taken relative to the best iterate). Not the start's
    #: ||R||: a small load step starts tiny, and its first step may raise ||R|| 1e5-fold and converge
    diverge: float | None = None
    #: give up once ||R|| has not fallen below 0.9 times its smallest value for this many
    #: iterations (None: only after max_iter): a solve cycling between contact states, or
    #: stuck on a plateau, costs a few iterations, not max_iter
    stall: int | None = None

    def __post_init__(self):
        if self.merit not in MERITS:
            raise ValueError(f"merit {self.merit!r} not in {MERITS}")
        if self.refactor not in ("always", "adaptive"):
            raise ValueError(f"refactor {self.refactor!r} not in ('always', 'adaptive')")
        if not 0 < self.contraction < 1:
            raise ValueError(f"contraction {self.contraction!r} not in (0, 1)")
        if self.diverge is not None and not self.diverge > 1:
            raise ValueError(f"diverge {self.diverge!r} must be None or > 1")
        if self.stall is not None and not self.stall >= 1:
            raise ValueError(f"stall {self.stall!r} must be None or >= 1")


class NotConverged(RuntimeError):
    """Newton or the load stepping failed; carries what is needed to report and resume.

    history: residual norms of the failed solve; x: its last iterate;
    last_converged: (t, x) of the last converged load step (None inside plain newton).
    """

    def __init__(self, message, history, x, last_converged=None):
        super().__init__(f"{message}; residual history {['%.3e' % r for r in history]}")
        self.history = list(history)
        self.x = x
        self.last_converged = last_converged


@dataclass
class NewtonResult:
    x: np.ndarray  #: the solution
    iterations: int  #: Newton iterations (linear solves)
    history: list  #: ||R|| at every iterate, first = initial
    steps: list  #: accepted line-search step lengths
    assembly_seconds: float = 0.0  #: time spent in fun
    solve_seconds: float = 0.0  #: time spent in the linear solver
    factorizations: int = 0  #: tangents factorised (= iterations for refactor="always")


def newton(fun, x0, options: NewtonOptions = NewtonOptions(), *, solver=None, scale=None,
           direction=None, on_accept=None, residual=None, converged=None, merit=None) -> NewtonResult:
    """Solve R(x) = 0 from x0; raises NotConverged with the residual history.

    fun(x) -> (R, K); solver: a :mod:`softhand.fem.linsolve` solver (default auto, unsymmetric);
    scale: reference for the relative tolerance (default ||R(x0)||);
    direction: search direction of the first iteration instead of -K^{-1} R (a load-step
    predictor, line-searched like a Newton step); on_accept(x): called with x0 and every
    accepted iterate before fun is evaluated around it (e.g. :class:`softhand.fem.mixed.MixedNewton`);
    residual(x) -> R: optional, fun's residual alone, for the line search's trial points and
    (Newton) the iterates, whose tangent is then evaluated only when a step needs it (not at a
    start that takes ``direction``, nor at the converged iterate);
    converged(x, R, it) -> bool: optional test of the iterate x (it Newton iterations so far)
    instead of ||R|| <= atol + rtol scale, e.g. one tolerance per block of a bordered system
    (:mod:`softhand.fem.volume_path`); merit(x, R) -> float: the measure of ``options.merit = "decrease"``.

    ``options.refactor = "adaptive"`` (quasi-Newton): the direction is
    :math:`-H R` with H the limited-memory BFGS update (secant pairs of the accepted steps
    since the last factorisation, :func:`softhand.fem.newton_steps.bfgs_direction`) of the inverse of the last
    factorised tangent, so an iteration costs a residual and a solve with the stored factor
    instead of an assembly and a factorisation. A step that does not lower ||R|| is
    discarded and redone with the tangent at the same iterate; one that lowers it by less
    than ``options.contraction`` (or is cut by the line search) is kept and the tangent is
    re-factorised at the new iterate. The convergence test is the same as Newton's.
    """
    solver = solver or make_solver()
    adaptive = options.refactor == "adaptive"
    t0 = time.perf_counter()
    x = np.array(x0, dtype=float)
    if on_accept is not None:
        on_accept(x)
    reuse = adaptive and factored_size(solver) == len(x)
    # Newton with a residual function evaluates the tangent only where a step needs it: not at
    # a start whose first step is the predictor's direction, nor at the converged iterate
    lazy = residual is not None and not adaptive
    R, K = (residual(x), None) if residual is not None and (reuse or lazy) else fun(x)
    K = None if reuse else K  # K: the tangent at x still to be factorised (None: keep the factor,
    # or, lazy, not evaluated yet)
    t_asm = time.perf_counter() - t0
    norm = float(np.linalg.norm(R))
    tol = options.atol + options.rtol * (norm if scale is None else scale)
    history, steps, t_solve, factorizations, pairs, etas = [norm], [], 0.0, 0, [], []
    done = (lambda x, R, it: float(np.linalg.norm(R)) <= tol) if converged is None else converged
    for it in range(options.max_iter + 1):
        if not np.isfinite(norm):
            raise NotConverged("residual is not finite", history, x)
        if options.diverge is not None and len(history) > 2 and norm > options.diverge * min(history[1:]):
            raise NotConverged(f"diverging (||R|| above {options.diverge:g} times its smallest)", history, x)
        if options.stall is not None and stalled(history, options.stall):
            raise NotConverged(f"stalled (||R|| not below 0.9 times its smallest in {options.stall} "
                               "iterations)", history, x)
        if done(x, R, len(history) - 1):
            return NewtonResult(x, it, history, steps, t_asm, t_solve, factorizations)
        if it == options.max_iter:
            break
        if lazy and K is None and not (it == 0 and direction is not None):
            t1 = time.perf_counter()
            R, K = fun(x)
            t_asm += time.perf_counter() - t1
        t1 = time.perf_counter()
        old = False  # the step uses a factorisation of another iterate's tangent
        try:
            if it == 0 and direction is not None:
                dx = np.asarray(direction)
            else:
                eta = None if options.forcing is None else forcing_term(history, tol, options.forcing, etas)
                etas.append(eta)  # None throughout when forcing is None (then never read)
                if K is not None:
                    dx, pairs = solver.solve(K, -R, rtol=eta), []
                    factorizations += 1
                else:  # the stored factor's inverse, as accurate as a Newton system would be solved
                    dx, old = bfgs_direction(R, pairs, lambda q: solver.apply(q, rtol=eta)), True
        except (RuntimeError, np.linalg.LinAlgError, ValueError) as err:
            raise NotConverged(f"linear solve failed ({err})", history, x) from err
        t_solve += time.perf_counter() - t1
        t1 = time.perf_counter()
        small = it > 0 and np.linalg.norm(dx) <= options.xtol * (1.0 + np.linalg.norm(x))
        xt, Rt, Kt, normt, s = line_search(fun, x, dx, R, norm, options, residual, merit=merit,
                                           first=not steps)
        rate = normt / norm
        if old and not rate < 1.0:  # the old factorisation is not good enough here: redo with K(x)
            R, K = fun(x)
            t_asm += time.perf_counter() - t1
            continue
        if adaptive:
            add_pair(pairs, xt - x, Rt - R, options.memory)
        x, R, K, norm = xt, Rt, Kt, normt
        history.append(norm)
        steps.append(s)
        if on_accept is not None:
            on_accept(x)
        if adaptive:
            if rate > options.contraction or factored_size(solver) != len(x):
                R, K = (R, K) if K is not None else fun(x)
            else:
                K = None
        t_asm += time.perf_counter() - t1
        if small and s == 1.0 and np.isfinite(norm) and (not old or rate <= options.contraction):
            return NewtonResult(x, it + 1, history, steps, t_asm, t_solve, factorizations)  # round-off
    raise NotConverged(f"no convergence in {options.max_iter} iterations (tol {tol:.2e})", history, x)


def forcing_term(history, tol: float, largest: float, etas) -> float:
    r"""The relative residual :math:`\eta_k` a Newton system needs to be solved to
    (Eisenstat and Walker's choice 2): :math:`0.9\,(\|R_k\| / \|R_{k-1}\|)^2`, kept
    from falling faster than :math:`0.9\,\eta_{k-1}^2` while that is above 0.1, at most
    ``largest``, and at least :math:`0.5\,\mathrm{tol} / \|R_k\|` (a solve more accurate
    than the tolerance on R asks gains nothing). history: ||R|| of the iterates so far,
    etas: the earlier terms. The converged answer is tested on
    R as before; only how accurately each step is solved changes, which for PARDISO in mixed
    precision is how many refinement steps follow the single-precision factorisation."""
    norm = history[-1]
    eta = largest
    if len(history) > 1 and history[-2] > 0:
        eta = 0.9 * (norm / history[-2]) ** 2
        if etas and 0.9 * etas[-1] ** 2 > 0.1:
            eta = max(eta, 0.9 * etas[-1] ** 2)
    floor = 0.5 * tol / norm if norm > 0 else largest
    return float(min(largest, max(eta, floor)))


def stalled(history, k: int, factor: float = 0.9) -> bool:
    """Whether the last k residual norms all stayed above ``factor`` times the smallest before them."""
    return len(history) > k and min(history[-k:]) >= factor * min(history[:-k])
