r"""One finger of the hold: the finger FEM under the cavity pressure and dead generalised
forces on its hinge angles, and its condensed stiffness.

The finger FEM (:class:`softhand.fem.hand.finger.FingerModel`, the half model on the bending plane)
at pressure P under physical generalised forces Q on its hinge angles q (the half model
carries Q / 2, as in :mod:`softhand.fem.hand.grasp`) has the equilibrium :math:`r(y; P) = (0, Q/2)`
with y = (u_free, q). The generalised force that holds the links at q,
:math:`Q^{int}(q; P)`, has the derivative (the condensed stiffness)

.. math:: S = \frac{\partial Q^{int}}{\partial q} = 2\,\big[(K_r^{-1})_{qq}\big]^{-1},

the inverse of the q-block of the reduced tangent's inverse (a Schur complement), taken
from the factorisation the last Newton step left (five back-substitutions, no new
factorisation). Loads move along a straight path from the last (P, Q) to the new one
(:func:`softhand.fem.newton_path.solve_path`, tangent predictor, cut-back).
"""
from __future__ import annotations

import numpy as np

from softhand.fem.hand.finger import FingerModel
from softhand.fem.linsolve import make_solver
from softhand.fem.newton import NewtonOptions
from softhand.fem.newton_path import PathOptions, solve_path


class HeldFinger:
    """A finger FEM state under (P, Q) with its condensed stiffness S (physical, whole finger)."""

    def __init__(self, model: FingerModel, newton: NewtonOptions | None = None):
        self.model = model
        self.newton = newton or NewtonOptions(rtol=1e-9, diverge=100.0)
        self.solver = make_solver(symmetric=True, precision="double")
        d = model.design
        self.scale = d.mu_sf * d.a ** 2 * d.l0  #: force scale of the tolerance [N mm]
        self.y = model.constraint.zero()
        self.P = 0.0
        self.Q = np.zeros(d.n_s)
        self.S = None
        self.iterations = 0

    @property
    def q(self) -> np.ndarray:
        return np.array(self.model.constraint.q(self.y))

    def copy_state(self) -> tuple:
        return self.y.copy(), self.P, self.Q.copy(), None if self.S is None else self.S.copy()

    def restore(self, state: tuple) -> None:
        self.y, self.P, self.Q, self.S = state[0].copy(), state[1], state[2].copy(), state[3]

    def solve(self, P: float, Q, steps: int = 1, *, stiffness: bool = True) -> None:
        """Move to pressure P [MPa] under physical generalised forces Q [N mm]; raises NotConverged.
        ``stiffness``: update S (else the last S is kept: a quasi-Newton iteration on the fingers)."""
        P0, Q0, Q1 = self.P, self.Q.copy(), np.asarray(Q, dtype=float)
        if P == P0 and np.array_equal(Q0, Q1) and self.S is not None:
            return
        n_s = self.model.design.n_s
        load = lambda t: (lambda q: (0.5 * (Q0 + t * (Q1 - Q0)), np.zeros((n_s, n_s))))  # noqa: E731
        pressure = lambda t: P0 + t * (P - P0)  # noqa: E731
        res = solve_path(lambda y, t: self.model.residual_tangent(y, pressure(t), load(t)), self.y,
                         PathOptions(steps=steps, newton=self.newton), solver=self.solver,
                         scale_t=lambda t: self.scale,
                         residual_t=lambda y, t: self.model.residual(y, pressure(t), load(t)))
        self.y, self.P, self.Q = res.x[-1], float(P), Q1.copy()
        self.iterations += res.total_iterations
        if stiffness or self.S is None:
            self.S = self.stiffness()

    def stiffness(self) -> np.ndarray:
        """Condensed stiffness S [N mm/rad] of the whole finger from the last factorisation."""
        return condensed_stiffness(self.solver, self.model.ndofs, self.model.design.n_s)

    def residual_norm(self) -> float:
        """||r(y; P) - (0, Q/2)|| of the current state [N mm] (the FEM equilibrium check)."""
        n_s = self.model.design.n_s
        return float(np.linalg.norm(self.model.residual(
            self.y, self.P, lambda q: (0.5 * self.Q, np.zeros((n_s, n_s))))))


def condensed_stiffness(solver, ndofs: int, n_s: int) -> np.ndarray:
    """S = 2 [(K_r^{-1})_qq]^{-1} [N mm/rad] (module doc) of the whole finger from the reduced tangent
    K_r of the half model factorised in ``solver`` (q the last n_s unknowns of ``ndofs``)."""
    C = np.empty((n_s, n_s))
    for j in range(n_s):
        e = np.zeros(ndofs)
        e[ndofs - n_s + j] = 1.0
        C[:, j] = solver.apply(e)[ndofs - n_s:]
    C = 0.5 * (C + C.T)
    return 2.0 * np.linalg.inv(C)
