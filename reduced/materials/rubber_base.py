"""The interface of the incompressible rubber models of :mod:`softhand.reduced.materials.rubber`: W and its
principal-stretch derivatives, the test modes (uniaxial, equibiaxial, pure shear) with their
nominal stresses, Drucker stability, and the chain rule of the invariant models W(I1, I2).
"""
from __future__ import annotations

from dataclasses import fields, replace

import numpy as np

from softhand.reduced.vocabulary.errors import InputError

__all__ = ["MODES", "PUBLIC_NAMES", "Rubber", "stretches", "InvariantRubber", "invariants"]

#: dataclass field -> public parameter name
PUBLIC_NAMES = {"mu": "mu_MPa", "C10": "C10_MPa", "C01": "C01_MPa", "C20": "C20_MPa",
                "C30": "C30_MPa", "Jm": "Jm"}

MODES = ("uniaxial", "equibiaxial", "pure-shear")


class Rubber:
    """Base of the models: principal-stretch interface, modes, parameters by public name."""

    model = ""  #: the name in design files (``model = "..."``)

    # -- parameters ----------------------------------------------------------------------
    def parameters(self) -> dict:
        """Public name -> value."""
        return {PUBLIC_NAMES[f.name]: float(getattr(self, f.name)) for f in fields(self)}

    def scaled(self, factor: float) -> "Rubber":
        """The same shape of W with every modulus [MPa] times ``factor``."""
        return replace(self, **{f.name: factor * getattr(self, f.name) for f in fields(self)
                                if PUBLIC_NAMES[f.name].endswith("_MPa")})

    @property
    def mu0(self) -> float:
        """Initial shear modulus [MPa]."""
        raise NotImplementedError

    # -- modes ---------------------------------------------------------------------------
    def mode_energy(self, mode: str, lam):
        """W along a test mode at stretch lam [MPa]."""
        return self.energy(*stretches(mode, lam))

    def nominal_stress(self, mode: str, lam):
        """Nominal stress [MPa] of a test mode at stretch lam (see the module docstring)."""
        lam = np.asarray(lam, float)
        dl, share = _path_rates(mode, lam)
        return np.einsum("i...,i...->...", self.dW(*stretches(mode, lam)), dl) / share

    def drucker_hessian(self, l1, l2, l3):
        r"""Hessian of w(e1, e2) = W(e^e1, e^e2, e^{-e1-e2}) in the log strains, (2, 2, ...).

        Positive definite <=> Drucker stable (d sigma : d epsilon > 0, incompressible)."""
        l = np.stack(np.broadcast_arrays(*map(np.asarray, (l1, l2, l3))))
        g, H = self.dW(*l), self.d2W(*l)
        out = np.empty((2, 2) + l.shape[1:])
        for a in range(2):
            for b in range(2):
                out[a, b] = (H[a, b] * l[a] * l[b] - H[a, 2] * l[a] * l[2] - H[b, 2] * l[b] * l[2]
                             + H[2, 2] * l[2] ** 2 + g[2] * l[2] + (a == b) * g[a] * l[a])
        return out


def stretches(mode: str, lam):
    """Principal stretches (l1, l2, l3) of an incompressible test mode at stretch lam."""
    lam = np.asarray(lam, float)
    if mode == "uniaxial":
        return lam, lam**-0.5, lam**-0.5
    if mode == "equibiaxial":
        return lam, lam, lam**-2.0
    if mode == "pure-shear":
        return lam, np.ones_like(lam), 1.0 / lam
    raise InputError("mode", mode, f"must be one of {', '.join(MODES)}")


def _path_rates(mode, lam):
    """(d l_i / d lam (3, ...), number of stretched directions sharing dW/dlam)."""
    one, zero = np.ones_like(lam), np.zeros_like(lam)
    if mode == "uniaxial":
        return np.stack([one, -0.5 * lam**-1.5, -0.5 * lam**-1.5]), 1.0
    if mode == "equibiaxial":
        return np.stack([one, one, -2.0 * lam**-3.0]), 2.0
    stretches(mode, lam)  # raises for an unknown mode
    return np.stack([one, zero, -lam**-2.0]), 1.0


class InvariantRubber(Rubber):
    """W(I1, I2): the principal-stretch derivatives follow by the chain rule."""

    def energy(self, l1, l2, l3):
        return self.W(*invariants(l1, l2, l3))

    def dW(self, l1, l2, l3):
        l = np.stack(np.broadcast_arrays(*map(np.asarray, (l1, l2, l3)))).astype(float)
        W1, W2 = self.dI(*invariants(*l))
        sq = l**2
        return 2.0 * l * (W1 + W2 * (sq.sum(axis=0) - sq))

    def d2W(self, l1, l2, l3):
        l = np.stack(np.broadcast_arrays(*map(np.asarray, (l1, l2, l3)))).astype(float)
        I1, I2 = invariants(*l)
        W1, W2 = self.dI(I1, I2)
        W11, W12, W22 = self.d2I(I1, I2)
        sq = l**2
        a = 2.0 * l                                  # dI1/dl_i
        b = 2.0 * l * (sq.sum(axis=0) - sq)          # dI2/dl_i
        eye = np.eye(3).reshape((3, 3) + (1,) * (l.ndim - 1))
        d2I2 = 4.0 * l[:, None] * l[None, :] * (1.0 - eye) + eye * (2.0 * (sq.sum(axis=0) - sq))[:, None]
        return (W11 * a[:, None] * a[None, :] + W12 * (a[:, None] * b[None, :] + b[:, None] * a[None, :])
                + W22 * b[:, None] * b[None, :] + W1 * 2.0 * eye + W2 * d2I2)


def invariants(l1, l2, l3):
    """(I1, I2) of the principal stretches (I2 = sum_{i<j} l_i^2 l_j^2)."""
    s1, s2, s3 = (np.asarray(x, float) ** 2 for x in (l1, l2, l3))
    return s1 + s2 + s3, s1 * s2 + s2 * s3 + s3 * s1
