"""The batch runner: every case of a study, on a local process pool or a Dask cluster.

Resumable and safe by construction:

* a case is keyed by a hash of its inputs (kind, case parameters, design hash) and the
  package version, so a rerun finds what is already done and a new release recomputes.
  The hash of the package's sources is recorded in each result's provenance;
  ``status`` counts the results that other sources computed, and ``run(fresh=True)``
  recomputes everything (a working tree under development changes its sources often);
* a worker computes a case in its own temporary folder and returns the numbers and the
  files; this process writes them into ``results/<study>/.<key>.<random>.tmp/`` and
  renames that folder to ``results/<study>/<key>/`` in one step. A killed run leaves
  finished cases complete and nothing half-written (a leftover temporary folder of a case
  is removed by the next run that claims the case). The same path serves the process
  pool and Dask, and a Dask cluster needs no shared file system;
* several runs of one study may run at once: each case is claimed (:mod:`softhand.studies.batch.claims`)
  before it is computed, a case another run holds is left to it and taken as reused once
  done, so every case is computed once;
* a case file that does not parse (truncated, empty, ``null``, edited) counts as not done:
  ``status`` reports it as corrupt and the next run recomputes it;
* a case that raises is recorded (``<key>/failed.json``, with the error and traceback)
  and the others go on; a rerun tries it again;
* pool workers die with this process (also on SIGKILL), and SIGTERM stops a run as
  Ctrl-C does: finished cases are kept and ``index.csv`` is written.

``results/<study>/index.csv`` lists every case of the sweep with its state and numbers.
"""
from __future__ import annotations

import os
import sys
import time
from contextlib import closing
from dataclasses import dataclass, field
from pathlib import Path

from softhand.studies.batch.cases import (FAILED, OWNER, RESULT, Case, case_key, case_state, code_version,  # noqa: F401
                                          commit, commit_case, execute_case, outcome_record,
                                          own_study_dir, package_versions, plan, read_case, study_dir,
                                          remove_leftovers)
from softhand.studies.batch.claims import Claims
from softhand.studies.io.outputs import MANIFEST, check_owned
from softhand.studies.batch.index import index_rows, other_sources, status, write_index  # noqa: F401
from softhand.studies.batch.studyfile import Study
from softhand.studies.io.files import kept_if_unwritable
from softhand.studies.io.outputs import check_output_tree


@dataclass
class RunSummary:
    """What a run did; ``failed`` maps case key -> one-line error."""

    total: int
    reused: int = 0
    computed: int = 0
    failed: dict = field(default_factory=dict)
    not_run: int = 0  #: cases left pending (a worker died, or interrupted)
    corrupt: int = 0  #: case files found unreadable at the start (recomputed)

    @property
    def ok(self) -> bool:
        return not self.failed and not self.not_run


# ---------------------------------------------------------------------- the run
#: the files a run writes into the study's folder beside the case folders and its claim locks
STUDY_OUTPUTS = (OWNER, "index.csv")


def run_study(study: Study, *, results_root: str | Path = "results", workers: int | None = None,
              scheduler: str | None = None, progress: bool = True,
              fresh: bool = False) -> RunSummary:
    """Run every case of ``study`` not yet done (``fresh``: every case); write results and index.csv.

    ``workers``: processes (default: the CPU count); 1 runs in this process.
    ``scheduler``: a Dask scheduler address, or 'local' for a LocalCluster.
    """
    sdir = own_study_dir(study, results_root, write=False, outputs=STUDY_OUTPUTS)
    cases = plan(study)
    # a case folder that is a symbolic link is a damaged case: recomputed, the link replaced
    check_output_tree(sdir, "--results", folders=[c.key for c in cases if not (sdir / c.key).is_symlink()])
    if not (sdir / MANIFEST).exists():  # a folder no study run wrote: its case-named folders are the user's
        check_owned(sdir, [c.key for c in cases], "--results")
    states = {c.key: case_state(sdir, c) for c in cases}
    todo = [c for c in cases if fresh or states[c.key] != "done"]
    summary = RunSummary(total=len(cases), reused=len(cases) - len(todo), not_run=len(todo),
                         corrupt=sum(state == "corrupt" for state in states.values()))
    if summary.corrupt:
        print(f"softhand study: {summary.corrupt} case files do not parse; recomputing them",
              file=sys.stderr)
    check_meshes(study.kind, [(c.key, c.params, c.design) for c in todo], study.name)  # folded: one line now
    workers = max(1, workers or os.cpu_count() or 1)
    dask = None
    if scheduler and todo:
        from softhand.studies.batch.cluster import open_cluster

        dask = open_cluster(scheduler, workers)  # reached before anything is written
    own_study_dir(study, results_root, write=True, outputs=STUDY_OUTPUTS)
    bar = _progress_bar(study, summary, progress)
    claims = Claims(sdir)
    try:
        while todo:
            deferred: list[Case] = []
            mine = _claimed(sdir, todo, claims, fresh, deferred, summary, bar)
            with closing(_outcomes(study, mine, workers, dask)) as outcomes:
                for case, output in outcomes:
                    if not _committed(sdir, study, case, output):
                        todo = []
                        break  # the disk refuses: the cases finished stay, the others are not run
                    claims.release(case.key)
                    summary.not_run -= 1
                    if output["status"] == "done":
                        summary.computed += 1
                    else:
                        summary.failed[case.key] = output["error"]
                    bar.update(1)
                    bar.set_postfix(running=min(workers, summary.not_run), failed=len(summary.failed))
            if not todo:
                break
            if deferred and len(deferred) == len(todo):
                time.sleep(0.2)  # every case left is another run's: wait for it
            todo, fresh = deferred, False
    finally:
        claims.release_all()
        bar.close()
        if dask is not None:
            from softhand.studies.batch.cluster import close_cluster

            close_cluster(*dask)
        with kept_if_unwritable(study_dir(study, results_root) / "index.csv", "study", say_written=False):
            write_index(study, results_root)
    return summary


