"""Mesh convergence of the rubber's stretch: the converged measure against the corner peak.

Finger: three designs (the paper's, and two corners of the calibration's design space) on
the layered mesh family of benchmarks/finger_convergence.py (cross-section fixed: 4
sectors, 5 wall layers from 0.2 mm; axial slices 5 / 2.5 / 1.25 mm, each level splitting
every slice of the one before), pressure path 0.2 : 0.2 : 0.8, 1.1 : 0.3 : 2.0 MPa; the
measures are read at 0.8 and 2.0 MPa. Reservoir: the sheet at its largest volume V0 on
three nested meshes (20 x 1, 40 x 2 (the default), 80 x 4 Q2 elements).

The FEM states are written to DIR/<case>.npz when solved and reused by the next run
(resumable; ``--solve-only`` stops there), so the measures are evaluated from the saved
displacements without solving again. Prints per case and level the unknowns, the wall
time, theta, the converged measure ``rubber_stretch``, the windings' hoop measure and the
peak ``max_principal_stretch``, then each measure's change between the two finest levels
and its Richardson extrapolation.

Run: ``nice python benchmarks/rubber_convergence.py [--levels 0 1 2] [--designs paper ...]
[--solve-only | --report-only] [--order DESIGN:LEVEL ...] [--out DIR]``.
"""
from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

from softhand.fem.hand.finger import FingerModel, FingerOptions, solve_pressures
from softhand.fem.hand.reservoir import SheetModel, inflate
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.calibration.space import finger_design
from softhand.studies.io.files import write_json
from softhand.studies.verification.convergence import richardson

#: the designs: name -> (a, b, d, l0, tie width) [mm]; None: the paper's finger
DESIGNS = {
    "paper": None,
    "thin": {"a_mm": 3.0, "b_mm": 3.0, "d_mm": 10.0, "l0_mm": 120.0, "tie_width_mm": 5.0},
    "wide": {"a_mm": 6.0, "b_mm": 5.0, "d_mm": 20.0, "l0_mm": 200.0, "tie_width_mm": 15.0},
}
#: pressures of the path [MPa]; the measures are read at READ_MPA
PRESSURES = (0.2, 0.4, 0.6, 0.8, 1.1, 1.4, 1.7, 2.0)
READ_MPA = (0.8, 2.0)
#: level n: axial slices of 5 / 2**n mm
AXIAL_MM = 5.0
#: the sheet's levels: (radial, through-thickness) Q2 elements, level 1 the default mesh (the
#: next, 160 x 8, stops on the way: no equilibrium at V = 15 619 mm^3 with the default path)
SHEET_LEVELS = ((20, 1), (40, 2), (80, 4))
#: the measures compared: JSON key -> column title
MEASURES = {"theta_deg": "theta [deg]", "rubber_stretch": "rubber_stretch",
            "radial_stretch": "radial_stretch", "max_principal_stretch": "peak (mesh-dependent)"}


def design_of(name: str) -> HandDesign:
    point = DESIGNS[name]
    return HandDesign() if point is None else finger_design(point)


def options_of(n: int) -> FingerOptions:
    return FingerOptions(axial_size=AXIAL_MM / 2 ** n)


def solve_case(out: Path, name: str, n: int) -> Path:
    """Solve design ``name`` on level n (unless DIR/<name>-level<n>.npz exists)."""
    path = out / f"{name}-level{n}.npz"
    if path.is_file():
        return path
    t0 = time.perf_counter()
    model = FingerModel(design_of(name), options_of(n))
    states, stats = solve_pressures(model, PRESSURES)
    kept = [s for s in states if any(math.isclose(s.P, p) for p in READ_MPA)]
    meta = {"ndofs": model.ndofs, "tets": int(model.mesh.t.shape[1]),
            "wall_seconds": time.perf_counter() - t0, "newton_iterations": stats.newton_iterations,
            "factorizations": stats.factorizations, "cutbacks": stats.cutbacks, "solver": stats.solver}
    out.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp.npz")
    np.savez(tmp, P=np.array([s.P for s in kept]), y=np.array([s.y for s in kept]),
             meta=json.dumps(meta))
    tmp.replace(path)
    return path


