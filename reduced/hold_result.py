r"""The result of a hold, the same for every model (the reduced hold model and the whole-hand FEM).

:class:`HoldResult` says whether the object stays in the hand under its own weight (``held``),
the largest pull beyond its weight along ``pull_direction`` it withstands (``holding_limit_N``;
0 when not held), every touching pad's forces (:class:`Contact`), the object's displacement and
rotation, both pressures by name (``P_cavity_MPa``: the fingers' oil; ``P_pump_MPa``: the pump's,
the cavity's less the reservoir's), and one row per load step (:class:`LoadStep`: the path
close -> release -> pull). :meth:`HoldResult.to_json` is the one JSON form (``softhand hold
--json``, ``result.json``); :func:`result_from_json` reads it back. Units: N, mm, deg, MPa, kg.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

#: contact states
STICK, SLIP = "stick", "slip"
#: the models that produce a hold
MODELS = ("reduced", "fem")


@dataclass(frozen=True)
class Contact:
    """One touching pad: the force of the object on it, split into normal and friction parts."""

    finger: int                 #: finger index (0 .. n-1, the layout's order)
    link: int                   #: pad / link index (0 base .. n_s tip)
    normal_N: float             #: normal force [N], >= 0
    friction_N: float           #: magnitude of the friction force [N]
    state: str                  #: "stick" (inside the cone) or "slip" (on it)
    point_mm: tuple = ()        #: contact point in the hand frame [mm]
    normal: tuple = ()          #: the object's outward normal there (unit)
    friction_dir: tuple = ()    #: direction of the friction force on the object (unit; () if none)


@dataclass(frozen=True)
class LoadStep:
    """One step of the path: what was applied and what the hand did."""

    stage: str                  #: "close", "release" or "pull"
    P_cavity_MPa: float
    pull_N: float               #: pull beyond the weight along the pull direction [N]
    held: bool
    displacement_mm: tuple = (0.0, 0.0, 0.0)
    rotation_deg: tuple = (0.0, 0.0, 0.0)
    contacts: int = 0           #: touching pads
    extra: dict = field(default_factory=dict)  #: model-specific numbers (residuals, iterations)


@dataclass(frozen=True)
class HoldResult:
    """A hold (module doc). ``holding_limit_N`` is along ``pull_direction`` beyond the weight."""

    model: str                          #: "reduced" or "fem"
    held: bool                          #: stays in the hand under its own weight
    holding_limit_N: float              #: largest pull beyond the weight [N]; 0 when not held
    pull_direction: tuple               #: unit vector in the hand frame (y down)
    contacts: tuple = ()                #: :class:`Contact` per touching pad, at the state reported
    P_cavity_MPa: float = math.nan
    P_pump_MPa: float = math.nan
    mass_kg: float = 0.0
    friction: float = 0.0
    object: dict = field(default_factory=dict)     #: the [object] table of the object held
    displacement_mm: tuple = (0.0, 0.0, 0.0)       #: the object's, under its own weight
    rotation_deg: tuple = (0.0, 0.0, 0.0)          #: the object's, under its own weight
    steps: tuple = ()                   #: :class:`LoadStep` rows
    symmetric: bool = False             #: one finger solved for all (the object symmetric to the hand)
    notes: tuple = ()                   #: one-line remarks (why not held, which pad limits)
    extra: dict = field(default_factory=dict)      #: model-specific numbers (residuals, tolerances, timing)

    @property
    def holding_limit_kg(self) -> float:
        """The holding limit as a mass [kg] (g = 9.80665 N/kg)."""
        return self.holding_limit_N / 9.80665

    def to_json(self) -> dict:
        """The JSON form (keys as the fields, plus ``holding_limit_kg``); tuples as lists."""
        out = asdict(self)
        out["holding_limit_kg"] = self.holding_limit_kg
        return _plain(out)


def _plain(value):
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if hasattr(value, "item") and getattr(value, "ndim", 1) == 0:
        return value.item()
    if hasattr(value, "tolist"):
        return value.tolist()
    return value


def result_from_json(data: dict) -> HoldResult:
    """A :class:`HoldResult` from its JSON form."""
    data = dict(data)
    data.pop("holding_limit_kg", None)
    data["contacts"] = tuple(Contact(**{k: tuple(v) if isinstance(v, list) else v for k, v in c.items()})
                             for c in data.get("contacts", ()))
    data["steps"] = tuple(LoadStep(**{k: tuple(v) if isinstance(v, list) else v for k, v in s.items()})
                          for s in data.get("steps", ()))
    for key in ("pull_direction", "displacement_mm", "rotation_deg", "notes"):
        if key in data:
            data[key] = tuple(data[key])
    return HoldResult(**data)
