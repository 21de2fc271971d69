"""Mesh convergence of the finger's bend angle theta(0.8 MPa) on nested mesh families.

``--family layered`` (the default mesh's family): the layered mesh of
:func:`softhand.meshes.finger.layered_tube_mesh` with the cross-section fixed (4 sectors, 5 wall
layers from 0.2 mm) and axial slices of 5 / 2.5 / 1.25 / 0.625 mm at levels 0-3: every
level splits each slice of the one before in two (the ring edges and the cavity end are
cuts of every level), nothing else changes. The cross-section's share of the error is
measured separately (``--cross-section``: 8 sectors, or 9 wall layers from 0.1 mm, at level 2).

``--family gmsh``: the CI mesh (gmsh, uniform, 6 mm) with every tetrahedron split into 8
n times (``FingerOptions.mesh_refine``); level 2 has 554k unknowns and needs ~15 GB and
~80 min on this 2-core machine.

Richardson extrapolation of the three coarsest levels asked for gives the observed order
and the extrapolated angle (refused when the three do not converge monotonically); finer
levels are reported against it.

Run: ``python benchmarks/finger_convergence.py [--family layered|gmsh] [--levels 0 1 2]
[--cross-section] [--out DIR]``. Each mesh's result is written to DIR/<name>.json when it
is done and reused by the next run (resumable). Prints per level the unknowns, theta,
Newton iterations and wall time, then the extrapolation and each level's error against it.
"""
from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import replace
from pathlib import Path

from softhand.fem.hand.finger import FingerModel, FingerOptions, solve_pressures
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.verification.convergence import richardson
from softhand.studies.io.files import write_json

#: the gmsh family's coarsest member: the CI mesh
BASE = FingerOptions(mesher="gmsh", mesh_size=6.0, edge_ratio=1.0, mesh_refine=0)
#: the layered family's coarsest member (level n: axial_size 5 / 2**n mm)
LAYERED = FingerOptions(mesher="layered", axial_size=5.0)
#: the layered family's cross-section refined at level 2: (name, changes)
CROSS_SECTION = (("sectors8", {"n_phi": 8}), ("layers9", {"layer_first": 0.1, "layer_ratio": 2 ** 0.5}))
#: pressures of the solve [MPa]; theta is read at the last (0.2 MPa steps: no cut-backs)
PRESSURES = (0.2, 0.4, 0.6, 0.8)


def theta_case(path: Path, options: FingerOptions, prepare=None) -> dict:
    """theta(0.8 MPa) of ``FingerModel(HandDesign(), options)`` along :data:`PRESSURES`, from
    ``path`` if it was computed before (else computed and written there). ``prepare(model)``,
    if given, may change the built model before the solve (benchmarks/finger_error_sources.py)."""
    if path.is_file():
        return json.loads(path.read_text())
    t0 = time.perf_counter()
    model = FingerModel(HandDesign(), options)
    if prepare is not None:
        prepare(model)
    states, stats = solve_pressures(model, PRESSURES)
    result = {"ndofs": model.ndofs, "tets": int(model.mesh.t.shape[1]),
              "theta_deg": math.degrees(states[-1].theta), "newton_iterations": stats.newton_iterations,
              "wall_seconds": time.perf_counter() - t0, "solver": stats.solver}
    write_json(path, result)
    return result


def level(family: str, n: int, out: Path, variant: tuple[str, dict] | None = None) -> dict:
    """theta(0.8 MPa) on level n of a family (layered: optionally a named cross-section
    ``variant`` of :data:`CROSS_SECTION`), from DIR if it was computed before."""
    if family == "gmsh":
        return {"level": n, **theta_case(out / f"level{n}.json", replace(BASE, mesh_refine=n))}
    suffix, changes = (f"-{variant[0]}", variant[1]) if variant else ("", {})
    options = replace(LAYERED, axial_size=LAYERED.axial_size / 2 ** n, **changes)
    return {"level": n, **theta_case(out / f"layered-level{n}{suffix}.json", options)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--family", choices=("layered", "gmsh"), default="layered")
    parser.add_argument("--levels", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--cross-section", action="store_true",
                        help="layered: also level 2 with the cross-section refined")
    parser.add_argument("--out", type=Path, default=Path("results/finger_convergence"))
    args = parser.parse_args()
    print(f"family {args.family}\nlevel  unknowns    tets  theta_0.8_deg  newton  wall_s")
    rows = []
    for n in sorted(args.levels):
        r = level(args.family, n, args.out)
        rows.append(r)
        print(f"{n:5d}  {r['ndofs']:8d}  {r['tets']:6d}  {r['theta_deg']:13.4f}  "
              f"{r['newton_iterations']:6d}  {r['wall_seconds']:6.0f}", flush=True)
    limit = None
    first = [r for r in rows if r["level"] in range(rows[0]["level"], rows[0]["level"] + 3)]
    if len(first) == 3:  # the coarsest three consecutive levels; finer ones check the limit
        try:
            order, limit = richardson(*(r["theta_deg"] for r in first))
        except InputError as err:
            print(f"no Richardson extrapolation: {err}")
        else:
            print(f"Richardson (levels {first[0]['level']}-{first[-1]['level']}): observed order {order:.2f}, "
                  f"extrapolated theta {limit:.4f} deg")
            for r in rows:
                print(f"  level {r['level']}: {100 * (r['theta_deg'] / limit - 1):+.2f} %")
    if args.cross_section and args.family == "layered":
        for name, changes in CROSS_SECTION:
            r = level("layered", 2, args.out, (name, changes))
            against = f", {100 * (r['theta_deg'] / limit - 1):+.2f} % vs the extrapolation" if limit else ""
            print(f"level 2, {name}: {r['ndofs']} unknowns, theta {r['theta_deg']:.4f} deg{against}", flush=True)


if __name__ == "__main__":
    main()
