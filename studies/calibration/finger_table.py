"""The table of the reduced finger model ``"fem"`` from finished FEM cases, and the design file that uses it.

:func:`write_table` turns the ``finger_bend`` cases of a design space
(:mod:`softhand.studies.calibration.finger`) into the nondimensional CSV of
:mod:`softhand.reduced.calibrated.finger_fem` with its provenance (code version, mesh, date, command);
:func:`write_design_with_table` writes the design that uses the table. The checks of the
calibrated model against FEM cases (held out, leave-one-design-out) are in
:mod:`softhand.studies.calibration.finger_check`.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from scipy.interpolate import PchipInterpolator

from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.calibrated.finger_fem import COLUMNS, GROUPS, SIZE_STRETCH, STRETCH, groups_of
from softhand.studies.calibration.finger import MIN_GAP_SLICES, cavity_pressures
from softhand.studies.calibration.space import DesignSpace, VARIABLES
from softhand.studies.calibration.tables import written_by
from softhand.studies.io.files import write_atomic


def space_ranges(box: dict) -> dict:
    """group -> (min, max) over a box of a, b, d, l0, tie width (the groups are monotone in
    each variable, so the extremes are at the box's corners)."""
    corners = [dict(zip(VARIABLES, c)) for c in np.array(np.meshgrid(*[box[v] for v in VARIABLES]))
               .reshape(len(VARIABLES), -1).T]
    # the groups of each corner, which need not be a finger (a + b >= d at some corners)
    values = [{"b_a": c["b_mm"] / c["a_mm"], "d_a": c["d_mm"] / c["a_mm"],
               "link_a": c["l0_mm"] / 6.0 / c["a_mm"], "tie_link": c["tie_width_mm"] / (c["l0_mm"] / 6.0)}
              for c in corners]
    return {g: (min(v[g] for v in values), max(v[g] for v in values)) for g in GROUPS}


def designs_ranges(rows: list[dict]) -> dict:
    """group -> (min, max) over the table rows' designs."""
    return {g: (min(r[g] for r in rows), max(r[g] for r in rows)) for g in GROUPS}


def table_rows(results: list[tuple[HandDesign, dict]]) -> list[dict]:
    """Nondimensional table rows from (design, numbers of its finger_bend case), P > 0 only;
    with the converged rubber stretch (s_tilde = lambda - 1) where every case has it, and at
    each a/rho (s_a_rho_X) where every case has those."""
    rows = []
    stretch = all("rubber_stretch" in numbers for _, numbers in results)
    sizes = stretch and all("rubber_stretch_a_rho" in numbers for _, numbers in results)
    for i, (design, numbers) in enumerate(results):
        groups = groups_of(design)
        for k, (P, theta, dQ) in enumerate(zip(cavity_pressures(numbers), numbers["theta_deg"], numbers["dQ_mm3"])):
            if P > 0:
                rows.append({"design": i, **groups, "theta": math.radians(theta),
                             "p_tilde": P / design.mu_sf, "q_tilde": dQ / design.a**3,
                             **({STRETCH: numbers["rubber_stretch"][k] - 1.0} if stretch else {}),
                             **(dict(zip(SIZE_STRETCH, np.array(numbers["rubber_stretch_a_rho"][k], float) - 1.0))
                                if sizes else {})})
    return rows


#: designs a table needs for the kernel fit (else least squares in linear terms)
KERNEL_MIN_DESIGNS = 12
KERNEL = "cubic"


def choose_fit(rows: list[dict], ranges: dict, prior: str) -> tuple[str, list[str]]:
    """The '# fit:' line's items after the prior for ``rows``, and a provenance note. With
    KERNEL_MIN_DESIGNS designs or more: the cubic radial-basis interpolant over the five
    features of :data:`~softhand.reduced.calibrated.finger_fem_terms.KERNEL_FEATURES` (per design a line in theta; exact at the designs).
    It was chosen by leave-one-design-out error of theta on the 41-design table (rms / worst,
    ``benchmarks/finger_loo.py``): cubic 1.33 / 6.4 %, thin-plate spline 1.62 / 9.0 %, linear
    2.02 / 12.9 % (dQ: 0.87 / 4.5, 0.75 / 2.3, 0.80 / 2.7 %); on the earlier 31-design table,
    least squares in terms linear in the features had twice the spline's error in y and 3x
    in ln kappa, quadratic terms 6x. With fewer designs: least squares in the varying groups'
    linear terms and theta (theta only if the designs are too few)."""
    from softhand.reduced.calibrated.finger_fem_terms import KERNEL_FEATURES, legacy_terms

    n_designs = len({r["design"] for r in rows})
    if n_designs >= KERNEL_MIN_DESIGNS:
        return (f"kernel={KERNEL}, features={' '.join(KERNEL_FEATURES)}",
                [f"fitted by the {KERNEL} interpolant over {n_designs} designs in {', '.join(KERNEL_FEATURES)}"])
    varying = {g: ranges[g][1] > ranges[g][0] * (1 + 1e-9) for g in GROUPS}
    degree = 1 if any(varying.values()) and n_designs >= sum(varying.values()) + 1 else 0
    terms = [" ".join(legacy_terms(kind, varying, degree, 1)) for kind in "pq"]
    return (f"p_terms={terms[0]}, q_terms={terms[1]}",
            [f"fitted by least squares, {'linear in the groups and ' if degree else ''}linear in theta "
             f"({n_designs} designs)"])


def table_csv(rows: list[dict], ranges: dict, provenance: list[str], fit: str,
              prior: str = "paper") -> str:
    """The calibration CSV of :mod:`softhand.reduced.calibrated.finger_fem`: provenance, range and fit lines, rows."""
    lines = [f"# {line}" for line in provenance]
    lines.append("# groups: b_a = b/a, d_a = d/a, link_a = (l0/6)/a, tie_link = tie width/(l0/6); "
                 "theta [rad]; p_tilde = P/mu_sf; q_tilde = dQ/a^3 (one finger)"
                 + ("; s_tilde = rubber_stretch - 1 (the converged stretch, fem.rubber_stretch)"
                    if rows and STRETCH in rows[0] else "")
                 + ("; s_a_rho_X = the same, averaged over a ball of radius a/X (X = a/rho)"
                    if rows and SIZE_STRETCH[0] in rows[0] else ""))
    lines.append("# range: " + ", ".join(f"{g}={ranges[g][0]:.10g}:{ranges[g][1]:.10g}" for g in GROUPS))
    lines.append(f"# fit: prior={prior}, {fit}")
    columns = tuple(c for c in (*COLUMNS, STRETCH, *SIZE_STRETCH) if not rows or c in rows[0])
    lines.append(",".join(columns))
    for r in rows:
        lines.append(",".join(str(int(r[c])) if c == "design" else f"{r[c]:.10g}" for c in columns))
    return "\n".join(lines) + "\n"


def provenance_lines(command: str, results: list[tuple[HandDesign, dict]], records: list[dict]) -> list[str]:
    """Who wrote the table, when, with which code and mesh."""
    from softhand.studies.batch.runner import code_version

    code = code_version()
    mesh = {f"{(r.get('mesh') or {}).get('mesher')}"
            + (f" (slices {r['inputs']['axial_size_mm']} mm)" if "axial_size_mm" in r["inputs"] else "")
            for r in records}
    dofs = sorted((r.get("mesh") or {}).get("dofs", 0) for r in records)
    wall = sum((r.get("solver") or {}).get("wall_time_s", 0.0) for r in records)
    return [written_by("FEM calibration of reduced/calibrated/finger_fem.py",
                       f" (softhand {code['softhand']}, sources {code['source_sha256']})"),
            command,
            f"model: finger FEM (fem/hand/finger.py), FingerOptions, mesher {', '.join(sorted(mesh))}, "
            f"{dofs[0]}..{dofs[-1]} unknowns; {len(results)} designs, {wall / 60:.1f} min of solver wall time"]


def mesh_correction(coarse: dict, fine: dict) -> tuple[float, float]:
    """(ln P_fine/P_coarse, dQ_fine/dQ_coarse) at equal bend, averaged over the pair's points:
    the same design on the space's mesh (``coarse`` numbers) and on the default mesh."""
    th_c, P_c, dQ_c = (np.array(v, float) for v in (coarse["theta_deg"], cavity_pressures(coarse), coarse["dQ_mm3"]))
    th_f, P_f, dQ_f = (np.array(v, float) for v in (fine["theta_deg"], cavity_pressures(fine), fine["dQ_mm3"]))
    inside = th_c <= th_f.max()
    at = th_c[inside]
    P_fine = PchipInterpolator(np.r_[0.0, th_f], np.r_[0.0, P_f])(at)
    dQ_fine = PchipInterpolator(np.r_[0.0, th_f], np.r_[0.0, dQ_f])(at)
    return float(np.mean(np.log(P_fine / P_c[inside]))), float(np.mean(dQ_fine / dQ_c[inside]))


def write_table(path, space: DesignSpace, results: list[tuple[HandDesign, dict]], command: str) -> Path:
    """Write the calibration CSV of ``results`` [(design, case record)], in the order of
    ``as_study(space).cases()`` (the designs, then the mesh pair if any), over ``space``'s box."""
    n = len(space.points)
    pairs = [(design, record["numbers"]) for design, record in results[:n]]
    rows = table_rows(pairs)
    records = [record["provenance"] for _, record in results]
    notes = provenance_lines(command, pairs, records)
    if space.mesh_pair is not None:  # scale the coarse mesh's points to the default mesh
        dy, rq = mesh_correction(results[n][1]["numbers"], results[n + 1][1]["numbers"])
        coarse = {i for i, (_, record) in enumerate(results[:n])
                  if "axial_size_mm" in record["provenance"]["inputs"]}
        for row in rows:
            if row["design"] in coarse:
                row["p_tilde"] *= math.exp(dy)
                row["q_tilde"] *= rq
        notes.append(f"mesh correction to the default mesh (the mesh_pair design on both meshes, at "
                     f"equal bend): P x {math.exp(dy):.5f}, dQ x {rq:.5f}, applied to the {len(coarse)} "
                     f"designs on the longer slices; {n - len(coarse)} designs (untied gap shorter than "
                     f"{MIN_GAP_SLICES} slices) ran on the default mesh")
    # the range a table states is that of its own designs, never more of the box than they
    # cover (a few designs of a wide box would otherwise answer far from any of them)
    ranges = {g: (lo, hi) for g, (lo, hi) in designs_ranges(rows).items()}
    fit, fit_notes = choose_fit(rows, ranges, space.prior)
    text = table_csv(rows, ranges, notes + fit_notes, fit, prior=space.prior)
    return write_atomic(path, text)


#: the first line of the design file :func:`write_design_with_table` writes (a file without it
#: is the user's, never written over)
DESIGN_MARK = "# softhand calibrate finger: this design on the finger table "


def design_file_for(table) -> Path:
    """Where the design using the table FILE.csv goes: FILE_fem.toml next to it (never FILE.toml,
    which is often the design the table was made from)."""
    table = Path(table)
    return table.with_name(f"{table.stem}_fem.toml")


def check_design_file(table, inputs, field: str = "--out") -> None:
    """Before any FEM: the design file of ``table`` can be written: not a folder, not one of the
    ``inputs`` (by any path), not a file of the user's (one this verb wrote begins with
    :data:`DESIGN_MARK`); InputError naming ``field`` otherwise."""
    from softhand.reduced.vocabulary.errors import InputError

    path = design_file_for(table)
    if path.is_dir() or path.is_symlink() and not path.exists():
        raise InputError(field, str(path), "is where the design using the table goes, and is a folder "
                                           "or a broken link; move it away or give another --out")
    for given in inputs:
        if given is not None and path.exists() and Path(given).exists() and path.samefile(given):
            raise InputError(field, str(path), "is where the design using the table goes, and is an "
                                               "input of this run; give another --out")
    if path.is_file():
        try:
            with open(path, "rb") as f:
                first = f.read(len(DESIGN_MARK.encode()))
        except OSError:
            first = b""
        if first != DESIGN_MARK.encode():
            raise InputError(field, str(path), "is where the design using the table goes, and holds a "
                                               "file softhand did not write; move it away or give "
                                               "another --out")


def write_design_with_table(design: HandDesign, table: Path) -> Path:
    """FILE_fem.toml next to FILE.csv (:func:`design_file_for`): the design with finger_model =
    "fem" and this table."""
    table = Path(table)
    path = design_file_for(table)
    text = DESIGN_MARK + table.name + "\n" + design.replace(finger_model="fem", finger_table=table.name).to_toml()
    return write_atomic(path, text)
