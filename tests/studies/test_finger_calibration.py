"""softhand calibrate finger on a CI-sized space: a table from two FEM designs, checked on a third."""
import json
from pathlib import Path

import pytest

from softhand.reduced.equations import hand
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.cli.main import main
from softhand.studies.calibration.space import finger_design, load_space

SPACE = """
name = "{name}"
mesh_size_mm = 6.0              # the CI mesh (gmsh, uniform)
pressures_mpa = [0.4, 0.8]
theta_target_deg = 1.0          # no steps beyond 0.8 MPa
[space]
a_mm = [4.0, 4.0]
b_mm = [5.0, 5.0]
d_mm = [15.0, 15.0]
l0_mm = [180.0, 180.0]
tie_width_mm = [6.0, 14.0]
"""
DESIGN = "[[design]]\na_mm = 4.0\nb_mm = 5.0\nd_mm = 15.0\nl0_mm = 180.0\ntie_width_mm = {tie}\n"


def _space(path, name, ties):
    path.write_text(SPACE.format(name=name) + "".join(DESIGN.format(tie=t) for t in ties))
    return path


@pytest.mark.slow
def test_table_from_two_ties_predicts_the_middle_one(tmp_path, capsys):
    """Ties of 6 and 14 mm predict the 10 mm tie's FEM bend to 5 % (measured +4.1 %; dQ 1.0 %),
    while the calibration designs bend > 10 % apart at 0.8 MPa: the fit predicts, it does not
    just repeat a neighbour. With the tie the only group varied, y is linear in the shape
    factor's square (b / gap)^2, which the 14-design table's leave-one-out chose; on this
    CI mesh y is closer to linear in -ln(1 - tie/link) (the earlier fit: +0.2 %)."""
    results, table = str(tmp_path / "results"), tmp_path / "ties.csv"
    space = _space(tmp_path / "ties.toml", "ties", (6.0, 14.0))
    assert main(["calibrate", "finger", "--space", str(space), "--out", str(table),
                 "--results", results, "--no-progress"]) == 0
    text = table.read_text()
    assert "p_terms=s2 th, q_terms=lt th" in text and "mesher gmsh" in text
    # each case's record says what its FEM cost: Newton iterations and tangent factorisations
    solvers = [json.loads(p.read_text())["provenance"]["solver"] for p in Path(results).rglob("result.json")]
    assert len(solvers) == 2
    assert all(isinstance(s["factorizations"], int) and 0 < s["factorizations"] for s in solvers)
    # ... and in which precision each sweep's factors were (a fall-back to double says why)
    assert all(s["linear_solvers"] and all("factorisations" in d for d in s["linear_solvers"])
               for s in solvers)
    held = _space(tmp_path / "held.toml", "held", (10.0,))
    capsys.readouterr()
    assert main(["calibrate", "finger", "--check", str(held), "--table", str(table),
                 "--results", results, "--no-progress", "--json"]) == 0
    check = json.loads(capsys.readouterr().out)
    errors = [r["theta_err_pct"] for r in check["rows"]]
    assert len(errors) == 2 and max(map(abs, errors)) < 5.0
    assert abs(check["worst"]["dQ_err_pct"]) < 2.0  # measured 1.0 %: dQ varies more with the tie
    # the calibration designs themselves at 0.8 MPa: far apart, so 1 % is a real prediction
    d6, d14 = (load_space(space).designs()[i].replace(finger_model="fem", finger_table=str(table))
               for i in (0, 1))
    spread = hand.bend_angle(0.8, d6, reservoir=False) / hand.bend_angle(0.8, d14, reservoir=False)
    assert spread > 1.1


def _gap_space(tmp_path, extra=""):
    """A space on 5 mm slices with two designs of l0 = 120 mm: rings of 5 mm (a 15 mm gap) and of
    15 mm (a 5 mm gap); ``extra``: more TOML (e.g. a mesh pair)."""
    path = tmp_path / "gaps.toml"
    path.write_text(SPACE.format(name="gaps").replace("mesh_size_mm = 6.0", "axial_size_mm = 5.0")
                    .replace("l0_mm = [180.0, 180.0]", "l0_mm = [120.0, 120.0]")
                    .replace("[6.0, 14.0]", "[5.0, 15.0]")
                    + DESIGN.format(tie=5.0).replace("180.0", "120.0")
                    + DESIGN.format(tie=15.0).replace("180.0", "120.0")
                    + extra)
    return path


