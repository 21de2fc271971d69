"""The free hand's pump pressure <-> bend angle, eqs. (27) with and (28) without the reservoir.

The one home of this result: :func:`at_angles` and :func:`at_pressures` compute the rows,
:func:`plot_curve` draws them (the paper's Fig. 7). ``softhand curve``, the batch kind
``curve`` and the reproduce section ``fig7_reduced`` only choose the inputs and the files.
"""
from __future__ import annotations

import numpy as np

from softhand.reduced.equations import hand, reservoir
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError


def at_angles(theta_deg, design: HandDesign) -> list[dict]:
    """Per bend angle [deg]: P with / without reservoir [MPa], the reservoir's V [mm^3] and
    :func:`softhand.reduced.equations.reservoir.state` (p_r; h, lambda_r for the ellipse model)."""
    theta_deg = np.atleast_1d(np.asarray(theta_deg, float))
    theta = hand.check_theta(np.radians(theta_deg))
    V = reservoir.oil_volume(theta, design)
    columns = {"theta_deg": theta_deg, "P_MPa": hand.pressure(theta, design),
               "P_no_reservoir_MPa": hand.pressure(theta, design, reservoir=False), "V_mm3": V,
               **reservoir.state(V, design)}
    return [{k: float(v[i]) for k, v in columns.items()} for i in range(len(theta_deg))]


def at_pressures(P, design: HandDesign, *, strict: bool = True) -> list[dict]:
    """Per pump pressure [MPa]: the free bend angle with / without reservoir [deg]. ``strict``:
    InputError unless both models reach every P; else NaN where one does not."""
    P = np.atleast_1d(np.asarray(P, float))
    if strict:
        theta, theta_free = (np.degrees(t) for t in hand.bend_angles(P, design))
    else:
        theta, theta_free = (np.array([_angle_or_nan(p, design, res) for p in P]) for res in (True, False))
    return [{"P_MPa": float(p), "theta_deg": float(t), "theta_no_reservoir_deg": float(u)}
            for p, t, u in zip(P, theta, theta_free)]


def _angle_or_nan(P: float, design: HandDesign, reservoir: bool) -> float:
    try:
        return float(np.degrees(hand.bend_angle(P, design, reservoir=reservoir)))
    except InputError:
        return float("nan")


def plot_curve(path, design: HandDesign, rows: list[dict], *, by_pressure: bool = False,
               title: str = "Free bending, reduced model (paper Fig. 7)", markers: bool = True,
               extra=(), xlim=None) -> None:
    """Bend angle vs pump pressure with and without the reservoir (Fig. 7) over the span of
    ``rows`` (their pressures if ``by_pressure``, else their angles) -> PNG at ``path``;
    ``markers``: the rows as points; ``extra``: more (label, P, theta_deg) lines."""
    from softhand.studies.io.files import figure, save_figure

    key = "P_MPa" if by_pressure else "theta_deg"
    lo, hi = min(r[key] for r in rows), max(r[key] for r in rows)
    span = np.linspace(lo, hi, 200) if hi > lo else np.array([lo])
    if by_pressure:
        P = P_free = span
        theta, theta_free = (np.degrees(t) for t in hand.bend_angles(span, design))
    else:
        theta = theta_free = span
        P, P_free = (hand.pressure(np.radians(span), design, reservoir=res) for res in (True, False))
    fig, (ax,) = figure()
    ax.plot(P, theta, "-", label="eq. (27), with reservoir")
    ax.plot(P_free, theta_free, ":", label="eq. (28), without reservoir")
    for label, P_line, theta_line in extra:
        ax.plot(P_line, theta_line, "--", label=label)
    if markers:
        ax.plot([r["P_MPa"] for r in rows], [r["theta_deg"] for r in rows], "o", ms=4,
                label="rows printed (with reservoir)")
    ax.set(xlabel="pump pressure P [MPa]", ylabel="bend angle θ [deg]", title=title)
    if xlim is not None:
        ax.set_xlim(*xlim)
    ax.axvline(0.0, color="0.7", lw=0.8)
    ax.grid(alpha=0.3)
    ax.legend()
    save_figure(fig, path)
