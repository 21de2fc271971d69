"""Checks of the reduced finger model ``"fem"`` against the FEM (``softhand calibrate finger``
writes the table with :mod:`softhand.studies.calibration.finger_table`): FEM cases the table was not
built from (:func:`~softhand.studies.calibration.finger_check.heldout_rows`, the whole hand's pump
pressure included), and each design of a table predicted by the table without it.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from scipy.interpolate import PchipInterpolator

from softhand.reduced.equations import finger, hand
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.calibrated.finger_fem import COLUMNS, GROUPS
from softhand.studies.calibration.finger import cavity_pressures
from softhand.studies.calibration.space import VARIABLES, finger_design


def heldout_rows(results: list[tuple[HandDesign, dict]], table: str | None = None):
    """Per FEM point of each design: theta and dQ by FEM and by the calibrated model, errors
    [%], and the whole hand's pump pressure at the FEM's theta by the models "fem" (finger and
    reservoir) against finger FEM + reservoir-sheet FEM (:func:`softhand.studies.compare.whole_hand`,
    the design's reservoir), error [MPa] (nan where the fingers take more oil than V0); per
    design with an FEM bend >= 60 deg, the model's bend at the FEM's pressure of 60 deg and the
    whole hand's error there (the FEM's pressure and oil at 60 deg by monotone cubic
    interpolation of its points). Where the table has the rubber's converged stretch and the
    case recorded it, also that stretch by FEM and by the model, error [%] of the stretch.
    Returns (rows, worst ``|error|`` per column)."""
    from softhand.reduced.calibrated.finger_fem import rubber_stretch

    rows = []
    for design, record in results:
        model = design.replace(finger_model="fem", finger_table=str(table or ""))
        n = record["numbers"]
        P, th, dQ = (np.array(v, float) for v in (cavity_pressures(n), n["theta_deg"], n["dQ_mm3"]))
        keep = P > 0
        P, th, dQ = P[keep], th[keep], dQ[keep]
        lam_m = rubber_stretch(np.radians(th), model) if "rubber_stretch" in n else None
        lam = None if lam_m is None else np.array(n["rubber_stretch"], float)[keep]
        at60 = th.max() >= 60.0
        if at60:
            P60, dQ60 = (float(PchipInterpolator(np.r_[0.0, th], np.r_[0.0, v])(60.0)) for v in (P, dQ))
        # one sheet FEM per design: the FEM points and the 60 deg point together
        hand_err = _whole_hand_errors(design, {"P_cavity_MPa": [*P, P60] if at60 else P,
                                               "theta_deg": [*th, 60.0] if at60 else th,
                                               "dQ_mm3": [*dQ, dQ60] if at60 else dQ}, table)
        th_m = np.degrees(hand.bend_angle(P, model, reservoir=False))
        dQ_m = finger.oil_taken(np.radians(th), model)
        point = " ".join(f"{design.to_dict()[k]:g}" for k in VARIABLES)
        for k in range(P.size):
            rows.append({"design": point, "P_cavity_MPa": P[k], "theta_fem_deg": th[k], "theta_model_deg": th_m[k],
                         "theta_err_pct": 100 * (th_m[k] / th[k] - 1), "dQ_fem_mm3": dQ[k],
                         "dQ_model_mm3": dQ_m[k], "dQ_err_pct": 100 * (dQ_m[k] / dQ[k] - 1),
                         "P_hand_err_MPa": hand_err[k],
                         **({} if lam is None else {"rubber_stretch_fem": lam[k], "rubber_stretch_model": lam_m[k],
                                                    "rubber_stretch_err_pct": 100 * (lam_m[k] / lam[k] - 1)})})
        if at60:
            t60 = float(np.degrees(hand.bend_angle(P60, model, reservoir=False)))
            rows.append({"design": point, "P_cavity_MPa": P60, "theta_fem_deg": 60.0, "theta_model_deg": t60,
                         "theta_err_pct": 100 * (t60 / 60.0 - 1), "dQ_fem_mm3": math.nan,
                         "dQ_model_mm3": math.nan, "dQ_err_pct": math.nan, "P_hand_err_MPa": hand_err[-1],
                         **({} if lam is None else {"rubber_stretch_fem": math.nan, "rubber_stretch_model": math.nan,
                                                    "rubber_stretch_err_pct": math.nan})})
    columns = ("theta_err_pct", "dQ_err_pct", "P_hand_err_MPa", "rubber_stretch_err_pct")
    worst = {k: float(np.nanmax([abs(r.get(k, math.nan)) for r in rows]))
             for k in columns if any(k in r for r in rows)}
    return rows, worst


def _whole_hand_errors(design: HandDesign, numbers: dict, table) -> np.ndarray:
    """P_hand of the models "fem" minus finger FEM + sheet FEM [MPa], per FEM point with P > 0."""
    import warnings

    from softhand.reduced.vocabulary.errors import InputError
    from softhand.studies.compare import whole_hand

    fem = [{"P_cavity_MPa": P, "theta_deg": t, "dQ_mm3": q}
           for P, t, q in zip(cavity_pressures(numbers), numbers["theta_deg"], numbers["dQ_mm3"]) if P > 0]
    with warnings.catch_warnings():  # a dry reservoir is a nan here, reported in the table
        warnings.simplefilter("ignore")
        rows = whole_hand(fem, design).rows
    model = design.replace(finger_model="fem", reservoir_model="fem", finger_table=str(table or ""))
    out = np.full(len(rows), math.nan)
    for k, r in enumerate(rows):
        if r["V_mm3"] > 0:
            try:
                out[k] = float(hand.pressure(math.radians(r["theta_deg"]), model, reservoir=True)) - r["P_pump_fem_MPa"]
            except InputError:  # the model's fingers take more oil than V0 there
                pass
    return out


def leave_one_out(path: str | Path | None = None) -> list[dict]:
    """Each design of a table predicted by the table without it (its rows removed, the fit
    redone, the ranges kept): per FEM row, theta at the FEM's pressure and dQ at the FEM's
    theta, errors [%]. A check of the fit that runs no FEM (the designs are at a = 4 mm, which
    the groups do not see). Where the table has the rubber's stretch: its error [%] at a = 4 mm
    (``rubber_stretch_err_pct``) and, where the table has it at each a/rho, the largest at the
    sizes a = rho a/rho of those columns (``rubber_stretch_sizes_err_pct``, signed)."""
    import tempfile

    from softhand.reduced.calibrated.finger_fem import (A_RHO, SIZE_STRETCH, STRETCH, TABLE_FILE, read_table,
                                                        rubber_stretch)
    from softhand.reduced.materials.rubber_parameters import CRITICAL_DISTANCE_MM

    table = read_table(path or TABLE_FILE)
    r = table.rows
    header = [line for line in table.header if "# range:" in line or "# fit:" in line]
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        for i in np.unique(r["design"]):
            at = r["design"] == i
            columns = [c for c in (*COLUMNS, STRETCH, *SIZE_STRETCH) if c in r]
            rest = [{c: r[c][k] for c in columns} for k in np.flatnonzero(~at)]
            lines = [line.lstrip("#").strip() for line in header]
            text = "\n".join(f"# {line}" for line in lines) + "\n" + ",".join(columns) + "\n"
            text += "".join(",".join(f"{row[c]:.10g}" for c in columns) + "\n" for row in rest)
            held = Path(tmp) / f"without_{int(i)}.csv"
            held.write_text(text)
            g = {k: float(r[k][at][0]) for k in GROUPS}
            a, L = 4.0, 4.0 * g["link_a"]
            design = finger_design({"a_mm": a, "b_mm": a * g["b_a"], "d_mm": a * g["d_a"],
                                    "l0_mm": 6 * L, "tie_width_mm": g["tie_link"] * L})
            model = design.replace(finger_model="fem", finger_table=str(held))
            theta, P = r["theta"][at], r["p_tilde"][at] * design.mu_sf
            th_m = hand.bend_angle(P, model, reservoir=False)
            dQ_m = finger.oil_taken(theta, model)
            lam_m = rubber_stretch(theta, model)
            own = r[SIZE_STRETCH[A_RHO.index(a / CRITICAL_DISTANCE_MM)]] if SIZE_STRETCH[0] in r else r.get(STRETCH)
            sizes = None
            if SIZE_STRETCH[0] in r:  # the same groups at each a of the table's a/rho
                e = np.array([100 * (rubber_stretch(theta, _scaled(model, x * CRITICAL_DISTANCE_MM / a))
                                     / (1 + r[c][at]) - 1) for c, x in zip(SIZE_STRETCH, A_RHO)])
                sizes = e[np.argmax(np.abs(e), axis=0), np.arange(theta.size)]
            for k in range(theta.size):
                out.append({"design": int(i), **{key: round(v, 4) for key, v in g.items()},
                            "P_cavity_MPa": float(P[k]), "theta_fem_deg": math.degrees(theta[k]),
                            "theta_err_pct": 100 * (th_m[k] / theta[k] - 1),
                            "dQ_err_pct": 100 * (dQ_m[k] / (r["q_tilde"][at][k] * a**3) - 1),
                            **({} if lam_m is None else  # of the stretch itself, not of its strain
                               {"rubber_stretch_err_pct": 100 * (lam_m[k] / (1 + own[at][k]) - 1)}),
                            **({} if sizes is None else {"rubber_stretch_sizes_err_pct": float(sizes[k])})})
    return out


def _scaled(design: HandDesign, k: float) -> HandDesign:
    """The design with its tube's lengths scaled by k: the same groups, another size."""
    return design.replace(a=design.a * k, b=design.b * k, d=design.d * k, l0=design.l0 * k,
                          hinge_s=tuple(s * k for s in design.hinge_s), tie_width=design.tie_width * k)
