"""A rubber model (:mod:`softhand.reduced.materials.rubber`) from its public parameters, as in a
design file's ``[finger.material]`` table, checked: the model's name, the parameter names
(matched regardless of case), their values, and that the material is defined and
Drucker-stable over the stretches a hand's rubber reaches
(:data:`softhand.reduced.materials.rubber_parameters.WORKING_STRETCHES`).
"""
from __future__ import annotations

import math
from dataclasses import fields

import numpy as np

from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.materials.rubber import MODELS, Ogden, drucker_check
from softhand.reduced.materials.rubber_base import PUBLIC_NAMES, Rubber

#: largest ``|alpha_p|`` of an Ogden term: a hand's stretches of 2 raised to 300 give 1e90 MPa
MAX_OGDEN_ALPHA = 30.0
#: stretches every mode of a hand's rubber reaches in use (tube walls, reservoir sheet): the
#: material must be defined and Drucker-stable over them, or the models' answers are nonsense
#: (negative pressures from an unstable Mooney-Rivlin, nan past Gent's locking)
WORKING_STRETCHES = (0.5, 2.0)
#: the rubber's critical distance rho [mm]: its stretch is judged averaged over a ball of this
#: radius (softhand.fem.rubber_stretch), a length of the material, not of the part; of 1, 1.5,
#: 2 and 3 mm the smallest whose value moved by less than 2 % between the layered meshes with
#: 5 and 2.5 mm slices (the paper's and a thin finger at 2.0 MPa; docs/finger.md)
CRITICAL_DISTANCE_MM = 2.0


def between_sizes(values, ratios, ratio: float):
    """A measure at a part's size ratio (size / CRITICAL_DISTANCE_MM) from its ``values`` (k, ...)
    at the tabulated increasing ``ratios`` (k,): piecewise linear in the ratio's logarithm (a
    power law of the part's size between neighbours, as near a bonded corner), the end
    segments continued beyond them."""
    nodes = np.log(np.asarray(ratios, float))
    x = math.log(ratio)
    k = int(np.clip(np.searchsorted(nodes, x) - 1, 0, len(nodes) - 2))
    t = (x - nodes[k]) / (nodes[k + 1] - nodes[k])
    return (1.0 - t) * np.asarray(values[k]) + t * np.asarray(values[k + 1])


def parameter_names(model: str, terms: int = 3) -> tuple[str, ...]:
    """The public parameter names of a model (``terms``: Ogden's number of terms)."""
    if model == "ogden":
        return tuple(k for p in range(1, terms + 1) for k in (f"mu{p}_MPa", f"alpha{p}"))
    cls = _model_class(model)
    return tuple(PUBLIC_NAMES[f.name] for f in fields(cls))


_MODEL_ALIASES = {"neohookean": "neo-hookean", "nh": "neo-hookean", "mooneyrivlin": "mooney-rivlin",
                  "mr": "mooney-rivlin"}


def canonical_model(model: str) -> str:
    """The model's name as in :data:`~softhand.reduced.materials.rubber.MODELS` (case, '_' or ' ' for '-', a few short names)."""
    name = str(model).strip().lower().replace("_", "-").replace(" ", "-")
    return _MODEL_ALIASES.get(name.replace("-", ""), name)


def _model_class(model):
    if model not in MODELS:
        raise InputError("model", model, f"must be one of {', '.join(MODELS)}")
    return MODELS[model]


def from_parameters(model: str, values: dict, *, source: str = "material") -> Rubber:
    """A validated model from its public parameter names (as in ``[finger.material]``; names
    and the model are matched regardless of case)."""
    model = canonical_model(model)
    try:
        cls = _model_class(model)
    except InputError as exc:
        raise exc.renamed(f"{source}.model") from None
    for key, value in values.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise InputError(f"{source}.{key}", value, "must be a finite number")
    if model == "ogden":
        terms = sum(1 for k in values if k.lower().startswith("mu") and k.lower().endswith("_mpa"))
        names = parameter_names(model, max(terms, 1))
    else:
        names = parameter_names(model)
    canonical = {n.lower(): n for n in names}
    seen = {}
    for key in values:  # names match regardless of case: two spellings of one name are one given twice
        if key.lower() in seen:
            raise InputError(f"{source}.{key}", values[key], f"is given twice (also as {seen[key.lower()]}; "
                             "parameter names match regardless of case)")
        seen[key.lower()] = key
    values = {canonical.get(k.lower(), k): v for k, v in values.items()}
    unknown = set(values) - set(names)
    if unknown:
        raise InputError(f"{source}.{sorted(unknown)[0]}", values[sorted(unknown)[0]],
                         f"unknown parameter of model {model!r}; allowed: {', '.join(names)}")
    required = names if model != "yeoh" else ("C10_MPa",)
    missing = [k for k in required if k not in values]
    if missing:
        raise InputError(f"{source}.{missing[0]}", None, f"missing; model {model!r} needs "
                         f"{', '.join(names)}")
    if model == "ogden":
        mus = [values[f"mu{p}_MPa"] for p in range(1, terms + 1)]
        alphas = [values[f"alpha{p}"] for p in range(1, terms + 1)]
        if any(a == 0 for a in alphas):
            raise InputError(f"{source}.alpha", alphas, "Ogden exponents must be nonzero")
        rubber = Ogden(tuple(mus), tuple(alphas))
    else:
        field_of = {v: k for k, v in PUBLIC_NAMES.items()}
        rubber = cls(**{field_of[k]: float(v) for k, v in values.items()})
    if not rubber.mu0 > 0:
        raise InputError(f"{source}", rubber.parameters(),
                         f"initial shear modulus {rubber.mu0:.6g} MPa must be positive")
    if model == "gent" and not rubber.Jm > 0:
        raise InputError(f"{source}.Jm", rubber.Jm, "must be positive")
    if model == "ogden" and not all(abs(a) <= MAX_OGDEN_ALPHA for a in rubber.alpha):
        raise InputError(f"{source}.alpha", list(rubber.alpha), f"Ogden exponents must be within "
                         f"+-{MAX_OGDEN_ALPHA:g} (rubber fits need at most ~10)")
    _check_working_range(rubber, source)
    return rubber


def _check_working_range(rubber: Rubber, source: str) -> None:
    check = drucker_check(rubber, WORKING_STRETCHES, n=61)
    lo, hi = WORKING_STRETCHES
    if check["skipped"]:
        raise InputError(f"{source}", rubber.parameters(), f"is not defined at every stretch in "
                         f"[{lo:g}, {hi:g}] (past Gent's locking?), which a hand's rubber reaches")
    if not check["stable"]:
        bad = check["first_unstable"]
        raise InputError(f"{source}", rubber.parameters(), f"is not stable (Drucker) in {bad['mode']} "
                         f"at stretch {bad['stretch']:.3g}, inside [{lo:g}, {hi:g}], which a hand's "
                         "rubber reaches")
