r"""Volume-controlled path following for a cavity (pressure = Lagrange multiplier).

Oil is incompressible, so the reservoir and the balloon are driven by their enclosed
volume V*, not by pressure: a rubber membrane's p(V) has a maximum past which pressure
control has no solution. The equilibrium states are the stationary points of

.. math:: L(u, p) = Π(u) - p\,(V(u) - V^*),

the bordered (symmetric, indefinite) system of :func:`softhand.fem.loads.volume_control` on the free
DOFs and p, which stays regular at and past the pressure maximum, where :math:`K - pH_V`
itself is singular. Along the path :math:`dΠ/dV^* = p`, so :math:`\int p\,dV = Π` is an
independent check of the residual, the tangent-free parts and the volume functional
(``tests/fem/test_reservoir.py``).

The path is the load path of :func:`softhand.fem.newton_path.solve_path` with the load t = V* [mm^3]:
the same Newton iteration, line search, cut-back and step growth as every other FEM
path, set up by :func:`volume_path_options`: Newton starts at the secant extrapolation
of the last two states, takes its first step whole and halves later ones until the merit
``|R_u|`` / f + ``|R_V|`` / v decreases (f the largest force scale ``|p g_V|``, ``|Π'|`` met in the solve,
v the volume scale); increments in mm^3 from a first step up to a largest one. Only the
measures are the border's own: the merit, and the convergence test -- the force residual
relative to the pressure load ``|p g_V|`` (or ``|Π'|``), the volume residual relative to the
volume scale, or the merit below a round-off floor and no longer halving (the bordered
matrix's condition grows with κ/μ and the mesh). Raises :class:`VolumeNotConverged` (a
:class:`softhand.fem.newton.NotConverged`, the one failure type of the FEM solvers) with the residual
history and the last converged state.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from softhand.fem.assembly import Restriction
from softhand.fem.linsolve import make_solver
from softhand.fem.loads import volume_control
from softhand.fem.newton import NewtonOptions, NotConverged
from softhand.fem.newton_path import PathOptions, solve_path

__all__ = ["PathOptions", "PathState", "NotConverged", "VolumeNotConverged", "follow_volume",
           "volume_path_options"]

VTOL = 1e-10  #: volume residual, relative to max(V*, volume_scale)
#: merit below which Newton that stops converging quadratically has reached round-off
FLOOR = 1e-5


def volume_path_options(*, first_step: float = 1.0, max_step: float = 200.0, atol: float = 0.0,
                        min_step: float = 1e-6, max_iter: int = 12) -> PathOptions:
    """:class:`softhand.fem.newton_path.PathOptions` of a volume path: increments [mm^3] from ``first_step``
    up to ``max_step``, grown 1.5x after a step of at most 5 iterations, halved down to
    ``min_step``; ``max_iter`` Newton iterations a step, from the secant predictor; ``atol``:
    force residual floor [N] (round-off of the stiff volumetric terms); the force residual
    relative to the pressure load is held to 1e-9 (see the module docstring)."""
    return PathOptions(first_step=first_step, max_step=max_step, min_dt=min_step, easy_iter=5,
                       predictor="secant",
                       newton=NewtonOptions(rtol=1e-9, atol=atol, xtol=0.0, max_iter=max_iter,
                                            merit="decrease", max_backtracks=4))


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
    (also as ``last_converged`` = (volume, u) and ``x`` = its u, like every :class:`~softhand.fem.newton.NotConverged`)."""

    def __init__(self, message, history, last: PathState):
        super().__init__(message, history, last.u, (last.volume, last.u))
        self.last = last


