"""The coefficients of :mod:`softhand.reduced.calibrated.hinge_blocked` from the finger FEM held by
grasp-like hinge loads over a design space.

For the paper's design and every design of the design space (the paper's blocked states of
``tests/data/blocked_hinges_paper.json``, other loads, stay held out), at each cavity pressure of ``PRESSURES``,
the finger FEM on its default mesh is solved free (hinge angles q_f, condensed stiffness S) and then
under hinge loads Q of six shapes (``PATTERNS``: a pad touching link 2, 3 or 5 loads the hinges
before it by levers shrinking towards it; one hinge alone, the base's or the middle one; the four
first hinges alike), each scaled by S so that its most-held hinge reaches 0.6, 0.3 and 0.1 of its
free bend; the hinge angles q it settles at are kept. The moments the coupled hinges miss there,
Q - M(q) less their miss at the free state, over P a^2 pi d, are fitted at each pressure by least
squares on the gradients of the three terms of the correction's energy, every hinge of every state
(held or free), design by design (r against the FEM's own free angles; the fast hold takes its
coupled free angles, which are the FEM's shares of the calibrated finger's bend). Run::

    python -m softhand.studies.calibration.hinge_blocked --space studies/hinge_space.toml --workers 2 \\
        --out reduced/calibrated/data/grasp_hinge_blocked.csv

each design one case of the batch runner (``--results``/<space>_blocked/, resumable; ``--scheduler``
for Dask; about 10 min of one core each). Prints the leave-one-out over designs: each design's held
hinges predicted by the mean of the others' coefficients.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from softhand.studies.calibration import tables
from softhand.studies.calibration.hinges import run_space, space_parser

#: cavity pressures [MPa]
PRESSURES = (0.6, 0.9, 1.2, 1.5, 1.8)
#: hinge-load shapes (base hinge first)
PATTERNS = {"pad2": (2.5, 1.5, 0.5, 0, 0), "pad3": (3.5, 2.5, 1.5, 0.5, 0), "pad5": (5.5, 4.5, 3.5, 2.5, 1.5),
            "one1": (1, 0, 0, 0, 0), "one3": (0, 0, 1, 0, 0), "flat4": (1, 1, 1, 1, 0)}
#: the most-held hinge's angle over its free angle
TARGETS = (0.6, 0.3, 0.1)


def blocked_states(design, pressures=PRESSURES) -> list[dict]:
    """The design's free finger and its blocked states (module doc): dicts P, Q, q (and S of the free
    states; pattern and target of the blocked ones). A pressure the free finger does not reach ends
    the list; a load it does not reach ends that pattern."""
    from softhand.fem.hand.finger import FingerModel, FingerOptions
    from softhand.fem.hand.hold_finger import HeldFinger
    from softhand.fem.newton import NotConverged

    finger, states = HeldFinger(FingerModel(design, FingerOptions())), []
    for P in pressures:
        try:
            finger.solve(P, np.zeros(design.n_s), steps=4)
        except NotConverged:
            break
        free = finger.copy_state()
        q_f, S = finger.q, finger.S.copy()
        states.append({"P": P, "Q": [0.0] * design.n_s, "q": q_f.tolist(), "S": S.tolist()})
        for name, shape in PATTERNS.items():
            u = np.asarray(shape, float)
            dq = np.linalg.solve(S, u)  # the hinges' opening per unit of load, linearly
            j = int(np.argmax(dq / q_f))
            finger.restore(free)
            for r in TARGETS:
                Q = -(1 - r) * q_f[j] / dq[j] * u
                try:
                    finger.solve(P, Q, steps=2)
                except NotConverged:
                    break
                states.append({"P": P, "pattern": name, "target": r, "Q": Q.tolist(), "q": finger.q.tolist()})
        finger.restore(free)
    return states


def blocked_case(params: dict, design, outdir: Path) -> dict:
    """Kind ``hinge_blocked`` of the batch runner: one design's states (:func:`blocked_states`) as rows
    P, pattern (its index in ``PATTERNS``; -1 the free finger), target, Q_1..Q_n, q_1..q_n."""
    names = list(PATTERNS)
    rows = [[s["P"], names.index(s["pattern"]) if "pattern" in s else -1, s.get("target", 1.0), *s["Q"], *s["q"]]
            for s in blocked_states(design)]
    return {"rows": [[float(v) for v in row] for row in rows]}


def states_of(rows) -> list[dict]:
    """The states of :func:`blocked_case`'s rows (the form :func:`blocked_states` returns, without S)."""
    names, out = list(PATTERNS), []
    for row in rows:
        n = (len(row) - 3) // 2
        s = {"P": row[0], "Q": list(row[3:3 + n]), "q": list(row[3 + n:])}
        if row[1] >= 0:
            s.update(pattern=names[int(row[1])], target=row[2])
        out.append(s)
    return out


