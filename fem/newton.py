r"""Newton's method with a backtracking line search, and a load-stepping driver with cut-back.

Generic: ``fun(x) -> (R, K)`` with R the residual (n,) and K its Jacobian (sparse,
n x n), for any extended system (Dirichlet-reduced displacements, bordered volume
control, rigid-body reduced coordinates, ...).

Line search: the merit is :math:`\phi(s) = \|R(x + s\,\Delta x)\|`. A trial step
is accepted when :math:`\phi(s) \le (1 - c\,s)\,\phi(0)` (Armijo, c = 1e-4);
otherwise s shrinks to the minimiser of the quadratic through
:math:`\phi^2(0), \tfrac{d}{ds}\phi^2(0) = -2\phi^2(0), \phi^2(s)`, clipped to
[0.1 s, 0.5 s]. The Jacobian evaluated at an accepted trial point is reused for
the next iteration, so a full step costs one assembly.

Load stepping (:func:`solve_path`): t runs from 0 to 1; each step starts from a
predictor: the secant extrapolation of the last two converged states, or, when
only one is known, the tangent (Euler) predictor
:math:`x - K^{-1}(R + \partial_t R\,\Delta t)` with :math:`\partial_t R` by a
forward difference in t (this keeps a prescribed boundary displacement from
distorting the boundary elements alone in the first step); a step that fails is
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
    max_iter: int = 25  #: Newton iterations per solve
    line_search: bool = True  #: backtracking on ||R||
    max_backtracks: int = 8  #: trial step halvings before giving up the iteration
    armijo: float = 1e-4  #: sufficient-decrease constant c


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


def newton(fun, x0, options: NewtonOptions = NewtonOptions(), *, solver=None, scale=None) -> NewtonResult:
    """Solve R(x) = 0 from x0; raises NotConverged with the residual history.

    fun(x) -> (R, K); solver: a :mod:`fem.linsolve` solver (default auto, unsymmetric);
    scale: reference for the relative tolerance (default ||R(x0)||).
    """
    solver = solver or make_solver()
    t0 = time.perf_counter()
    x = np.array(x0, dtype=float)
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
            dx = solver.solve(K, -R)
        except (RuntimeError, np.linalg.LinAlgError, ValueError) as err:
            raise NotConverged(f"linear solve failed ({err})", history, x) from err
        t_solve += time.perf_counter() - t1
        t1 = time.perf_counter()
        x, R, K, norm, s = _line_search(fun, x, dx, norm, options)
        t_asm += time.perf_counter() - t1
        history.append(norm)
        steps.append(s)
    raise NotConverged(f"no convergence in {options.max_iter} iterations (tol {tol:.2e})", history, x)


def _line_search(fun, x, dx, norm0, options):
    """Backtracking on ||R||; returns the accepted (x, R, K, ||R||, s)."""
    s = 1.0
    for _ in range(options.max_backtracks + 1):
        xt = x + s * dx
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            R, K = fun(xt)
        norm = float(np.linalg.norm(R))
        if not options.line_search or (np.isfinite(norm) and norm <= (1 - options.armijo * s) * norm0):
            return xt, R, K, norm, s
        phi0, phis = norm0 ** 2, norm ** 2 if np.isfinite(norm) else np.inf
        s_quad = s * s * phi0 / (phis - phi0 + 2 * s * phi0) if np.isfinite(phis) else 0.1 * s
        s = float(np.clip(s_quad, 0.1 * s, 0.5 * s))
    return xt, R, K, norm, s  # not sufficient: take the last trial, Newton may still recover


@dataclass(frozen=True)
class PathOptions:
    steps: int = 5  #: initial number of equal load steps on t in [0, 1]
    min_dt: float = 1e-4  #: smallest load increment before giving up
    grow: float = 1.5  #: increment growth after a step converging in <= easy_iter iterations
    easy_iter: int = 4  #: iterations counted as an easy step
    predictor: bool = True  #: secant extrapolation of the last two converged states
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
               callback=None) -> PathResult:
    """Follow R(x, t) = 0 for t from 0 (state x0) to 1; fun_t(x, t) -> (R, K).

    scale_t(t): optional reference residual norm for the relative tolerance at t
    (e.g. the norm of the external load); callback(t, x) after each converged step.
    """
    solver = solver or make_solver()
    res = PathResult([0.0], [np.array(x0, dtype=float)], [], 0, [])
    dt = 1.0 / options.steps
    while res.t[-1] < 1.0 - 1e-12:
        t = min(1.0, res.t[-1] + dt)
        guess = _predict(res, t, fun_t, solver) if options.predictor else res.x[-1]
        try:
            r = newton(lambda x: fun_t(x, t), guess, options.newton, solver=solver,
                       scale=None if scale_t is None else scale_t(t))
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


def _predict(res: PathResult, t: float, fun_t, solver) -> np.ndarray:
    """Secant extrapolation from the last two converged states to t, else the tangent predictor."""
    if len(res.t) < 2:
        t0, x0 = res.t[-1], res.x[-1]
        eps = 1e-7 * max(t - t0, 1e-3)
        R0, K0 = fun_t(x0, t0)
        R1 = fun_t(x0, t0 + eps)[0]
        try:
            return x0 - solver.solve(K0, R0 + (R1 - R0) * ((t - t0) / eps))
        except (RuntimeError, np.linalg.LinAlgError, ValueError):
            return x0
    t1, t2 = res.t[-2], res.t[-1]
    return res.x[-1] + (t - t2) / (t2 - t1) * (res.x[-1] - res.x[-2])
