"""Leave-one-out check of the finger calibration table: each FEM design predicted by the
table without it (fit redone, ranges kept), no FEM run. Prints theta and dQ errors per
design (worst over its FEM points), and the rubber's converged stretch where the table holds
it (at a = 4 mm, and where the table has its a/rho columns the worst at a = 2 to 8 mm), and the
rms / worst over all points.

Run: ``python benchmarks/finger_loo.py [TABLE.csv]`` (default: the shipped table).
"""
from __future__ import annotations

import sys

import numpy as np

from softhand.studies.calibration.finger_check import leave_one_out


def main() -> None:
    rows = leave_one_out(sys.argv[1] if len(sys.argv) > 1 else None)
    keys = ["theta_err_pct", "dQ_err_pct"] + [k for k in ("rubber_stretch_err_pct", "rubber_stretch_sizes_err_pct")
                                              if k in rows[0]]
    titles = {"rubber_stretch_err_pct": "  |stretch err| max [%]", "rubber_stretch_sizes_err_pct": "  at a = 2-8 mm [%]"}
    print("design  b/a    d/a    link/a  tie/link  |theta err| max [%]  |dQ err| max [%]"
          + "".join(titles[k] for k in keys[2:]))
    for i in sorted({r["design"] for r in rows}):
        mine = [r for r in rows if r["design"] == i]
        g = mine[0]
        worst = [max(abs(r[k]) for r in mine) for k in keys]
        print(f"{i:6d}  {g['b_a']:5.3f}  {g['d_a']:5.3f}  {g['link_a']:6.3f}  {g['tie_link']:8.3f}  "
              f"{worst[0]:19.2f}  {worst[1]:16.2f}" + "".join(f"  {w:{len(titles[k]) - 2}.2f}"
                                                             for k, w in zip(keys[2:], worst[2:])))
    for key in keys:
        e = np.array([r[key] for r in rows])
        print(f"{key}: rms {np.sqrt(np.mean(e**2)):.2f} %, worst {np.abs(e).max():.2f} % over {e.size} FEM points")


if __name__ == "__main__":
    main()
