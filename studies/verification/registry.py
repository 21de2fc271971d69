"""The FEM verification suite behind ``softhand verify``: closed form vs FEM, case by case.

A case is a function ``case(quick: bool) -> list[Check]`` registered in :data:`REGISTRY`
by its import path (imported only when run). To add a case, write the function anywhere
under ``studies/`` or ``fem/`` and add one line to :data:`REGISTRY`; its checks then appear
in ``softhand verify`` and in ``tests/studies/test_verify.py``.
"""
from __future__ import annotations

import importlib
import time
from dataclasses import dataclass

#: case name -> "module:function"; the order is the order of the report.
REGISTRY: dict[str, str] = {
    "uniaxial": "softhand.studies.verification.solid:uniaxial_tension",
    "tube": "softhand.studies.verification.solid:tube_plane_strain",
    "locking": "softhand.studies.verification.solid:tube_locking",
    "fiber_tube": "softhand.studies.verification.solid:fiber_tube",
    "convergence": "softhand.studies.verification.solid:tube_convergence",
    "newton": "softhand.studies.verification.newton_checks:tangent_and_newton",
    "balloon": "softhand.studies.verification.balloon:balloon",
    "modes": "softhand.studies.verification.materials:homogeneous_modes",
    "balloon_models": "softhand.studies.verification.materials:balloon_models",
}


@dataclass(frozen=True)
class Check:
    """One verified number: the closed form, the FEM value and the allowed relative error."""

    case: str         #: case name (a key of REGISTRY)
    quantity: str     #: what is compared, with its unit
    exact: float      #: closed-form value
    fem: float        #: FEM value
    tolerance: float  #: allowed relative error; the docstring of the case says what bounds it
    at_least: bool = False  #: one-sided: only fem below exact counts as error (e.g. an order)

    @property
    def rel_error(self) -> float:
        error = (self.exact - self.fem) if self.at_least else abs(self.fem - self.exact)
        return max(error, 0.0) / abs(self.exact)

    @property
    def passed(self) -> bool:
        return bool(self.rel_error <= self.tolerance)

    def row(self) -> dict:
        """The JSON/table row: case, quantity, exact, fem, rel_error, tolerance, passed."""
        return {"case": self.case, "quantity": self.quantity, "exact": self.exact,
                "fem": self.fem, "rel_error": self.rel_error, "tolerance": self.tolerance,
                "passed": self.passed}


def case_function(name: str):
    """The registered function of case ``name``."""
    module, function = REGISTRY[name].split(":")
    return getattr(importlib.import_module(module), function)


def run_case(name: str, *, quick: bool = False) -> tuple[list[Check], float]:
    """(checks, wall seconds) of one case."""
    t0 = time.perf_counter()
    checks = case_function(name)(quick)
    return checks, time.perf_counter() - t0
