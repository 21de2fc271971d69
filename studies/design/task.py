"""A design task: the object to hold, the pump, the limits, and which design keys are free.

A task is a TOML file (``studies/designs/tasks/paper_task.toml`` is the paper's)::

    base_design = "studies/designs/paper.toml"   # optional; default the paper's
    [object]
    diameter_mm = 180.0
    mass_kg = 2.0             # 0: a massless object (with force_factor the fingers just touch it)
    [grasp]
    force_factor = 2.0        # F_v >= force_factor * m g / n, 1 to 100  (or margin_N: F_v >= m g / n + margin)
    objective = "pressure"    # "pressure": least pump pressure; "margin": largest F_v margin at the pump limit
    opening_mm = 180.0        # optional: the open hand's tip span must pass this (default and least: the diameter)
    [pump]
    max_pressure_MPa = 1.0
    [limits]                  # optional
    rubber_stretch = 1.5      # the converged rubber stretch of the tube and the sheet
    min_wall_mm = 1.0
    [material]                # optional: mu per part, over the base design
    mu_sf_MPa = 1.15
    [design]                  # optional: any other design key over the base design (not one of [free])
    finger_model = "fem"      # the default: the FEM-calibrated finger and reservoir models
    reservoir_model = "fem"
    [free]                    # design variables and their bounds
    a_mm = [3.0, 6.0]
    [hold]                    # optional: judge the task by the fast hold model (any [object] shape)
    margin = 2.0              # the hold bears 2 x the weight along the pull (or pull_N = 10.0: newtons beyond it)
    pull = [0.0, 1.0, 0.0]    # the pull's direction, hand frame (y down); default straight down
    [fem]                     # optional: the FEM proof's finger mesh (gmsh)
    mesh_size_mm = 6.0
    edge_ratio = 0.5          # element size at the ring edges / mesh_size (1: uniform)

An ``[object]`` with any key of the object table beyond ``diameter_mm`` and ``mass_kg``
(``shape``, ``size_mm``, ``friction``, ...) or a ``[hold]`` table makes a **hold task**: the
design is judged by the fast hold model (:mod:`softhand.reduced.holding.hold`): the least pump pressure whose
holding limit along the pull reaches the margin, the holding limit at the pump's limit.
``base_design`` is looked up as given, then next to the task file, then in the package.
A task designs on the FEM-calibrated models (``finger_model = "fem"``, ``reservoir_model =
"fem"``, :data:`~softhand.studies.design.task.MODELS`) unless its ``[design]`` table names others: those are the models the
FEM proof checks. With the packaged finger table, the free bounds are clipped to the box the
table was calibrated on (:data:`softhand.studies.design.task_values.CALIBRATED_SPACE`, its
``[space]``); the table's group ranges are the optimiser's constraints
(:func:`softhand.studies.design.constraints.calibrated_range`). The values' checks are in
:mod:`softhand.studies.design.task_values`.
Every mistake is one :class:`~softhand.reduced.vocabulary.errors.InputError` naming the key.
"""
from __future__ import annotations

import os

import numpy as np
from dataclasses import dataclass, field
from pathlib import Path

from softhand.reduced.vocabulary.design import HandDesign

from softhand.reduced.vocabulary.design_files import design_from_dict

from softhand.reduced.vocabulary.inputfiles import read_toml
from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.holding.objects import GraspObject
from softhand.studies.design.task_values import (FINGER_KEYS, UPPER, base_design, calibrated_bounds,
                                                 check_free_bounds_keep_the_rules, checked_number, free_bounds)

OBJECTIVES = ("pressure", "margin")
_SECTIONS = {
    "object": {"diameter_mm", "mass_kg", "shape", "length_mm", "size_mm", "file", "offset_mm", "rotation_deg",
               "friction"},
    "hold": {"margin", "pull_N", "pull"},
    "grasp": {"force_factor", "margin_N", "objective", "opening_mm"},
    "pump": {"max_pressure_MPa"},
    "limits": {"rubber_stretch", "min_wall_mm"},
    "material": {"mu_sf_MPa", "mu_sr_MPa"},
    "fem": {"mesh_size_mm", "edge_ratio", "dP_MPa"},
}
#: the reduced models a task designs with unless its [design] table says otherwise
MODELS = {"finger_model": "fem", "reservoir_model": "fem"}
_TOP = {"base_design", "object", "grasp", "pump", "limits", "material", "design", "free", "fem", "hold"}


