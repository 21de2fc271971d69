"""The registry of study kinds: what one case computes and the parameters it accepts.

The built-in kinds are :data:`~softhand.studies.batch.registry.KINDS`; installed packages add more through the
``softhand.kinds`` entry-point group (:func:`~softhand.studies.batch.registry.all_kinds`). A study file names a kind; no
import path written in a file is ever imported (see :mod:`softhand.studies.batch.studyfile`).
"""
from __future__ import annotations

import importlib
import math
from dataclasses import dataclass

from softhand.reduced.equations import finger
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.equations.grasp import MAX_WEIGHT


@dataclass(frozen=True)
class Num:
    """A numeric case parameter in [lo, hi] (``choices``: only these values)."""

    lo: float = -math.inf
    hi: float = math.inf
    choices: tuple = ()

    def check(self, where: str, value) -> None:
        if not _is_number(value) or not math.isfinite(value):
            raise InputError(where, value, "must be a finite number")
        if self.choices and value not in self.choices:
            raise InputError(where, value, f"must be one of {', '.join(f'{c:g}' for c in self.choices)}")
        if not self.lo <= value <= self.hi:
            raise InputError(where, value, f"must be a number in [{self.lo:g}, {self.hi:g}]")


@dataclass(frozen=True)
class NumList:
    """A case parameter that is a list of finite numbers (at most ``max_len``), each in [lo, hi]
    (``above_lo``: in (lo, hi]); ``increasing``: strictly."""

    max_len: int = 100
    lo: float = -math.inf
    hi: float = math.inf
    increasing: bool = False
    above_lo: bool = False

    def check(self, where: str, value) -> None:
        ok = isinstance(value, list) and 0 < len(value) <= self.max_len \
            and all(_is_number(v) and math.isfinite(v) for v in value)
        if ok:
            ok = all((self.lo < v if self.above_lo else self.lo <= v) and v <= self.hi for v in value) \
                and (not self.increasing or all(a < b for a, b in zip(value, value[1:])))
        if not ok:
            within = "" if math.isinf(self.lo) and math.isinf(self.hi) else \
                f" in {'(' if self.above_lo else '['}{self.lo:g}, {self.hi:g}]"
            raise InputError(where, value, f"must be a list of 1 to {self.max_len} "
                             f"{'increasing ' if self.increasing else ''}finite numbers{within}")


def _grasp_weights(params: dict, design: HandDesign, src: str) -> None:
    """weights or diameter_mm, not both (as ``softhand grasp``); weights: n_s numbers that move
    the tip sideways at the case's theta (else F_x is undetermined, as the verb refuses). Their
    sum is not checked: eq. (23) asks for 1, but the paper's own w for 180 mm sums to 1.4."""
    if "weights" in params and "diameter_mm" in params:
        raise InputError(f"{src}: diameter_mm", params["diameter_mm"], "give weights or diameter_mm, not both")
    if "weights" not in params:
        return
    from softhand.reduced.equations.grasp import projected_jacobian

    w = params["weights"]
    if len(w) != design.n_s:
        raise InputError(f"{src}: weights", w, f"must be n_s = {design.n_s} numbers")
    J_xw, _ = projected_jacobian(math.radians(params["theta_deg"]), w, design)
    if not abs(float(J_xw)) >= 1e-9:
        raise InputError(f"{src}: weights", w, f"make J_x w = 0 at theta_deg = {params['theta_deg']:g}: "
                         "the tip does not move sideways, F_x is undetermined")


def _one_mesh(params: dict, design: HandDesign, src: str) -> None:
    if "mesh_size_mm" in params and "axial_size_mm" in params:
        raise InputError(f"{src}: axial_size_mm", params["axial_size_mm"],
                         "applies to the layered mesh; remove mesh_size_mm (a uniform gmsh mesh)")


def finger_mesh_fits(params: dict, design: HandDesign, src: str) -> None:
    """The case's finger mesh fits this machine's memory (a lower bound on its unknowns, counted
    without meshing): one line when the study is read, not a case failing after the others ran."""
    from softhand.fem.hand.finger_options import finger_tube
    from softhand.fem.hand.finger_options import check_size, mesh_options
    from softhand.reduced.vocabulary.errors import MeshTooLarge

    options = mesh_options(params.get("mesh_size_mm"), params.get("axial_size_mm"))
    try:
        check_size(finger_tube(design, options), options)
    except MeshTooLarge as exc:
        key = "axial_size_mm" if "axial_size_mm" in params else "mesh_size_mm"
        raise InputError(f"{src}: {key}", params.get(key), exc.allowed) from None


