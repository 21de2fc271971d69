"""Study files: a TOML description of a batch of cases, validated into a :class:`~softhand.studies.batch.studyfile.Study`.

A study file names a *kind* (what one case computes), a design, the sweep axes and
optionally fixed parameters and a mesh size::

    kind = "curve"                      # a registered kind (see all_kinds())
    name = "curve_mu"                   # optional; default: the file's stem
    description = "P(theta) for three rubber moduli"
    design = "designs/paper.toml"       # a file, relative to the study file ...
    # [design]                          # ... or inline overrides (public design keys),
    # file = "designs/paper.toml"       #     optionally over a base file
    # V0_mm3 = 16000.0
    mesh_size_mm = 2.0                  # FEM kinds only

    [sweep]                             # axes, combined as a product
    theta_deg = "0:90:10"               # start:stop:step, stop included
    mu_sf_MPa = [1.0, 1.15, 1.3]        # a design key: one design per value

    [params]                            # fixed case parameters
    mass_kg = 2.0

A sweep axis is either a parameter of the kind or a public design key
(:data:`softhand.reduced.vocabulary.design.PUBLIC_KEYS`). Every error is one line naming the field.

A study file is data: its kind is a *name*, looked up in the built-in :data:`~softhand.studies.batch.registry.KINDS` and in
the ``softhand.kinds`` entry-point group of installed packages (:func:`~softhand.studies.batch.registry.all_kinds`); no
import path written in a file is ever imported. Registering a built-in kind is one line
in :data:`softhand.studies.batch.registry.KINDS`: ``name -> Kind("module:function", {param: Num(lo, hi), ...}, fem=...)``;
a plugin package declares ``[project.entry-points."softhand.kinds"] name =
"package.module:KIND"`` pointing at a :class:`~softhand.studies.batch.registry.Kind` (or at the case function itself,
whose parameters are then not checked). The function has the signature
``fn(case_params: dict, design: HandDesign, outdir: Path) -> dict`` and returns
numbers (floats or lists of floats; optional ``"mesh"`` and ``"solver"`` dicts go
into the provenance); it may write VTK/PNG files into ``outdir``. The module is
imported only when a case of that kind runs.

The whole file is validated before the first case runs: every case's parameters against
their kind's ranges, every swept design, and the number of cases (at most
:data:`~softhand.studies.batch.registry.MAX_CASES` unless the caller allows more).
"""
from __future__ import annotations

import itertools
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

from softhand.reduced.equations import reservoir
from softhand.reduced.vocabulary.design import PUBLIC_KEYS, HandDesign
from softhand.reduced.vocabulary.design_files import design_from_dict, load_design
from softhand.reduced.vocabulary.inputfiles import read_toml
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.io.values import parse_values
from softhand.studies.batch.registry import ENTRY_POINT_GROUP, KINDS, MAX_CASES, Kind, Num, NumList, all_kinds, \
    resolve_kind

__all__ = ["KINDS", "MAX_CASES", "Kind", "Num", "NumList", "Study", "all_kinds", "load_study",
           "resolve_kind", "study_from_dict"]


_TOP_KEYS = ("kind", "name", "description", "design", "mesh_size_mm", "sweep", "params")
#: what a study's (and a design space's) name may be: it names a results folder
NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")


def is_folder_name(name) -> bool:
    """``name`` can name a results folder: letters, digits, '_', '-', '.', starting with a letter
    or digit, at most 100 characters (never '.', '..' nor a path)."""
    return isinstance(name, str) and bool(NAME_RE.match(name)) and len(name) <= 100


