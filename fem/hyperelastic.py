r"""Nearly incompressible rubber of any :mod:`softhand.reduced.materials.rubber` model as an FEM law.

The strain energy is split into an isochoric and a volumetric part,

.. math:: \psi(F) = W(\bar\lambda_1, \bar\lambda_2, \bar\lambda_3) + \tfrac{\kappa}{2}(J - 1)^2,
          \qquad \bar\lambda_i = J^{-1/3}\lambda_i ,

so that the mean-dilatation solids (P2-P0 in :mod:`softhand.fem.solid`, Q2/P1disc in
:mod:`softhand.fem.axisym`) take the volumetric part element-wise: locking-free for every model.
The same W object serves the reduced model; here it is evaluated at the isochoric
invariants or stretches of F.

Invariant models (NH, Mooney-Rivlin, Yeoh, Gent), with :math:`\bar I_1 = J^{-2/3} I_1`,
:math:`\bar I_2 = J^{-4/3} I_2`, :math:`g_k = \partial \bar I_k/\partial F`:

.. math:: P = W_1 g_1 + W_2 g_2, \qquad
          A = \sum_{kl} W_{kl}\, g_k \otimes g_l + W_1 \partial^2\bar I_1 + W_2 \partial^2 \bar I_2,

with :math:`g_1 = J^{-2/3}(2F - \tfrac23 I_1 F^{-T})`,
:math:`g_2 = J^{-4/3}(2(I_1 F - F C) - \tfrac43 I_2 F^{-T})`.

Ogden: W is an isotropic function Phi(lambda_1, lambda_2, lambda_3) of the principal
stretches of F (from the eigen-decomposition of C); P = sum_a Phi_a n_a (x) N_a and the
tangent is the spectral formula with the coefficients
(Phi_a lambda_a - Phi_b lambda_b) / (lambda_a^2 - lambda_b^2) and
(Phi_a lambda_b - Phi_b lambda_a) / (lambda_a^2 - lambda_b^2), replaced by their limits
where two stretches coincide (``_pair_coefficients()``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softhand.fem import kinematics as kin
from softhand.fem.materials import Law, SplitLaw, Volumetric
from softhand.reduced.materials import rubber as rubber_models

#: relative gap of two principal stretches below which the coincident limit is used
COINCIDENT = 1e-6


def _eye4(ndim_batch):
    d = np.einsum("ab,KL->aKbL", np.eye(3), np.eye(3))
    return d.reshape(d.shape + (1,) * ndim_batch)


@dataclass(frozen=True)
class IsochoricRubber(Law):
    """The isochoric part W(J^{-1/3} lambda_i) of a :mod:`softhand.reduced.materials.rubber` model."""

    material: rubber_models.Rubber

    def energy(self, F):
        if isinstance(self.material, rubber_models.InvariantRubber):
            return self.material.W(*self._bar_invariants(F)[:2])
        lam, _, _ = _principal(F)
        return self.material.energy(*(lam * kin.det(F) ** (-1.0 / 3.0)))

    def stress(self, F):
        if not isinstance(self.material, rubber_models.InvariantRubber):
            return _ogden_stress_tangent(self.material, F, tangent=False)
        I1b, I2b, g1, g2, _ = self._bar_invariants(F, gradients=True)
        W1, W2 = self.material.dI(I1b, I2b)
        return W1 * g1 + W2 * g2

    def tangent(self, F):
        if not isinstance(self.material, rubber_models.InvariantRubber):
            return _ogden_stress_tangent(self.material, F, tangent=True)
        I1b, I2b, g1, g2, parts = self._bar_invariants(F, gradients=True)
        W1, W2 = self.material.dI(I1b, I2b)
        W11, W12, W22 = self.material.d2I(I1b, I2b)
        A = W11 * kin.outer(g1, g1) + W1 * self._d2I1(F, parts)
        if np.any(W2) or np.any(W12) or np.any(W22):
            A = A + (W12 * (kin.outer(g1, g2) + kin.outer(g2, g1)) + W22 * kin.outer(g2, g2)
                     + W2 * self._d2I2(F, parts, g2))
        return A

    @staticmethod
    def _bar_invariants(F, gradients=False):
        J = kin.det(F)
        C = kin.right_cauchy_green(F)
        I1 = np.einsum("KK...->...", C)
        I2 = 0.5 * (I1**2 - np.einsum("KL...,KL...->...", C, C))
        j23 = J ** (-2.0 / 3.0)
        if not gradients:
            return j23 * I1, j23**2 * I2
        Fi = kin.inv_transpose(F)
        FC = np.einsum("aM...,MK...->aK...", F, C)
        g1 = j23 * (2.0 * F - (2.0 / 3.0) * I1 * Fi)
        G2 = 2.0 * (I1 * F - FC)
        g2 = j23**2 * (G2 - (4.0 / 3.0) * I2 * Fi)
        return j23 * I1, j23**2 * I2, g1, g2, (j23, I1, I2, Fi, C, G2)

    @staticmethod
    def _d2I1(F, parts):
        j23, I1, _, Fi, _, _ = parts
        return 2.0 * j23 * (_eye4(F.ndim - 2) - 2.0 / 3.0 * (kin.outer(F, Fi) + kin.outer(Fi, F))
                            + 2.0 / 9.0 * I1 * kin.outer(Fi, Fi) + I1 / 3.0 * kin.outer_swap(Fi, Fi))

    @staticmethod
    def _d2I2(F, parts, g2):
        j23, I1, I2, Fi, C, G2 = parts
        eye = np.eye(3)
        B = np.einsum("aM...,bM...->ab...", F, F)
        dG2 = 2.0 * (2.0 * kin.outer(F, F) + I1 * _eye4(F.ndim - 2)) - 2.0 * (
            np.einsum("ab,LK...->aKbL...", eye, C) + kin.outer_swap(F, F)
            + np.einsum("ab...,KL->aKbL...", B, eye))
        return j23**2 * (dG2 - 4.0 / 3.0 * (kin.outer(G2, Fi) + kin.outer(Fi, G2))
                         + 16.0 / 9.0 * I2 * kin.outer(Fi, Fi) + 4.0 / 3.0 * I2 * kin.outer_swap(Fi, Fi))


def _principal(F):
    """Principal stretches (3, *batch), reference directions N (3, 3, *batch: N[:, a]) and
    current directions n = F N / lambda, from the eigen-decomposition of C."""
    C = kin.right_cauchy_green(F)
    ev, vec = np.linalg.eigh(np.moveaxis(C, (0, 1), (-2, -1)))
    lam = np.sqrt(np.moveaxis(ev, -1, 0))
    N = np.moveaxis(vec, (-2, -1), (0, 1))
    n = np.einsum("aK...,Kb...->ab...", F, N) / lam[None]
    return lam, N, n


def _ogden_stress_tangent(material, F, tangent):
    """P or A of Phi(lambda) = W(J^{-1/3} lambda) by the spectral formulas (module docstring)."""
    lam, N, n = _principal(F)
    j13 = kin.det(F) ** (-1.0 / 3.0)
    bar = lam * j13
    g, H = material.dW(*bar), material.d2W(*bar)
    # d bar_b / d lam_a = j13 (delta_ab - lam_b / (3 lam_a))
    D = j13 * (np.eye(3).reshape((3, 3) + (1,) * (lam.ndim - 1)) - lam[None, :] / (3.0 * lam[:, None]))
    Phi1 = np.einsum("ab...,b...->a...", D, g)
    # d^2 Phi / dlam_a dlam_c = D_ab H_bd D_cd + g_b d^2 bar_b / dlam_a dlam_c
    Phi2 = np.einsum("ab...,bd...,cd...->ac...", D, H, D) + _d2bar_term(lam, j13, g)
    M = np.einsum("aA...,KA...->aKA...", n, N)  # M[:, :, A] = n_A (x) N_A
    P = np.einsum("A...,aKA...->aK...", Phi1, M)
    if not tangent:
        return P
    A = np.einsum("AB...,aKA...,bLB...->aKbL...", Phi2, M, M)
    c1, c2 = _pair_coefficients(lam, Phi1, Phi2)
    for a in range(3):
        for b in range(3):
            if a == b:
                continue
            nN = np.einsum("a...,K...->aK...", n[:, a], N[:, b])
            Nn = np.einsum("a...,K...->aK...", n[:, b], N[:, a])
            A = A + c1[a, b] * kin.outer(nN, nN) + c2[a, b] * kin.outer(nN, Nn)
    return A


def _d2bar_term(lam, j13, g):
    r"""sum_b g_b d^2 bar_b / (dlam_a dlam_c) with bar_b = J^{-1/3} lam_b, J = lam_1 lam_2 lam_3.

    d bar_b/dlam_a = j13 (delta_ab - lam_b/(3 lam_a)); differentiating again in lam_c:
    j13 [ -1/(3 lam_c) (delta_ab - lam_b/(3 lam_a)) - delta_bc/(3 lam_a) + delta_ac lam_b/(3 lam_a^2) ].
    """
    eye = np.eye(3).reshape((3, 3) + (1,) * (lam.ndim - 1))
    gl = np.einsum("b...,b...->...", g, lam)  # sum_b g_b lam_b
    inv = 1.0 / lam
    # sum_b g_b (delta_ab - lam_b/(3 lam_a)) = g_a - gl/(3 lam_a)
    s_a = g - gl * inv / 3.0
    term = (-inv[None, :] / 3.0 * s_a[:, None]          # -1/(3 lam_c) s_a
            - g[None, :] * inv[:, None] / 3.0           # -g_c /(3 lam_a)
            + eye * (gl * inv**2 / 3.0)[:, None])       # delta_ac gl /(3 lam_a^2)
    return j13 * term


def _pair_coefficients(lam, Phi1, Phi2):
    """c1[a, b], c2[a, b] of the spectral tangent and their limits for lam_a = lam_b."""
    la, lb = lam[:, None], lam[None, :]
    pa, pb = Phi1[:, None], Phi1[None, :]
    diff = la**2 - lb**2
    close = np.abs(la - lb) <= COINCIDENT * la
    safe = np.where(close, 1.0, diff)
    paa = np.einsum("aa...->a...", Phi2)[:, None]
    pab = Phi2
    c1 = np.where(close, 0.5 * (paa - pab + pa / la), (pa * la - pb * lb) / safe)
    c2 = np.where(close, 0.5 * (paa - pab - pa / la), (pa * lb - pb * la) / safe)
    return c1, c2


@dataclass(frozen=True)
class RubberLaw(SplitLaw):
    """W(J^{-1/3} lambda_i) + kappa/2 (J - 1)^2: any :mod:`softhand.reduced.materials.rubber` model, split for the
    mean-dilatation solids (``kappa`` default 1000 mu0, as :class:`softhand.fem.materials.NeoHookean`)."""

    material: rubber_models.Rubber
    kappa: float | None = None  #: bulk modulus [MPa]

    def __post_init__(self):
        if self.kappa is None:
            object.__setattr__(self, "kappa", 1000.0 * self.material.mu0)

    def split(self):
        return IsochoricRubber(self.material), Volumetric(self.kappa)



def rubber_law(material: rubber_models.Rubber, kappa: float):
    """The FEM law of a rubber: the closed-form :class:`softhand.fem.materials.NeoHookean` for NH."""
    from softhand.fem.materials import NeoHookean

    if isinstance(material, rubber_models.NeoHookean):
        return NeoHookean(material.mu, kappa)
    return RubberLaw(material, kappa)
