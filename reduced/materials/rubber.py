r"""Incompressible rubber: strain energies W(lambda1, lambda2, lambda3) and their derivatives.

One place for the hyperelastic models (their common interface, the test modes and the
invariants in :mod:`softhand.reduced.materials.rubber_base`), pure NumPy and vectorised over any array shape.
The reduced model evaluates them on its kinematics (finger: lambda, 1, 1/lambda;
reservoir: lambda, lambda, 1/lambda^2); ``softhand material fit`` on the test modes; the
FEM (:mod:`softhand.fem.materials`) builds its isochoric stress and tangent tensors from the
invariant derivatives of the same objects, at the isochoric stretches J^{-1/3} lambda_i.

Models (I1 = sum lambda_i^2, I2 = sum_{i<j} lambda_i^2 lambda_j^2, both at J = 1):

.. math::
    W_\text{NH} &= \tfrac{\mu}{2}(I_1 - 3), \qquad
    W_\text{MR} = C_{10}(I_1 - 3) + C_{01}(I_2 - 3), \\
    W_\text{Yeoh} &= C_{10}(I_1 - 3) + C_{20}(I_1 - 3)^2 + C_{30}(I_1 - 3)^3, \qquad
    W_\text{Gent} = -\tfrac{\mu J_m}{2}\ln\Big(1 - \frac{I_1 - 3}{J_m}\Big), \\
    W_\text{Ogden} &= \sum_p \frac{\mu_p}{\alpha_p}(\lambda_1^{\alpha_p} + \lambda_2^{\alpha_p}
        + \lambda_3^{\alpha_p} - 3) \quad\text{(Ogden's 1972 convention)}.

Initial shear moduli: mu, 2 (C10 + C01), 2 C10, mu, (1/2) sum mu_p alpha_p.

Every model gives ``energy``, ``dW`` (dW/dlambda_i, shape (3, ...)) and ``d2W``
(d2W/dlambda_i dlambda_j, (3, 3, ...)), exact; invariant models also ``dI``
((W_1, W_2)) and ``d2I`` ((W_11, W_12, W_22)). Test modes (incompressible, nominal
stress = force per reference area, in the stretched direction):

* ``uniaxial``: (lambda, lambda^-1/2, lambda^-1/2), P = dW/dlambda;
* ``equibiaxial``: (lambda, lambda, lambda^-2), P = (1/2) dW/dlambda (per direction);
* ``pure-shear`` (planar tension): (lambda, 1, 1/lambda), P = dW/dlambda.

The parameter names are public (TOML keys and ``--json``): NH ``mu_MPa``; MR ``C10_MPa``,
``C01_MPa``; Yeoh ``C10_MPa``, ``C20_MPa``, ``C30_MPa``; Gent ``mu_MPa``, ``Jm``; Ogden
``mu1_MPa``, ``alpha1``, ``mu2_MPa``, ``alpha2``, ... Units: MPa.

A model from its public parameter names, checked: :mod:`softhand.reduced.materials.rubber_parameters`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from softhand.reduced.materials.rubber_base import MODES, InvariantRubber, Rubber, stretches

__all__ = ["drucker_check", "NeoHookean", "MooneyRivlin", "Yeoh", "Gent", "Ogden", "MODELS"]

@dataclass(frozen=True)
class NeoHookean(InvariantRubber):
    """W = mu/2 (I1 - 3)."""

    mu: float  #: shear modulus [MPa]
    model = "neo-hookean"

    @property
    def mu0(self):
        return self.mu

    def W(self, I1, I2):
        return 0.5 * self.mu * (I1 - 3.0)

    def dI(self, I1, I2):
        return 0.5 * self.mu * np.ones_like(I1), np.zeros_like(I1)

    def d2I(self, I1, I2):
        zero = np.zeros_like(I1)
        return zero, zero, zero


@dataclass(frozen=True)
class MooneyRivlin(InvariantRubber):
    """W = C10 (I1 - 3) + C01 (I2 - 3)."""

    C10: float  #: [MPa]
    C01: float  #: [MPa]
    model = "mooney-rivlin"

    @property
    def mu0(self):
        return 2.0 * (self.C10 + self.C01)

    def W(self, I1, I2):
        return self.C10 * (I1 - 3.0) + self.C01 * (I2 - 3.0)

    def dI(self, I1, I2):
        one = np.ones_like(I1)
        return self.C10 * one, self.C01 * one

    def d2I(self, I1, I2):
        zero = np.zeros_like(I1)
        return zero, zero, zero


@dataclass(frozen=True)
class Yeoh(InvariantRubber):
    """W = C10 (I1 - 3) + C20 (I1 - 3)^2 + C30 (I1 - 3)^3."""

    C10: float  #: [MPa]
    C20: float = 0.0  #: [MPa]
    C30: float = 0.0  #: [MPa]
    model = "yeoh"

    @property
    def mu0(self):
        return 2.0 * self.C10

    def W(self, I1, I2):
        x = I1 - 3.0
        return x * (self.C10 + x * (self.C20 + x * self.C30))

    def dI(self, I1, I2):
        x = I1 - 3.0
        return self.C10 + x * (2.0 * self.C20 + 3.0 * self.C30 * x), np.zeros_like(x)

    def d2I(self, I1, I2):
        x = I1 - 3.0
        zero = np.zeros_like(x)
        return 2.0 * self.C20 + 6.0 * self.C30 * x, zero, zero


@dataclass(frozen=True)
class Gent(InvariantRubber):
    """W = -mu Jm / 2 ln(1 - (I1 - 3)/Jm); nan beyond the chain-locking limit I1 - 3 >= Jm."""

    mu: float  #: initial shear modulus [MPa]
    Jm: float  #: locking parameter: the largest I1 - 3 [-]
    model = "gent"

    @property
    def mu0(self):
        return self.mu

    def _g(self, I1):
        g = 1.0 - (np.asarray(I1, float) - 3.0) / self.Jm
        return np.where(g > 0.0, g, np.nan)

    def W(self, I1, I2):
        return -0.5 * self.mu * self.Jm * np.log(self._g(I1))

    def dI(self, I1, I2):
        return 0.5 * self.mu / self._g(I1), np.zeros_like(np.asarray(I1, float))

    def d2I(self, I1, I2):
        zero = np.zeros_like(np.asarray(I1, float))
        return 0.5 * self.mu / (self.Jm * self._g(I1) ** 2), zero, zero


@dataclass(frozen=True)
class Ogden(Rubber):
    """W = sum_p mu_p / alpha_p (l1^alpha_p + l2^alpha_p + l3^alpha_p - 3)."""

    mu: tuple  #: mu_p [MPa]
    alpha: tuple  #: alpha_p [-], nonzero
    model = "ogden"

    def __post_init__(self):
        object.__setattr__(self, "mu", tuple(float(m) for m in self.mu))
        object.__setattr__(self, "alpha", tuple(float(a) for a in self.alpha))

    @property
    def mu0(self):
        return 0.5 * sum(m * a for m, a in zip(self.mu, self.alpha))

    def parameters(self):
        out = {}
        for p, (m, a) in enumerate(zip(self.mu, self.alpha), start=1):
            out[f"mu{p}_MPa"], out[f"alpha{p}"] = m, a
        return out

    def scaled(self, factor):
        return Ogden(tuple(factor * m for m in self.mu), self.alpha)

    def energy(self, l1, l2, l3):
        l = np.stack(np.broadcast_arrays(*map(np.asarray, (l1, l2, l3)))).astype(float)
        return sum(m / a * ((l**a).sum(axis=0) - 3.0) for m, a in zip(self.mu, self.alpha))

    def dW(self, l1, l2, l3):
        l = np.stack(np.broadcast_arrays(*map(np.asarray, (l1, l2, l3)))).astype(float)
        return sum(m * l ** (a - 1.0) for m, a in zip(self.mu, self.alpha))

    def d2W(self, l1, l2, l3):
        l = np.stack(np.broadcast_arrays(*map(np.asarray, (l1, l2, l3)))).astype(float)
        diag = sum(m * (a - 1.0) * l ** (a - 2.0) for m, a in zip(self.mu, self.alpha))
        eye = np.eye(3).reshape((3, 3) + (1,) * (l.ndim - 1))
        return eye * diag[:, None]


#: the rubber models by name
MODELS = {cls.model: cls for cls in (NeoHookean, MooneyRivlin, Yeoh, Gent, Ogden)}


def drucker_check(material: Rubber, stretch_range: tuple[float, float], n: int = 200) -> dict:
    """Drucker stability in the three modes at n log-spaced stretches of ``stretch_range``.

    Returns {"stable", "range", "first_unstable": {"mode", "stretch"} or None, "skipped"}:
    points where W is not defined (beyond Gent's locking) are skipped and counted."""
    lo, hi = stretch_range
    lam = np.geomspace(lo, hi, n)
    first, skipped = None, 0
    for mode in MODES:
        H = material.drucker_hessian(*stretches(mode, lam))
        ok = np.all(np.isfinite(H), axis=(0, 1))
        skipped += int(np.sum(~ok))
        eig = np.full(lam.shape, np.inf)
        eig[ok] = np.linalg.eigvalsh(np.moveaxis(H[:, :, ok], -1, 0))[:, 0]
        bad = np.flatnonzero(eig <= 0)
        if bad.size and first is None:
            near = bad[np.argmin(np.abs(np.log(lam[bad])))]  # the one nearest the reference
            first = {"mode": mode, "stretch": float(lam[near])}
    return {"stable": first is None, "range": [float(lo), float(hi)], "first_unstable": first,
            "skipped": skipped}