@dataclass(frozen=True)
class Study:
    """A validated study: the product of its sweep axes over a base design."""

    name: str  #: results go to results/<name>/
    kind: str  #: a name of :func:`~softhand.studies.batch.registry.all_kinds`
    design: HandDesign  #: the base design, before design axes are applied
    axes: tuple[tuple[str, tuple], ...]  #: (axis name, values) in file order
    params: dict = field(default_factory=dict)  #: fixed case parameters
    mesh_size_mm: float | None = None  #: FEM mesh size [mm]
    description: str = ""
    path: Path | None = None  #: the study file

    def cases(self) -> list[tuple[dict, HandDesign]]:
        """(case params, design) for every point of the sweep, in sweep order."""
        names = [name for name, _ in self.axes]
        out = []
        for values in itertools.product(*(vals for _, vals in self.axes)):
            point = dict(zip(names, values))
            design_keys = {k: v for k, v in point.items() if k in PUBLIC_KEYS}
            params = {**self.params, **{k: v for k, v in point.items() if k not in design_keys}}
            if self.mesh_size_mm is not None:
                params["mesh_size_mm"] = self.mesh_size_mm
            out.append((params, design_from_dict(design_keys, self.design, source="sweep")
                        if design_keys else self.design))
        return out


def load_study(path: str | Path, *, max_cases: int = MAX_CASES) -> Study:
    """Read and validate a study TOML file (at most ``max_cases`` cases)."""
    path = Path(path)
    doc = read_toml(path, "study file", "a study TOML file")
    return study_from_dict(doc, path=path, max_cases=max_cases)


def study_from_dict(doc: dict, *, path: Path | None = None, max_cases: int = MAX_CASES) -> Study:
    """Validate a parsed study document; file paths are relative to ``path``'s folder."""
    src = path.name if path else "study"
    for key in doc:
        if key not in _TOP_KEYS:
            raise InputError(f"{src}: {key}", doc[key], f"unknown key; allowed: {', '.join(_TOP_KEYS)}")
    kind = _kind(doc.get("kind"), src)
    name = doc.get("name", path.stem if path else None)
    if not is_folder_name(name):
        given = "" if "name" in doc else (" (the study's results folder is named after its file "
                                          "unless the file sets name = \"...\")")
        raise InputError(f"{src}: name", name, "must be a string of at most 100 letters, digits, '_', "
                         f"'-', '.', starting with a letter or digit{given}")
    description = doc.get("description", "")
    if not isinstance(description, str):
        raise InputError(f"{src}: description", description, "must be a string")
    base = path.parent if path else Path.cwd()
    design = _design(doc.get("design"), base, src)
    mesh = _mesh_size(doc.get("mesh_size_mm"), kind, src)
    params = _params(doc.get("params", {}), kind, src)
    axes = _axes(doc.get("sweep"), kind, params, src)
    inline = doc.get("design") if isinstance(doc.get("design"), dict) else {}
    for key, values in axes:
        if key in inline:
            raise InputError(f"{src}: sweep.{key}", list(values), "is also in [design]; give it once "
                             "(the sweep would override it)")
    count = math.prod(len(values) for _, values in axes)
    if count > max_cases:
        raise InputError(f"{src}: sweep", f"{count} cases", f"at most {max_cases} cases "
                         "(the product of the axes' lengths); --max-cases N allows more")
    study = Study(name=name, kind=kind, design=design, axes=axes, params=params,
                  mesh_size_mm=mesh, description=description, path=path)
    spec = all_kinds()[kind]
    for case_params, case_design in study.cases():  # every case now, not in a worker
        try:
            reservoir.check_holds(case_design.V0, case_design)  # a swept V0 or R too
        except InputError as exc:
            raise exc.renamed(f"{src}: {exc.field}") from None
        _check_case(case_params, case_design, spec, src)
    return study


def _check_case(params: dict, design: HandDesign, kind: Kind, src: str) -> None:
    """One case's parameters against its kind: ranges, required, exactly one of, checks."""
    if kind.params is None:
        return
    for key, value in params.items():
        spec = kind.params.get(key)
        if spec is not None:
            spec.check(f"{src}: {key}", value)
    missing = [k for k in kind.required if k not in params]
    if missing:
        raise InputError(f"{src}: {missing[0]}", None, "missing; give it in [sweep] or [params]")
    if kind.exactly_one and sum(k in params for k in kind.exactly_one) != 1:
        raise InputError(f"{src}: sweep", sorted(k for k in params if k in kind.exactly_one),
                         f"give exactly one of {', '.join(kind.exactly_one)}")
    for check in kind.checks:
        check(params, design, src)


