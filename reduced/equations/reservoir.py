r"""The rubber-sheet reservoir: oil volume (15), height (14), Ramanujan arc (13), stretch (16),
strain energy (11), zeta_r (18) and the reservoir pressure p_r(V) = dW_r/dV.

The sheet (radius R, thickness t) is clamped at its rim and bulges into half an ellipsoid of
revolution with height h holding the oil volume V = (2/3) pi R^2 h (14). The fingers take oil
from it, V(theta) = V0 - n a^2 pi d theta (15). Its meridian, half an ellipse with semi-axes
R and h, has the length L(h) (13), 2L being Ramanujan's full perimeter; the sheet is taken as
equi-biaxially stretched by lambda_r = L / (2R) (12), (16). Neo-Hookean (11):

.. math:: W_r = \frac{\mu_{sr}}{2}\,(2\lambda_r^2 + \lambda_r^{-4} - 3)\,\pi R^2 t, \qquad
          \zeta_r = 2(\lambda_r - \lambda_r^{-5})\frac{d\lambda_r}{d\theta}\pi R^2 t  \quad (18)

with the analytic chain rule d lambda_r / d theta = L'(h) / (2R) * 3 / (2 pi R^2) * (-n a^2 pi d).
The reservoir's gauge pressure is p_r(V) = dW_r/dV, hence
mu_sr zeta_r(theta) / (n a^2 pi d) = -p_r(V(theta)).

Other rubber (``design.reservoir_rubber``, :mod:`softhand.reduced.materials.rubber`): the same equi-biaxial
membrane kinematics (lambda_r, lambda_r, 1/lambda_r^2) give W_r = W(lambda_r, lambda_r,
lambda_r^-2) pi R^2 t and p_r = (dW/dlambda_r)(d lambda_r/dV) pi R^2 t, where dW/dlambda_r is
twice the equibiaxial nominal stress; for Neo-Hookean 2 mu (lambda - lambda^-5), eq. (18).

Reservoir models. :func:`pressure` dispatches on ``design.reservoir_model`` through a small
registry: ``"ellipse"`` (this module) is built in; another model registers a function
``pressure_fn(V, design) -> p_r [MPa]`` with :func:`register_model`. A model name that is
not registered yet is looked up in the module ``reduced.reservoir_<name>``, which must call
:func:`register_model` when imported.

Units: mm, mm^3, MPa, N*mm, rad.
"""
from __future__ import annotations

import warnings
from typing import Callable

import numpy as np

from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.vocabulary.registry import lookup
from softhand.reduced.equations.finger import oil_taken

PressureFn = Callable[[np.ndarray, HandDesign], np.ndarray]
_MODELS: dict[str, PressureFn] = {}


def oil_volume(theta, design: HandDesign):
    """Eq. (15): oil left in the reservoir at finger bend theta [rad] -> V [mm^3]; with
    another finger model than the paper's, V0 - n (Q(theta) - Q(0)) of that model."""
    g = design
    if g.finger_model != "paper":
        return g.V0 - g.n * oil_taken(theta, g)
    return g.V0 - g.a**2 * np.pi * g.d * g.n * np.asarray(theta, float)


def height(V, design: HandDesign):
    """Eq. (14): height h [mm] of the half-ellipsoid holding the volume V [mm^3]."""
    return 3.0 * np.asarray(V, float) / (2.0 * np.pi * design.R**2)


def half_perimeter(h, design: HandDesign):
    """Eq. (13): L(h) [mm], half of Ramanujan's perimeter of the ellipse with semi-axes R, h."""
    R, h = design.R, np.asarray(h, float)
    return 0.5 * np.pi * (3.0 * (R + h) - np.sqrt((R + 3.0 * h) * (h + 3.0 * R)))


def dhalf_perimeter_dh(h, design: HandDesign):
    """dL/dh of eq. (13) [-], analytic."""
    R, h = design.R, np.asarray(h, float)
    return 0.5 * np.pi * (3.0 - (3.0 * h + 5.0 * R) / np.sqrt((R + 3.0 * h) * (h + 3.0 * R)))


def stretch(V, design: HandDesign):
    """Eq. (16): equi-biaxial sheet stretch lambda_r = L(h(V)) / (2R) [-]."""
    return half_perimeter(height(V, design), design) / (2.0 * design.R)


#: thickest sheet, as t / R, that the sheet models describe: they are membrane models (eqs.
#: (11)-(18); the "fem" model adds the bending share measured by the FEM at t/R = 1/24 and
#: 1/12, the thickest of its tables, where it is 5 % of the pressure: p t / (mu R) at the
#: paper's V0 is 1.435, 1.463, 1.512 for t/R = 1/48, 1/24, 1/12)
MAX_THICKNESS_RATIO = 1.0 / 12.0

#: largest stretch of the reservoir sheet by eq. (16): rubber sheets break before (NBR's
#: elongation at break is 300-500 %, a stretch of 4-6)
MAX_SHEET_STRETCH = 6.0


