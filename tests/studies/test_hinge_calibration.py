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