def _kind(kind, src: str) -> str:
    kinds = all_kinds()
    if isinstance(kind, str) and kind in kinds:
        return kind
    raise InputError(f"{src}: kind", kind, f"unknown kind; allowed: {', '.join(kinds)} "
                     f"(more from installed plugins, entry-point group {ENTRY_POINT_GROUP})")


def _accepted(kind: str) -> tuple[str, ...] | None:
    """The parameters ``kind`` accepts; None for a plugin kind that does not declare them."""
    params = all_kinds()[kind].params
    return None if params is None else tuple(params)


def _design(spec, base: Path, src: str) -> HandDesign:
    if spec is None:
        return HandDesign()
    if isinstance(spec, str):
        try:
            return load_design(base / spec)
        except InputError as exc:
            raise (exc.renamed(f"{src}: design") if exc.field == "--design" else exc) from None
    if not isinstance(spec, dict):
        raise InputError(f"{src}: design", spec, "must be a file name or a table of design keys")
    overrides = dict(spec)
    file = overrides.pop("file", None)
    if file is not None and not isinstance(file, str):
        raise InputError(f"{src}: design.file", file, "must be a file name")
    try:
        start = load_design(base / file) if file else HandDesign()
    except InputError as exc:
        raise (exc.renamed(f"{src}: design.file") if exc.field == "--design" else exc) from None
    for key in ("finger_table", "hinge_table"):
        table = overrides.get(key)
        if isinstance(table, str) and table and "\0" not in table:  # next to the study file, as a design file's
            overrides[key] = os.path.abspath(base / table)
    return design_from_dict(overrides, start, source=f"{src}: design")


def _mesh_size(value, kind: str, src: str) -> float | None:
    if value is None:
        return None
    spec = all_kinds()[kind]
    if spec.params is not None and not spec.fem:
        raise InputError(f"{src}: mesh_size_mm", value, f"kind {kind!r} has no mesh; remove it")
    spec.mesh.check(f"{src}: mesh_size_mm", value)
    return float(value)


def _check_param_name(key: str, kind: str, where: str, *, design_ok: bool) -> None:
    accepted = _accepted(kind)
    if accepted is None or key in accepted or (design_ok and key in PUBLIC_KEYS):
        return
    allowed = ", ".join(accepted + (("or a design key",) if design_ok else ()))
    raise InputError(where, key, f"unknown parameter of kind {kind!r}; allowed: {allowed}")


def _params(table, kind: str, src: str) -> dict:
    if not isinstance(table, dict):
        raise InputError(f"{src}: params", table, "must be a table of name = value")
    for key, value in table.items():
        _check_param_name(key, kind, f"{src}: params", design_ok=False)
        if not _is_scalar(value) and not (isinstance(value, list) and all(map(_is_number, value))):
            raise InputError(f"{src}: params.{key}", value,
                             "must be a number, a string or a list of numbers")
    return dict(table)


def _axes(table, kind: str, params: dict, src: str) -> tuple[tuple[str, tuple], ...]:
    if not isinstance(table, dict) or not table:
        raise InputError(f"{src}: sweep", table,
                         "must be a non-empty table of axis = list or 'start:stop:step'")
    axes = []
    for key, spec in table.items():
        _check_param_name(key, kind, f"{src}: sweep", design_ok=True)
        if key in params:
            raise InputError(f"{src}: sweep.{key}", spec, "is also in [params]; give it once")
        axes.append((key, _axis_values(spec, f"{src}: sweep.{key}")))
    return tuple(axes)


def _axis_values(spec, where: str) -> tuple:
    if isinstance(spec, str):
        return tuple(round(float(v), 12) for v in parse_values(spec, where))
    if not isinstance(spec, list) or not spec:
        what = "empty sweep" if isinstance(spec, list) else "a sweep is a list of values or a range"
        one = f" ([{spec}] for one value)" if _is_number(spec) else ""
        raise InputError(where, spec, f"{what}; give a non-empty list or 'start:stop:step'{one}")
    if not all(_is_scalar(v) for v in spec):
        raise InputError(where, spec, "must list numbers or strings")
    return tuple(spec)


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _is_scalar(value) -> bool:
    return _is_number(value) or isinstance(value, str)
