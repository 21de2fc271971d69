"""What a design fit (:func:`softhand.reduced.fitting.fit.fit`) returns: the fitted parameters with
their uncertainty, how well the model matches the data, and the same as plain numbers for JSON.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from softhand.reduced.vocabulary.design import HandDesign


@dataclass(frozen=True)
class FitResult:
    """Fitted parameters with their uncertainty, and how well the model matches the data."""

    params: tuple[str, ...]  #: public design keys fitted
    initial: np.ndarray  #: starting values (units in the keys)
    values: np.ndarray  #: fitted values (units in the keys)
    stderr: np.ndarray  #: standard errors (inf where not identifiable)
    correlation: np.ndarray  #: k x k correlation matrix (nan where not identifiable)
    observed: np.ndarray  #: measured values (data units)
    predicted: np.ndarray  #: model values at the fitted parameters (data units)
    initial_predicted: np.ndarray  #: model values at the starting parameters
    design: HandDesign  #: the calibrated design
    quantity: str  #: what was fitted, with its unit: theta_deg or F_v_N
    condition: float  #: condition number of the column-normalised Jacobian
    singular_values: np.ndarray  #: of the column-normalised Jacobian, largest first
    unidentifiable: tuple[str, ...] = ()  #: parameters the data cannot determine
    at_bound: tuple[str, ...] = ()  #: parameters that ended on a bound
    warnings: tuple[str, ...] = ()  #: one sentence each
    nfev: int = 0  #: model evaluations of the optimiser
    finger: np.ndarray | None = field(default=None, repr=False)  #: finger label per point

    @property
    def residuals(self) -> np.ndarray:
        """Model minus measurement, data units."""
        return self.predicted - self.observed

    @property
    def rmse(self) -> float:
        return float(np.sqrt(np.mean(self.residuals**2)))

    @property
    def max_error(self) -> float:
        return float(np.max(np.abs(self.residuals)))

    @property
    def initial_rmse(self) -> float:
        return float(np.sqrt(np.mean((self.initial_predicted - self.observed) ** 2)))

    @property
    def dof(self) -> int:
        return self.observed.size - len(self.params)

    @property
    def sigma(self) -> float:
        """Estimated measurement scatter sqrt(S / (N - k)), data units."""
        return float(np.sqrt(np.sum(self.residuals**2) / self.dof))

    def rmse_by_finger(self) -> dict[int, float]:
        if self.finger is None:
            return {}
        return {int(f): float(np.sqrt(np.mean(self.residuals[self.finger == f] ** 2)))
                for f in np.unique(self.finger)}

    def to_dict(self) -> dict:
        """Plain numbers for JSON (inf/nan as None)."""
        unit = self.quantity.rsplit("_", 1)[1]
        return {
            "params": {k: {"initial": _num(p0), "value": _num(v), "stderr": _num(se)}
                       for k, p0, v, se in zip(self.params, self.initial, self.values, self.stderr)},
            "correlation": [[_num(c) for c in row] for row in self.correlation],
            "quantity": self.quantity, f"rmse_{unit}": self.rmse,
            f"max_error_{unit}": self.max_error, f"initial_rmse_{unit}": self.initial_rmse,
            f"sigma_{unit}": self.sigma, "n_points": int(self.observed.size), "dof": self.dof,
            "condition": _num(self.condition),
            "singular_values": [_num(s) for s in self.singular_values],
            "unidentifiable": list(self.unidentifiable), "at_bound": list(self.at_bound),
            "warnings": list(self.warnings), "nfev": self.nfev,
            "rmse_by_finger": {str(k): v for k, v in self.rmse_by_finger().items()},
            "design": self.design.to_dict(),
        }


def _num(x):
    x = float(x)
    return x if math.isfinite(x) else None
