"""Fig. 7 with FEM points: bend angle against pressure, the finger FEM against eqs. (27), (28)."""
from __future__ import annotations

import numpy as np

from softhand.reduced.equations import hand
from softhand.studies.io.files import figure, save_figure


def plot_bending(path, rows: list[dict], design, hand_rows: list[dict] | None = None, *,
                 title: str | None = None) -> None:
    """theta vs P: the free finger's FEM points (``rows`` of a bending study) and eq. (28);
    with ``hand_rows`` (of :func:`softhand.studies.compare.whole_hand`) the whole hand's FEM points
    (finger FEM + reservoir-sheet FEM) and eq. (27)."""
    theta_max = max(max(r["theta_deg"] for r in rows), 1.0)
    theta_deg = np.linspace(0.0, theta_max, 101)
    theta = np.radians(theta_deg)
    fig, (ax,) = figure()
    ax.plot(hand.pressure(theta, design, reservoir=False), theta_deg, "k:",
            label="eq. (28), no reservoir")
    ax.plot([r["P_cavity_MPa"] for r in rows], [r["theta_deg"] for r in rows], "o",
            label="finger FEM (no reservoir)")
    if hand_rows:
        ax.plot(hand.pressure(theta, design, reservoir=True), theta_deg, "k-",
                label="eq. (27), with reservoir")
        ax.plot([r["P_pump_fem_MPa"] for r in hand_rows],
                [r["theta_deg"] for r in hand_rows], "s", mfc="none",
                label="finger FEM + reservoir FEM")
    ax.set(xlabel="pump pressure P [MPa]", ylabel="bend angle θ [deg]", title=title)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    save_figure(fig, path)
