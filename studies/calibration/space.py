"""The design space of the finger calibration: its TOML file, its designs and their sampling.

A *design space* (a TOML file, e.g. ``studies/finger_space.toml``) gives ranges of the
dimensional design variables a, b, d, l0 and the tie width (n_s = 5 equal hinges, so 6
equal links of l0 / 6), a Latin-hypercube sample size and seed, explicit extra designs
(``[[design]]`` tables, e.g. corners) and the pressures::

    name = "finger_fem"
    lhs = 14                      # Latin-hypercube designs inside the box
    seed = 1
    pressures_mpa = [0.2, 0.5, 0.8]
    theta_target_deg = 64.0       # then go on until this bend (if p_max_mpa allows)
    p_max_mpa = 2.0
    p_step_mpa = 0.5
    [space]                        # [min, max] of each variable
    a_mm = [3.0, 6.0]
    b_mm = [3.0, 7.0]
    d_mm = [10.0, 20.0]
    l0_mm = [120.0, 200.0]
    tie_width_mm = [5.0, 15.0]
    # mesh_size_mm = 6.0           # optional: a uniform gmsh mesh (e.g. the CI mesh)
    # axial_size_mm = 5.0          # optional: the layered mesh with longer slices
    # base_design = "designs/paper.toml"   # optional: the other design values
    [[design]]                     # optional explicit designs (all five keys; may also set
                                   # its own p_max_mpa, p_step_mpa)
    a_mm = 3.0
    ...

:mod:`softhand.studies.calibration.finger` runs its designs as FEM cases.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from softhand.reduced.vocabulary.design import HandDesign

from softhand.reduced.vocabulary.design_files import load_design
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.batch.registry import check_path_end
from softhand.studies.batch.studyfile import NAME_RE

#: the dimensional variables of a design space, in this order
VARIABLES = ("a_mm", "b_mm", "d_mm", "l0_mm", "tie_width_mm")
#: load-path parameters a [[design]] table may set for itself
PATH_KEYS = ("p_max_mpa", "p_step_mpa")
_KEYS = ("name", "lhs", "seed", "pressures_mpa", "theta_target_deg", "p_max_mpa", "p_step_mpa",
         "space", "design", "base_design", "mesh_size_mm", "axial_size_mm", "mesh_pair", "prior")


@dataclass(frozen=True)
class DesignSpace:
    """A validated design space: the box, the sampled designs and the load path."""

    name: str  #: results go to results/<name>/
    box: dict  #: variable -> (min, max)
    points: tuple[dict, ...]  #: the designs, each variable -> value
    pressures_mpa: tuple[float, ...] = (0.2, 0.5, 0.8)
    theta_target_deg: float = 64.0
    p_max_mpa: float = 2.0
    p_step_mpa: float = 0.5
    base: HandDesign = HandDesign()
    mesh_size_mm: float | None = None  #: a uniform gmsh mesh of this size; None: the default mesh
    axial_size_mm: float | None = None  #: the layered mesh's largest slice [mm]; None: its default
    #: (point, pressures): one design run on this mesh and on the default one, to correct the
    #: table for the mesh (see studies.finger_table.mesh_correction); None: no correction
    mesh_pair: tuple | None = None
    prior: str = "paper"  #: the physics the table's residual is taken against (reduced.calibrated.finger_fem.PRIORS)

    def designs(self) -> list[HandDesign]:
        return [finger_design(p, self.base) for p in self.points]


def finger_design(point: dict, base: HandDesign = HandDesign()) -> HandDesign:
    """The design of one point (a, b, d, l0, tie width [mm]) with 5 equal hinges."""
    l0 = float(point["l0_mm"])
    return base.replace(a=float(point["a_mm"]), b=float(point["b_mm"]), d=float(point["d_mm"]),
                        l0=l0, n_s=5, hinge_s=tuple(l0 * k / 6.0 for k in range(1, 6)),
                        tie_width=float(point["tie_width_mm"]))


#: most Latin hypercubes drawn to find a design space's lhs designs that keep the design rules
MAX_DRAWS = 50


def latin_hypercube(box: dict, n: int, seed: int, keep=lambda point: True) -> list[dict]:
    """n points of a Latin hypercube in the box (one per stratum of each variable) that
    ``keep`` accepts: where it refuses some (a box whose corners break the design rules, e.g.
    a + b >= d), further hypercubes from the same seeded generator make up the number, their
    points in order (at most MAX_DRAWS hypercubes; fewer points if they do not suffice)."""
    rng = np.random.default_rng(seed)
    lo, hi = (np.array([box[v][i] for v in VARIABLES]) for i in (0, 1))
    points = []
    for _ in range(MAX_DRAWS):
        u = (np.array([rng.permutation(n) for _ in VARIABLES]).T + rng.uniform(size=(n, len(VARIABLES)))) / n
        points += [p for p in (dict(zip(VARIABLES, np.round(lo + row * (hi - lo), 3).tolist())) for row in u)
                   if keep(p)]
        if len(points) >= n:
            return points[:n]
    return points


#: (lowest, highest) of a design space's numbers: designs sampled, pressures [MPa], the target
#: angle [deg], the mesh [mm] (the bounds of ``softhand bend``'s options)
LIMITS = {"lhs": (0, 200), "seed": (0, 2**32 - 1), "pressures_mpa": (0.01, 5.0),
          "theta_target_deg": (1.0, 180.0), "p_max_mpa": (0.01, 5.0), "p_step_mpa": (0.01, 5.0),
          "mesh_size_mm": (0.5, 12.0), "axial_size_mm": (0.25, 20.0)}
#: most pressures of one design's path
MAX_PRESSURES = 50


def load_space(path: str | Path) -> DesignSpace:
    """Read and validate a design-space TOML file (see the module docstring)."""
    from softhand.reduced.vocabulary.inputfiles import read_toml

    path = Path(path)
    doc = read_toml(path, "--space", "a design-space TOML file")
    src = path.name
    for key in doc:
        if key not in _KEYS:
            raise InputError(f"{src}: {key}", doc[key], f"unknown key; allowed: {', '.join(_KEYS)}")
    name = doc.get("name", path.stem)
    if not isinstance(name, str) or not NAME_RE.match(name) or len(name) > 100:
        raise InputError(f"{src}: name", name,
                         "must be a string of at most 100 letters, digits, '_', '-', '.'")
    box = _box(doc.get("space"), src)
    tables = doc.get("design", [])
    if not isinstance(tables, list):
        raise InputError(f"{src}: design", tables, "must be [[design]] tables")
    points = [_point(p, box, f"{src}: design[{i}]") for i, p in enumerate(tables)]
    lhs, seed = (_whole(doc, key, default, src) for key, default in (("lhs", 0), ("seed", 0)))
    if "base_design" in doc and not isinstance(doc["base_design"], str):
        raise InputError(f"{src}: base_design", doc["base_design"], "must be a file name")
    try:
        base = load_design(path.parent / doc["base_design"]) if "base_design" in doc else HandDesign()
    except InputError as exc:
        raise exc.renamed(f"{src}: base_design") from None
    sampled = latin_hypercube(box, lhs, seed, keep=lambda p: _keeps_the_rules(p, base)) if lhs else []
    if len(sampled) < lhs:
        raise InputError(f"{src}: lhs", lhs, f"too many: {MAX_DRAWS} Latin hypercubes of the [space] box gave "
                         f"{len(sampled)} designs that keep the design rules (a + b < d, ties shorter than "
                         f"the links l0/6); narrow the box or sample fewer")
    points += sampled
    if not points:
        raise InputError(f"{src}: design", [], "no designs: give lhs > 0 or [[design]] tables")
    pressures = doc.get("pressures_mpa", [0.2, 0.5, 0.8])
    lo, hi = LIMITS["pressures_mpa"]
    if not isinstance(pressures, list) or not 0 < len(pressures) <= MAX_PRESSURES or any(
            not _number(p) or not lo <= p <= hi for p in pressures) or any(np.diff(pressures) <= 0):
        raise InputError(f"{src}: pressures_mpa", pressures,
                         f"must be 1 to {MAX_PRESSURES} increasing numbers in [{lo:g}, {hi:g}] MPa")
    numbers = {key: _bounded(doc, key, default, src)
               for key, default in (("theta_target_deg", 64.0), ("p_max_mpa", 2.0), ("p_step_mpa", 0.5))}
    check_path_end(pressures, numbers["p_max_mpa"], f"{src}: pressures_mpa")
    mesh, axial = (_bounded(doc, key, None, src) for key in ("mesh_size_mm", "axial_size_mm"))
    if mesh is not None and axial is not None:
        raise InputError(f"{src}: axial_size_mm", axial, "applies to the layered mesh; remove mesh_size_mm")
    pair = doc.get("mesh_pair")
    if pair is not None:
        if not isinstance(pair, dict) or "pressures_mpa" not in pair:
            raise InputError(f"{src}: mesh_pair", pair, f"must give {', '.join(VARIABLES)} and pressures_mpa")
        pair = dict(pair)
        pressures_pair = pair.pop("pressures_mpa")
        if not isinstance(pressures_pair, list) or not 2 <= len(pressures_pair) <= MAX_PRESSURES or any(
                not _number(p) or not lo <= p <= hi for p in pressures_pair) or any(np.diff(pressures_pair) <= 0):
            raise InputError(f"{src}: mesh_pair.pressures_mpa", pressures_pair,
                             f"must be 2 to {MAX_PRESSURES} increasing numbers in [{lo:g}, {hi:g}] MPa")
        pair = (_point(pair, {k: (0.0, math.inf) for k in VARIABLES}, f"{src}: mesh_pair"),
                tuple(float(p) for p in pressures_pair))
    from softhand.reduced.calibrated.finger_fem import PRIORS
    prior = doc.get("prior", "paper")
    if prior not in PRIORS:
        raise InputError(f"{src}: prior", prior, f"must be one of {', '.join(PRIORS)}")
    space = DesignSpace(name, box, tuple(points),
                        tuple(float(p) for p in pressures), base=base,
                        mesh_size_mm=None if mesh is None else float(mesh),
                        axial_size_mm=None if axial is None else float(axial), mesh_pair=pair,
                        prior=prior,
                        **{k: float(v) for k, v in numbers.items()})
    space.designs()  # validates every design now
    return space


def _keeps_the_rules(point: dict, base: HandDesign) -> bool:
    try:
        finger_design(point, base)
    except InputError:
        return False
    return True


def _number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _whole(doc: dict, key: str, default: int, src: str) -> int:
    value, (lo, hi) = doc.get(key, default), LIMITS[key]
    if not isinstance(value, int) or isinstance(value, bool) or not lo <= value <= hi:
        raise InputError(f"{src}: {key}", value, f"must be a whole number in [{lo}, {hi}]")
    return value


def _bounded(doc: dict, key: str, default, src: str):
    """``doc[key]`` as a float in LIMITS[key] (``default`` if absent)."""
    value, (lo, hi) = doc.get(key, default), LIMITS[key]
    if value is default:
        return value
    if not _number(value) or not lo <= value <= hi:
        raise InputError(f"{src}: {key}", value, f"must be a number in [{lo:g}, {hi:g}]")
    return float(value)


def _box(table, src: str) -> dict:
    if not isinstance(table, dict) or set(table) != set(VARIABLES):
        raise InputError(f"{src}: space", table, f"must give [min, max] of {', '.join(VARIABLES)}")
    box = {}
    for key in VARIABLES:
        span = table[key]
        if not (isinstance(span, list) and len(span) == 2 and all(map(_number, span))
                and 0 < span[0] <= span[1]):
            raise InputError(f"{src}: space.{key}", span, "must be [min, max] with 0 < min <= max [mm]")
        box[key] = (float(span[0]), float(span[1]))
    return box


def _point(table, box: dict, where: str) -> dict:
    if not isinstance(table, dict) or not set(VARIABLES) <= set(table) <= set(VARIABLES + PATH_KEYS):
        raise InputError(where, table, f"must give {', '.join(VARIABLES)} (and optionally "
                                       f"{', '.join(PATH_KEYS)})")
    for key in VARIABLES:
        if not _number(table[key]) or not box[key][0] <= table[key] <= box[key][1]:
            raise InputError(f"{where}.{key}", table[key], f"must be in [{box[key][0]}, {box[key][1]}]")
    for key in sorted(set(table) & set(PATH_KEYS)):
        lo, hi = LIMITS[key]
        if not _number(table[key]) or not lo <= table[key] <= hi:
            raise InputError(f"{where}.{key}", table[key], f"must be a number in [{lo:g}, {hi:g}] MPa")
    return {key: float(value) for key, value in table.items()}


def single_design_space(path: str | Path) -> DesignSpace:
    """The design space of one design file (its own box), for a table of that design alone."""
    from softhand.reduced.calibrated.finger_fem import groups_of

    design = load_design(path)
    groups_of(design)  # 5 equal hinges, or one error line
    point = {"a_mm": design.a, "b_mm": design.b, "d_mm": design.d, "l0_mm": design.l0,
             "tie_width_mm": design.tie_width}
    return DesignSpace(f"finger_{Path(path).stem}", {k: (v, v) for k, v in point.items()}, (point,),
                       base=design)