@dataclass(frozen=True)
class Task:
    """What the hand must do and what may change (mm, kg, N, MPa)."""

    base: HandDesign                       #: the design the free keys vary (with material, design overrides)
    diameter: float                        #: object diameter [mm]
    mass: float                            #: object mass [kg]
    free: tuple[tuple[str, float, float], ...]  #: (public key, lower, upper), inside the calibrated box
    max_pressure: float                    #: pump pressure limit [MPa]
    force_factor: float = 2.0              #: F_v >= force_factor m g / n
    margin: float | None = None            #: ... or F_v >= m g / n + margin [N]
    objective: str = "pressure"            #: one of OBJECTIVES
    opening: float | None = None           #: open tip span to pass [mm]; None: the diameter
    #: limit of the rubber's converged stretch (fem.rubber_stretch) in the tube and the sheet
    max_stretch: float = 1.5
    #: the FEM's peak stretch over eq. (8)'s, in (lambda - 1): 1 until a proof has measured it
    stretch_factor: float = 1.0
    min_wall: float = 1.0                  #: least tube wall and sheet thickness [mm]
    mesh_size: float = 6.0                 #: FEM proof: finger element size [mm]
    edge_ratio: float = 0.5                #: FEM proof: element size at the ring edges / mesh_size
    dP: float = 0.05                       #: FEM proof: pressure step of the secant [MPa]
    name: str = "task"
    #: a hold task (an [object] of any shape or a [hold] table): the object, judged by the fast hold model
    obj: GraspObject | None = None
    hold_margin: float = 2.0               #: the hold bears hold_margin x the weight along the pull ...
    hold_pull_N: float | None = None       #: ... or this pull beyond the weight [N]
    hold_pull: tuple = (0.0, 1.0, 0.0)     #: the pull's direction (hand frame, y down)
    source: dict = field(default_factory=dict, compare=False, repr=False)  #: the file's tables
    clipped: tuple[tuple[str, float, float], ...] = ()  #: free bounds as given, where clipped

    def required_hold_N(self) -> float:
        """A hold task's holding limit along the pull beyond the weight [N]."""
        return self.hold_pull_N if self.hold_pull_N is not None else (self.hold_margin - 1.0) * self.mass * self.base.g

    def required_F_v(self) -> float:
        """The normal force each finger must press with [N] (a hold task: its holding limit)."""
        if self.obj is not None:
            return self.required_hold_N()
        share = self.mass * self.base.g / self.base.n
        return share + self.margin if self.margin is not None else self.force_factor * share

    @property
    def opening_mm(self) -> float:
        return self.diameter if self.opening is None else self.opening


def load_task(path: str | Path) -> Task:
    """Read and validate a task TOML file."""
    path = Path(path)
    data = read_toml(path, "--task", "a task TOML file")
    return task_from_dict(data, folder=path.parent, name=path.stem)