def check_holds(V, design: HandDesign, field: str = "V0_mm3") -> None:
    """InputError naming ``field`` if the sheet holding V [mm^3] stretches past
    MAX_SHEET_STRETCH; a warning if the sheet is thicker than MAX_THICKNESS_RATIO (the models
    are extrapolated there). For a design a user gives (its V0) and the volumes asked of it; not
    for the optimiser's trial designs, which the task's own limits steer back (its answers
    beyond, negative pump pressures and stretches in the hundreds, are no answers)."""
    if design.t / design.R > MAX_THICKNESS_RATIO:
        warnings.warn(f"the reservoir sheet's t/R = {design.t:g}/{design.R:g} is above 1/12: the reservoir "
                      f"models are membrane models, checked against the sheet FEM up to 1/12 (bending "
                      f"adds 5 % to the pressure there); beyond, their answers are extrapolations")
    lam = float(stretch(V, design))
    if not lam <= MAX_SHEET_STRETCH:
        raise InputError(field, V, f"stretches the sheet (R_mm = {design.R:g}) to {lam:.4g} by "
                                   f"eq. (16); at most {MAX_SHEET_STRETCH:g}, where rubber breaks")


def dstretch_dV(V, design: HandDesign):
    """d lambda_r / dV [1/mm^3] from (13), (14), (16), analytic."""
    return dhalf_perimeter_dh(height(V, design), design) * 3.0 / (4.0 * np.pi * design.R**3)


def dstretch_dtheta(theta, design: HandDesign):
    """d lambda_r / d theta [1/rad], analytic: (d lambda_r/dV) (dV/dtheta), dV/dtheta = -n a^2 pi d."""
    g = design
    return dstretch_dV(oil_volume(theta, g), g) * (-g.n * g.a**2 * np.pi * g.d)


def zeta_r(theta, design: HandDesign):
    """Eq. (18): zeta_r(theta) [mm^3] with dW_r/dtheta = mu_sr * zeta_r; the ellipse model."""
    lam = stretch(oil_volume(theta, design), design)
    return 2.0 * (lam - lam**-5) * dstretch_dtheta(theta, design) * np.pi * design.R**2 * design.t


def strain_energy(V, design: HandDesign):
    """Eq. (11) with (12): strain energy W_r [N*mm] of the sheet holding V [mm^3] (ellipse model)."""
    lam = stretch(V, design)
    if not design.reservoir_is_neo_hookean:
        return design.reservoir_rubber.mode_energy("equibiaxial", lam) * np.pi * design.R**2 * design.t
    return 0.5 * design.mu_sr * (2.0 * lam**2 + lam**-4 - 3.0) * np.pi * design.R**2 * design.t


def ellipse_pressure(V, design: HandDesign):
    """p_r(V) = dW_r/dV [MPa] of the ellipse model: mu_sr 2 (lam - lam^-5) (dlam/dV) pi R^2 t
    (Neo-Hookean), dW/dlam (dlam/dV) pi R^2 t for another rubber."""
    V = np.asarray(V, float)
    if np.any(V <= 0.0):
        raise InputError("V_mm3", float(np.min(V)), "reservoir volume must be positive")
    lam = stretch(V, design)
    if not design.reservoir_is_neo_hookean:
        dW = 2.0 * design.reservoir_rubber.nominal_stress("equibiaxial", lam)  # dW/dlambda_r
        return dW * dstretch_dV(V, design) * np.pi * design.R**2 * design.t
    return design.mu_sr * 2.0 * (lam - lam**-5) * dstretch_dV(V, design) * np.pi * design.R**2 * design.t


def register_model(name: str, pressure_fn: PressureFn) -> None:
    """Make ``pressure_fn(V [mm^3], design) -> p_r [MPa]`` the reservoir model called ``name``."""
    _MODELS[name] = pressure_fn


def model(name: str) -> PressureFn:
    """The registered pressure function of reservoir model ``name`` (imports reduced.reservoir_<name>)."""
    return lookup(_MODELS, name, module=f"softhand.reduced.calibrated.reservoir_{name}", field="reservoir_model")


def pressure(V, design: HandDesign):
    """Reservoir gauge pressure p_r(V) = dW_r/dV [MPa] of the model ``design.reservoir_model``."""
    return model(design.reservoir_model)(np.asarray(V, float), design)


def oil_left(dQ, design: HandDesign):
    """Oil left in the reservoir [mm^3] once each of the n fingers has taken dQ [mm^3]: V0 - n dQ."""
    return design.V0 - design.n * np.asarray(dQ, float)


def pump_pressure(P_cavity, V, design: HandDesign, p_r=None):
    """The pump's pressure [MPa]: the fingers' cavity pressure P_cavity [MPa] less the
    reservoir's p_r at the oil left V [mm^3] (:func:`oil_volume` at a bend, :func:`oil_left`
    after an FEM finger's dQ). ``p_r``: the reservoir as a function V -> p_r [MPa] -- an FEM
    sheet's path, a plant's table; default the design's reservoir model (:func:`pressure`)."""
    return P_cavity - (pressure(V, design) if p_r is None else p_r(V))


def state(V, design: HandDesign) -> dict:
    """The reservoir at oil volume V [mm^3]: its pressure ``p_reservoir_MPa`` (any model) and,
    for the ellipse model only, the apex height ``h_mm`` (14) and sheet stretch ``lambda_r``
    (16) -- quantities of that geometry, which another model (e.g. "fem") does not assume."""
    out = {"p_reservoir_MPa": pressure(V, design)}
    if design.reservoir_model == "ellipse":
        out.update(h_mm=height(V, design), lambda_r=stretch(V, design))
    return out


register_model("ellipse", ellipse_pressure)
