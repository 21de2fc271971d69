r"""Newton's method with a backtracking line search, and a load-stepping driver with cut-back.

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
jumps by 1e3 after the first: any merit on it would cut those steps). A non-finite
residual (inverted element) halves the step. The Jacobian evaluated at an accepted
trial point is reused for the next iteration, so a full step costs one assembly.
Given a cheaper ``residual(x) -> R`` (for the P2 solid a residual costs ~5 % of a
residual + tangent), trial points evaluate only R and the tangent is assembled once, at
the accepted point: a rejected trial then costs a residual, not a full assembly.

Load stepping (:func:`solve_path`): t runs from 0 to 1; each step starts from the
last converged state along a predictor direction, line-searched like a Newton
step: the tangent (Euler) direction :math:`-K^{-1}(R + \partial_t R\,\Delta t)`
with :math:`\partial_t R` by a forward difference in t (default: it keeps a
prescribed boundary displacement from distorting the boundary elements alone), or
the secant of the last two converged states, or none; a step that fails is
halved (cut-back) down to ``min_dt``; easy steps let the increment grow again.
On final failure :class:`NotConverged` carries the last converged (t, x).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from fem.linsolve import make_solver


@dataclass(frozen=True)
class NewtonOptions:
    rtol: float = 1e-8  #: on ||R||, relative to ``scale`` (default: ||R(x0)||)
    atol: float = 1e-10  #: absolute floor on ||R|| [units of R]
    xtol: float = 1e-10  #: also converged when the Newton correction ||dx|| <= xtol (1 + ||x||)
    max_iter: int = 25  #: Newton iterations per solve
    line_search: bool = True  #: adjust the step length (see ``merit``)
    #: "slope": R(x + s dx).dx -> 0 (energy); "residual": Armijo on ||R||; "finite": full
    #: steps, halved only where R is not finite (the mixed (u, p) iteration, see fem.solid.MixedNewton)
    merit: str = "slope"
    eta: float = 0.5  #: "slope": accept when |R(x + s dx).dx| <= eta |R(x).dx|
    max_backtracks: int = 6  #: trial steps before taking the last one
    armijo: float = 1e-4  #: "residual": sufficient-decrease constant c

    def __post_init__(self):
        if self.merit not in ("slope", "residual", "finite"):
            raise ValueError(f"merit {self.merit!r} not in ('slope', 'residual', 'finite')")


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


def newton(fun, x0, options: NewtonOptions = NewtonOptions(), *, solver=None, scale=None,
           direction=None, on_accept=None, residual=None) -> NewtonResult:
    """Solve R(x) = 0 from x0; raises NotConverged with the residual history.

    fun(x) -> (R, K); solver: a :mod:`fem.linsolve` solver (default auto, unsymmetric);
    scale: reference for the relative tolerance (default ||R(x0)||);
    direction: search direction of the first iteration instead of -K^{-1} R (a load-step
    predictor, line-searched like a Newton step); on_accept(x): called with x0 and every
    accepted iterate before fun is evaluated around it (e.g. :class:`fem.solid.MixedNewton`);
    residual(x) -> R: optional, fun's residual alone, for the line search's trial points.
    """
    solver = solver or make_solver()
    t0 = time.perf_counter()
    x = np.array(x0, dtype=float)
    if on_accept is not None:
        on_accept(x)
    R, K = fun(x)
    t_asm = time.perf_counter() - t0
    norm = float(np.linalg.norm(R))
    tol = options.atol + options.rtol * (norm if scale is None else scale)
    history, steps, t_solve = [norm], [], 0.0
    for it in range(options.max_iter + 1):
        if not np.isfinite(norm):
            raise NotConverged("residual is not finite", history, x)
        if norm <= tol:
            return NewtonResult(x, it, history, steps, t_asm, t_solve)
        if it == options.max_iter:
            break
        t1 = time.perf_counter()
        try:
            dx = solver.solve(K, -R) if (it > 0 or direction is None) else np.asarray(direction)
        except (RuntimeError, np.linalg.LinAlgError, ValueError) as err:
            raise NotConverged(f"linear solve failed ({err})", history, x) from err
        t_solve += time.perf_counter() - t1
        t1 = time.perf_counter()
        small = it > 0 and np.linalg.norm(dx) <= options.xtol * (1.0 + np.linalg.norm(x))
        x, R, K, norm, s = _line_search(fun, x, dx, R, norm, options, residual)
        t_asm += time.perf_counter() - t1
        history.append(norm)
        steps.append(s)
        if on_accept is not None:
            on_accept(x)
        if small and s == 1.0 and np.isfinite(norm):  # converged to round-off (ill-conditioned K)
            return NewtonResult(x, it + 1, history, steps, t_asm, t_solve)
    raise NotConverged(f"no convergence in {options.max_iter} iterations (tol {tol:.2e})", history, x)


def _line_search(fun, x, dx, R0, norm0, options, residual=None):
    """Step length on x + s dx; returns the accepted (x, R, K, ||R||, s). See the module docstring."""
    trial = fun if residual is None else (lambda xt: (residual(xt), None))
    g0 = float(R0 @ dx)  # slope of the energy along dx at s = 0 (< 0 for a descent direction)
    s, lo, glo, hi, ghi = 1.0, 0.0, g0, None, None
    for _ in range(options.max_backtracks + 1):
        xt = x + s * dx
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            R, K = trial(xt)
        norm = float(np.linalg.norm(R))
        if not options.line_search or (options.merit == "finite" and np.isfinite(norm)):
            break
        if not np.isfinite(norm):  # e.g. an inverted element: shorten
            hi, ghi, s = s, None, 0.5 * (lo + s)
            continue
        if options.merit == "residual":
            if norm <= (1 - options.armijo * s) * norm0:
                break
            phi0, phis = norm0 ** 2, norm ** 2
            s = float(np.clip(s * s * phi0 / (phis - phi0 + 2 * s * phi0), 0.1 * s, 0.5 * s))
            continue
        g = float(R @ dx)
        if g0 >= 0 or abs(g) <= options.eta * abs(g0) or (g < 0 and hi is None):
            break  # slope small enough, or still descending at the full step
        if g < 0:
            lo, glo = s, g
        else:
            hi, ghi = s, g
        # regula falsi for the zero of the slope in [lo, hi], kept off the ends
        s_new = lo + (hi - lo) * glo / (glo - ghi) if ghi is not None else 0.5 * (lo + hi)
        s = float(np.clip(s_new, lo + 0.1 * (hi - lo), hi - 0.1 * (hi - lo)))
    # accepted, or no sufficient step in max_backtracks: the last trial (Newton may still recover)
    if K is None:
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            R, K = fun(xt)
    return xt, R, K, norm, s


@dataclass(frozen=True)
class PathOptions:
    steps: int = 5  #: initial number of equal load steps on t in [0, 1]
    min_dt: float = 1e-4  #: smallest load increment before giving up
    grow: float = 1.5  #: increment growth after a step converging in <= easy_iter iterations
    easy_iter: int = 4  #: iterations counted as an easy step
    #: "tangent": Euler predictor every step (best with prescribed displacements);
    #: "secant": extrapolate the last two converged states (tangent for the first step);
    #: "none": start each step from the last converged state (pure load control needs no more)
    predictor: str = "tangent"
    newton: NewtonOptions = field(default_factory=NewtonOptions)


@dataclass
class PathResult:
    t: list  #: converged load factors, first 0
    x: list  #: converged states
    iterations: list  #: Newton iterations of each converged step
    cutbacks: int  #: failed attempts that were retried with a smaller step
    histories: list  #: residual histories of the converged steps
    assembly_seconds: float = 0.0
    solve_seconds: float = 0.0

    @property
    def total_iterations(self) -> int:
        return int(sum(self.iterations))


def solve_path(fun_t, x0, options: PathOptions = PathOptions(), *, solver=None, scale_t=None,
               callback=None, on_accept=None, residual_t=None) -> PathResult:
    """Follow R(x, t) = 0 for t from 0 (state x0) to 1; fun_t(x, t) -> (R, K).

    scale_t(t): optional reference residual norm for the relative tolerance at t
    (e.g. the norm of the external load); callback(t, x) after each converged step;
    on_accept: passed to :func:`newton` (also called before each predictor);
    residual_t(x, t) -> R: optional, fun_t's residual alone (:func:`newton`'s ``residual``).
    """
    solver = solver or make_solver()
    res = PathResult([0.0], [np.array(x0, dtype=float)], [], 0, [])
    dt = 1.0 / options.steps
    while res.t[-1] < 1.0 - 1e-12:
        t = min(1.0, res.t[-1] + dt)
        if on_accept is not None:
            on_accept(res.x[-1])
        step = _predict(res, t, fun_t, solver, options.predictor)
        try:
            r = newton(lambda x: fun_t(x, t), res.x[-1], options.newton, solver=solver,
                       scale=None if scale_t is None else scale_t(t), direction=step, on_accept=on_accept,
                       residual=None if residual_t is None else (lambda x: residual_t(x, t)))
        except NotConverged as err:
            res.cutbacks += 1
            dt *= 0.5
            if dt < options.min_dt:
                raise NotConverged(f"load step cut back below {options.min_dt} at t = {t:.4g}",
                                   err.history, err.x, (res.t[-1], res.x[-1])) from err
            continue
        res.t.append(t)
        res.x.append(r.x)
        res.iterations.append(r.iterations)
        res.histories.append(r.history)
        res.assembly_seconds += r.assembly_seconds
        res.solve_seconds += r.solve_seconds
        if callback is not None:
            callback(t, r.x)
        if r.iterations <= options.easy_iter:
            dt *= options.grow
    return res


def _predict(res: PathResult, t: float, fun_t, solver, kind: str):
    """Predictor step from the last converged state to t (None: none, or a singular tangent)."""
    if kind not in ("tangent", "secant", "none"):
        raise ValueError(f"predictor {kind!r} not in ('tangent', 'secant', 'none')")
    if kind == "none":
        return None
    if kind == "tangent" or len(res.t) < 2:
        t0, x0 = res.t[-1], res.x[-1]
        eps = 1e-7 * max(t - t0, 1e-3)
        R0, K0 = fun_t(x0, t0)
        R1 = fun_t(x0, t0 + eps)[0]
        try:
            return -solver.solve(K0, R0 + (R1 - R0) * ((t - t0) / eps))
        except (RuntimeError, np.linalg.LinAlgError, ValueError):
            return None
    t1, t2 = res.t[-2], res.t[-1]
    return (t - t2) / (t2 - t1) * (res.x[-1] - res.x[-2])