def _committed(sdir: Path, study: Study, case: Case, output: dict) -> bool:
    """Store a case's outcome (:func:`commit_case`); False, after one warning, if the disk
    refuses it (full, a file-size limit, read-only): the run then stops, exit code 3."""
    from softhand.studies.io.files import UNWRITTEN

    before = len(UNWRITTEN)
    with kept_if_unwritable(sdir / case.key, "study", say_written=False):
        commit_case(sdir, study, case, output)
    return len(UNWRITTEN) == before


def _finger_options(kind: str, params: dict, design):
    """The finger FEM's options of a case of ``kind``, or None if the kind builds no finger."""
    if kind == "finger_bend":
        from softhand.studies.calibration.finger import case_options

        return case_options(params)
    if kind == "weights":
        from softhand.studies.weights import WeightsCase, finger_options

        return finger_options(WeightsCase(design=design, **{k: float(v) for k, v in params.items()}).mesh_size_mm)
    return None


def check_meshes(kind: str, cases, src: str) -> None:
    """Each case's finger mesh one the FEM takes (not folded), before any case runs: one line
    naming the case, as ``bend`` and ``design`` refuse such a mesh up front, not a failed case
    after the others ran. ``cases``: (key, params, design)."""
    from softhand.fem.hand.finger_options import check_finger_mesh
    from softhand.reduced.vocabulary.errors import InputError, MeshRejected

    for key, params, design in cases:
        options = _finger_options(kind, params, design)
        if options is None:
            return
        try:
            check_finger_mesh(design, options)
        except MeshRejected as exc:
            raise InputError(f"{src}: case {key}", exc.value, exc.allowed) from None


def _claimed(sdir: Path, todo: list[Case], claims: Claims, fresh: bool, deferred: list,
             summary: RunSummary, bar):
    """Yield the cases of ``todo`` this run claims and must compute, one at a time (claimed
    when taken); a case another run holds goes to ``deferred``, one it finished is reused."""
    for case in todo:
        if not claims.try_claim(case.key):
            deferred.append(case)
            continue
        if not fresh and case_state(sdir, case) == "done":  # another run has just finished it
            claims.release(case.key)
            summary.reused += 1
            summary.not_run -= 1
            bar.update(1)
            continue
        remove_leftovers(sdir, case.key)
        yield case


def _progress_bar(study: Study, summary: RunSummary, enabled: bool):
    from tqdm import tqdm

    return tqdm(total=summary.total, initial=summary.reused, desc=study.name, unit="case",
                file=sys.stderr, disable=not enabled, dynamic_ncols=True)


def _outcomes(study: Study, todo, workers: int, dask):
    """Yield (case, output) as cases finish, on the chosen executor (``dask``: an open
    (client, cluster)); ``todo`` is an iterator, read only as workers become free (each case
    is claimed when read)."""
    todo = iter(todo)
    if dask is not None:
        from softhand.studies.batch.cluster import dask_outcomes

        cases = list(todo)
        if cases:
            yield from dask_outcomes(study, cases, dask[0])
    elif workers == 1:
        for case in todo:
            yield case, execute_case(study.kind, case.params, case.design)
    else:
        from softhand.studies.batch.pool import pool_outcomes

        yield from pool_outcomes(study, todo, workers)