def task_from_dict(data: dict, *, folder: Path = Path("."), name: str = "task") -> Task:
    """A :class:`Task` from the task file's tables (see the module docstring)."""
    for key in data:
        if key not in _TOP:
            raise InputError(key, data[key], f"unknown task key; allowed: {', '.join(sorted(_TOP))}")
    tables = {s: _table(data, s) for s in (*_SECTIONS, "design", "free")}
    if "max_principal_stretch" in tables["limits"]:
        raise InputError("limits.max_principal_stretch", tables["limits"]["max_principal_stretch"],
                         "is now limits.rubber_stretch (the converged rubber stretch; the corner peak "
                         "depends on the mesh)")
    for section, allowed in _SECTIONS.items():
        for key in tables[section]:
            if key not in allowed:
                raise InputError(f"{section}.{key}", tables[section][key],
                                 f"unknown key; allowed: {', '.join(sorted(allowed))}")
    for key in tables["design"]:
        if key in tables["free"]:
            raise InputError(f"design.{key}", tables["design"][key],
                             "is also in [free]; give a fixed value in [design] or bounds in [free], not both")
        if key in tables["material"]:
            raise InputError(f"design.{key}", tables["design"][key],
                             "is also in [material]; give it in one of them")
    base = base_design(data.get("base_design"), folder)
    fixed = dict(tables["design"])
    for key in ("finger_table", "hinge_table"):
        table = fixed.get(key)
        if isinstance(table, str) and table and not Path(table).is_absolute():
            fixed[key] = os.path.abspath(folder / table)  # next to the task, as a design file's
    base = design_from_dict({**MODELS, **fixed, **tables["material"]}, base, source="design")
    free, clipped = calibrated_bounds(free_bounds(tables["free"], base), base)
    finger_free = [key for key, _, _ in free if key in FINGER_KEYS]
    if base.hinge_table and finger_free:
        raise InputError("design.hinge_table", base.hinge_table,
                         f"is made for one finger; with {', '.join(finger_free)} free the optimiser tries others "
                         "(leave it out: each design's hold then carries the paper's design's table over)")
    check_free_bounds_keep_the_rules(free, base)
    obj, grasp, pump, limits, fem = (tables[s] for s in ("object", "grasp", "pump", "limits", "fem"))
    if "force_factor" in grasp and "margin_N" in grasp:
        raise InputError("grasp.margin_N", grasp["margin_N"], "give force_factor or margin_N, not both")
    objective = grasp.get("objective", "pressure")
    if objective not in OBJECTIVES:
        raise InputError("grasp.objective", objective, f"must be one of {', '.join(OBJECTIVES)}")
    held = _hold_object(obj, tables["hold"], folder)
    for key in ("force_factor", "margin_N"):
        if held[0] is not None and key in grasp:
            raise InputError(f"grasp.{key}", grasp[key], "does not apply to a hold task (an [object] shape "
                             "or a [hold] table): its margin is [hold] margin or pull_N")
    diameter = held[1] if held[0] is not None else checked_number(obj, "object", "diameter_mm", required=True)
    opening = checked_number(grasp, "grasp", "opening_mm", default=None)
    if opening is not None and opening < diameter:
        raise InputError("grasp.opening_mm", grasp["opening_mm"], f"must be >= the object's diameter_mm "
                         f"= {diameter:g} (the open hand must pass the object) and <= {UPPER['opening_mm']:g}")
    return Task(
        base=base, name=name, source=data,
        diameter=diameter,
        mass=checked_number(obj, "object", "mass_kg", required=True, positive=False),
        obj=held[0], **held[2],
        free=free, clipped=clipped,
        max_pressure=checked_number(pump, "pump", "max_pressure_MPa", required=True),
        force_factor=checked_number(grasp, "grasp", "force_factor", default=2.0),
        margin=checked_number(grasp, "grasp", "margin_N", default=None, positive=False),
        objective=objective,
        opening=opening,
        max_stretch=checked_number(limits, "limits", "rubber_stretch", default=1.5, above=1.0),
        min_wall=checked_number(limits, "limits", "min_wall_mm", default=1.0),
        mesh_size=checked_number(fem, "fem", "mesh_size_mm", default=6.0),
        edge_ratio=checked_number(fem, "fem", "edge_ratio", default=0.5),
        dP=checked_number(fem, "fem", "dP_MPa", default=0.05))


def _hold_object(obj: dict, hold: dict, folder: Path):
    """(GraspObject or None, its span across the palm's axis [mm], the Task's hold fields): a hold
    task when [object] has more than today's diameter and mass, or [hold] is given."""
    if set(obj) <= {"diameter_mm", "mass_kg"} and not hold:
        return None, None, {}
    from softhand.reduced.holding.object_geometry import place
    from softhand.reduced.holding.objects import object_from_table

    if "mass_kg" not in obj:
        raise InputError("object.mass_kg", None, "is required")
    thing = object_from_table(obj, source="object", base_dir=folder)
    pts = place(thing, (0.0, 0.0, 0.0)).surface(resolution=32)[0]
    span = 2.0 * float(np.max(np.hypot(pts[:, 0], pts[:, 2])))
    if span > UPPER["diameter_mm"]:  # as a grasp task's diameter: no design's open hand passes more
        raise InputError("object", thing.describe(),
                         f"spans {span:.4g} mm across the palm's axis: at most {UPPER['diameter_mm']:g} mm")
    if "margin" in hold and "pull_N" in hold:
        raise InputError("hold.pull_N", hold["pull_N"], "give margin or pull_N, not both")
    fields = {"hold_margin": checked_number(hold, "hold", "margin", default=2.0),
              "hold_pull_N": checked_number(hold, "hold", "pull_N", default=None, positive=False)}
    if "pull" in hold:
        from softhand.reduced.holding.hold import pull_unit

        fields["hold_pull"] = tuple(float(v) for v in pull_unit(hold["pull"], "hold.pull"))
    return thing, span, fields


def _table(data: dict, section: str) -> dict:
    value = data.get(section, {})
    if not isinstance(value, dict):
        raise InputError(section, value, "must be a table ([" + section + "])")
    return value