def test_longer_slices_only_where_they_resolve_the_gap(tmp_path):
    """A space's longer slices put at least 3 slices across every untied gap: a 15 mm gap (l0 =
    120, 5 mm rings) keeps them; a 5 mm gap (15 mm rings) runs on the default mesh instead (one
    5 mm slice there bends 26 % less than the default mesh: a locked element, not a correction)."""
    from softhand.studies.calibration.finger import design_cases, resolves_gap

    (p5, d5), (p15, d15) = design_cases(load_space(_gap_space(tmp_path)))
    assert (d5.tie_width, d15.tie_width) == (5.0, 15.0)
    assert p5["axial_size_mm"] == 5.0 and "axial_size_mm" not in p15
    assert resolves_gap(d15, 2.49) and not resolves_gap(d15, 2.5)  # 3 slices of 5 mm need < 2.5


def test_mesh_correction_scales_only_the_designs_on_longer_slices(tmp_path):
    """write_table multiplies P and dQ of the coarse-mesh designs by the mesh pair's ratios and
    leaves the default-mesh designs as the FEM gave them."""
    import math

    from softhand.reduced.calibrated.finger_fem import read_table
    from softhand.studies.calibration.finger import as_study, design_cases
    from softhand.studies.calibration.finger_table import write_table

    space = load_space(_gap_space(tmp_path, "[mesh_pair]\na_mm = 4.0\nb_mm = 5.0\nd_mm = 15.0\n"
                                              "l0_mm = 180.0\ntie_width_mm = 10.0\npressures_mpa = [0.4, 0.8]\n"))
    numbers = {"P_cavity_MPa": [0.4, 0.8], "theta_deg": [10.0, 20.0], "dQ_mm3": [100.0, 200.0]}
    fine = {"P_cavity_MPa": [0.4, 0.8], "theta_deg": [11.0, 22.0], "dQ_mm3": [110.0, 220.0]}
    cases = as_study(space).cases()
    records = [{"numbers": n, "provenance": {"inputs": params, "mesh": {"mesher": "layered", "dofs": 1},
                                             "solver": {"wall_time_s": 1.0}}}
               for n, (params, _) in zip((numbers, numbers, numbers, fine), cases)]
    assert len(design_cases(space)) == 2 and len(records) == 4
    table = read_table(write_table(tmp_path / "t.csv", space, list(zip([c[1] for c in cases], records)), "test"))
    P = table.rows["p_tilde"] * cases[0][1].mu_sf
    # the pair: the fine mesh bends 10 % more at equal P, so at equal bend it needs less P
    assert P[0] < 0.4 * (1 - 1e-3) and P[1] < 0.8 * (1 - 1e-3)  # design 0: corrected
    # closed form: the pair is linear in theta, so at equal bend P_fine / P_coarse = 10 / 11 exactly
    assert P[:2] == pytest.approx([0.4 * 10 / 11, 0.8 * 10 / 11], rel=1e-9)
    assert P[2:] == pytest.approx([0.4, 0.8], rel=1e-9)  # design 1 (5 mm gap): as computed (CSV: 10 digits)
    assert math.isclose(table.rows["q_tilde"][2] * 4.0**3, 100.0, rel_tol=1e-9)


