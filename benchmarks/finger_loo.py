"""Leave-one-out check of the finger calibration table: each FEM design predicted by the
table without it (fit redone, ranges kept), no FEM run. Prints theta and dQ errors per
design (worst over its FEM points) and the rms / worst over all points.

Run: ``python benchmarks/finger_loo.py [TABLE.csv]`` (default: the shipped table).
"""
from __future__ import annotations

import sys

import numpy as np

from softhand.studies.calibration.finger_check import leave_one_out


def main() -> None:
    rows = leave_one_out(sys.argv[1] if len(sys.argv) > 1 else None)
    print("design  b/a    d/a    link/a  tie/link  |theta err| max [%]  |dQ err| max [%]")
    for i in sorted({r["design"] for r in rows}):
        mine = [r for r in rows if r["design"] == i]
        g = mine[0]
        print(f"{i:6d}  {g['b_a']:5.3f}  {g['d_a']:5.3f}  {g['link_a']:6.3f}  {g['tie_link']:8.3f}  "
              f"{max(abs(r['theta_err_pct']) for r in mine):19.2f}  {max(abs(r['dQ_err_pct']) for r in mine):16.2f}")
    for key in ("theta_err_pct", "dQ_err_pct"):
        e = np.array([r[key] for r in rows])
        print(f"{key}: rms {np.sqrt(np.mean(e**2)):.2f} %, worst {np.abs(e).max():.2f} % over {e.size} FEM points")


if __name__ == "__main__":
    main()
