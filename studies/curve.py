"""The free hand's pump pressure <-> bend angle, eqs. (27) with and (28) without the reservoir.

The one home of this result: :func:`at_angles` and :func:`at_pressures` compute the rows,
:func:`plot_curves` draws one or several designs' curves (the paper's Fig. 7). ``softhand
curve``, the batch kind ``curve`` and the reproduce section ``fig7_reduced`` only choose the
inputs and the files. Pressures are named as what they are: ``P_pump_MPa`` (the pump's, with
the reservoir) and ``P_cavity_MPa`` (the fingers' cavity, which without a reservoir is also the
pump's).
"""
from __future__ import annotations

import numpy as np

from softhand.reduced.equations import hand, reservoir
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError


def at_angles(theta_deg, design: HandDesign) -> list[dict]:
    """Per bend angle [deg]: the pump pressure with the reservoir and the cavity pressure (= the
    pump pressure without reservoir) [MPa], the reservoir's V [mm^3] and
    :func:`softhand.reduced.equations.reservoir.state` (p_r; h, lambda_r for the ellipse model)."""
    theta_deg = np.atleast_1d(np.asarray(theta_deg, float))
    theta = hand.check_theta(np.radians(theta_deg))
    V = reservoir.oil_volume(theta, design)
    columns = {"theta_deg": theta_deg, "P_pump_MPa": hand.pressure(theta, design),
               "P_cavity_MPa": hand.pressure(theta, design, reservoir=False), "V_mm3": V,
               **reservoir.state(V, design)}
    return [{k: float(v[i]) for k, v in columns.items()} for i in range(len(theta_deg))]


def at_pressures(P, design: HandDesign, *, strict: bool = True) -> list[dict]:
    """Per pump pressure [MPa]: the free bend angle with the reservoir [deg], the cavity pressure
    there [MPa] and the bend angle without the reservoir (pump = cavity pressure) [deg].
    ``strict``: InputError unless both models reach every P; else NaN where one does not."""
    P = np.atleast_1d(np.asarray(P, float))
    if strict:
        theta, theta_free = (np.degrees(t) for t in hand.bend_angles(P, design))
    else:
        theta, theta_free = (np.array([_angle_or_nan(p, design, res) for p in P]) for res in (True, False))
    finite = np.isfinite(theta)
    P_cavity = np.full(len(P), np.nan)
    P_cavity[finite] = hand.pressure(np.radians(theta[finite]), design, reservoir=False)
    return [{"P_pump_MPa": float(p), "theta_deg": float(t), "P_cavity_MPa": float(c),
             "theta_no_reservoir_deg": float(u)} for p, t, c, u in zip(P, theta, P_cavity, theta_free)]


def _angle_or_nan(P: float, design: HandDesign, reservoir: bool) -> float:
    try:
        return float(np.degrees(hand.bend_angle(P, design, reservoir=reservoir)))
    except InputError:
        return float("nan")


def _span(design: HandDesign, rows: list[dict], by_pressure: bool):
    """(P, theta, P_free, theta_free) along the span of ``rows``: pump pressures [MPa] and
    bends [deg] with the reservoir, then without (where pump and cavity pressure are one)."""
    key = "P_pump_MPa" if by_pressure else "theta_deg"
    lo, hi = min(r[key] for r in rows), max(r[key] for r in rows)
    span = np.linspace(lo, hi, 200) if hi > lo else np.array([lo])
    if by_pressure:
        theta, theta_free = (np.degrees(t) for t in hand.bend_angles(span, design))
        return span, theta, span, theta_free
    P, P_free = (hand.pressure(np.radians(span), design, reservoir=res) for res in (True, False))
    return P, span, P_free, span


def plot_curves(path, found: list[tuple[str, HandDesign, list[dict]]], *, by_pressure: bool = False,
                title: str | None = None, markers: bool = True, extra=(), xlim=None) -> None:
    """Fig. 7 of each (label, design, rows) on one plot: the bend against the pump pressure with
    the reservoir (solid) and without it (dotted) over the span of the rows (their pressures if
    ``by_pressure``, else their angles), the rows as points if ``markers`` -> PNG at ``path``.
    ``title``: default names the design and finger model; ``extra``: more (label, P, theta_deg)
    lines."""
    from softhand.studies.io.files import figure, save_figure

    fig, (ax,) = figure(width=6.5 if len(found) > 1 else 5.5, height=4.5)
    one = len(found) == 1
    for k, (label, design, rows) in enumerate(found):
        P, theta, P_free, theta_free = _span(design, rows, by_pressure)
        colour = f"C{k % 10}"
        ax.plot(P, theta, "-", color=colour, label="eq. (27), with reservoir" if one else label)
        ax.plot(P_free, theta_free, ":", color=colour, label="eq. (28), without reservoir" if one else None)
        if markers:
            ax.plot([r["P_pump_MPa"] for r in rows], [r["theta_deg"] for r in rows], "o", ms=4,
                    color=colour, label="rows printed (with reservoir)" if one else None)
    for label, P_line, theta_line in extra:
        ax.plot(P_line, theta_line, "--", label=label)
    ax.set_xlabel("pump pressure P_pump [MPa] (without reservoir: = P_cavity)")
    ax.set_ylabel("bend angle θ [deg]")
    if title is None:
        title = (f"Free bending, reduced model: {found[0][0]}" if one else
                 "Free bending, reduced model: with reservoir (solid), without (dotted)")
    ax.set_title(title, fontsize=10)
    if xlim is not None:
        ax.set_xlim(*xlim)
    ax.axvline(0.0, color="0.7", lw=0.8)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8 if not one else None)
    save_figure(fig, path)
