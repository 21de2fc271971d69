"""What the rubber model changes: theta(P) of the hand to 2.0 MPa and the reservoir's p(V),
Neo-Hookean against Yeoh and Mooney-Rivlin with the same initial shear modulus (1.15 MPa,
the paper's), the same material in finger and sheet.

Run: ``python benchmarks/material_effect.py [--fem] [--fem-finger] [--plot FILE.png]``. Yeoh has the shape
of its fit to Treloar's data (studies/data/treloar1944.csv), scaled to mu0 = 1.15 MPa;
Mooney-Rivlin has C01/C10 = 0.25 (an illustrative ratio; the fit to Treloar gives C01 ~ 0).
``--fem`` adds the reservoir sheet's FEM p(V) (about a minute per material),
``--fem-finger`` the finger FEM's theta(P) without reservoir on the CI mesh (gmsh, 6 mm;
a few minutes per material). Prints Markdown tables.
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from softhand.reduced.equations import hand, reservoir
from softhand.reduced.materials import rubber
from softhand.reduced.vocabulary.design_files import load_design
from softhand.reduced.materials.material_fit import fit_material
from softhand.reduced.materials.stress_data import read_test_data

MU0 = 1.15
PRESSURES = (0.5, 1.0, 1.5, 2.0)
DATA = Path(__file__).resolve().parent.parent / "studies" / "data" / "treloar1944.csv"


def materials() -> dict:
    yeoh = fit_material(read_test_data(DATA), "yeoh").material
    return {"neo-hookean": rubber.NeoHookean(MU0), "yeoh (Treloar shape)": yeoh.scaled(MU0 / yeoh.mu0),
            "mooney-rivlin (C01/C10 = 0.25)": rubber.MooneyRivlin(0.4 * MU0, 0.1 * MU0)}


def designs() -> dict:
    base = load_design()
    return {name: base.replace(finger_material=m, reservoir_material=m, mu_sf=MU0, mu_sr=MU0)
            for name, m in materials().items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fem", action="store_true", help="also the reservoir sheet's FEM p(V)")
    parser.add_argument("--fem-finger", action="store_true", help="also the finger FEM's theta(P)")
    parser.add_argument("--plot", metavar="FILE.png", help="theta(P) and p(V) per material")
    args = parser.parse_args()
    if args.fem_finger:
        finger_fem_table(designs())
    cases = designs()
    for name, m in materials().items():
        print(f"# {name}: " + ", ".join(f"{k} = {v:.6g}" for k, v in m.parameters().items()))
    print("\n| material | " + " | ".join(f"theta({p:g} MPa) [deg] with / without reservoir"
                                          for p in PRESSURES) + " |")
    print("|---" * (len(PRESSURES) + 1) + "|")
    for name, d in cases.items():
        cells = [f"{math.degrees(float(hand.bend_angle(p, d))):.2f} / "
                 f"{math.degrees(float(hand.bend_angle(p, d, reservoir=False))):.2f}" for p in PRESSURES]
        print(f"| {name} | " + " | ".join(cells) + " |")
    base = next(iter(cases.values()))
    V = np.array([float(reservoir.oil_volume(math.pi / 2, base)), base.V0, base.V0 + 2000.0])
    print("\n| material | " + " | ".join(f"p_r({v:.0f} mm^3) [MPa] ellipse" + (" / FEM" if args.fem else "")
                                          for v in V) + " |")
    print("|---" * (len(V) + 1) + "|")
    fem = {}
    for name, d in cases.items():
        ell = reservoir.ellipse_pressure(V, d)
        if args.fem:
            from softhand.fem.hand.reservoir import SheetModel, inflate

            fem[name] = inflate(SheetModel.from_design(d), V)
        cells = [f"{e:.4f}" + (f" / {s.pressure:.4f}" if args.fem else "")
                 for e, s in zip(ell, fem[name].states if args.fem else ell)]
        print(f"| {name} | " + " | ".join(cells) + " |")
    if args.plot:
        plot(args.plot, cases, fem)


def finger_fem_table(cases) -> None:
    """theta(P) of one finger without reservoir: FEM (CI mesh) and eq. (28), per material."""
    from softhand.fem.hand.finger import FingerOptions
    from softhand.studies.bending import BendingStudy, run

    print("\n| material | " + " | ".join(f"theta({p:g} MPa) [deg] FEM / eq. (28)" for p in PRESSURES)
          + " | largest principal stretch at 2.0 MPa (FEM) |")
    print("|---" * (len(PRESSURES) + 2) + "|")
    for name, d in cases.items():
        result = run(BendingStudy(design=d, pressures_mpa=PRESSURES,
                                  options=FingerOptions(mesher="gmsh", mesh_size=6.0)))
        cells = [f"{r['theta_deg']:.2f} / {r['theta_reduced_deg']:.2f}" for r in result.rows]
        print(f"| {name} | " + " | ".join(cells) + f" | {result.rows[-1]['max_principal_stretch']:.3f} |",
              flush=True)


def plot(path, cases, fem) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from softhand.studies.io.files import save_figure

    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    P = np.linspace(0.0, 2.0, 81)
    for k, (name, d) in enumerate(cases.items()):
        c = f"C{k}"
        ax[0].plot(P, np.degrees(hand.bend_angle(P, d)), "-", color=c, label=f"{name}")
        ax[0].plot(P, np.degrees(hand.bend_angle(P, d, reservoir=False)), ":", color=c)
        V = np.linspace(8000.0, d.V0 + 2000.0, 100)
        ax[1].plot(V, reservoir.ellipse_pressure(V, d), "-", color=c, label=f"{name}, ellipse model")
        if name in fem:
            r = fem[name]
            ax[1].plot(r.path_volume[1:], r.path_pressure[1:], "--", color=c, label=f"{name}, FEM")
    ax[0].set(xlabel="pump pressure P [MPa]", ylabel="bend angle theta [deg]",
              title="hand: with reservoir (-), without (:)")
    ax[1].set(xlabel="oil volume V [mm^3]", ylabel="reservoir pressure p_r [MPa]",
              title="reservoir sheet p(V)", xlim=(8000.0, None))
    for a in ax:
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    save_figure(fig, path)


if __name__ == "__main__":
    main()
