"""The constraints a design is judged by for a task (:func:`softhand.studies.design.evaluate.evaluate`):
:class:`~softhand.studies.design.constraints.Constraint` and its normalised slack, the list of them for a design, and the limits
they are measured against (the reservoir's limit point, the calibrated finger table's space).

Constraints (each ``(name, value, limit, sense)``, normalised slack >= 0 when met): the tube
fits its links (a + b < d), walls (b >= min wall, t > 0), the reservoir keeps oil at the grasp
and sits below the first pressure maximum of its model p_r(V) (limit point), peak stretch,
pump pressure (at most the pump's limit), the open hand passes the object and at rest (pump
off) does not reach into the object's place (the free hand's pump pressure at the grasp angle,
P_contact >= 0, so P_grasp >= 0 too: the pump pushes oil into the fingers), the sheet is thin
enough for the membrane models of the reservoir (t/R <=
:data:`softhand.reduced.equations.reservoir.MAX_THICKNESS_RATIO`), and the finger model's calibrated range when
it has one.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from softhand.reduced.calibrated import reservoir_fem
from softhand.reduced.equations import reservoir
from softhand.reduced.vocabulary.design import HandDesign
from softhand.studies.design.grasp_force import asks_force_at_limit
from softhand.studies.design.task import Task


@dataclass(frozen=True)
class Constraint:
    name: str
    value: float
    limit: float
    sense: str  #: "<=" or ">="
    scale: float | None = None  #: of the normalised slack; None: ``|limit|``
    #: a value with no number (inf): how far the design is from having one, in (0, 1] (None: no measure)
    shortfall: float | None = None

    @property
    def slack(self) -> float:
        """Normalised distance to the limit, >= 0 when met; -1 - shortfall for a value with no number
        but a measure of how far it is from one, else -1e3."""
        if not math.isfinite(self.value):
            return -1.0 - self.shortfall if self.shortfall is not None else -1e3
        if not math.isfinite(self.limit):  # no limit (e.g. no limit point): met, by far
            return 1e3
        gap = self.limit - self.value if self.sense == "<=" else self.value - self.limit
        scale = self.scale if self.scale is not None else abs(self.limit)
        return min(gap / max(scale, 1e-9), 1e3)

    @property
    def satisfied(self) -> bool:
        return self.slack >= -1e-9

    def as_dict(self) -> dict:
        return {"name": self.name, "value": self.value, "limit": self.limit, "sense": self.sense,
                "satisfied": self.satisfied}


@lru_cache(maxsize=4096)
def limit_point_volume(design: HandDesign) -> float:
    """Oil volume [mm^3] of the first pressure maximum of p_r(V) up to 4 V0 (inf: none)."""
    V = np.linspace(0.01, 4.0, 201) * design.V0
    p = reservoir.pressure(V, design)
    falls = np.flatnonzero(np.diff(p) <= 0.0)
    return float(V[falls[0]]) if falls.size else math.inf


def design_constraints(design: HandDesign, task: Task, oil, stretch, sheet, P_grasp, P_contact, F_lim,
                       P_open, grasp_shortfall: float | None = None) -> list:
    """Every constraint of a design; how many depends on the task and the finger model alone.
    ``grasp_shortfall``: the pump pressure's :attr:`Constraint.shortfall` (no P_grasp)."""
    return [
        Constraint("tube_fits_links (a + b < d) [mm]", design.a + design.b, design.d, "<="),
        Constraint("tube_wall b [mm]", design.b, task.min_wall, ">="),
        Constraint("sheet_thickness t [mm]", design.t, 0.0, ">=", 1.0),
        Constraint("reservoir_oil the fingers take at the grasp [mm^3]", oil, design.V0, "<="),
        Constraint("reservoir_below_limit_point V0 [mm^3]", design.V0, limit_point_volume(design), "<="),
        Constraint("rubber_stretch of the tube", stretch, task.max_stretch, "<="),
        Constraint("sheet_stretch at V0" + (" (FEM-calibrated rubber_stretch)" if design.reservoir_model == "fem"
                                            and reservoir_fem.rubber_stretch(design.V0, design) is not None
                                            else ", eq. (16)"), sheet, task.max_stretch, "<="),
        Constraint("pump_pressure at the grasp [MPa]", P_grasp, task.max_pressure, "<=", shortfall=grasp_shortfall),
        Constraint("contact: P(theta_g), the free hand's pump pressure where a pad touches the object "
                   "[MPa] (the hand at rest must not reach into the object's place)", P_contact, 0.0, ">=",
                   task.max_pressure),
        *([Constraint("F_v at the pump limit [N]" if design.finger_model != "fem" else
                      "F_v at the pump limit, or where one pad stops holding the object alone below it [N]",
                      F_lim, task.required_F_v(), ">=")]
          if asks_force_at_limit(design, task) else []),
        Constraint("opening: P(theta_open), the free hand's pump pressure where the tips "
                   f"span {task.opening_mm:g} mm [MPa]", P_open, 0.0, ">=", task.max_pressure),
        Constraint("thin_sheet t/R (membrane models)", design.t / design.R,
                   reservoir.MAX_THICKNESS_RATIO, "<="),
        *calibrated_range(design),
    ]


def calibrated_range(design: HandDesign) -> list[Constraint]:
    """The FEM-calibrated finger model's space (its table's group ranges) as constraints;
    none for the paper's model."""
    if getattr(design, "finger_model", "paper") == "paper":
        return []
    from softhand.reduced.calibrated import finger_fem

    table = _finger_table(design.finger_table or str(finger_fem.TABLE_FILE))
    groups = finger_fem.groups_of(design)
    out = []
    for g in finger_fem.GROUPS:
        lo, hi = table.ranges[g]
        label = f"calibrated range of {finger_fem.LABELS[g]}"
        out += [Constraint(label, groups[g], lo, ">="), Constraint(label, groups[g], hi, "<=")]
    return out


@lru_cache(maxsize=4)
def _finger_table(path: str):
    from softhand.reduced.calibrated import finger_fem

    return finger_fem.read_table(path)