def test_latin_hypercube_designs_keep_the_design_rules(tmp_path):
    """The packaged box holds designs with a + b >= d (a 6 + b 7 > d 10): its Latin hypercubes
    keep only designs, drawing further hypercubes from the same seed until lhs are found;
    a box that holds none is refused naming lhs."""
    from softhand.studies.calibration.space import MAX_DRAWS, latin_hypercube

    box = {"a_mm": (3.0, 6.0), "b_mm": (3.0, 7.0), "d_mm": (10.0, 20.0), "l0_mm": (120.0, 200.0),
           "tie_width_mm": (5.0, 15.0)}
    unchecked = latin_hypercube(box, 20, 3)
    assert any(p["a_mm"] + p["b_mm"] >= p["d_mm"] for p in unchecked)  # the case this is about
    text = (Path(__file__).resolve().parents[2] / "studies" / "finger_space.toml").read_text()
    space = tmp_path / "s.toml"
    space.write_text(text.replace("lhs = 6", "lhs = 20").replace("seed = 1", "seed = 3"))
    points = load_space(space).points
    sampled = points[-20:]
    assert len(sampled) == 20 and all(p["a_mm"] + p["b_mm"] < p["d_mm"] for p in sampled)
    kept = [p for p in unchecked if p["a_mm"] + p["b_mm"] < p["d_mm"]]
    assert list(sampled[:len(kept)]) == kept  # the first hypercube's designs first, in order
    assert all(lo <= p[k] <= hi for p in sampled for k, (lo, hi) in box.items())
    space.write_text("lhs = 20\n[space]\n" + "".join(f"{k} = [{lo}, {hi}]\n" for k, (lo, hi) in
                                                      {**box, "d_mm": (6.0, 6.5)}.items()))
    with pytest.raises(InputError, match=f"lhs = 20: too many: {MAX_DRAWS} Latin hypercubes"):
        load_space(space)


def _table_rows(path):
    """The numeric rows of a calibration table (its comment lines hold the command, which differs)."""
    import csv

    lines = [line for line in path.read_text().splitlines() if line and not line.startswith("#")]
    return list(csv.DictReader(lines))


@pytest.mark.slow
def test_table_on_a_local_dask_cluster_is_the_process_pools(tmp_path):
    """The table of a CI-sized space (two designs, CI mesh) from a Dask LocalCluster with two
    workers (``--scheduler local``, what ``--scheduler tcp://...`` does on a remote cluster)
    equals the one from the process pool: the same cases in other processes. Tolerance 1e-7
    relative: the FEM's Newton tolerance (1e-9 on the residual) and PARDISO's threads (a worker's
    share of the cores differs between the runs) move theta by ~1e-9 of itself."""
    pytest.importorskip("dask.distributed")
    tables = []
    for name, how in (("pool", ["--workers", "1"]), ("dask", ["--workers", "2", "--scheduler", "local"])):
        space = _space(tmp_path / f"{name}.toml", "ties", (6.0, 14.0))
        table = tmp_path / f"{name}.csv"
        assert main(["calibrate", "finger", "--space", str(space), "--out", str(table),
                     "--results", str(tmp_path / name), "--no-progress", *how]) == 0
        tables.append(_table_rows(table))
    pool, dask = tables
    assert len(pool) == len(dask) == 2 * 2  # two designs, two pressures each
    for a, b in zip(pool, dask):
        assert a.keys() == b.keys()
        for key in a:
            try:
                x, y = float(a[key]), float(b[key])
            except ValueError:
                assert a[key] == b[key]
                continue
            assert y == pytest.approx(x, rel=1e-7, abs=1e-12), key


def test_a_table_is_built_on_a_neo_hookean_tube_of_the_rubbers_initial_modulus(tmp_path, capsys):
    """The table holds the tube's geometry: calibrating a design with its own rubber runs the
    FEM on a Neo-Hookean tube of that rubber's mu0 (finger_model "fem" adds the rubber back),
    and says so; the design file written beside the table keeps the rubber."""
    from softhand.studies.calibration.space import single_design_space
    from softhand.studies.cli.verbs.calibrate import neo_hookean

    design = tmp_path / "own.toml"
    design.write_text('[finger.material]\nmodel = "yeoh"\nC10_MPa = 0.44\nC20_MPa = -0.017\nC30_MPa = 0.0037\n')
    space = single_design_space(design)
    built = neo_hookean(space)
    assert built.base.finger_is_neo_hookean and built.base.mu_sf == pytest.approx(0.88)
    assert built.points == space.points and not space.base.finger_is_neo_hookean
    assert "Neo-Hookean tube of the rubber's initial shear modulus mu_sf_MPa = 0.88" in capsys.readouterr().err
    assert neo_hookean(built) is built
