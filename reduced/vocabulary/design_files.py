"""Designs from TOML files and dicts: the public keys (units in the names) to a checked
:class:`~softhand.reduced.vocabulary.design.HandDesign`.

Every design built from a file or a study's keys passes :func:`design_from_dict`, which also
reads and fits a design's own finger calibration table at once (so a bad table is one line
at load time, not an error deep inside a run); this is why it lives above the finger model
and not beside the design vocabulary.

Rubber. A design file may give a part another strain energy than the paper's Neo-Hooke
(:mod:`softhand.reduced.materials.rubber`) as a table::

    [finger.material]
    model = "yeoh"            # neo-hookean | mooney-rivlin | yeoh | gent | ogden
    C10_MPa = 0.18
    C20_MPa = -1.4e-3
    C30_MPa = 4.0e-5

    [reservoir.material]
    model = "mooney-rivlin"
    C10_MPa = 0.5
    C01_MPa = 0.075

The parameter names are those of ``softhand material fit``. With a material table,
``mu_sf_MPa`` / ``mu_sr_MPa`` become that material's initial shear modulus (computed; a
value in the same file that disagrees is overridden, with a warning).
"""
from __future__ import annotations

import dataclasses
import math
import os
import warnings
from pathlib import Path

from softhand.reduced.equations import finger
from softhand.reduced.materials import rubber, rubber_parameters
from softhand.reduced.vocabulary.design import KEY_OF, MODULUS_OF, PARTS, HandDesign, field_changes
from softhand.reduced.vocabulary.design_rules import BOUNDS, in_bounds, is_number
from softhand.reduced.vocabulary.errors import InputError, Note
from softhand.reduced.vocabulary.inputfiles import read_toml

__all__ = ["design_from_dict", "load_design"]

def _material_changes(part: str, table, source: str, values: dict) -> dict:
    """Changes of the design fields from a ``[<part>.material]`` table."""
    if not isinstance(table, dict) or set(table) != {"material"} or not isinstance(table["material"], dict):
        raise InputError(f"{source}: {part}", table, f"must hold only a [{part}.material] table")
    params = dict(table["material"])
    model = params.pop("model", None)
    if not isinstance(model, str):
        raise InputError(f"{source}: {part}.material.model", model,
                         f"must be one of {', '.join(rubber.MODELS)}")
    material = rubber_parameters.from_parameters(model, params, source=f"{source}: {part}.material")
    name = MODULUS_OF[part]
    lo, hi = BOUNDS[KEY_OF[name]]
    if not lo <= material.mu0 <= hi:  # named by the table the user wrote, not the key it becomes
        raise InputError(f"{source}: {part}.material", f"{model}, mu0 = {material.mu0:.6g} MPa",
                         f"its initial shear modulus must be in [{lo:g}, {hi:g}] MPa")
    given = values.get(KEY_OF[name])
    if given is not None:  # overridden, but still a value of the file: a bad one is bad input
        try:
            in_bounds(KEY_OF[name], given)
        except InputError as exc:
            raise exc.renamed(f"{source}: {KEY_OF[name]}") from None
    if is_number(given) and not math.isclose(given, material.mu0, rel_tol=1e-9):
        warnings.warn(f"{source}: {KEY_OF[name]} = {given} is overridden by [{part}.material], "
                      f"whose initial shear modulus is {material.mu0:.6g} MPa")
    return {f"{part}_material": material, name: material.mu0}


def design_from_dict(values: dict, base: HandDesign | None = None, *, source: str = "design") -> HandDesign:
    """A design from public keys (as in TOML), over ``base`` (default: the paper's). Without
    ``hinge_s_mm``, a new ``l0_mm`` scales the base's hinge positions with it and a new ``n_s``
    spaces the hinges equally."""
    base = base if base is not None else HandDesign()
    changes = field_changes({k: v for k, v in values.items() if k not in PARTS}, base, source=source)
    for part in PARTS:
        if part in values:
            changes.update(_material_changes(part, values[part], source, values))
    design = dataclasses.replace(base, **changes)
    note_inherited_reservoir(values, design, base, source)
    if changes.get("finger_table"):
        if design.finger_model != "fem":  # the table would be unused
            raise InputError(f"{source}: finger_table", values["finger_table"], f"is the table of "
                             f"finger_model = 'fem'; this design's finger_model is {design.finger_model!r}")
        try:  # read and fitted now (cached per file), not where a run first uses it
            finger.check_data(design)
        except InputError as exc:
            raise exc.renamed(f"{source}: finger_table") from None
    if changes.get("hinge_table"):
        from softhand.reduced.calibrated import finger_hinges
        try:  # read now, not where a hold first uses it
            finger_hinges.hinge_data(design)
        except InputError as exc:
            raise exc.renamed(f"{source}: hinge_table") from None
    return design


#: the reservoir's keys, sized for the base design's number of fingers
RESERVOIR_KEYS = ("V0_mm3", "R_mm", "t_mm")


def note_inherited_reservoir(values: dict, design: HandDesign, base: HandDesign, source: str) -> None:
    """A :class:`~softhand.reduced.vocabulary.errors.Note` when a design changes the number of
    fingers but keeps the base's reservoir."""
    if design.n != base.n and not any(k in values for k in RESERVOIR_KEYS):
        warnings.warn(f"{source}: n = {design.n} fingers share the reservoir sized for {base.n} "
                      f"(V0_mm3 = {base.V0:g}, R_mm = {base.R:g}, t_mm = {base.t:g}, not set in "
                      f"this design); set them to size its own", Note, stacklevel=3)


def load_design(path: str | Path | None = None) -> HandDesign:
    """Read a design TOML file (keys as in ``studies/designs/paper.toml``); None: the paper's
    (Table I, :class:`~softhand.reduced.vocabulary.design.HandDesign`'s defaults)."""
    if path is None:
        return HandDesign()
    path = Path(path)
    values = read_toml(path, "--design", "a design TOML file")
    for key in ("finger_table", "hinge_table"):
        table = values.get(key)
        if isinstance(table, str) and table and not Path(table).is_absolute():
            # relative to the file; absolute without touching the file system (a link loop or a NUL
            # in the name is the table reader's one line to say)
            values[key] = os.path.abspath(path.parent / table)
    return design_from_dict(values, source=path.name)
