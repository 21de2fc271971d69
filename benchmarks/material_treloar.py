"""Every rubber model fitted to Treloar's data (studies/data/treloar1944.csv), and Ogden's
(1972) three-term parameters evaluated on the same data as a cross-check.

Run: ``python benchmarks/material_treloar.py``. Prints a Markdown table: parameters, rms
error per mode [MPa], Drucker stability over the data's stretches (1/7.6 .. 7.6), time.
The same numbers come from ``softhand material fit --data ... --model M``.
"""
from __future__ import annotations

import time
from pathlib import Path

from softhand.reduced.materials import rubber, rubber_base
from softhand.reduced.materials.material_fit import FIT_MODELS, fit_material
from softhand.reduced.materials.stress_data import read_test_data
from softhand.reduced.materials.rubber import drucker_check

DATA = Path(__file__).resolve().parent.parent / "studies" / "data" / "treloar1944.csv"
KGF_CM2 = 0.0980665  #: MPa
#: Ogden, Proc. R. Soc. Lond. A 326 (1972) 565-584: mu_p in kgf/cm^2, W = sum mu_p/alpha_p (...)
OGDEN_1972 = rubber.Ogden((6.3 * KGF_CM2, 0.012 * KGF_CM2, -0.1 * KGF_CM2), (1.3, 5.0, -2.0))


def rms_by_mode(data, material) -> dict:
    r = data.predict(material) - data.stress
    return {m: float((r[data.mode == m] ** 2).mean() ** 0.5) for m in rubber_base.MODES}


def main() -> None:
    data = read_test_data(DATA)
    top = float(data.stretch.max())
    print("| model | parameters | rms uniaxial | rms equibiaxial | rms pure shear [MPa] | Drucker-stable | fit time |")
    print("|---|---|---|---|---|---|---|")
    rows = []
    for name in FIT_MODELS:
        t0 = time.perf_counter()
        fit = fit_material(data, name)
        seconds = time.perf_counter() - t0
        rows.append((name, fit.material, f"{seconds:.2f} s"))
    rows.append(("Ogden 1972 (not fitted here)", OGDEN_1972, "-"))
    for name, material, seconds in rows:
        params = ", ".join(f"{k} {v:.4g}" for k, v in material.parameters().items())
        rms = rms_by_mode(data, material)
        stable = drucker_check(material, (1.0 / top, top))["stable"]
        print(f"| {name} | {params} | " + " | ".join(f"{rms[m]:.4f}" for m in rubber_base.MODES)
              + f" | {'yes' if stable else 'no'} | {seconds} |")


if __name__ == "__main__":
    main()