def misses(design, states) -> list[tuple]:
    """Per blocked state: (P, the terms' gradients scaled as the moments (n, len(TERMS)), the coupled hinges'
    miss (Q - M(q) less the free state's) / (P a^2 pi d) (n,), Q / (P a^2 pi d) (n,))."""
    from softhand.reduced.calibrated.finger_hinges import coupled_moments
    from softhand.reduced.calibrated.hinge_blocked import basis, unit_of

    unit, free, rows = unit_of(design), {}, []
    for s in states:
        P, q, Q = s["P"], np.asarray(s["q"]), np.asarray(s["Q"])
        if "pattern" not in s:
            free[P] = (q, coupled_moments(q, P, design, blocked=False))
            continue
        q_f, M_f = free[P]
        grad = basis(q / q_f)[1] * (q_f.mean() / q_f)[:, None]
        rows.append((P, grad, (Q - coupled_moments(q, P, design, blocked=False) + M_f) / (P * unit), Q / (P * unit)))
    return rows


def fit(rows, pressures=PRESSURES) -> np.ndarray:
    """(K, len(TERMS)) one design's coefficients at ``pressures``: least squares over every hinge of its
    states at each (a pressure it did not reach keeps the last one's)."""
    out = []
    for P in pressures:
        at = [r for r in rows if r[0] == P]
        if not at:
            out.append(out[-1])
            continue
        X = np.concatenate([r[1] for r in at])
        y = np.concatenate([r[2] for r in at])
        out.append(np.linalg.lstsq(X, y, rcond=None)[0])
    return np.array(out)


def held_errors(rows, coefficients: np.ndarray, pressures=PRESSURES) -> tuple[np.ndarray, np.ndarray]:
    """The held hinges' (M - Q) / abs(Q) without and with the correction of ``coefficients`` (K, len(TERMS))."""
    before, after = [], []
    for P, grad, y, Q in rows:
        c = np.array([np.interp(P, pressures, coefficients[:, k]) for k in range(coefficients.shape[1])])
        held = Q != 0
        before.append(y[held] / Q[held])
        after.append((y - grad @ c)[held] / Q[held])
    return np.concatenate(before), np.concatenate(after)


def leave_one_out(coefficients: np.ndarray, per_design: list) -> np.ndarray:
    """(D, 4): each design's rms and worst relative miss of its held hinges, uncorrected and with the
    mean of the other designs' coefficients (``coefficients`` (D, K, len(TERMS)))."""
    out = []
    for k, rows in enumerate(per_design):
        others = np.delete(coefficients, k, axis=0).mean(axis=0)
        before, after = held_errors(rows, others)
        out.append([f(v) for v in (before, after)
                    for f in (lambda v: np.sqrt(np.mean(v ** 2)), lambda v: np.max(np.abs(v)))])
    return np.array(out)


def main(argv=None) -> int:
    args = space_parser(__doc__.splitlines()[0]).parse_args(argv)
    command = "python -m softhand.studies.calibration.hinge_blocked " + " ".join(sys.argv[1:] if argv is None else argv)
    from softhand.reduced.calibrated import hinge_blocked
    from softhand.reduced.calibrated.finger_fem import GROUPS, groups_of
    from softhand.reduced.calibrated.finger_hinges import fem_finger

    designs, numbers = run_space(args.space, "hinge_blocked", "blocked", "the finger held by grasp-like hinge loads",
                                 args.results, max(1, args.workers), args.scheduler, not args.no_progress)
    designs = [fem_finger(d) for d in designs]
    per_design = [misses(d, states_of(case["rows"])) for d, case in zip(designs, numbers)]
    rows = []
    for i, (d, design_rows) in enumerate(zip(designs, per_design)):
        g = groups_of(d)
        rows += [(i, *(g[k] for k in GROUPS), P, *c) for P, c in zip(PRESSURES, fit(design_rows))]
    loo = leave_one_out(hinge_blocked.table(np.array(rows, float)).c, per_design)
    line = ("leave-one-out over %d designs, the held hinges' moment: uncorrected rms %.2f %%, worst %.1f %%; "
            "corrected rms %.2f %%, worst %.1f %%" % (len(designs), 100 * np.sqrt(np.mean(loo[:, 0] ** 2)),
                                                     100 * loo[:, 1].max(), 100 * np.sqrt(np.mean(loo[:, 2] ** 2)),
                                                     100 * loo[:, 3].max()))
    head = [tables.written_by("FEM blocked hinges of reduced/calibrated/hinge_blocked.py"), command,
            f"model: finger FEM (fem/hand/finger.py) on the default mesh, {len(designs)} designs (the paper's and "
            f"those of {Path(args.space).name}), held by grasp-like hinge loads at P = "
            f"{', '.join(f'{p:g}' for p in PRESSURES)} MPa",
            "groups as the finger table's; P [MPa]; the correction's coefficients (dimensionless), fitted per design "
            "and pressure (a pressure a design did not reach keeps the last one's)", line]
    tables.write_table(args.out, head, ["design", *GROUPS, "P", *hinge_blocked.TERMS], rows)
    print(line, file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
