"""Speed-up of a batch of finger FEM cases on 2 workers over 1 (process pool and Dask).

Run: ``python benchmarks/bench_batch.py [--designs N] [--mesh-size-mm H]``. Runs the same
small design space (N finger designs of similar cost, free bending to 0.2, 0.5, 0.8 MPa, a
gmsh mesh of size H) through the batch runner, each time into a fresh results folder (the meshes cached beforehand): in
this process (1 worker), on the local process pool with 2 workers, and on a Dask
LocalCluster with 2 workers (if dask is installed). Prints wall seconds, the speed-up over
1 worker and the bend of every case, which must be equal across the runs.
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from softhand.fem.hand.finger import FingerModel, FingerOptions
from softhand.studies.batch.cases import plan, read_case, study_dir
from softhand.studies.batch.runner import run_study
from softhand.studies.calibration.finger import as_study
from softhand.studies.calibration.space import load_space

SPACE = """name = "bench_batch"
pressures_mpa = [0.2, 0.5, 0.8]
theta_target_deg = 1.0
mesh_size_mm = {h}
[space]
a_mm = [4.0, 4.0]
b_mm = [5.0, 5.0]
d_mm = [15.0, 15.0]
l0_mm = [180.0, 180.0]
tie_width_mm = [8.0, 12.0]
"""


def space_file(folder: Path, designs: int, h: float) -> Path:
    """The paper's finger with N tie widths from 8 to 12 mm (cases of about equal cost)."""
    text = SPACE.format(h=h) + "".join(
        f"[[design]]\na_mm = 4.0\nb_mm = 5.0\nd_mm = 15.0\nl0_mm = 180.0\n"
        f"tie_width_mm = {8.0 + 4.0 * k / max(designs - 1, 1):.3f}\n" for k in range(designs))
    path = folder / "space.toml"
    path.write_text(text)
    return path


def timed(study, root: Path, **how) -> tuple[float, list[float]]:
    """Wall seconds of one run into ``root`` and the bend [deg] at the last pressure of each case."""
    t0 = time.perf_counter()
    summary = run_study(study, results_root=root, progress=False, **how)
    wall = time.perf_counter() - t0
    if summary.failed:
        raise SystemExit(f"cases failed: {summary.failed}")
    sdir = study_dir(study, root)
    return wall, [read_case(sdir, case)["numbers"]["theta_deg"][-1] for case in plan(study)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--designs", type=int, default=6, help="cases in the batch (default 6)")
    parser.add_argument("--mesh-size-mm", type=float, default=6.0, help="gmsh mesh size (default 6, the CI mesh)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        space = load_space(space_file(tmp, args.designs, args.mesh_size_mm))
        study = as_study(space)
        for design in space.designs():  # the meshes into the mesh cache, so that no run pays for them
            FingerModel(design, FingerOptions(mesher="gmsh", mesh_size=args.mesh_size_mm))
        runs = [("1 worker (in process)", {"workers": 1}), ("process pool, 2 workers", {"workers": 2})]
        try:
            import dask.distributed  # noqa: F401
            runs.append(("Dask LocalCluster, 2 workers", {"workers": 2, "scheduler": "local"}))
        except ImportError:
            print("# dask not installed: no Dask run (pip install 'softhand[cluster]')")
        print(f"# {args.designs} finger cases, gmsh {args.mesh_size_mm:g} mm, {os.cpu_count()} cores")
        print("run                              wall_s  speed-up  theta_0.8_deg")
        base, ref = None, None
        for k, (name, how) in enumerate(runs):
            wall, thetas = timed(study, tmp / f"run{k}", **how)
            base = base or wall
            ref = ref or thetas
            same = max(abs(a - b) for a, b in zip(thetas, ref)) < 1e-6
            print(f"{name:32s} {wall:6.1f}  {base / wall:8.2f}  "
                  f"{' '.join(f'{t:.3f}' for t in thetas)}{'' if same else '  (differs from 1 worker!)'}",
                  flush=True)


if __name__ == "__main__":
    main()
