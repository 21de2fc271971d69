r"""The finger tube: oil volume (2), axial stretch (8), strain energy (5) and zeta_f (10).

A tube of inner radius ``a``, wall ``b`` and length ``l0`` has its axis a distance ``d``
from the hinge plate, the finger's inextensible neutral line (Fig. 4). Bending the finger
by the total angle theta stretches the material point at radius rho = a + r (0 <= r <= b)
and polar angle phi of the cross-section by eq. (8):

.. math:: \lambda_f = 1 + c\,\theta, \qquad c(r, \phi) = \frac{d + (a + r)\sin\phi}{l_0}.

Kevlar windings keep lambda_2 = 1 and the rubber is incompressible, so lambda_3 = 1/lambda_f
(7) and the Neo-Hookean energy (5) is

.. math:: W_f = \int \frac{\mu_{sf}}{2}(\lambda_f^2 + \lambda_f^{-2} - 2)\, l_0 \rho\, dr\, d\phi,
          \qquad \frac{dW_f}{d\theta} = \mu_{sf}\,\zeta_f(\theta)   \quad (9), (10).

Other rubber (``design.finger_rubber``, :mod:`softhand.reduced.materials.rubber`): the same kinematics
lambda_1 = lambda_f, lambda_2 = 1, lambda_3 = 1/lambda_f (pure shear, planar tension) give

.. math:: W_f = \int \hat W(\lambda_f)\, l_0 \rho\, dr\, d\phi, \qquad
          \frac{dW_f}{d\theta} = \int \hat W'(\lambda_f)\, c\; l_0 \rho\, dr\, d\phi,
          \qquad \hat W(\lambda) = W(\lambda, 1, 1/\lambda),

with W'(lambda) the pure-shear nominal stress; for Neo-Hookean it is mu (lambda - lambda^-3)
and :func:`finger_force` is mu_sf zeta_f, computed by the paper's closed form (10).

Numerics. The integrand depends on phi only through sin phi and sin(pi - phi) = sin phi, so
the phi-integral over [0, 2 pi] is twice the one over [-pi/2, pi/2]. Both integrals use
tensor Gauss-Legendre rules (no adaptive quadrature). With x = c theta the integrands are
written without cancellation at small theta:

.. math:: \lambda - \lambda^{-3} = x\Big(1 + \frac{3 + 3x + x^2}{(1 + x)^3}\Big), \qquad
          \lambda^2 + \lambda^{-2} - 2 = \Big(\frac{x (2 + x)}{1 + x}\Big)^2.

Everything is vectorised over theta (any shape). Units: mm, MPa, N*mm, rad.

Finger models. What the hand (eqs. (25), (27), (28)) needs of a finger is its strain
energy W_f(theta) and its oil volume Q(theta), both of one finger, with their derivatives:
the pressure that holds a free finger at theta is P = (dW_f/dtheta) / (dQ/dtheta).
:func:`energy`, :func:`energy_rate`, :func:`volume`, :func:`volume_rate` and
:func:`oil_taken` dispatch on ``design.finger_model`` through a small registry mirroring the
reservoir's: ``"paper"`` (this module: eqs. (2), (5), (10)) is built in; another model
registers a :class:`FingerFunctions` with :func:`register_model`. A name not registered yet
is looked up in the module ``reduced.finger_<name>``, which must register it when imported.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Callable

import numpy as np

from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.vocabulary.registry import lookup

#: Gauss-Legendre orders across the wall (r) and around the tube (phi, half turn); the
#: relative quadrature error is below 1e-11 for -pi/2 <= theta <= pi (tests/reduced/test_reduced_finger.py).
ORDERS = (5, 10)
#: theta-values evaluated per block, so that the (block, nodes) work arrays stay in cache
_BLOCK = 2048


def Q(theta, design: HandDesign):
    """Eq. (2): oil volume inside the n fingers at total bend theta [rad] -> [mm^3]."""
    return design.n * design.a**2 * np.pi * (design.l0 + design.d * np.asarray(theta, float))


def axial_stretch(theta, r, phi, design: HandDesign):
    """Eq. (8): axial stretch at wall depth r [mm] (0..b), polar angle phi [rad], bend theta [rad]."""
    g = design
    return (g.l0 + (g.d + (g.a + r) * np.sin(phi)) * theta) / g.l0


@lru_cache(maxsize=8)
def _gauss(order: int):
    """Gauss-Legendre nodes and weights on [-1, 1] (numpy's leggauss costs ~1 ms a call)."""
    return np.polynomial.legendre.leggauss(order)


@lru_cache(maxsize=32)
def _nodes(a: float, b: float, d: float, l0: float, orders: tuple[int, int]):
    """Quadrature nodes c_q = d(lambda_f)/d(theta) and weights of l0 * rho dr dphi over the tube."""
    xr, wr = _gauss(orders[0])
    xp, wp = _gauss(orders[1])
    rho = a + 0.5 * b * (xr + 1.0)                  # [a, a + b]
    phi = 0.5 * np.pi * xp                          # [-pi/2, pi/2]
    c = (d + np.outer(rho, np.sin(phi))) / l0       # (n_r, n_phi)
    weight = 2.0 * l0 * np.outer(0.5 * b * wr * rho, 0.5 * np.pi * wp)  # factor 2: symmetry
    c, weight = c.ravel(), weight.ravel()
    c.flags.writeable = weight.flags.writeable = False
    return c, weight


def quadrature(design: HandDesign, orders: tuple[int, int] = ORDERS):
    """(c, weight): nodes c = d(lambda_f)/d(theta) [1/rad] and weights [mm^3] of the tube volume."""
    return _nodes(design.a, design.b, design.d, design.l0, tuple(orders))


def _integrate(kernel, theta, design: HandDesign, orders, weight_power: int) -> np.ndarray:
    """sum_q weight_q c_q^k kernel(c_q theta), blockwise over the flattened theta."""
    theta = np.asarray(theta, dtype=float)
    c, weight = quadrature(design, orders)
    weight = weight * c**weight_power
    flat = theta.ravel()
    out = np.empty(flat.shape)
    for start in range(0, flat.size, _BLOCK):       # loop over blocks of angles, not nodes
        x = np.multiply.outer(flat[start:start + _BLOCK], c)
        out[start:start + _BLOCK] = np.einsum("tq,q->t", kernel(x), weight)  # no BLAS threads
    return out.reshape(theta.shape)


def _stress_kernel(x):
    """(lambda - lambda^-3 - x) / x = u + u^2 + u^3 with u = 1/lambda; overwrites x."""
    u = np.reciprocal(np.add(x, 1.0, out=x), out=x)
    h = u + 1.0
    h *= u
    h += 1.0
    h *= u
    return h


def _energy_kernel(x):
    """(lambda^2 + lambda^-2 - 2) / 2, cancellation-free in x = c theta."""
    s = x * (2.0 + x) / (1.0 + x)
    return 0.5 * s * s


def _check_stretch(theta, design: HandDesign) -> None:
    c_max = (design.d + design.a + design.b) / design.l0
    if np.any(np.asarray(theta) * c_max <= -1.0):
        raise InputError("theta_deg", float(np.degrees(np.min(theta))),
                         f"must exceed {-np.degrees(1 / c_max):.0f} deg (tube stretch > 0)")


def zeta_f(theta, design: HandDesign, orders: tuple[int, int] = ORDERS):
    """Eq. (10): zeta_f(theta) [mm^3] with dW_f/dtheta = mu_sf * zeta_f, any-shaped theta [rad]."""
    _check_stretch(theta, design)
    theta = np.asarray(theta, dtype=float)
    c, weight = quadrature(design, orders)
    # lambda - lambda^-3 = x (1 + u + u^2 + u^3): no cancellation at small theta
    return theta * (weight @ c**2 + _integrate(_stress_kernel, theta, design, orders, 2))


def zeta_f_small_angle(theta, design: HandDesign):
    """Eq. (10) linearised (lambda - lambda^-3 ~ 4 (lambda - 1)), in closed form [mm^3].

    zeta_f ~ (4 pi theta / l0) [d^2 ((a+b)^2 - a^2) + ((a+b)^4 - a^4) / 4].
    """
    a, b, d, l0 = design.a, design.b, design.d, design.l0
    ro = a + b
    return 4.0 * np.pi * np.asarray(theta, float) / l0 * (d**2 * (ro**2 - a**2) + (ro**4 - a**4) / 4)


def strain_energy(theta, design: HandDesign, orders: tuple[int, int] = ORDERS):
    """Eq. (5) with (7), (8): strain energy W_f of one finger tube [N*mm] at bend theta [rad]
    (any rubber; Neo-Hookean by the paper's integrand)."""
    _check_stretch(theta, design)
    if design.finger_is_neo_hookean:
        return design.mu_sf * _integrate(_energy_kernel, theta, design, orders, 0)
    rubber = design.finger_rubber
    return _integrate(lambda x: rubber.mode_energy("pure-shear", 1.0 + x), theta, design, orders, 0)


def finger_force(theta, design: HandDesign, orders: tuple[int, int] = ORDERS):
    """dW_f/dtheta [N*mm/rad] of one finger tube, any rubber: mu_sf zeta_f (10) for Neo-Hookean."""
    if design.finger_is_neo_hookean:
        return design.mu_sf * zeta_f(theta, design, orders)
    _check_stretch(theta, design)
    rubber = design.finger_rubber
    return _integrate(lambda x: rubber.nominal_stress("pure-shear", 1.0 + x), theta, design, orders, 1)


# ---------------------------------------------------------------------- finger models
Fn = Callable[[np.ndarray, HandDesign], np.ndarray]


@dataclass(frozen=True)
class FingerFunctions:
    """One finger model: functions ``(theta [rad], design) -> array`` of theta's shape."""

    energy: Fn  #: strain energy W_f of one finger [N mm]
    energy_rate: Fn  #: dW_f/dtheta [N mm / rad]
    volume: Fn  #: oil volume Q inside one finger [mm^3]
    volume_rate: Fn  #: dQ/dtheta of one finger [mm^3 / rad]
    #: ``check(design)``: InputError if the model's own data for the design (a calibration
    #: table) cannot be used; None: the model has none
    check: Callable[[HandDesign], None] | None = None


_MODELS: dict[str, FingerFunctions] = {}


def check_volume(design: HandDesign, theta_max: float) -> None:
    """Raise if V0 cannot supply the oil the fingers take at bend ``theta_max`` [rad] (eq. (15))."""
    needed = design.n * float(oil_taken(theta_max, design))
    if needed >= design.V0:
        raise InputError("V0_mm3", design.V0,
                         f"must exceed the {needed:.0f} mm^3 the fingers take at "
                         f"{math.degrees(theta_max):.1f} deg")


def check_data(design: HandDesign) -> None:
    """The design's finger model's own data (its calibration table) read and checked now, not
    where a run first uses it: InputError naming it."""
    check = model(design.finger_model).check
    if check is not None:
        check(design)


def register_model(name: str, functions: FingerFunctions) -> None:
    """Make ``functions`` the finger model called ``name``."""
    _MODELS[name] = functions


def model(name: str) -> FingerFunctions:
    """The registered finger model ``name`` (imports reduced.finger_<name> on first use)."""
    return lookup(_MODELS, name, module=f"softhand.reduced.calibrated.finger_{name}", field="finger_model")


def energy(theta, design: HandDesign):
    """Strain energy W_f(theta) of one finger [N mm] of the model ``design.finger_model``."""
    return model(design.finger_model).energy(np.asarray(theta, float), design)


def energy_rate(theta, design: HandDesign):
    """dW_f/dtheta of one finger [N mm/rad]; the paper's model: mu_sf zeta_f (9)."""
    return model(design.finger_model).energy_rate(np.asarray(theta, float), design)


def volume(theta, design: HandDesign):
    """Oil volume Q(theta) inside one finger [mm^3]; the paper's model: eq. (2) / n."""
    return model(design.finger_model).volume(np.asarray(theta, float), design)


def volume_rate(theta, design: HandDesign):
    """dQ/dtheta of one finger [mm^3/rad]; the paper's model: a^2 pi d (eq. (4))."""
    return model(design.finger_model).volume_rate(np.asarray(theta, float), design)


def oil_taken(theta, design: HandDesign):
    """Q(theta) - Q(0) of one finger [mm^3]: the oil it has drawn from the reservoir at theta."""
    m = model(design.finger_model)
    if m is PAPER:  # eq. (2): a^2 pi d theta, without the cancellation of Q(theta) - Q(0)
        return design.a**2 * math.pi * design.d * np.asarray(theta, float)
    theta = np.asarray(theta, float)
    return m.volume(theta, design) - m.volume(np.zeros(()), design)


PAPER = FingerFunctions(
    energy=strain_energy,
    energy_rate=finger_force,
    volume=lambda theta, design: Q(theta, design) / design.n,
    volume_rate=lambda theta, design: np.full(np.shape(theta), design.a**2 * math.pi * design.d),
)
register_model("paper", PAPER)
