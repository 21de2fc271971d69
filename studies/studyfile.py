"""Study files: a TOML description of a batch of cases, validated into a :class:`Study`.

A study file names a *kind* (what one case computes), a design, the sweep axes and
optionally fixed parameters and a mesh size::

    kind = "curve"                      # a name in KINDS, or "package.module:function"
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
(:data:`reduced.design.PUBLIC_KEYS`). Every error is one line naming the field.

Registering a kind is one line in :data:`KINDS`: ``name -> Kind("module:function",
(accepted params...), fem=...)``. The function has the signature
``fn(case_params: dict, design: HandDesign, outdir: Path) -> dict`` and returns
numbers (floats or lists of floats; optional ``"mesh"`` and ``"solver"`` dicts go
into the provenance); it may write VTK/PNG files into ``outdir``. The module is
imported only when a case of that kind runs.
"""
from __future__ import annotations

import importlib
import itertools
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from reduced.design import PUBLIC_KEYS, HandDesign, design_from_dict, load_design
from reduced.errors import InputError
from studies.args import parse_values


@dataclass(frozen=True)
class Kind:
    """What one case of a study computes."""

    target: str  #: "package.module:function", imported lazily
    params: tuple[str, ...]  #: case parameters the function accepts
    fem: bool = False  #: True if it takes mesh_size_mm


#: kind name -> Kind. Add a kind with one line here.
KINDS: dict[str, Kind] = {
    "curve": Kind("studies.kinds:curve", ("theta_deg", "pressure_mpa")),
    "grasp": Kind("studies.kinds:grasp",
                  ("pressure_mpa", "theta_deg", "mass_kg", "diameter_mm", "weights")),
    "control": Kind("studies.kinds:control", ("theta_ref_deg", "mass_kg", "diameter_mm",
                                              "push_n", "push_at_s", "t_end_s")),
    "reservoir": Kind("studies.kinds:reservoir", ("theta_max_deg",), fem=True),
    "weights": Kind("studies.kinds:weights", ("diameter_mm", "mass_kg", "pressure_mpa", "dP_mpa"),
                    fem=True),
    "finger_bend": Kind("studies.finger_calibration:bend_case",
                        ("pressures_mpa", "theta_target_deg", "p_max_mpa", "p_step_mpa"), fem=True),
}

_TOP_KEYS = ("kind", "name", "description", "design", "mesh_size_mm", "sweep", "params")
_NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")


@dataclass(frozen=True)
class Study:
    """A validated study: the product of its sweep axes over a base design."""

    name: str  #: results go to results/<name>/
    kind: str  #: a key of KINDS or "module:function"
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


def resolve_kind(kind: str):
    """The case function of ``kind`` (a KINDS name or "module:function"), imported now."""
    target = KINDS[kind].target if kind in KINDS else kind
    module_name, _, func = target.partition(":")
    try:
        return getattr(importlib.import_module(module_name), func)
    except (ImportError, AttributeError) as exc:
        raise InputError("kind", kind, f"cannot be loaded ({exc})") from None


def load_study(path: str | Path) -> Study:
    """Read and validate a study TOML file."""
    path = Path(path)
    try:
        with open(path, "rb") as f:
            doc = tomllib.load(f)
    except (FileNotFoundError, IsADirectoryError):
        raise InputError("study file", str(path), "no such file; give a study TOML file") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError("study file", str(path), f"is not valid TOML ({exc})") from None
    return study_from_dict(doc, path=path)


def study_from_dict(doc: dict, *, path: Path | None = None) -> Study:
    """Validate a parsed study document; file paths are relative to ``path``'s folder."""
    src = path.name if path else "study"
    for key in doc:
        if key not in _TOP_KEYS:
            raise InputError(f"{src}: {key}", doc[key], f"unknown key; allowed: {', '.join(_TOP_KEYS)}")
    kind = _kind(doc.get("kind"), src)
    name = doc.get("name", path.stem if path else None)
    if not isinstance(name, str) or not _NAME_RE.match(name):
        raise InputError(f"{src}: name", name, "must be a string of letters, digits, '_', '-', '.'")
    description = doc.get("description", "")
    if not isinstance(description, str):
        raise InputError(f"{src}: description", description, "must be a string")
    base = path.parent if path else Path.cwd()
    design = _design(doc.get("design"), base, src)
    mesh = _mesh_size(doc.get("mesh_size_mm"), kind, src)
    params = _params(doc.get("params", {}), kind, src)
    axes = _axes(doc.get("sweep"), kind, params, src)
    study = Study(name=name, kind=kind, design=design, axes=axes, params=params,
                  mesh_size_mm=mesh, description=description, path=path)
    study.cases()  # validates every swept design now, not in a worker
    return study


def _kind(kind, src: str) -> str:
    if isinstance(kind, str) and (kind in KINDS or re.match(r"^[\w.]+:\w+$", kind)):
        return kind
    raise InputError(f"{src}: kind", kind,
                     f"unknown kind; allowed: {', '.join(KINDS)} or 'package.module:function'")


def _accepted(kind: str) -> tuple[str, ...] | None:
    """The parameters ``kind`` accepts; None for a user's "module:function" kind (unchecked)."""
    return KINDS[kind].params if kind in KINDS else None


def _design(spec, base: Path, src: str) -> HandDesign:
    if spec is None:
        return HandDesign()
    if isinstance(spec, str):
        return load_design(base / spec)
    if not isinstance(spec, dict):
        raise InputError(f"{src}: design", spec, "must be a file name or a table of design keys")
    overrides = dict(spec)
    file = overrides.pop("file", None)
    if file is not None and not isinstance(file, str):
        raise InputError(f"{src}: design.file", file, "must be a file name")
    start = load_design(base / file) if file else HandDesign()
    return design_from_dict(overrides, start, source=f"{src}: design")


def _mesh_size(value, kind: str, src: str) -> float | None:
    if value is None:
        return None
    if kind in KINDS and not KINDS[kind].fem:
        raise InputError(f"{src}: mesh_size_mm", value, f"kind {kind!r} has no mesh; remove it")
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
        raise InputError(f"{src}: mesh_size_mm", value, "must be a positive number [mm]")
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
        raise InputError(where, spec, "empty sweep; give a non-empty list or 'start:stop:step'")
    if not all(_is_scalar(v) for v in spec):
        raise InputError(where, spec, "must list numbers or strings")
    return tuple(spec)


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _is_scalar(value) -> bool:
    return _is_number(value) or isinstance(value, str)
