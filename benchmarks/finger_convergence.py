"""Mesh convergence of the finger's bend angle theta(0.8 MPa) on nested meshes.

Level n is the CI mesh (uniform, element size 6 mm) with every tetrahedron split into 8
n times (``FingerOptions.mesh_refine``): the element size halves per level and nothing
else about the mesh changes, so Richardson extrapolation of three consecutive levels
gives the observed order and the extrapolated angle. Unknowns: ~9.7k / 72k / 570k;
level 2 needs ~13 GB and ~40 min on this 2-core machine.

Run: ``python benchmarks/finger_convergence.py [--levels 0 1 2] [--out DIR]``. Each level's
result is written to DIR/level<n>.json when it is done and reused by the next run
(resumable). Prints per level the unknowns, theta, Newton iterations and wall time, then
the extrapolation and the error of each level against it.
"""
from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import replace
from pathlib import Path

from fem.finger import FingerModel, FingerOptions, solve_pressures
from reduced.design import HandDesign
from studies.convergence import richardson
from studies.output import write_json

#: the nested family's coarsest member: the CI mesh
BASE = FingerOptions(mesh_size=6.0, edge_ratio=1.0, mesh_refine=0)
#: pressures of the solve [MPa]; theta is read at the last (0.2 MPa steps: no cut-backs)
PRESSURES = (0.2, 0.4, 0.6, 0.8)


def level(n: int, out: Path) -> dict:
    """theta(0.8 MPa) on level n, from DIR/level<n>.json if it was computed before."""
    path = out / f"level{n}.json"
    if path.is_file():
        return json.loads(path.read_text())
    t0 = time.perf_counter()
    model = FingerModel(HandDesign(), replace(BASE, mesh_refine=n))
    states, stats = solve_pressures(model, PRESSURES)
    result = {"level": n, "ndofs": model.ndofs, "tets": int(model.mesh.t.shape[1]),
              "theta_deg": math.degrees(states[-1].theta), "newton_iterations": stats.newton_iterations,
              "wall_seconds": time.perf_counter() - t0, "solver": stats.solver}
    write_json(path, result)
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--out", type=Path, default=Path("results/finger_convergence"))
    args = parser.parse_args()
    print("level  unknowns    tets  theta_0.8_deg  newton  wall_s")
    rows = []
    for n in sorted(args.levels):
        r = level(n, args.out)
        rows.append(r)
        print(f"{n:5d}  {r['ndofs']:8d}  {r['tets']:6d}  {r['theta_deg']:13.4f}  "
              f"{r['newton_iterations']:6d}  {r['wall_seconds']:6.0f}", flush=True)
    if len(rows) >= 3 and [r["level"] for r in rows[-3:]] == list(range(rows[-3]["level"], rows[-1]["level"] + 1)):
        order, limit = richardson(*(r["theta_deg"] for r in rows[-3:]))
        print(f"Richardson (levels {rows[-3]['level']}-{rows[-1]['level']}): observed order {order:.2f} "
              f"in h, extrapolated theta {limit:.4f} deg")
        for r in rows:
            print(f"  level {r['level']}: {100 * (r['theta_deg'] / limit - 1):+.2f} %")


if __name__ == "__main__":
    main()
