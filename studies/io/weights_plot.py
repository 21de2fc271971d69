"""Plots of the grasp FEM studies: w(D) and the Fig. 8 analogue (matplotlib, Agg)."""
from __future__ import annotations

import numpy as np

from softhand.reduced.equations.grasp import KGF


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def plot_weights(path, result) -> None:
    """w_i against the object diameter (one line per hinge), the interpolation check as crosses."""
    from softhand.studies.io.files import save_figure

    plt = _pyplot()
    D = np.array([r["diameter_mm"] for r in result.rows])
    W = np.array([r["w"] for r in result.rows])
    fig, ax = plt.subplots(figsize=(6, 4))
    free = np.array([sum(r.get("contact_force_N", [1.0])) == 0 for r in result.rows])
    for i in range(W.shape[1]):
        line, = ax.plot(D, W[:, i], "o-", label=f"w{i + 1}")
        ax.plot(D[free], W[free, i], "o", mfc="white", color=line.get_color())  # no contact
        if result.check:
            ax.plot(result.check["diameter_mm"], result.check["w_fem"][i], "x", ms=9, color=line.get_color())
    ax.set_xlabel("object diameter D [mm]")
    ax.set_ylabel("hinge weight w_i")
    ax.axhline(0.0, color="0.7", lw=0.8)
    ax.legend(ncol=5, fontsize=8)
    ax.set_title("grasp FEM: w(D) (open marker: no contact; x: FEM at an unseen D)", fontsize=9)
    save_figure(fig, path)


def plot_fig8(path, result) -> None:
    """F_v [kgf] vs theta [deg] of a :class:`softhand.studies.fig8.Fig8Result`: FEM points, eq. (25) lines."""
    from softhand.studies.io.files import save_figure

    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6, 4))
    draw_fig8(ax, result)
    case = result.case
    ax.set_title(f"D = {case.diameter_mm:g} mm, m = {case.mass_kg:g} kg (cavity pressure)")
    save_figure(fig, path)


def draw_fig8(ax, result) -> None:
    """The Fig. 8 analogue of a :class:`softhand.studies.fig8.Fig8Result` on the axes ``ax``: per
    pressure the FEM points and eq. (25) with that pressure's mean FEM w."""
    for k, (P, theta_deg, F_v_kgf) in enumerate(result.model_lines()):
        pts = [r for r in result.rows if r["P_cavity_MPa"] == P]
        color = f"C{k}"
        ax.plot([r["theta_deg"] for r in pts], [r["F_v_fem_N"] / KGF for r in pts], "o",
                color=color, label=f"FEM {P:g} MPa")
        ax.plot(theta_deg, F_v_kgf, "-", color=color, label=f"eq. (25) {P:g} MPa")
    ax.set_xlabel("bend angle theta [deg]")
    ax.set_ylabel("F_v [kgf]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