class _Bordered:
    """L(u, p)'s residual and Jacobian on x = (free DOFs, p), and the border's convergence test."""

    def __init__(self, solid, volume, free, volume_scale, newton: NewtonOptions):
        n = solid.ndofs
        self.solid, self.volume, self.volume_scale, self.newton = solid, volume, volume_scale, newton
        self.free, self.red = free, Restriction(n + 1, np.append(free, n))
        self.merits, self.fnorm = [], 1.0  # the merits and the largest force scale of this solve
        self.forces = (None, 0.0)  # (x, max(``|p g_V|``, ``|Π'|``)) of the last call

    def split(self, x):
        """(u [mm] (ndofs,), p [MPa]) of x."""
        y = self.red.expand(x)
        return y[:-1], y[-1]

    def join(self, u, p):
        return self.red.vector(np.append(u, p))

    def __call__(self, x, V, tangent=True):
        u, p = self.split(x)
        f = self.solid.residual(u)
        Rb, Kb = volume_control(f, self.solid.tangent(u) if tangent else None, p, self.volume, u, V)
        Rb, f = self.red.vector(Rb), f[self.free]
        self.forces = (x, max(np.linalg.norm(f - Rb[:-1]), np.linalg.norm(f)))  # ``|p g_V|``, ``|Π'|``
        return Rb, None if Kb is None else self.red.restrict(Kb)

    def force_scale(self, x, V) -> float:
        """max(``|p g_V|``, ``|Π'|``) [N] at x."""
        if not (self.forces[0] is x or np.array_equal(self.forces[0], x)):
            self(x, V, tangent=False)
        return self.forces[1]

    def merit(self, x, R, V) -> float:
        """``|R_u|`` / f + ``|R_V|`` / v: f the largest force scale of the solve (x's included)."""
        f = max(self.fnorm, self.force_scale(x, V))
        return float(np.linalg.norm(R[:-1]) / f + abs(R[-1]) / max(abs(V), self.volume_scale))

    def converged(self, x, R, it, V) -> bool:
        """Force residual within rtol ``|p g_V|`` + atol and volume residual within VTOL, or the
        merit below FLOOR and no longer halving (round-off)."""
        fscale = self.force_scale(x, V)
        self.fnorm = max(fscale, self.newton.atol, 1e-300) if it == 0 else max(self.fnorm, fscale)
        self.merits = ([] if it == 0 else self.merits) + [self.merit(x, R, V)]
        if (np.linalg.norm(R[:-1]) <= self.newton.rtol * fscale + self.newton.atol
                and abs(R[-1]) <= VTOL * max(abs(V), self.volume_scale)):
            return True
        return it >= 2 and FLOOR > self.merits[-1] > 0.5 * self.merits[-2]


def follow_volume(solid, volume, fixed_dofs, targets, *, options: PathOptions | None = None,
                  volume_scale=1.0, progress=None, start: PathState | None = None,
                  solver=None) -> tuple[list[PathState], list[PathState]]:
    """Follow the equilibrium path from ``start`` (default u = 0) through the volumes ``targets``.

    ``volume``: the cavity's functional (``value``, ``gradient``, ``hessian`` of V(u));
    ``targets`` [mm^3] must run strictly monotonically away from the start volume, up
    (inflating) or down (oil leaving); ``options``: default :func:`volume_path_options`;
    ``solver``: a :mod:`softhand.fem.linsolve` solver (default: auto, symmetric). Returns (states at
    the targets, every converged state from the start on).
    """
    options = options or volume_path_options()
    free = np.setdiff1d(np.arange(solid.ndofs), fixed_dofs)
    prob = _Bordered(solid, volume, free, volume_scale, options.newton)
    if start is None:
        start = PathState(volume.value(np.zeros(solid.ndofs)), 0.0, 0.0, np.zeros(solid.ndofs))
    try:
        res = solve_path(prob, prob.join(start.u, start.pressure), options,
                         solver=solver or make_solver(symmetric=True), t0=start.volume, stops=targets,
                         residual_t=lambda x, V: prob(x, V, tangent=False)[0],
                         converged_t=prob.converged, merit_t=prob.merit,
                         callback=None if progress is None else (lambda V, x: progress(V)))
    except NotConverged as err:
        V, x = err.last_converged
        raise VolumeNotConverged(f"no equilibrium at V = {err.t:.6g} mm^3", err.history,
                                 _state(prob, V, x)) from err
    path = [start] + [_state(prob, V, x, its) for V, x, its in zip(res.t[1:], res.x[1:], res.iterations)]
    return [path[k] for k in res.stops], path


def _state(prob: _Bordered, V, x, iterations=0) -> PathState:
    u, p = prob.split(x)
    return PathState(float(V), float(p), prob.solid.energy(u), u, iterations)
