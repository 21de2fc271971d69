"""The reservoir study's pictures and VTK: the sheet's profiles and p(V) against the ellipse
model, the hand's P(theta) with both reservoir models, and the deformed sheet per volume."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from softhand.reduced.equations import hand, reservoir
from softhand.studies.io.files import figure, save_figure


def plot_reservoir(path, result) -> None:
    """Profiles (FEM vs ellipse), p(V) of both models, P(theta) with both reservoir models."""
    d = result.study.design
    fig, ax = figure(3, width=5.0, height=4.2)
    r = np.linspace(0, d.R, 200)
    for k, s in enumerate(result.states):
        c = f"C{k}"
        ax[0].plot(s.r, s.z, "-", color=c, label=f"FEM V={s.volume:.0f}")
        h = float(reservoir.height(s.volume, d))
        ax[0].plot(r, h * np.sqrt(1 - (r / d.R) ** 2), "--", color=c)
    ax[0].set(xlabel="r [mm]", ylabel="z [mm] (wet surface)", title="profiles: FEM (-), ellipse (--)",
              aspect="equal")
    fem = result.fem
    V = np.asarray(fem.path_volume[1:])
    ax[1].plot(V, fem.path_pressure[1:], "-", label="FEM")
    ax[1].plot(V, reservoir.ellipse_pressure(V, d), "--", label="ellipse (11)-(18)")
    ax[1].axvspan(*result.verdict["V_range_mm3"], color="0.9", label="operating range")
    ax[1].set(xlabel="V [mm^3]", ylabel="p_r [MPa]", title="reservoir pressure p(V)")
    theta = np.linspace(0, math.pi / 2, 91)
    models = (("ellipse", "--"), ("fem", "-")) if d.reservoir_is_neo_hookean else (("ellipse", "--"),)
    for name, style in models:  # the FEM-calibrated table is Neo-Hookean only
        P = hand.pressure(theta, d.replace(reservoir_model=name))
        ax[2].plot(np.degrees(theta), P, style, label=f"reservoir model '{name}'")
    ax[2].plot(np.degrees(theta), hand.pressure(theta, d, reservoir=False), ":", label="no reservoir")
    ax[2].set(xlabel="theta [deg]", ylabel="P [MPa]", title="pump pressure P(theta), eq. (27)")
    for a in ax:
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    save_figure(fig, path)


def write_sheet_vtk(result, outdir: Path) -> list[str]:
    """The deformed sheet per volume: the scene series sheet.pvd (the sheet revolved in 3D,
    one .vtm per volume, by increasing volume) and the r-z sections sheet_V<volume>_rz.vtu;
    the names written."""
    return write_sheet_states(result.fem.model.build()[0], result.states, outdir)


def write_sheet_states(solid, states, outdir: Path) -> list[str]:
    """:func:`write_sheet_vtk` of the sheet states ``states`` on the mesh of ``solid``."""
    from softhand.fem.hand.reservoir import sheet_vtk
    from softhand.fem.hand.scene import sheet_block
    from softhand.fem.io import SceneSeries
    from softhand.meshes.convert import write_vtu

    names = []
    series = SceneSeries(Path(outdir) / "sheet.pvd")
    for state in sorted({s.volume: s for s in states}.values(), key=lambda s: s.volume):
        series.write(state.volume, [sheet_block(solid, state)],
                     {"volume_mm3": state.volume, "p_reservoir_MPa": state.pressure})
        name = f"sheet_V{state.volume:.0f}_rz.vtu"
        points, cells, data = sheet_vtk(solid, state)
        write_vtu(Path(outdir) / name, points, cells, point_data=data)
        names.append(name)
    return ["sheet.pvd", *names]
