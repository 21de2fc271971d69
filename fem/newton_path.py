r"""The load path: R(x, t) = 0 followed in load steps of :func:`softhand.fem.newton.newton`, with a
predictor, cut-back and growing increments.

Load stepping (:func:`solve_path`): t runs from 0 to 1 (or from t0 through given stops,
e.g. volumes); each step starts from the last converged state along a predictor
direction, line-searched like a Newton step: the tangent (Euler) direction
:math:`-K^{-1}(R + \partial_t R\,\Delta t)` with :math:`\partial_t R` by a forward
difference in t (default: it keeps a prescribed boundary displacement from distorting
the boundary elements alone), or none; or Newton starts at the secant extrapolation of
the last two converged states (``predictor="secant"``); a step that fails is
halved (cut-back) down to ``min_dt``; easy steps let the increment grow again, and so do
``grow_after`` converged steps in a row after a cut-back.
On final failure :class:`~softhand.fem.newton.NotConverged` carries the last converged (t, x).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from softhand.fem.linsolve import make_solver
from softhand.fem.newton import NewtonOptions, NotConverged, newton
from softhand.fem.newton_steps import predict, record


@dataclass(frozen=True)
class PathOptions:
    steps: int = 5  #: initial number of equal load steps on t in [0, 1] (the whole path)
    #: first increment of t instead (e.g. a volume [mm^3] for :func:`softhand.fem.volume_path.follow_volume`)
    first_step: float | None = None
    max_step: float = np.inf  #: largest increment of t
    min_dt: float = 1e-4  #: smallest load increment before giving up
    grow: float = 1.5  #: increment growth after a step converging in <= easy_iter iterations
    easy_iter: int = 4  #: iterations counted as an easy step
    #: after a cut-back, this many converged steps in a row let the increment grow even when
    #: they were not easy (a problem that always needs more than easy_iter iterations, e.g.
    #: the mixed (u, p) iteration's 5-6, would otherwise keep the cut-back increment for good)
    grow_after: int = 2
    #: "tangent": Euler predictor every step (best with prescribed displacements);
    #: "secant": Newton starts at the extrapolation of the last two converged states
    #: (tangent for the first step);
    #: "none": start each step from the last converged state (pure load control needs no more)
    predictor: str = "tangent"
    newton: NewtonOptions = field(default_factory=NewtonOptions)


@dataclass
class PathResult:
    t: list  #: converged load factors, first the start (0)
    x: list  #: converged states
    iterations: list  #: Newton iterations of each converged step
    cutbacks: int  #: failed attempts that were retried with a smaller step
    histories: list  #: residual histories of the converged steps
    assembly_seconds: float = 0.0
    solve_seconds: float = 0.0
    factorizations: int = 0  #: tangents factorised, predictors and failed attempts included
    stops: list = field(default_factory=list)  #: indices into t and x of the states at the stops

    @property
    def total_iterations(self) -> int:
        return int(sum(self.iterations))


def solve_path(fun_t, x0, options: PathOptions = PathOptions(), *, solver=None, scale_t=None,
               callback=None, on_accept=None, residual_t=None, converged_t=None, merit_t=None, t0=0.0,
               stops=(1.0,), first_direction=None) -> PathResult:
    """Follow R(x, t) = 0 for t from t0 (state x0) through ``stops``; fun_t(x, t) -> (R, K).

    stops: the values of t the path lands on, running strictly monotonically away from t0
    (up or down; default: t in [0, 1]); scale_t(t): optional reference residual norm for the
    relative tolerance at t (e.g. the norm of the external load); callback(t, x) after each
    converged step; on_accept: passed to :func:`softhand.fem.newton.newton` (also called before each predictor);
    residual_t(x, t) -> R, converged_t(x, R, it, t) -> bool and merit_t(x, R, t) -> float:
    optional, :func:`softhand.fem.newton.newton`'s ``residual``, ``converged`` and ``merit`` at t. On failure the :class:`~softhand.fem.newton.NotConverged` also carries ``t``,
    the load it failed at. first_direction: the first step's predictor direction, already
    computed by the caller for the first increment the options give (not used after a cut-back).
    """
    solver = solver or make_solver()
    stops = np.asarray(stops, dtype=float)
    sign = np.sign(stops[0] - t0)
    if sign == 0 or np.any(sign * np.diff(stops) <= 0):
        raise ValueError(f"path stops must run strictly monotonically away from t0 = {t0:.6g}")
    res = PathResult([float(t0)], [np.array(x0, dtype=float)], [], 0, [])
    factorizations0 = getattr(solver, "n_factorizations", 0)
    reuse = options.newton.refactor == "adaptive"
    span = abs(stops[-1] - t0)
    dt = span / options.steps if options.first_step is None else options.first_step
    dt, streak = min(dt, options.max_step), None  # streak: converged steps since the last cut-back
    for stop in stops:
        while sign * (stop - res.t[-1]) > 1e-12 * span:
            t = float(stop if dt >= sign * (stop - res.t[-1]) else res.t[-1] + sign * dt)
            if on_accept is not None:
                on_accept(res.x[-1])
            if first_direction is not None and len(res.t) == 1 and not res.cutbacks:
                x_start, step = res.x[-1], first_direction
            else:
                x_start, step = predict(res, t, fun_t, solver, options.predictor, residual_t, reuse,
                                        rtol=options.newton.forcing)
            try:
                r = newton(lambda x: fun_t(x, t), x_start, options.newton, solver=solver,
                           scale=None if scale_t is None else scale_t(t), direction=step,
                           on_accept=on_accept,
                           converged=None if converged_t is None else (lambda x, R, it: converged_t(x, R, it, t)),
                           merit=None if merit_t is None else (lambda x, R: merit_t(x, R, t)),
                           residual=None if residual_t is None else (lambda x: residual_t(x, t)))
            except NotConverged as err:
                res.cutbacks += 1
                dt, streak = 0.5 * dt, 0
                if reuse and hasattr(solver, "forget"):  # the failed solve's last factor is of an
                    solver.forget()  # iterate far off the path: the retry's predictor must not use it
                if dt < options.min_dt:
                    failed = NotConverged(f"load step cut back below {options.min_dt} at t = {t:.4g}",
                                          err.history, err.x, (res.t[-1], res.x[-1]))
                    failed.t = t
                    raise failed from err
                continue
            dt, streak = record(res, t, r, options, dt, streak, reuse)
            if callback is not None:
                callback(t, r.x)
        res.stops.append(len(res.t) - 1)
    res.factorizations = getattr(solver, "n_factorizations", 0) - factorizations0
    return res
