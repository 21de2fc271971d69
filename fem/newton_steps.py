"""The pieces of :mod:`softhand.fem.newton`'s iterations: the step length on the Newton direction
(line search, see that module's docstring for the merits), the limited-memory BFGS
direction of its quasi-Newton mode, and a load step's predictor and step-size update."""
from __future__ import annotations

import numpy as np


def bfgs_direction(R, pairs, apply):
    """-H R by the two-loop recursion: H the BFGS update of H0 = apply (the stored factor's
    inverse) by the secant pairs (s, y, 1 / s.y), oldest first."""
    q, alphas = np.array(R, dtype=float), []
    for s, y, rho in reversed(pairs):
        alphas.append(rho * (s @ q))
        q -= alphas[-1] * y
    r = apply(q)
    for (s, y, rho), a in zip(pairs, reversed(alphas)):
        r += (a - rho * (y @ r)) * s
    return -r


def add_pair(pairs, s, y, memory):
    """Keep the secant pair (s = dx, y = dR) when its curvature s.y is positive (BFGS stays
    positive definite), at most ``memory`` of them."""
    sy = float(s @ y)
    if np.isfinite(sy) and sy > 1e-12 * np.linalg.norm(s) * np.linalg.norm(y):
        pairs.append((s, y, 1.0 / sy))
        del pairs[:-memory]


def line_search(fun, x, dx, R0, norm0, options, residual=None, merit=None, first=False):
    """Step length on x + s dx; returns the accepted (x, R, K, ||R||, s); K is None when
    only ``residual`` was evaluated (the caller evaluates a tangent where a step needs one). See :mod:`softhand.fem.newton`'s docstring.

    merit(x, R) -> float: the measure "decrease" compares (default ||R||); first: the solve's
    first step ("decrease" takes it whole)."""
    trial = fun if residual is None else (lambda xt: (residual(xt), None))
    measure = merit or (lambda x, R: float(np.linalg.norm(R)))
    m0 = measure(x, R0) if options.merit == "decrease" else None
    g0 = float(R0 @ dx)  # slope of the energy along dx at s = 0 (< 0 for a descent direction)
    s, lo, glo, hi, ghi = 1.0, 0.0, g0, None, None
    for _ in range(options.max_backtracks + 1):
        xt = x + s * dx
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            R, K = trial(xt)
        norm = float(np.linalg.norm(R))
        if not options.line_search or (options.merit == "finite" and np.isfinite(norm)):
            break
        if options.merit == "decrease":
            m = measure(xt, R)
            if first or (np.isfinite(m) and m < m0):
                break
            s *= 0.5
            continue
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
    return xt, R, K, norm, s


def factored_size(solver):
    """Order of the solver's current factorisation (None: none, or a solver without one)."""
    return getattr(solver, "factored_size", None)


def record(res, t, r, options, dt, streak, reuse):
    """Append the converged step (t, r: a NewtonResult) to res (a PathResult); the next
    (increment, streak) by options (PathOptions)."""
    res.t.append(t)
    res.x.append(r.x)
    res.iterations.append(r.iterations)
    res.histories.append(r.history)
    res.assembly_seconds += r.assembly_seconds
    res.solve_seconds += r.solve_seconds
    streak = None if streak is None else streak + 1
    if r.iterations <= options.easy_iter or (reuse and r.factorizations <= 1):
        dt *= options.grow  # easy: few iterations, or (quasi-Newton) at most one factorisation
    elif streak is not None and streak >= options.grow_after:
        dt, streak = dt * options.grow, 0  # steady progress since the cut-back
    return min(dt, options.max_step), streak


def predict(res, t: float, fun_t, solver, kind: str, residual_t=None, reuse=False, rtol=None):
    """(Newton's start, its first direction) for the step from the last converged state to t;
    the direction None: Newton's own (no predictor, the secant's start, or a singular tangent).

    ``residual_t``: the residual at t0 + eps costs no tangent; with ``reuse`` (quasi-Newton)
    and a factorisation of this size in ``solver`` the tangent predictor solves with that
    factorisation (the last iterate's tangent) instead of factorising K(x0), and only to the
    relative residual ``rtol`` (a guess on an old factor: Newton's largest forcing term); with
    K(x0) factorised the Euler step is solved exactly (solved to 1e-2, the mixed (u, p)
    iteration of a nearly incompressible tube needed one more iteration)."""
    if kind not in ("tangent", "secant", "none"):
        raise ValueError(f"predictor {kind!r} not in ('tangent', 'secant', 'none')")
    t0, x0 = res.t[-1], res.x[-1]
    if kind == "none":
        return x0, None
    if kind == "secant" and len(res.t) >= 2:
        t1 = res.t[-2]
        return x0 + (t - t0) / (t0 - t1) * (x0 - res.x[-2]), None
    eps = 1e-7 * max(abs(t - t0), 1e-3)
    old = reuse and residual_t is not None and factored_size(solver) == len(x0)
    R0, K0 = (residual_t(x0, t0), None) if old else fun_t(x0, t0)
    R1 = residual_t(x0, t0 + eps) if residual_t is not None else fun_t(x0, t0 + eps)[0]
    try:
        rhs = R0 + (R1 - R0) * ((t - t0) / eps)
        return x0, -(solver.apply(rhs, rtol=rtol) if old else solver.solve(K0, rhs))
    except (RuntimeError, np.linalg.LinAlgError, ValueError):
        return x0, None
