"""The calibrated finger table's rubber stretch: its column, its fit over the design space, its
dependence on the tube's size (the averaging radius is the rubber's: a/rho columns), the
held-out check and the design optimiser's use of it (no FEM: a table whose stretch column is a
known function of the groups)."""
import math

import numpy as np
import pytest

from softhand.reduced.calibrated import finger_fem
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.calibrated.finger_fem import A_RHO, SIZE_STRETCH, STRETCH, TABLE_FILE, read_table, stretch_prior
from softhand.reduced.materials.rubber_parameters import CRITICAL_DISTANCE_MM
from softhand.studies.calibration.finger_table import table_rows
from softhand.studies.calibration.finger_check import leave_one_out


def known_z(b_a, theta):
    """A residual the kernel fit reproduces exactly: linear in its feature ln(b/a) and, per
    design, a line in ln theta (the fit's own form: a power law of the bend)."""
    return 1.2 + 0.3 * np.log(b_a) - 0.1 * np.log(theta)


#: the known residual's dependence on the size: z grows by SIZE_SLOPE ln(a/rho) (a power law of a)
SIZE_SLOPE = 0.35


def stretch_table(tmp_path, sizes=False):
    """The shipped table's P and dQ with s_tilde = eq. (8)'s strain x e^known_z appended; with
    ``sizes``, also the a/rho columns, z = known_z + SIZE_SLOPE ln(a/rho) (s_tilde at a/rho = 2)."""
    table = read_table(TABLE_FILE)
    r = table.rows
    z = known_z(r["b_a"], r["theta"])
    s = [stretch_prior(r["theta"], r) * np.exp(z + SIZE_SLOPE * math.log(x) * sizes) for x in (2.0, *A_RHO)]
    columns = (*finger_fem.COLUMNS, STRETCH, *(SIZE_STRETCH if sizes else ()))
    text = "\n".join(table.header) + "\n" + ",".join(columns) + "\n"
    text += "".join(",".join(f"{r[c][k]:.12g}" for c in finger_fem.COLUMNS) + "".join(
        f",{v[k]:.12g}" for v in s[:len(columns) - len(finger_fem.COLUMNS)]) + "\n" for k in range(r["theta"].size))
    path = tmp_path / f"with_stretch{'_sizes' if sizes else ''}.csv"
    path.write_text(text)
    return path


def test_a_table_without_the_column_predicts_no_stretch(tmp_path):
    """A table written before the column (the shipped one's P and dQ alone) predicts no stretch;
    the shipped table has it."""
    table = read_table(TABLE_FILE)
    r = table.rows
    text = "\n".join(table.header) + "\n" + ",".join(finger_fem.COLUMNS) + "\n"
    text += "".join(",".join(f"{r[c][k]:.12g}" for c in finger_fem.COLUMNS) + "\n" for k in range(r["theta"].size))
    path = tmp_path / "without_stretch.csv"
    path.write_text(text)
    assert finger_fem.rubber_stretch(0.5, HandDesign(finger_model="fem", finger_table=str(path))) is None
    assert finger_fem.rubber_stretch(0.5, HandDesign(finger_model="fem")) > 1.0


def test_the_fit_reproduces_a_stretch_it_can_represent(tmp_path):
    """At a design between the table's, the calibrated stretch is 1 + eq. (8)'s strain x e^z with
    z the known function (rtol 1e-6: the RBF solve's round-off on 41 designs)."""
    design = HandDesign(finger_model="fem", finger_table=str(stretch_table(tmp_path)), b=4.3, d=14.0)
    theta = np.array([0.3, 0.8])
    groups = finger_fem.groups_of(design)
    expected = 1.0 + stretch_prior(theta, groups) * np.exp(known_z(groups["b_a"], theta))
    np.testing.assert_allclose(finger_fem.rubber_stretch(theta, design), expected, rtol=1e-6)


@pytest.mark.parametrize("a", [2.0, 2.5, 3.0, 4.0, 6.0, 10.0])
def test_the_stretch_follows_the_tube_size_between_and_beyond_the_columns(tmp_path, a):
    """The same groups at another tube size a: z at ln(a/rho) piecewise linear between the table's
    a/rho columns (exact for a power law of a) and continued beyond them (a = 10 mm, a/rho 5)."""
    path = stretch_table(tmp_path, sizes=True)
    base = HandDesign(finger_model="fem", finger_table=str(path), b=4.3, d=14.0)
    k = a / base.a
    design = base.replace(a=a, b=base.b * k, d=base.d * k, l0=base.l0 * k, tie_width=base.tie_width * k,
                          hinge_s=tuple(x * k for x in base.hinge_s))
    theta = np.array([0.3, 0.8])
    groups = finger_fem.groups_of(design)
    z = known_z(groups["b_a"], theta) + SIZE_SLOPE * math.log(a / CRITICAL_DISTANCE_MM)
    np.testing.assert_allclose(finger_fem.rubber_stretch(theta, design), 1.0 + stretch_prior(theta, groups) * np.exp(z),
                               rtol=1e-6)


