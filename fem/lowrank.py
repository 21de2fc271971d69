r"""Element stiffness matrices written as low-rank products: no fourth-order tangent per point.

For the isochoric Neo-Hookean law (:class:`softhand.fem.materials.NeoHookeanIsochoric`) plus the
mean-dilatation pressure term of :mod:`softhand.fem.solid`, every term of the tangent
:math:`A_{aKbL}` contracted with two shape-function gradients is a product of the vectors
:math:`v_{na} = F_{aK}G_{nK}` and :math:`h_{na} = F^{-T}_{aK}G_{nK}` (G: gradients of the
scalar shape functions), or a Kronecker delta. With :math:`j = J^{-2/3}`, the element
pressure p of the geometric term and :math:`S_{nm} = G_n\cdot G_m`,

.. math::
    \sum_{KL} A_{aKbL} G_{nK} G_{mL} = \mu j\Bigl[\delta_{ab} S_{nm}
        - \tfrac23 (v_{an} h_{bm} + h_{an} v_{bm}) + \tfrac29 I_1 h_{an} h_{bm}
        + \tfrac13 I_1 h_{am} h_{bn}\Bigr] + pJ\,(h_{an} h_{bm} - h_{am} h_{bn}),

from :math:`A = \mu j[\delta\delta - \frac23(F\otimes F^{-T} + F^{-T}\otimes F) + \frac29 I_1
F^{-T}\otimes F^{-T} + \frac13 I_1 F^{-T}\boxtimes F^{-T}] + p\,\partial^2 J/\partial F^2` and
:math:`\partial^2 J/\partial F_{aK}\partial F_{bL} = J(F^{-T}_{aK}F^{-T}_{bL} - F^{-T}_{aL}F^{-T}_{bK})`.
The swapped products are split as
:math:`h_{am}h_{bn} = h_{an}h_{bm} + \varepsilon_{abc}(h_m\times h_n)_c`, so per element

.. math::
    K_{(na)(bm)} = \sum_k L_{(na)k} R_{k(bm)} + \delta_{ab} S_{nm} + \varepsilon_{abc} X_{c,nm},

one batched matrix product with an inner dimension of 2 per quadrature point (plus a
column per extra rank-one term: the mean-dilatation :math:`b_e b_e^T`, a fiber family's
:math:`c_1 (f_a g_n)(f_b g_m)`), and one small product that adds the delta and epsilon
parts. It replaces the general kernel's 81-component tangent per point and its two
products (:func:`softhand.fem.solid_kernels.element_matrices`); tests/test_lowrank.py checks that both give the
same matrices.
"""
from __future__ import annotations

import numpy as np

from softhand.fem import kinematics as kin

#: E[(a b), 0] = delta_ab, E[(a b), 1 + c] = eps_abc: the delta and epsilon parts of the kernel
_E = np.concatenate((np.eye(3).reshape(9, 1), kin.EPS.reshape(9, 3)), axis=1)


def neo_hookean_terms(F, G, W, mu: float, p_geo):
    """The low-rank factors of the Neo-Hookean isochoric tangent plus p_geo d2J/dF2 of one chunk
    (module docstring): (L (ne, 3 nloc, 2 nq), R (ne, 2 nq, 3 nloc), S (ne, nloc, nloc),
    X (ne, 3, nloc, nloc)).

    F (3, 3, ne, nq); G (ne, nq, nloc, 3) reference gradients; W (ne, nq) weights; mu [MPa];
    p_geo (ne,) the pressure of the geometric term [MPa] (None: no such term).
    """
    ne, nq, nloc, _ = G.shape
    J = kin.det(F)
    I1 = np.einsum("aKeq,aKeq->eq", F, F)
    muj = mu * J ** (-2.0 / 3.0) * W
    pJ = 0.0 if p_geo is None else p_geo[:, None] * J * W
    # V[e, n, a, q, i]: v (i = 0) and h (i = 1); the rows (n a) of L, its columns (q i)
    V = np.ascontiguousarray(np.einsum("iaKeq,eqnK->enaqi", np.stack((F, kin.cofactor(F) / J)), G, optimize=True))
    C = np.zeros((ne, nq, 2, 2))                                # [[0, b1], [b1, b2 + b3]] per point
    C[:, :, 0, 1] = C[:, :, 1, 0] = -2.0 / 3.0 * muj
    C[:, :, 1, 1] = 5.0 / 9.0 * I1 * muj                        # 2/9 + 1/3 (the swap's share); pJ cancels
    R = np.matmul(C, V.transpose(0, 3, 4, 2, 1).reshape(ne, nq, 2, 3 * nloc)).reshape(ne, 2 * nq, 3 * nloc)
    L = V.reshape(ne, 3 * nloc, 2 * nq)
    S = np.einsum("eq,eqnK,eqmK->enm", muj, G, G, optimize=True)
    # X_c[n, m] = sum_q b3 (h_m x h_n)_c = P^T - P with P_de[n, m] = sum_q b3 h_dn h_em
    h = V[..., 1].transpose(0, 2, 1, 3)                         # h[e, a, n, q]
    b3 = I1 / 3.0 * muj - pJ
    P = np.matmul(h[:, [1, 0, 0]] * b3[:, None, None, :], h[:, [2, 2, 1]].transpose(0, 1, 3, 2))
    X = P.transpose(0, 1, 3, 2) - P
    X[:, 1] *= -1.0                                             # X_1 = P_02 - P_02^T
    return L, R, S, X


def write_matrices(Ke, L, R, S=None, X=None, *, add: bool = False) -> None:
    """Ke[e, n, a, b, m] (=, or += with ``add``) sum_k L[e, (n a), k] R[e, k, (b m)]
    + delta_ab S[e, n, m] + eps_abc X[e, c, n, m]; Ke in :func:`softhand.fem.solid_kernels.element_matrices`'s
    block layout (ne, nloc, 3, 3, nloc)."""
    ne, nloc = Ke.shape[:2]
    flat = Ke.reshape(ne, 3 * nloc, 3 * nloc)
    if add:
        flat += np.matmul(L, R)
    else:
        np.matmul(L, R, out=flat)
    if S is None and X is None:
        return
    Z = np.zeros((ne, 4, nloc, nloc))
    if S is not None:
        Z[:, 0] = S
    if X is not None:
        Z[:, 1:] = X
    Ke.reshape(ne, nloc, 9, nloc)[...] += np.matmul(_E, Z.transpose(0, 2, 1, 3))
