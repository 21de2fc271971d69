"""``softhand grasp``: tip forces of a finger holding an object, eqs. (24), (25), (29).

Given the pump pressure, the bend angle, the object's mass and a weight vector w, prints
F_x (25), F_y (24) and the normal force F_v (29) in N and kgf. w is given as numbers, by the
name of one of the paper's vectors (``--weights paper180``), or from the grasp FEM for any
object diameter (``--diameter-mm D``: :mod:`softhand.studies.weights`, cached; the first call for a
new diameter runs the FEM). ``w_source`` in the output says which. Axes and signs:
docs/conventions.md (F_v > 0: the finger squeezes).

``--model fem`` (with ``--diameter-mm D``) replaces eq. (25) by the FEM-informed estimate of
:mod:`softhand.reduced.calibrated.grasp_fem`: the calibrated finger in equilibrium hinge by hinge against the
object, touching where the geometry says; P is converted to the cavity pressure with the
reservoir at theta, and the object's depth is the one that gives theta. Both are computed
by :mod:`softhand.studies.grasp`; this verb reads the options and prints.
"""
from __future__ import annotations

import sys
import warnings

import numpy as np

from softhand.fem.newton import NotConverged
from softhand.reduced.equations import grasp
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.cli.args import NUMBER_LIST, add_design_option, add_json_option, design_from_args, \
    parse_values, print_json, require_finite
from softhand.studies.grasp import state, state_fem

#: the paper's weight vectors by name (--weights paper180)
PAPER_NAMES = {f"paper{D:g}": D for D in grasp.PAPER_WEIGHTS}
_WEIGHT_FORMS = f"{NUMBER_LIST}, or one of {', '.join(PAPER_NAMES)}"

HELP = "grasping forces F_x, F_y, F_v at a pressure, bend angle and mass (eqs. 24, 25, 29)"
#: --model: eq. (25) as printed, or the FEM-informed estimate (reduced.calibrated.grasp_fem)
MODELS = ("paper", "fem")


def configure(parser) -> None:
    parser.add_argument("--pressure-mpa", required=True, metavar="P", help="pump pressure [MPa]")
    parser.add_argument("--theta-deg", required=True, metavar="T", help="bend angle [deg]")
    parser.add_argument("--mass-kg", required=True, metavar="M", help="mass of the object [kg]")
    which = parser.add_mutually_exclusive_group(required=True)
    which.add_argument("--weights", metavar="W1,..",
                       help="weight vector w, n_s comma-separated numbers "
                            "(write --weights=-0.13,0,... when the first is negative), or the "
                            f"paper's by name: {', '.join(PAPER_NAMES)}")
    which.add_argument("--diameter-mm", metavar="D",
                       help="object diameter [mm]: w from the grasp FEM (cached; see softhand weights)")
    parser.add_argument("--normalise", action="store_true", help="scale w to sum to 1 (eq. (23))")
    parser.add_argument("--model", default="paper", metavar="|".join(MODELS),
                        help="paper: eq. (25) with w (default); fem: the calibrated finger in "
                             "equilibrium against the object where it touches (needs --diameter-mm)")
    add_design_option(parser)
    add_json_option(parser)


#: option -> (lowest, highest) allowed
LIMITS = {"--pressure-mpa": (-5.0, 5.0), "--theta-deg": (-90.0, 180.0), "--mass-kg": (0.0, 100.0),
          "--diameter-mm": (60.0, 500.0)}


def _scalar(text: str, field: str) -> float:
    lo, hi = LIMITS[field]
    allowed = f"one number in [{lo:g}, {hi:g}]"
    values = parse_values(text, field, 1, allowed)
    if not lo <= values[0] <= hi:
        raise InputError(field, text, f"must be {allowed}")
    return float(values[0])


def _fem_weights(diameter: float, mass: float, design) -> tuple[np.ndarray, str, list[str]]:
    """w from the grasp FEM (studies.weights, cached) at its default pressure and mesh, where it
    came from, and the caveat on eq. (25) with it where the FEM's own F_v says it is off."""
    from softhand.studies.weights import WeightsCase, weights
    from softhand.studies.weights_rows import reduced_note

    if not diameter > 0:
        raise InputError("diameter_mm", diameter, "must be a positive number")
    case = WeightsCase(design=design, diameter_mm=diameter, mass_kg=mass)
    result = weights(case)
    note = reduced_note(result.get("F_v_reduced_N"), result["F_v_fem_N"], result["contact_force_N"], design) \
        if "F_v_fem_N" in result else None
    caveat = [f"at the grasp FEM's own state (P_cavity {result['P_cavity_MPa']:g} MPa, theta "
              f"{result['theta_deg']:.4g} deg) {note}; --model fem puts the force where the finger "
              "touches"] if note else []
    return np.array(result["w"]), (f"FEM: D = {diameter:g} mm, m = {mass:g} kg, P_cavity = "
                                   f"{case.pressure_mpa:g} + {case.dP_mpa:g} MPa, mesh "
                                   f"{case.mesh_size_mm:g} mm{' (cached)' if result['cached'] else ''}"), caveat