def test_a_table_with_its_own_sizes_only_does_not_see_the_tube_size(tmp_path):
    """A table with the designs' own s_tilde alone (written before the a/rho columns) predicts the
    same stretch at any tube size; the shipped table does not (a 3 mm tube stretches less than its
    4 mm twin at the same bend: the rubber's 2 mm ball covers more of its wall's gradient)."""
    old = HandDesign(finger_model="fem", finger_table=str(stretch_table(tmp_path)))
    shipped = HandDesign(finger_model="fem")
    k = 0.75
    for d in (old, shipped):
        twin = d.replace(a=d.a * k, b=d.b * k, d=d.d * k, l0=d.l0 * k, tie_width=d.tie_width * k,
                         hinge_s=tuple(x * k for x in d.hinge_s))
        ratio = finger_fem.rubber_stretch(0.8, twin) / finger_fem.rubber_stretch(0.8, d)
        if d is old:
            assert ratio == pytest.approx(1.0, abs=1e-12)
        else:
            assert 0.9 < ratio < 0.99


def test_leave_one_out_reports_the_stretch_error(tmp_path):
    """Each design predicted by the table without it: a representable stretch comes back within
    rounding (1e-6 %) up to the other designs' largest bend, so the column runs through the
    held-out check; beyond it z is held at its end value (one design bends to 143 deg, the
    others to 127 deg at most: 0.96 % there)."""
    rows = leave_one_out(stretch_table(tmp_path))
    theta = read_table(TABLE_FILE).rows["theta"]
    design = read_table(TABLE_FILE).rows["design"]
    inside = [r for r in rows if math.radians(r["theta_fem_deg"]) <= theta[design != r["design"]].max()]
    err = np.array([r["rubber_stretch_err_pct"] for r in inside])
    assert len(inside) >= len(rows) - 2 and np.max(np.abs(err)) < 1e-6
    assert "rubber_stretch_sizes_err_pct" not in rows[0]
    sized = leave_one_out(stretch_table(tmp_path, sizes=True))
    inside = [r for r in sized if math.radians(r["theta_fem_deg"]) <= theta[design != r["design"]].max()]
    assert np.max(np.abs([r["rubber_stretch_sizes_err_pct"] for r in inside])) < 1e-6


def test_the_calibration_rows_carry_the_converged_stretch():
    """table_rows turns each case's rubber_stretch into s_tilde = lambda - 1 (P > 0 rows only),
    and leaves the column out when any case lacks it (older cases)."""
    design = HandDesign()
    numbers = {"P_MPa": [0.0, 0.4], "theta_deg": [0.0, 10.0], "dQ_mm3": [0.0, 500.0],
               "rubber_stretch": [1.0, 1.12]}
    rows = table_rows([(design, numbers)])
    assert len(rows) == 1 and rows[0][STRETCH] == pytest.approx(0.12, rel=1e-12)
    assert rows[0]["theta"] == pytest.approx(math.radians(10.0))
    old = {k: v for k, v in numbers.items() if k != "rubber_stretch"}
    assert STRETCH not in table_rows([(design, numbers), (design, old)])[0]
    sized = {**numbers, "rubber_stretch_a_rho": [[1.0] * len(A_RHO), [1.1 + x / 100 for x in A_RHO]]}
    row = table_rows([(design, sized)])[0]
    assert [row[c] for c in SIZE_STRETCH] == pytest.approx([0.1 + x / 100 for x in A_RHO], rel=1e-12)
    assert SIZE_STRETCH[0] not in table_rows([(design, sized), (design, numbers)])[0]


def test_the_optimiser_judges_the_tube_by_the_calibrated_stretch(tmp_path):
    """With such a table, a design's evaluated tube stretch is the table's prediction at the bend
    the free finger reaches under the grasp's cavity pressure (not eq. (8) x a factor)."""
    from softhand.reduced.equations import hand
    from softhand.studies.design import evaluate
    from softhand.studies.design.task import task_from_dict

    task = task_from_dict({"object": {"diameter_mm": 180.0, "mass_kg": 2.0}, "pump": {"max_pressure_MPa": 2.0},
                           "design": {"finger_table": str(stretch_table(tmp_path))},
                           "free": {"d_mm": [10.0, 20.0]}})
    ev = evaluate.evaluate(task.base, task)
    th, design = ev.theta_hold, task.base
    p_r = float(hand.pressure(th, design, reservoir=False) - hand.pressure(th, design))
    free = float(hand.bend_angle(ev.P_grasp + p_r, design, reservoir=False))
    assert free > th
    assert ev.stretch == pytest.approx(float(finger_fem.rubber_stretch(free, design)), rel=1e-12)
    assert ev.stretch != pytest.approx(evaluate.peak_stretch(ev.theta_hold, task.base), rel=1e-3)
