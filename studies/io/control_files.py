"""The control study's time series and Fig. 10: angle control against pressure control."""
from __future__ import annotations

import numpy as np

from softhand.studies.io.files import save_figure


def series_rows(sim, every: int) -> list[dict]:
    """The time series at the sensor rate (every ``every``-th integration step)."""
    theta = np.degrees(sim.theta[::every])
    columns = {"t_s": sim.t[::every], "P_MPa": sim.P[::every], "P_ref_MPa": sim.P_ref[::every],
               "theta_mean_deg": theta.mean(axis=1),
               **{f"theta_{j + 1}_deg": theta[:, j] for j in range(theta.shape[1])},
               "V_mm3": sim.V[::every], "push_N": sim.force[::every], "flow_limit": sim.flow_limit[::every]}
    return [dict(zip(columns, row)) for row in zip(*(c.tolist() for c in columns.values()))]


def plot_fig10(path, result, mode: str, theta_ref_deg: float) -> None:
    """Fig. 10 (c), (d): each finger's angle and the mean, the pump pressure and the push against
    time, for the ``mode`` run of :func:`reduced.control.flexibility`'s ``result``, the other
    mode dotted."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sim, other = (result.angle, result.pressure) if mode == "angle" else (result.pressure, result.angle)
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for j in range(sim.theta.shape[1]):
        ax1.plot(sim.t, np.degrees(sim.theta[:, j]), lw=0.9, label=f"finger {j + 1}")
    ax1.plot(sim.t, np.degrees(sim.theta_mean), "k", lw=1.6, label=f"mean, {mode} control")
    ax1.plot(other.t, np.degrees(other.theta_mean), "k:", lw=1.4, label="mean, other mode")
    ax1.axhline(theta_ref_deg, color="grey", ls="--", lw=0.8, label="θ_ref")
    ax1.set(ylabel="bend angle θ [deg]", title="Fig. 10 (c) analogue")
    ax2.plot(sim.t, sim.P, lw=1.4, label=f"P, {mode} control")
    ax2.plot(sim.t, sim.P_ref, lw=0.8, alpha=0.7, label="P_ref (controller)")
    ax2.plot(other.t, other.P, ":", lw=1.2, label="P, other mode")
    ax2.set(xlabel="t [s]", ylabel="pump pressure P [MPa]", title="Fig. 10 (d) analogue")
    twin = ax2.twinx()
    twin.plot(sim.t, sim.force, color="tab:red", lw=0.8, alpha=0.6, label="external push (right axis)")
    twin.set_ylabel("push [N]", color="tab:red")
    ax1.grid(alpha=0.3)
    ax1.legend(fontsize=7, loc="lower right", ncol=2, title="bend angle of each finger and their mean",
               title_fontsize=7)
    ax2.grid(alpha=0.3)
    lines = ax2.get_lines() + twin.get_lines()
    ax2.legend(lines, [line.get_label() for line in lines], fontsize=7, loc="lower right")
    save_figure(fig, path)
