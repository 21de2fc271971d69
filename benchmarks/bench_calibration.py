"""Time of the finger calibration table for N workers, measured on a sample of its designs.

Run: ``python benchmarks/bench_calibration.py [--space FILE.toml] [--designs K] [--workers N ...]
[--scheduler local|tcp://HOST:PORT]``. Runs K designs of the space (default
studies/finger_space.toml, 41 designs), spread evenly over its list, each on the space's own
mesh and load path, through the batch runner with N workers (the local process pool, or the
Dask cluster at ``--scheduler``; ``local`` starts a LocalCluster), each run into a fresh
results folder. Prints per N: the wall time, the sum of the cases' own FEM wall times, and
the whole table's time estimated from them, wall x (designs in the space) / K: a measured
rate, as good as the sample is typical of the space (its designs differ in cost: use K of at
least the workers, and more for a better estimate). The whole table is
``softhand calibrate finger --space FILE.toml --out T.csv --workers N [--scheduler ...]``.

``--from-results DIR [--workers N ...]``: no FEM; the whole table's time for N workers from the
measured case times of a finished run of the whole space (its ``--results`` folder): the case
list dealt out in order, each case to the worker that frees first (as the process pool and
Dask's scheduler do), each case as long as it took in that run (workers as fast as the ones that
ran it; on one 2-core machine two workers each run a case ~1.3x slower than one alone).
"""
from __future__ import annotations

import argparse
import dataclasses
import heapq
import os
import tempfile
import time
from pathlib import Path

from softhand.studies.batch.cases import plan, read_case, study_dir
from softhand.studies.batch.runner import run_study
from softhand.studies.calibration.finger import as_study
from softhand.studies.calibration.space import load_space

ROOT = Path(__file__).resolve().parents[1]


def sample(space, k: int):
    """The space's study with k of its design cases, evenly spread over the list (no mesh pair)
    and the number of designs in the space."""
    study, n = as_study(space), len(space.points)  # the design cases come first, then the pair
    picks = sorted({round(i * (n - 1) / max(k - 1, 1)) for i in range(k)})
    return dataclasses.replace(study, case_list=tuple(study.case_list[i] for i in picks)), n


def list_schedule(times, workers: int) -> float:
    """Wall time when the cases (times, in order) go each to the worker that frees first."""
    free = [0.0] * workers
    for t in times:
        heapq.heappush(free, heapq.heappop(free) + t)
    return max(free)


def case_times(space, results: Path) -> list[float]:
    """The measured wall times [s] of the space's cases in a finished run's results folder, in the
    order the runner deals them out."""
    study = as_study(space)
    sdir = study_dir(study, results)
    times = []
    for case in plan(study):
        record = read_case(sdir, case)
        if record is None or record.get("status") != "done":
            raise SystemExit(f"case {case} is not finished in {sdir}: run the whole space first")
        times.append(record["provenance"]["solver"]["wall_time_s"])
    return times


def from_results(space, results: Path, workers) -> None:
    times = case_times(space, results)
    print(f"# {len(times)} cases measured in {results}: {sum(times) / 60:.1f} min of case time, "
          f"the longest {max(times):.0f} s")
    print("workers  table_estimate_min")
    for n in workers:
        print(f"{n:7d}  {list_schedule(times, n) / 60:18.1f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--space", default=str(ROOT / "studies" / "finger_space.toml"),
                        help="design space (default: the package's, 41 designs)")
    parser.add_argument("--designs", type=int, default=2, help="designs in the sample (default 2)")
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2], help="worker counts (default 1 2)")
    parser.add_argument("--scheduler", default=None, help="a Dask scheduler address, or 'local'")
    parser.add_argument("--from-results", type=Path, default=None, metavar="DIR",
                        help="no FEM: estimate from a finished run's case times (its --results folder)")
    args = parser.parse_args()
    if args.from_results is not None:
        return from_results(load_space(args.space), args.from_results, args.workers)
    study, n_space = sample(load_space(args.space), args.designs)
    k = len(study.case_list)
    where = "process pool" if args.scheduler is None else f"Dask at {args.scheduler}"
    print(f"# {k} of the {n_space} designs of {args.space}; {where}; {os.cpu_count()} cores here")
    print("workers  wall_s  sum_case_s  table_estimate_min")
    with tempfile.TemporaryDirectory() as tmp:
        for n in args.workers:
            root = Path(tmp) / f"w{n}"
            t0 = time.perf_counter()
            summary = run_study(study, results_root=root, workers=n, scheduler=args.scheduler, progress=False)
            wall = time.perf_counter() - t0
            if not summary.ok:
                raise SystemExit(f"cases failed or not run: {summary.failed}")
            sdir = study_dir(study, root)
            case_s = sum(read_case(sdir, c)["provenance"]["solver"]["wall_time_s"] for c in plan(study))
            print(f"{n:7d}  {wall:6.1f}  {case_s:10.1f}  {wall * n_space / k / 60:18.1f}", flush=True)


if __name__ == "__main__":
    main()