def _push_before_end(params: dict, design: HandDesign, src: str) -> None:
    push, end = params.get("push_at_s", 5.0), params.get("t_end_s", 10.0)
    if not push < end:
        raise InputError(f"{src}: push_at_s", push, f"must be before t_end_s = {end:g}")


def _enough_oil(params: dict, design: HandDesign, src: str) -> None:
    if "theta_deg" in params and params["theta_deg"] > 0:
        finger.check_volume(design, math.radians(params["theta_deg"]))


def _oil_to_theta_max(params: dict, design: HandDesign, src: str) -> None:
    """The reservoir holds the oil the fingers take up to the stroke's end (default: the
    design's own), checked at load time as the curve kind checks its angles."""
    finger.check_volume(design, math.radians(params.get("theta_max_deg", 90.0)))  # the kind's default


def _paper_weights_fit(params: dict, design: HandDesign, src: str) -> None:
    """Without ``weights``, the case takes the paper's w for its diameter: the design needs its
    number of hinges (as ``softhand control`` / ``grasp`` refuse it up front)."""
    if "weights" not in params:
        from softhand.reduced.equations.grasp import weights_for_diameter

        try:
            weights_for_diameter(params.get("diameter_mm", 180.0), design)
        except InputError as exc:
            raise exc.renamed(f"{src}: {exc.field}") from None


#: the reservoir sheet's most elements along the radius and through the thickness (as
#: ``softhand reservoir --n-radial/--n-thick`` allow)
RESERVOIR_ELEMENTS = {"n_radial": 400, "n_thick": 20}


def _reservoir_mesh(params: dict, design: HandDesign, src: str) -> None:
    """The sheet's elements that mesh_size_mm gives this design (R / h, t / h) within what the
    reservoir verb allows."""
    h = params.get("mesh_size_mm")
    if h is None:
        return
    for name, length, where in (("n_radial", design.R, "along the radius"),
                                ("n_thick", design.t, "through the thickness")):
        n, most = math.ceil(length / h), RESERVOIR_ELEMENTS[name]
        if n > most:
            raise InputError(f"{src}: mesh_size_mm", h, f"gives {n} elements {where} of this design's "
                             f"sheet; at most {most}: a mesh size >= {length / most:.4g} mm")


def check_path_end(pressures, p_max: float, where: str) -> None:
    """The listed pressures [MPa] end at or below the load path's end p_max (a design space's,
    and the finger_bend kind's)."""
    if pressures[-1] > p_max:
        raise InputError(where, pressures, f"must end at or below p_max_mpa = {p_max:g} MPa, the load path's end")


def _path_within_p_max(params: dict, design: HandDesign, src: str) -> None:
    """The pressures end at or below the load path's end p_max_mpa (as a design space checks)."""
    if params.get("pressures_mpa") and "p_max_mpa" in params:
        check_path_end(params["pressures_mpa"], params["p_max_mpa"], f"{src}: pressures_mpa")


def _pressure_reached(params: dict, design: HandDesign, src: str) -> None:
    """A pressure the design's free hand reaches (its range depends on the design): the reduced
    model's inverse, at load time, not as a failed case."""
    if "pressure_mpa" in params:
        from softhand.reduced.equations import hand

        try:
            hand.bend_angles(params["pressure_mpa"], design)
        except InputError as exc:
            raise InputError(f"{src}: pressure_mpa", params["pressure_mpa"], exc.allowed) from None


@dataclass(frozen=True)
class Kind:
    """What one case of a study computes, and the parameters it accepts."""

    target: str  #: "package.module:function", imported lazily
    params: dict | None  #: parameter name -> Num / NumList; None: a plugin's, unchecked
    fem: bool = False  #: True if it takes mesh_size_mm
    required: tuple[str, ...] = ()  #: parameters every case must have
    exactly_one: tuple[str, ...] = ()  #: every case has exactly one of these
    mesh: Num = Num(0.1, 50.0)  #: allowed mesh_size_mm [mm] (FEM kinds)
    #: checks of a whole case, fn(params, design, src) raising InputError (cheap: no model runs)
    checks: tuple = ()


_THETA, _PRESSURE, _MASS = Num(-90.0, 180.0), Num(-5.0, 5.0), Num(0.0, 100.0)
_PAPER_D = Num(choices=(180.0, 240.0))  #: the paper's weight vectors

