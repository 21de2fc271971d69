r"""Volume-controlled path following for an axisymmetric cavity (pressure = Lagrange multiplier).

Oil is incompressible, so the reservoir and the balloon are driven by their enclosed
volume V*, not by pressure: a rubber membrane's p(V) has a maximum past which pressure
control has no solution. The equilibrium states are the stationary points of

.. math:: L(u, p) = Π(u) - p\,(V(u) - V^*),

solved by Newton on the bordered (symmetric, indefinite) system

.. math:: \begin{pmatrix} K - p\,H_V & -g_V \\ -g_V^T & 0 \end{pmatrix}
          \begin{pmatrix} Δu \\ Δp \end{pmatrix}
          = -\begin{pmatrix} Π'(u) - p\,g_V \\ V^* - V(u) \end{pmatrix},

with :math:`g_V = V'(u)` and :math:`H_V = V''(u)` (the load stiffness of the follower
pressure). The bordered matrix stays regular at and past the pressure maximum, where
:math:`K - pH_V` itself is singular. Along the path :math:`dΠ/dV^* = p`, so
:math:`\int p\,dV = Π` is an independent check of the residual, the tangent-free parts
and the volume functional (``tests/test_reservoir.py``).

Steps: a secant predictor from the last two converged states, Newton with a backtracking
line search on the residual norm, and load-step cut-back (halve ΔV*) when Newton fails;
the step grows again after easy steps. Raises :class:`VolumeNotConverged` (a
:class:`fem.newton.NotConverged`, the one failure type of the FEM solvers) with the
residual history and the last converged state.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from softhand.fem.linsolve import make_solver
from softhand.fem.newton import NotConverged

__all__ = ["PathOptions", "PathState", "NotConverged", "VolumeNotConverged", "follow_volume"]


@dataclass(frozen=True)
class PathOptions:
    """Step control and tolerances of :func:`follow_volume`."""

    first_step: float = 1.0  #: first volume increment [mm^3]
    max_step: float = 200.0  #: largest volume increment [mm^3]
    rtol: float = 1e-9  #: force residual, relative to the pressure load |p g_V| (or |Π'|)
    atol: float = 0.0  #: force residual floor [N]: round-off of the stiff volumetric terms
    #: merit below which Newton that stops converging quadratically has reached round-off
    #: (the bordered matrix's condition grows with κ/μ and the mesh)
    floor: float = 1e-5
    vtol: float = 1e-10  #: volume residual, relative to max(V*, volume_scale)
    max_iter: int = 12  #: Newton iterations per step before cut-back
    min_step: float = 1e-6  #: smallest volume increment before giving up [mm^3]
    grow: float = 1.5  #: step growth after a step that took <= 5 iterations
    solver: str = "auto"  #: :func:`fem.linsolve.make_solver` method for the bordered system


@dataclass(frozen=True)
class PathState:
    """One converged equilibrium state."""

    volume: float  #: enclosed volume V [mm^3]
    pressure: float  #: Lagrange multiplier p [MPa]
    energy: float  #: stored strain energy Π [N mm]
    u: np.ndarray = field(repr=False)  #: displacement vector [mm]
    iterations: int = 0  #: Newton iterations of this step


class VolumeNotConverged(NotConverged):
    """Newton failed at the smallest volume step; ``last``: the last converged :class:`PathState`
    (also as ``last_converged`` = (volume, u) and ``x`` = its u, like every :class:`NotConverged`)."""

    def __init__(self, message, history, last: PathState):
        super().__init__(message, history, last.u, (last.volume, last.u))
        self.last = last


class _Problem:
    """Residual and tangent of L(u, p) on the free DOFs."""

    def __init__(self, solid, volume, free, volume_scale, solver):
        self.solid, self.volume, self.free = solid, volume, free
        self.volume_scale = volume_scale
        self.solver = solver

    def full(self, uf):
        u = np.zeros(self.solid.ndofs)
        u[self.free] = uf
        return u

    def residual(self, uf, p, target):
        u = self.full(uf)
        f, g = self.solid.residual(u)[self.free], self.volume.gradient(u)[self.free]
        return f - p * g, target - self.volume.value(u), max(np.linalg.norm(p * g), np.linalg.norm(f))

    def newton_step(self, uf, p, ru, rv):
        u = self.full(uf)
        K = self.solid.tangent(u) - p * self.volume.hessian(u)
        g = self.volume.gradient(u)[self.free][:, None]
        A = sp.bmat([[K[self.free][:, self.free], sp.csr_matrix(-g)], [sp.csr_matrix(-g.T), None]],
                    format="csr")
        x = self.solver.solve(A, -np.append(ru, rv))
        return x[:-1], x[-1]


def _newton(prob, uf, p, target, opt: PathOptions):
    """Newton with backtracking line search; returns ((uf, p, iterations) or None, history).

    The first step (from the predictor) is taken whole; later steps backtrack on the merit
    |R_u| / f + |R_V| / v, f the largest force scale (|p g_V|, |Π'|, atol) met in this
    solve, v the volume scale. Converged: both residuals within tolerance, or the merit
    below ``floor`` and no longer halving (round-off).
    """
    history = []
    vscale = max(abs(target), prob.volume_scale)
    ru, rv, fscale = prob.residual(uf, p, target)
    fnorm = max(fscale, opt.atol, 1e-300)
    for it in range(opt.max_iter + 1):
        merit = np.linalg.norm(ru) / fnorm + abs(rv) / vscale
        history.append(merit)
        if np.linalg.norm(ru) <= opt.rtol * fscale + opt.atol and abs(rv) <= opt.vtol * vscale:
            return (uf, p, it), history
        if it >= 2 and merit < opt.floor and merit > 0.5 * history[-2]:
            return (uf, p, it), history  # stagnating at the round-off floor of the solve
        if it == opt.max_iter or not np.isfinite(merit):
            break
        du, dp = prob.newton_step(uf, p, ru, rv)
        for alpha in (1.0, 0.5, 0.25, 0.125, 0.0625):
            with np.errstate(invalid="ignore", divide="ignore", over="ignore"):  # J < 0 trials
                trial = prob.residual(uf + alpha * du, p + alpha * dp, target)
            new = np.linalg.norm(trial[0]) / max(fnorm, trial[2]) + abs(trial[1]) / vscale
            if it == 0 or (np.isfinite(new) and new < merit):
                break
        uf, p = uf + alpha * du, p + alpha * dp
        ru, rv, fscale = trial
        fnorm = max(fnorm, fscale)
    return None, history


def follow_volume(solid, volume, fixed_dofs, targets, *, options=PathOptions(),
                  volume_scale=1.0, progress=None,
                  start: PathState | None = None) -> tuple[list[PathState], list[PathState]]:
    """Follow the equilibrium path from ``start`` (default u = 0) through the volumes ``targets``.

    ``targets`` [mm^3] must run strictly monotonically away from the start volume, up
    (inflating) or down (oil leaving). Returns (states at the targets, every converged state
    from the start on).
    """
    targets = np.asarray(targets, dtype=float)
    free = np.setdiff1d(np.arange(solid.ndofs), fixed_dofs)
    prob = _Problem(solid, volume, free, volume_scale, make_solver(options.solver, symmetric=True))
    if start is None:
        start = PathState(volume.value(np.zeros(solid.ndofs)), 0.0, 0.0, np.zeros(solid.ndofs))
    sign = np.sign(targets[0] - start.volume)
    if sign == 0 or np.any(sign * np.diff(targets) <= 0):
        raise ValueError(f"volume targets must run strictly monotonically away from "
                         f"{start.volume:.6g} mm^3")
    path, step, hits = [start], options.first_step, []
    for target in targets:
        while sign * (target - path[-1].volume) > 0:
            nxt = path[-1].volume + sign * min(step, sign * (target - path[-1].volume))
            result, history = _newton(prob, *_predict(path, free, nxt), nxt, options)
            if result is None:
                step /= 2
                if step < options.min_step:
                    raise VolumeNotConverged(f"no equilibrium at V = {nxt:.6g} mm^3", history, path[-1])
                continue
            uf, p, its = result
            u = prob.full(uf)
            path.append(PathState(nxt, p, solid.energy(u), u, its))
            if progress is not None:
                progress(nxt)
            if its <= 5:
                step = min(step * options.grow, options.max_step)
        hits.append(path[-1])
    return hits, path


def _predict(path, free, volume):
    """(u_free, p) at ``volume``: secant through the last two converged states, else the last."""
    last = path[-1]
    if len(path) < 2:
        return last.u[free], last.pressure
    before = path[-2]
    s = (volume - last.volume) / (last.volume - before.volume)
    return (last.u[free] + s * (last.u[free] - before.u[free]),
            last.pressure + s * (last.pressure - before.pressure))