def _weights(args, design, mass: float) -> tuple[np.ndarray, str, list[str]]:
    """The w asked for (checked, maybe normalised), where it came from, the warnings about it."""
    caveat = []
    if args.weights is not None and args.weights.strip() in PAPER_NAMES:
        D = PAPER_NAMES[args.weights.strip()]
        w, source = grasp.weights_for_diameter(D, design), f"paper, {D:g} mm (section III-C)"
    elif args.weights is not None:
        if ":" in args.weights:  # a range start:stop:step is no vector of hinge weights
            raise InputError("--weights", args.weights, f"must be {_WEIGHT_FORMS}: one weight per hinge, "
                                                        "not a range")
        w, source = parse_values(args.weights, "--weights", forms=_WEIGHT_FORMS, more=None), "given"
    else:
        w, source, caveat = _fem_weights(_scalar(args.diameter_mm, "--diameter-mm"), mass, design)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", grasp.WeightSumWarning)
        w = grasp.check_weights(w, design, normalise=args.normalise)
    return w, source, [str(warning.message) for warning in caught] + caveat


def _model(args) -> str:
    model = args.model.strip()
    if model not in MODELS:
        raise InputError("--model", args.model, f"must be one of {', '.join(MODELS)}")
    if model == "fem" and (args.weights is not None or args.normalise):
        raise InputError("--model", args.model, "takes the object's --diameter-mm, not --weights "
                                                "or --normalise")
    return model


def run(args) -> int:
    design = design_from_args(args)
    P = _scalar(args.pressure_mpa, "--pressure-mpa")
    theta_deg = _scalar(args.theta_deg, "--theta-deg")
    mass = _scalar(args.mass_kg, "--mass-kg")
    if _model(args) == "fem":
        diameter = _scalar(args.diameter_mm, "--diameter-mm")
        try:
            result = state_fem(P, theta_deg, mass, diameter, design)
        except InputError as exc:  # named as the option the user typed
            raise (exc.renamed("--theta-deg") if exc.field == "theta_deg" else exc) from None
        _require_finite(result, args)
        return _print(args, result)
    if args.weights is not None and args.weights.strip() not in PAPER_NAMES:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", grasp.WeightSumWarning)
                grasp.check_weights(parse_values(args.weights, "--weights", 1000, _WEIGHT_FORMS, more=None), design)
        except InputError as exc:
            raise exc.renamed("--weights") from None
    try:
        w, source, notes = _weights(args, design, mass)
    except NotConverged as exc:  # the grasp FEM behind --diameter-mm: one line, exit 1
        print(f"softhand grasp: error: the grasp FEM for w at --diameter-mm {args.diameter_mm} did not "
              f"converge: {str(exc).split(';')[0]}; 'softhand weights --diameter-mm "
              f"{args.diameter_mm}' keeps the state it reached", file=sys.stderr)
        return 1
    result = state(P, theta_deg, mass, w, design) | {"model": "paper", "w_source": source}
    _require_finite(result, args)  # before the warnings: a refused result prints one line only
    for note in notes:  # only once the inputs are known to be good
        print(f"softhand grasp: warning: {note}", file=sys.stderr)
    return _print(args, result)


def _require_finite(result: dict, args) -> None:
    require_finite(result, args, f"at P_pump = {result['P_pump_MPa']:g} MPa, theta = {result['theta_deg']:g} deg")


def _print(args, result: dict) -> int:
    if args.json:
        print_json(result)
    else:
        width = max(map(len, result))
        lines = [f"{key:<{width}}  {_text(value)}" for key, value in result.items()]
        print("\n".join(lines))  # formatted first: nothing half-printed
    return 0


def _text(value) -> str:
    """One value of the result table (None: not applicable, e.g. no contact point)."""
    if value is None:
        return "none"
    if isinstance(value, list):
        return "[" + ", ".join(f"{v:g}" for v in value) + "]"
    return value if isinstance(value, str) else f"{value:.4g}"