#: kind name -> Kind. Add a kind with one line here.
KINDS: dict[str, Kind] = {
    "curve": Kind("softhand.studies.batch.kinds:curve", {"theta_deg": _THETA, "pressure_mpa": _PRESSURE},
                  exactly_one=("theta_deg", "pressure_mpa"), checks=(_enough_oil, _pressure_reached)),
    "grasp": Kind("softhand.studies.batch.kinds:grasp",
                  {"pressure_mpa": _PRESSURE, "theta_deg": _THETA, "mass_kg": _MASS,
                   "diameter_mm": _PAPER_D, "weights": NumList(20, -MAX_WEIGHT, MAX_WEIGHT)},
                  required=("pressure_mpa", "theta_deg"), checks=(_grasp_weights, _paper_weights_fit)),
    "control": Kind("softhand.studies.batch.kinds:control",
                    {"theta_ref_deg": Num(-29.9, 119.9), "mass_kg": _MASS, "diameter_mm": _PAPER_D,
                     "push_n": Num(-1000.0, 1000.0), "push_at_s": Num(1.0, 600.0),
                     "t_end_s": Num(2.0, 600.0)}, checks=(_push_before_end, _paper_weights_fit)),
    "reservoir": Kind("softhand.studies.batch.kinds:reservoir", {"theta_max_deg": Num(1.0, 180.0)}, fem=True,
                      mesh=Num(0.05, 24.0), checks=(_oil_to_theta_max, _reservoir_mesh)),
    "weights": Kind("softhand.studies.batch.kinds:weights",
                    {"diameter_mm": Num(60.0, 500.0), "mass_kg": Num(0.0, 20.0),
                     "pressure_mpa": Num(0.01, 5.0), "dP_mpa": Num(0.001, 0.5)}, fem=True,
                    mesh=Num(2.0, 12.0)),
    # the load path as a design space's (studies.calibration.space.LIMITS); bend_case needs all four
    "finger_bend": Kind("softhand.studies.calibration.finger:bend_case",
                        {"pressures_mpa": NumList(200, 0.01, 5.0, increasing=True),
                         "theta_target_deg": Num(1.0, 180.0), "p_max_mpa": Num(0.01, 5.0),
                         "p_step_mpa": Num(0.01, 5.0), "axial_size_mm": Num(0.25, 20.0)},
                        fem=True, mesh=Num(2.0, 12.0), checks=(_one_mesh, finger_mesh_fits, _path_within_p_max),
                        required=("pressures_mpa", "theta_target_deg", "p_max_mpa", "p_step_mpa")),
    # one design's blocked-hinge grid (studies.calibration.hinges: --space); no parameters
    "hinge_grid": Kind("softhand.studies.calibration.hinges:grid_case", {}),
    # one design's free hinges and their condensed stiffness (studies.calibration.hinge_coupling); no parameters
    "hinge_coupling": Kind("softhand.studies.calibration.hinge_coupling:coupling_case", {}),
    # one design's finger held by grasp-like hinge loads (studies.calibration.hinge_blocked); no parameters
    "hinge_blocked": Kind("softhand.studies.calibration.hinge_blocked:blocked_case", {}),
}
#: the entry-point group where installed packages declare more kinds
ENTRY_POINT_GROUP = "softhand.kinds"
#: most cases a study may have unless the caller allows more (``--max-cases``)
MAX_CASES = 10_000


def all_kinds() -> dict[str, Kind]:
    """The built-in kinds and those of installed plugins (a built-in name wins)."""
    from importlib.metadata import entry_points

    kinds = {}
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        if ep.name not in KINDS:
            kinds[ep.name] = _plugin_kind(ep)
    return {**kinds, **KINDS}


def _plugin_kind(ep) -> Kind:
    try:
        obj = ep.load()
    except Exception as exc:  # a broken plugin is the plugin's bad input, one line
        raise InputError("kind", ep.name, f"plugin {ep.value} cannot be loaded ({exc})") from None
    if isinstance(obj, Kind):
        return obj
    if callable(obj):
        return Kind(ep.value, None)
    raise InputError("kind", ep.name, f"plugin {ep.value} is neither a Kind nor a function")


def resolve_kind(kind: str):
    """The case function of the registered kind ``kind``, imported now."""
    kinds = KINDS if kind in KINDS else all_kinds()
    if kind not in kinds:
        raise InputError("kind", kind, f"unknown kind; allowed: {', '.join(all_kinds())}")
    module_name, _, func = kinds[kind].target.partition(":")
    try:
        return getattr(importlib.import_module(module_name), func)
    except (ImportError, AttributeError) as exc:
        raise InputError("kind", kind, f"cannot be loaded ({exc})") from None


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)
