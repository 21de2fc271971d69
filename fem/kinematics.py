r"""Batched 3x3 tensor algebra for finite strain, shapes ``(3, 3, *batch)``.

Every function acts on the two leading axes and broadcasts over the trailing
batch axes (elements, quadrature points, ...), so a material law or a form never
loops in Python.

The cofactor and its derivatives carry the volume change and the area change
(Nanson: :math:`n\,da = \operatorname{cof}F\,N\,dA`):

.. math::
    \operatorname{cof}F_{aK} = J F^{-T}_{aK}
        = \tfrac12 \varepsilon_{abc}\varepsilon_{KLM} F_{bL} F_{cM},\qquad
    \frac{\partial J}{\partial F} = \operatorname{cof}F,\qquad
    \frac{\partial^2 J}{\partial F_{aK}\,\partial F_{bL}}
        = \varepsilon_{abc}\varepsilon_{KLM} F_{cM}.

These polynomial forms need no inverse, so they hold for any F.
"""
from __future__ import annotations

import numpy as np

#: Levi-Civita symbol eps[i, j, k]
EPS = np.zeros((3, 3, 3))
EPS[0, 1, 2] = EPS[1, 2, 0] = EPS[2, 0, 1] = 1.0
EPS[0, 2, 1] = EPS[2, 1, 0] = EPS[1, 0, 2] = -1.0


def identity(batch=()) -> np.ndarray:
    """Identity tensor broadcast to shape ``(3, 3, *batch)``."""
    return np.eye(3).reshape((3, 3) + (1,) * len(batch)) * np.ones(batch)


def det(F: np.ndarray) -> np.ndarray:
    """J = det F, shape batch."""
    return (F[0, 0] * (F[1, 1] * F[2, 2] - F[1, 2] * F[2, 1])
            - F[0, 1] * (F[1, 0] * F[2, 2] - F[1, 2] * F[2, 0])
            + F[0, 2] * (F[1, 0] * F[2, 1] - F[1, 1] * F[2, 0]))


def cofactor(F: np.ndarray) -> np.ndarray:
    """cof F = J F^{-T} = dJ/dF, shape ``(3, 3, *batch)``."""
    C = np.empty_like(F)
    for a in range(3):
        b, c = (a + 1) % 3, (a + 2) % 3
        for K in range(3):
            L, M = (K + 1) % 3, (K + 2) % 3
            C[a, K] = F[b, L] * F[c, M] - F[b, M] * F[c, L]
    return C


def inv_transpose(F: np.ndarray) -> np.ndarray:
    """F^{-T}, shape ``(3, 3, *batch)``."""
    return cofactor(F) / det(F)


def d2det(F: np.ndarray) -> np.ndarray:
    """Second derivative of J: eps_abc eps_KLM F_cM, shape ``(3, 3, 3, 3, *batch)`` [a, K, b, L]."""
    return np.einsum("abc,KLM,cM...->aKbL...", EPS, EPS, F, optimize=True)


def right_cauchy_green(F: np.ndarray) -> np.ndarray:
    """C = F^T F, shape ``(3, 3, *batch)``."""
    return np.einsum("aK...,aL...->KL...", F, F)


def outer(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """(A ⊗ B)_{aKbL} = A_aK B_bL, shape ``(3, 3, 3, 3, *batch)``."""
    return np.einsum("aK...,bL...->aKbL...", A, B)


def outer_swap(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """A_aL B_bK: the term d(F^{-T})/dF = -F^{-T}_aL F^{-T}_bK is built from it."""
    return np.einsum("aL...,bK...->aKbL...", A, B)


def deformation_gradient(grad_u: np.ndarray) -> np.ndarray:
    """F = I + grad u for grad u of shape ``(3, 3, *batch)``."""
    F = grad_u.copy()
    F[0, 0] += 1.0
    F[1, 1] += 1.0
    F[2, 2] += 1.0
    return F
