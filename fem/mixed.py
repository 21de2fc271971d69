r"""The mixed (u, p) Newton iteration of a nearly incompressible :class:`softhand.fem.solid.Solid`.

After a Newton step of the condensed mean-dilatation residual its element pressures
U'(Jbar) are off by kappa times the second-order volume error, which poisons the next
tangent's geometric term. The mixed iteration keeps the P0 pressure linearised at the
previous accepted iterate (:class:`~softhand.fem.mixed.PressureAnchor`, made by ``Solid.anchor``); that is
Newton's method on the uncondensed three-field problem, ~4-5 full steps for kappa/mu =
1e2..1e5 alike. :class:`~softhand.fem.mixed.MixedNewton` re-anchors it from the Newton driver's ``on_accept``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["PressureAnchor", "MixedNewton"]


@dataclass(frozen=True)
class PressureAnchor:
    r"""Element pressures linearised at an iterate u0 (the P0 pressure of the mixed iteration):
    :math:`p_e(u) = U'(\bar J_e) + U''(\bar J_e)/V_e\; b_e\cdot(u - u_0)_e`."""

    u0: np.ndarray  #: the iterate [mm], (ndofs,)
    p0: np.ndarray  #: U'(Jbar_e(u0)) [MPa], (nel,)
    c0: np.ndarray  #: U''(Jbar_e(u0)) / V_e [MPa/mm^3], (nel,)
    b: np.ndarray  #: b_e = int cof F : grad phi [mm^2], (nel, 3 nloc)

    def pressure(self, u, elements, vdofs) -> np.ndarray:
        """p_e(u) of the given elements (vdofs: their vector dofs, (ne, 3 nloc))."""
        du = (u - self.u0)[vdofs]
        return self.p0[elements] + self.c0[elements] * np.einsum("ei,ei->e", self.b[elements], du)


class MixedNewton:
    """Glue for :func:`softhand.fem.newton.newton`: ``on_accept`` re-anchors the element pressures.

    ``expand(x)`` must return the **full** displacement at the unknowns x, prescribed values
    included: the pressures are linearised at that state, and an anchor taken at a state
    with the prescribed displacements missing (zeros) makes Newton converge only linearly.
    A :class:`softhand.fem.assembly.Restriction` built with ``values=`` expands that way. Usage::

        red = Restriction(solid.ndofs, free, values=u_prescribed)
        mixed = MixedNewton(solid, red.expand)
        fun = lambda x: ... solid.residual_tangent(red.expand(x), anchor=mixed.anchor) ...
        newton(fun, x0, on_accept=mixed.accept)   # or solve_path(..., on_accept=mixed.accept)

    For prescribed values that grow with the load factor t, pass an ``expand`` that applies
    the current t (see ``studies/verification/solid.py``).
    """

    def __init__(self, solid: "Solid", expand):
        self.solid, self.expand, self.anchor = solid, expand, None

    def accept(self, x) -> None:
        """Called by Newton with every accepted iterate."""
        self.anchor = self.solid.anchor(self.expand(x))
