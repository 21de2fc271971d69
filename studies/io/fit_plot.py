"""The figure of ``softhand fit``: data against the fitted model, and the residuals."""
from __future__ import annotations

import dataclasses

import numpy as np

from softhand.reduced.fitting.csvdata import Measurements
from softhand.reduced.vocabulary.design_files import design_from_dict
from softhand.reduced.fitting.fit_result import FitResult
from softhand.studies.io.files import save_figure


def plot_fit(result: FitResult, data: Measurements, predictor_for, path) -> None:
    """Left: data and model (theta(P) curves, or measured vs predicted F_v); right: residuals.

    ``predictor_for(measurements)`` returns the model predictor for other points (the curve).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, ax_r) = plt.subplots(1, 2, figsize=(11, 4.2))
    groups = np.unique(data.finger) if data.finger is not None else [None]
    for g in groups:
        rows = slice(None) if g is None else data.finger == g
        label = "data" if g is None else f"finger {int(g)}"
        if data.kind == "bending":
            ax.plot(data.P[rows], result.observed[rows], "o", ms=4, label=label)
        else:
            ax.plot(result.observed[rows], result.predicted[rows], "o", ms=4, label=label)
        ax_r.plot(data.P[rows], result.residuals[rows], "o", ms=4, label=label)
    if data.kind == "bending":
        _bending_curves(ax, result, data, predictor_for)
    else:
        lim = [min(result.observed.min(), result.predicted.min()),
               max(result.observed.max(), result.predicted.max())]
        ax.plot(lim, lim, "k-", lw=1, label="model = data")
        ax.set(xlabel="measured F_v [N]", ylabel="fitted model F_v [N]")
    fitted = ", ".join(f"{k} = {v:.4g} ± {se:.2g}"
                       for k, v, se in zip(result.params, result.values, result.stderr))
    ax.set_title(fitted, fontsize=9)
    ax.legend(fontsize=8)
    ax_r.axhline(0.0, color="k", lw=1)
    for s in (-result.sigma, result.sigma):
        ax_r.axhline(s, color="gray", ls=":", lw=1)
    ax_r.set(xlabel="P [MPa]", ylabel=f"model − data [{data.unit}]",
             title=f"RMSE {result.rmse:.3g} {data.unit}, max {result.max_error:.3g} {data.unit} "
                   f"(dotted: ±σ)")
    for a in (ax, ax_r):
        a.grid(alpha=0.3)
    save_figure(fig, path)


def _bending_curves(ax, result, data, predictor_for) -> None:
    P = np.linspace(data.P.min(), data.P.max(), 101)
    dense = dataclasses.replace(data, P=P, theta=np.zeros_like(P), finger=None)
    predict = predictor_for(dense)
    ax.plot(P, predict(result.design), "k-", lw=1.5, label="fitted model")
    start = design_from_dict(dict(zip(result.params, map(float, result.initial))), result.design)
    try:
        ax.plot(P, predict(start), "k--", lw=1, label="start")
    except ValueError:  # the starting design cannot reach every pressure: no start curve
        pass
    ax.set(xlabel="P [MPa]", ylabel="θ [deg]")

