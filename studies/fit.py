"""The fit study: design parameters calibrated to measured points (bounded least squares).

:func:`run` fits the public design keys of a :class:`FitStudy` to the measured points
(free-bending angles through eq. (27) or (28), or grasping forces through eqs. (24), (25),
(29); :mod:`softhand.reduced.fitting.fit`) and returns a :class:`FitStudyResult` that summarises (values,
standard errors, correlation, errors, every identifiability note), writes the calibrated
design (a TOML file every verb reads with ``--design``) and plots itself (data against the
fitted model, residuals). ``softhand fit`` only reads its options and prints.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field

from softhand.reduced.fitting.csvdata import Measurements
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.fitting.fit import fit, make_predictor
from softhand.reduced.fitting.fit_result import FitResult


@dataclass(frozen=True)
class FitStudy:
    """What to fit to which points, and how the model predicts them."""

    data: Measurements = field(repr=False)   #: the measured points
    params: tuple[str, ...]                  #: design keys to fit, e.g. ("V0_mm3", "mu_sf_MPa")
    design: HandDesign = field(default_factory=HandDesign)  #: the start and the fixed keys
    model: str = "reduced"
    reservoir: bool = True                   #: eq. (27); False: eq. (28), without reservoir
    weights: tuple | None = None             #: grasp data without diameters: the weight vector w
    normalise: bool = False                  #: scale w to sum 1 (eq. (23))
    bounds: dict | None = None               #: key -> (low, high) in the key's units
    data_name: str = "data"                  #: where the points came from (the report names it)

    def predictor(self, points: Measurements):
        """The model's prediction of ``points.observed`` as a function of a design."""
        return make_predictor(points, self.model, reservoir=self.reservoir, weights=self.weights,
                              normalise=self.normalise, design=self.design)


@dataclass(frozen=True)
class FitStudyResult:
    study: FitStudy
    fit: FitResult
    notes: tuple = ()  #: every warning of the fit (model warnings, then identifiability)

    def summary(self) -> dict:
        """Fitted values and their errors, the data, the model and the notes (``softhand fit --json``)."""
        s = self.study
        return {**self.fit.to_dict(), "data": s.data_name, "model": s.model, "reservoir": s.reservoir,
                "notes": list(self.notes)}

    def design_toml(self) -> str:
        """The calibrated design as TOML, its provenance in ``#`` lines."""
        s, r = self.study, self.fit
        fitted = ", ".join(f"{k} = {v:.6g} +- {se:.2g}" for k, v, se in zip(r.params, r.values, r.stderr))
        head = (f"# calibrated by softhand fit from {s.data_name} ({len(s.data)} points, model "
                f"{s.model}{'' if s.reservoir else ', no reservoir'})\n"
                f"# fitted: {fitted}; RMSE {r.rmse:.4g} {s.data.unit}\n")
        return head + r.design.to_toml()

    def write(self, path) -> list[str]:
        """The calibrated design (:meth:`design_toml`) as the TOML file ``path``; its name."""
        from softhand.studies.io.files import write_atomic

        write_atomic(path, self.design_toml())
        return [str(path)]

    def plot(self, path) -> None:
        """Data against the fitted model, and the residuals (:func:`softhand.studies.io.fit_plot.plot_fit`)."""
        from softhand.studies.io.fit_plot import plot_fit

        plot_fit(self.fit, self.study.data, self.study.predictor, path)


def run(study: FitStudy) -> FitStudyResult:
    """Fit; the warnings raised on the way become notes of the result (none is lost)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        predictor = study.predictor(study.data)
        result = fit(study.data, study.params, predictor, study.design, bounds=study.bounds)
    return FitStudyResult(study, result, tuple(str(w.message) for w in caught) + tuple(result.warnings))