def measure_case(out: Path, name: str, n: int) -> list[dict]:
    """The measures of every saved state of design ``name`` on level n (DIR/<name>-level<n>.npz)."""
    saved = np.load(solve_case(out, name, n))
    meta = json.loads(str(saved["meta"]))
    model = FingerModel(design_of(name), options_of(n))
    rows = []
    for P, y in zip(saved["P"], saved["y"]):
        s = model.state(y, P)
        rows.append({"design": name, "level": n, "P_MPa": float(P), "ndofs": meta["ndofs"],
                     "wall_seconds": meta["wall_seconds"], "theta_deg": math.degrees(s.theta),
                     "rubber_stretch": s.rubber_stretch, "radial_stretch": s.radial_stretch,
                     "max_principal_stretch": s.max_principal_stretch})
    return rows


def sheet_case(out: Path, n: int) -> dict:
    """The paper's sheet at V0 on sheet level n (DIR/sheet-level<n>.json, reused)."""
    path = out / f"sheet-level{n}.json"
    if path.is_file():
        return json.loads(path.read_text())
    design = HandDesign()
    n_radial, n_thick = SHEET_LEVELS[n]
    result = inflate(SheetModel.from_design(design, n_radial=n_radial, n_thick=n_thick), [design.V0])
    s = result.states[0]
    row = {"design": "sheet", "level": n, "P_MPa": s.pressure, "ndofs": result.ndofs,
           "wall_seconds": result.wall_time, "mean_stretch": s.mean_stretch,
           "rubber_stretch": s.rubber_stretch, "max_principal_stretch": s.max_principal_stretch}
    write_json(path, row)
    return row


def changes(rows: list[dict], key: str) -> str:
    """The change between the two finest levels [%] and the Richardson extrapolation of the three."""
    v = [r[key] for r in rows]
    change = 100 * (v[-1] / v[-2] - 1)
    try:
        order, limit = richardson(*v[-3:])
    except (InputError, ValueError):
        return f"{change:+.2f} % (not monotone: no extrapolation)"
    return f"{change:+.2f} % (order {order:.1f}, limit {limit:.4f}, finest {100 * (v[-1] / limit - 1):+.2f} %)"


def report(groups: dict) -> None:
    """Print the table (markdown) and, per group, each measure's change between the finest two."""
    print("| design | P [MPa] | level | unknowns | wall [s] | theta [deg] | rubber_stretch | "
          "radial_stretch | peak (mesh-dependent) |\n|---|---|---|---|---|---|---|---|---|")
    for (name, _), rows in groups.items():
        for r in rows:
            cells = [f"{r.get(k, float('nan')):.4f}" for k in ("theta_deg", "rubber_stretch", "radial_stretch",
                                                                 "max_principal_stretch")]
            print(f"| {name} | {r['P_MPa']:.3g} | {r['level']} | {r['ndofs']} | {r['wall_seconds']:.0f} | "
                  + " | ".join(cells) + " |")
    for (name, P), rows in groups.items():
        if len(rows) < 3:
            continue
        print(f"{name} at {P:g} {'mm^3' if name.startswith('sheet') else 'MPa'}:")
        for key in ("theta_deg", "rubber_stretch", "radial_stretch", "max_principal_stretch", "mean_stretch"):
            if key in rows[0]:
                print(f"  {key:22s} {changes(rows, key)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--designs", nargs="+", default=list(DESIGNS), choices=list(DESIGNS))
    parser.add_argument("--solve-only", action="store_true")
    parser.add_argument("--order", nargs="+", metavar="DESIGN:LEVEL", help="solve these cases first, in this order")
    parser.add_argument("--report-only", action="store_true", help="report the cases solved so far")
    parser.add_argument("--no-sheet", action="store_true", help="leave out the reservoir sheet")
    parser.add_argument("--out", type=Path, default=Path("results/rubber_convergence"))
    args = parser.parse_args()
    order = args.order or [f"{name}:{n}" for n in sorted(args.levels) for name in args.designs]
    for case in [] if args.report_only else order:  # default: the coarse levels of every design first
        name, n = case.split(":")
        t0 = time.perf_counter()
        solve_case(args.out, name, int(n))
        print(f"solved {name} level {n} in {time.perf_counter() - t0:.0f} s", flush=True)
    if args.solve_only:
        return
    groups = {}
    for n in sorted(args.levels):
        for name in args.designs:
            if not (args.out / f"{name}-level{n}.npz").is_file():  # --report-only, not solved yet
                print(f"{name} level {n}: not solved")
                continue
            for row in measure_case(args.out, name, n):
                groups.setdefault((name, row["P_MPa"]), []).append(row)
    if not args.no_sheet:  # (its P_MPa: the oil's pressure at V0 on that mesh)
        groups[("sheet at V0", HandDesign().V0)] = [sheet_case(args.out, n) for n in range(len(SHEET_LEVELS))]
    report(groups)


if __name__ == "__main__":
    main()
