"""The control study's files: the push profile read from CSV, the time series, and Fig. 10.

Disturbance file: CSV, header ``t_s,force_N``, then rows of time [s] (increasing, >= 0) and
push force [N]; ``#`` lines are comments. Between rows the force is interpolated linearly;
before the first row it is 0, after the last row it keeps the last value.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from softhand.reduced.vocabulary.errors import InputError
from softhand.reduced.vocabulary.inputfiles import csv_cells, plain_float
from softhand.studies.io.files import save_figure

DISTURBANCE_HEADER = ("t_s", "force_N")
#: allowed push force [N], of ``--push-N`` and of a disturbance file's rows
PUSH_LIMITS_N = (-1000.0, 1000.0)
#: the quiet time before any push [s]: the window the summary measures the hold in
#: (:func:`softhand.reduced.dynamics.control.summarize`), as for --push-at-s
QUIET_S = 1.0


def read_disturbance(path: str | Path, t_end: float | None = None):
    """The push profile of a ``t_s,force_N`` CSV file as a function of t [s]; InputError on bad
    files, and on a profile that starts at or after ``t_end`` [s] (the run would not see it)."""
    path = Path(path)
    from softhand.reduced.vocabulary.inputfiles import read_input_file

    data = read_input_file(path, "--disturbance", "a CSV file t_s,force_N")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise InputError("--disturbance", str(path), "is not a text (CSV) file") from None
    rows = [(number, cells) for number, cells in enumerate(csv_cells(text.splitlines(), "--disturbance", path),
                                                           start=1)
            if cells and "".join(cells).strip() and not cells[0].lstrip().startswith("#")]
    if not rows or tuple(c.strip() for c in rows[0][1]) != DISTURBANCE_HEADER:
        raise InputError("--disturbance", str(path), f"must start with the header {','.join(DISTURBANCE_HEADER)}")
    if len(rows) < 2:
        raise InputError("--disturbance", str(path), "has no data rows")
    values = np.array([_row(path, number, cells) for number, cells in rows[1:]])
    t, force = values[:, 0], values[:, 1]
    if np.any(t < 0) or np.any(np.diff(t) <= 0):
        bad = int(np.flatnonzero(np.concatenate([[t[0] < 0], np.diff(t) <= 0]))[0])
        raise InputError(f"--disturbance {path.name}: line {rows[bad + 1][0]}", float(t[bad]),
                         "times must be >= 0 and strictly increasing")
    moving = np.flatnonzero((force != 0) | (np.r_[force[1:], 0.0] != 0))  # pushes just after t_k
    if moving.size and t[moving[0]] < QUIET_S:
        raise InputError("--disturbance", str(path), f"pushes from t_s = {t[moving[0]]:g} s; the "
                                                     f"force must be 0 until {QUIET_S:g} s (the "
                                                     "controller settles first)")
    if t_end is not None and t[0] >= t_end:
        raise InputError("--disturbance", str(path), f"starts at t_s = {t[0]:g} s, not before the "
                                                     f"run's end --t-end-s = {t_end:g} s")
    return lambda x: np.interp(x, t, force, left=0.0, right=force[-1])


def _row(path: Path, number: int, cells: list[str]) -> tuple[float, float]:
    where = f"--disturbance {path.name}: line {number}"
    if len(cells) != 2:
        raise InputError(where, ",".join(cells), "must be two numbers: t_s,force_N")
    try:
        t, force = plain_float(cells[0]), plain_float(cells[1])
    except ValueError:
        raise InputError(where, ",".join(cells), "must be two numbers: t_s,force_N") from None
    if not (math.isfinite(t) and math.isfinite(force)):
        raise InputError(where, ",".join(cells), "must be finite numbers")
    lo, hi = PUSH_LIMITS_N
    if not (t <= 600 and lo <= force <= hi):
        raise InputError(where, ",".join(cells), f"t_s must be at most 600 s and force_N in [{lo:g}, {hi:g}]")
    return t, force


def series_rows(sim, every: int) -> list[dict]:
    """The time series at the sensor rate (every ``every``-th integration step)."""
    theta = np.degrees(sim.theta[::every])
    columns = {"t_s": sim.t[::every], "P_pump_MPa": sim.P[::every], "P_pump_ref_MPa": sim.P_ref[::every],
               "theta_mean_deg": theta.mean(axis=1),
               **{f"theta_{j + 1}_deg": theta[:, j] for j in range(theta.shape[1])},
               "V_mm3": sim.V[::every], "push_N": sim.force[::every], "flow_limit": sim.flow_limit[::every]}
    return [dict(zip(columns, row)) for row in zip(*(c.tolist() for c in columns.values()))]


def plot_fig10(path, result, mode: str, theta_ref_deg: float) -> None:
    """Fig. 10 (c), (d): each finger's angle and the mean, the pump pressure and the push against
    time, for the ``mode`` run of :func:`softhand.reduced.dynamics.control.flexibility`'s ``result``, the other
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
