"""The blocked-hinge table's study (python -m softhand.studies.calibration.hinges) at a reverse bend:
its moments, taken up by stiff springs that lock the hinges, hold the finger FEM where they were
measured when applied instead as dead generalised forces (load control, an independent solution
of the same equilibrium: the springs' sign, the half model's factor 2 and the rates' sum over the
pressure steps all enter), and the CSV it writes is the table the fast hold reads."""
import math

import numpy as np
import pytest

from softhand.fem.hand.finger import FingerModel
from softhand.fem.hand.hold_finger import HeldFinger
from softhand.reduced.calibrated import hinge_table
from softhand.reduced.vocabulary.design import HandDesign
from softhand.studies.calibration import hinges
from softhand.studies.weights import finger_options

BEND = -3.0  #: a reverse bend [deg]


@pytest.fixture(scope="module")
def measured():
    model = FingerModel(HandDesign(), finger_options(6.0))
    return model, hinges.reverse_rates(model, bends_deg=(BEND,), top=0.3)


def test_the_reverse_moments_hold_the_finger_where_they_were_measured(measured):
    model, rows = measured
    assert [round(P, 9) for _, P, _ in rows] == [0.0, 0.05, 0.15, 0.25]
    q = np.full(model.design.n_s, math.radians(BEND) / model.design.n_s)
    M0 = rows[0][2]
    M = M0 - hinges.DP * sum(A for _, _, A in rows[1:])           # the moment at 0.3 MPa
    assert np.all(M0 < 0) and np.all(M < M0)   # held open against the rubber, then the pressure too
    finger = HeldFinger(model)
    for P, Q in ((0.0, M0), (0.3, M)):
        finger.solve(P, Q, steps=3)
        locked = q - Q / (2.0 * hinges.SPRING)                   # where the springs let the hinges sit
        np.testing.assert_allclose(finger.q, locked, rtol=2e-4)


def test_the_study_writes_the_table_the_fast_hold_reads(measured, tmp_path, monkeypatch):
    model, rows = measured
    monkeypatch.setattr(hinges, "reverse_rates", lambda model, **kw: rows)
    free = [(0.0, 0.05, np.full(5, 1380.0)), (0.0, 0.15, np.full(5, 1381.0)),
            (0.1, 0.25, np.full(5, 900.0))]
    monkeypatch.setattr(hinges, "volume_rates", lambda model, *a, **kw: free)
    path = tmp_path / "h.csv"
    path.write_text(hinges.table_text(HandDesign(), 6.0, "test"))
    hinge_table.read.cache_clear()
    t = hinge_table.read(str(path))
    unit = 4.0 ** 2 * math.pi * 15.0
    np.testing.assert_allclose(t.theta, [math.radians(BEND), 0.0, 0.1])
    np.testing.assert_allclose(t.m0[0], rows[0][2] / unit, rtol=1e-9)
    np.testing.assert_allclose(t.a[0, 0], rows[1][2] / unit, rtol=1e-9)
    assert "reverse bends" in path.read_text().splitlines()[2]


def _fake_grid(design):
    """A design's grid rows without the FEM: rates and moments that scale with its wall b."""
    s = design.b / 5.0
    rows = []
    for t in hinges.GRID_REVERSE:
        rows += [(0.0, math.radians(t), 0.0, *np.full(5, -0.1 * s))]
        rows += [(0.0, math.radians(t), P, *np.full(5, 1.5 * s)) for P in (0.1, 0.3)]
    for P0, t in zip(hinges.GRID_PRESSURES, (0.0, 0.1, 0.2)):
        rows += [(P0, t, P, *np.full(5, 1.2 * s)) for P in (0.1, 0.3) if P > P0]
    return rows


def test_the_space_grid_is_written_once_per_design_and_resumed(tmp_path, monkeypatch):
    """--space: every design's grid kept as a batch case as it finishes; the table assembled
    from them is the grid the fast hold reads; a second run computes nothing."""
    from softhand.reduced.calibrated import hinge_space

    space = tmp_path / "space.toml"
    space.write_text('name = "s"\n[space]\na_mm = [3.0, 6.0]\nb_mm = [3.0, 7.0]\nd_mm = [10.0, 20.0]\n'
                     'l0_mm = [120.0, 200.0]\ntie_width_mm = [5.0, 15.0]\n' + "".join(
                         f"[[design]]\na_mm = {a}\nb_mm = {b}\nd_mm = {d}\nl0_mm = {l}\ntie_width_mm = {t}\n"
                         for a, b, d, l, t in [(3.5, 4.0, 12.0, 150.0, 8.0), (5.0, 6.0, 18.0, 170.0, 12.0),
                                               (4.5, 3.5, 14.0, 190.0, 6.0), (3.2, 5.5, 16.0, 130.0, 11.0),
                                               (5.5, 4.5, 13.0, 160.0, 9.0), (4.2, 6.5, 19.0, 140.0, 7.0)]))
    monkeypatch.setattr(hinges, "grid_rows", _fake_grid)
    out = tmp_path / "grid.csv"
    assert hinges.main(["--space", str(space), "--results", str(tmp_path / "w"), "--no-progress", "--out", str(out)]) == 0
    assert len(list((tmp_path / "w").rglob("result.json"))) == 7
    hinge_space.read.cache_clear()
    grid = hinge_space.read(str(out))
    np.testing.assert_allclose(np.exp(grid.log_r[1:, 0, 0, 0]), [4.0 / 5, 6.0 / 5, 3.5 / 5, 5.5 / 5, 4.5 / 5, 6.5 / 5])
    monkeypatch.setattr(hinges, "grid_rows", lambda design: pytest.fail("a finished design was run again"))
    text = out.read_text()
    assert hinges.main(["--space", str(space), "--results", str(tmp_path / "w"), "--no-progress", "--out", str(out)]) == 0
    assert out.read_text().splitlines()[3:] == text.splitlines()[3:]
