"""softhand.reduced.calibrated.hinge_table: the moment is the exact integral of the table's volume
rate over the pressure (closed forms for rates constant and linear in P), its pressure
derivative is the rate (the Maxwell relation it rests on), a hinge bent backwards is anchored at
its measured moment at zero pressure, and bad tables are refused."""
import numpy as np
import pytest

from softhand.reduced.calibrated import finger_hinges, hinge_space, hinge_table
from softhand.reduced.vocabulary.design import HandDesign
from softhand.reduced.vocabulary.errors import InputError

THETA = (0.0, 0.1, 0.25)
P = np.round(0.05 + 0.1 * np.arange(20), 9)


def write(tmp_path, rate, first=(0.0, 0.2, 0.4), name="t.csv", reverse=()):
    """A table of two hinges, a_j = rate(theta, P, j), node i measured from P >= first[i]; and
    reverse nodes (theta < 0, m0 (2,)) measured from P = 0."""
    rows = ["# test", "theta,P,a_1,a_2"]
    for t, m0 in reverse:
        rows += [f"{t},0,{m0[0]!r},{m0[1]!r}"] + [f"{t},{p},{float(rate(t, p, 0))!r},{float(rate(t, p, 1))!r}"
                                                  for p in P]
    for t, p0 in zip(THETA, first):
        rows += [f"{t},{p},{float(rate(t, p, 0))!r},{float(rate(t, p, 1))!r}" for p in P if p >= p0]
    path = tmp_path / name
    path.write_text("\n".join(rows) + "\n")
    hinge_table.read.cache_clear()
    return hinge_table.read(str(path))


def test_a_rate_independent_of_the_pressure_gives_the_linear_law(tmp_path):
    """a_j(theta) alone: M_j = -a_j(theta) (P - P_free), the same below, inside and beyond the nodes."""
    rate = lambda t, p, j: 1.8 - 2.0 * t + 0.1 * j  # noqa: E731
    t = write(tmp_path, rate)
    theta = np.array([[-0.05, 0.02], [0.13, 0.3], [0.24, 0.5]])
    for Pc, Pf in [(0.9, 0.3), (2.6, -0.2), (0.0, 0.5)]:
        want = -np.array([[rate(x, 0, j) for j, x in enumerate(r)] for r in theta]) * (Pc - Pf)
        np.testing.assert_allclose(hinge_table.moment(t, theta, Pc, Pf), want, rtol=1e-12, atol=1e-12)


def test_a_rate_linear_in_the_pressure_is_integrated_exactly(tmp_path):
    """a = alpha(theta) + beta p on every node: M = -(alpha (P - Pf) + beta (P^2 - Pf^2) / 2) inside
    the measured pressures (the first node's whole range: it starts at 0)."""
    rate = lambda t, p, j: 1.2 + 0.5 * t + (0.3 + j * 0.1) * p  # noqa: E731
    t = write(tmp_path, rate, first=(0.0, 0.0, 0.0))
    theta = np.array([0.05, 0.2])
    for Pc, Pf in [(0.9, 0.3), (1.95, 0.05), (0.61, 0.6)]:
        want = [-((1.2 + 0.5 * x) * (Pc - Pf) + (0.3 + j * 0.1) * 0.5 * (Pc ** 2 - Pf ** 2))
                for j, x in enumerate(theta)]
        np.testing.assert_allclose(hinge_table.moment(t, theta, Pc, Pf), want, rtol=1e-12)


def test_a_hinge_bent_backwards_is_anchored_at_its_moment_at_zero_pressure(tmp_path):
    """Reverse nodes: M = m0(theta) - int_0^P a dp, m0 linear between the nodes and 0 at theta = 0
    (continuous there with the free law, P_free(0) = 0), extended linearly below the last node."""
    rate = lambda t, p, j: 1.8 - 2.0 * t + 0.1 * j  # noqa: E731  (constant in P: the integral is a P)
    m0 = {-0.2: (-0.9, -1.0), -0.05: (-0.2, -0.25)}
    t = write(tmp_path, rate, first=(0.0, 0.0, 0.0), reverse=sorted(m0.items()))

    def anchor(x, j):
        if x <= -0.05:
            return m0[-0.05][j] + (x + 0.05) / -0.15 * (m0[-0.2][j] - m0[-0.05][j])
        return m0[-0.05][j] * x / -0.05

    theta = np.array([[-0.3, -0.2], [-0.1, -0.01]])
    for Pc in (0.0, 0.9, 2.0):
        want = [[anchor(x, j) - rate(x, 0, j) * Pc for j, x in enumerate(r)] for r in theta]
        np.testing.assert_allclose(hinge_table.moment(t, theta, Pc, 5.0), want, rtol=1e-12, atol=1e-12)
    for Pc in (0.4, 1.3):  # at theta = 0 from both sides: the free law's -a P with P_free(0) = 0
        at = lambda x: hinge_table.moment(t, np.array([x, x]), Pc, 0.0)  # noqa: E731
        np.testing.assert_allclose(at(-1e-12), at(0.0), atol=1e-9)
        np.testing.assert_allclose(at(1e-12), at(0.0), atol=1e-9)


def test_the_moments_pressure_rate_is_minus_the_volume_rate():
    """dM_j/dP = -A_j at fixed hinge angles, by differences, on the finger's own table."""
    design = finger_hinges.fem_finger(HandDesign())
    q, h = np.radians([0.3, 1.2, 2.5, 4.0, 9.0]), 1e-6
    for P in (0.37, 0.9, 1.4):
        fd = (finger_hinges.hinge_moments(q, P + h, design) - finger_hinges.hinge_moments(q, P - h, design)) / (2 * h)
        np.testing.assert_allclose(fd, -finger_hinges.volume_rate(design.n_s * q, P, design), rtol=1e-6)


def test_the_finger_tables_rate_grows_with_the_pressure_at_a_locked_bend():
    """The measured table itself: at a locked bend the tube swells and draws more oil per radian
    as the pressure rises above the free one (the reason the table has P)."""
    design = finger_hinges.fem_finger(HandDesign())
    theta = np.full(design.n_s, 0.12)
    low, high = (finger_hinges.volume_rate(theta, P, design) for P in (0.5, 1.5))
    assert np.all(high[:4] > 1.05 * low[:4])


@pytest.mark.parametrize("header, rows, says", [
    ("theta,a_1,a_2", ["0,1,1", "0.1,1,1"], "theta,P,a_1"),
    ("theta,P,a_1", ["0,0.1,1", "0,0.2,1", "0,0.4,1", "0.1,0.1,1", "0.1,0.2,1", "0.1,0.4,1"], "equally spaced"),
    ("theta,P,a_1", ["0,0.1,1", "0,0.2,1", "0,0.3,1", "0.1,0.1,1", "0.1,0.3,1"], "in one run"),
    ("theta,P,a_1", ["-0.1,0.1,1", "-0.1,0.2,1", "0,0.1,1", "0,0.2,1"], "row at P = 0"),
    ("theta,P,a_1", ["0,0,1", "0,0.1,1", "0,0.2,1", "0.1,0.1,1", "0.1,0.2,1"], "row at P = 0"),
    ("theta,P,a_1", ["-0.1,0,-1", "-0.1,0,-2", "-0.1,0.1,1", "0,0.1,1", "0,0.2,1"], "row at P = 0"),
])
def test_a_bad_table_is_one_line(tmp_path, header, rows, says):
    path = tmp_path / "bad.csv"
    path.write_text("\n".join([header, *rows]) + "\n")
    with pytest.raises(InputError, match=says) as e:
        hinge_table.read(str(path))
    assert "\n" not in str(e.value) and "hinge_table" in str(e.value)


def _scaled_copy(tmp_path, factor: float, drop_last: bool = False):
    """The shipped table with every rate and moment times ``factor`` (or its last hinge dropped)."""
    lines = hinge_space.TABLE_FILE.read_text().splitlines()
    out = []
    for line in lines:
        cells = line.split(",")
        if line.startswith("#") or not cells[0][:1].isdigit() and cells[0][:1] != "-":
            out.append(",".join(cells[:-1]) if drop_last and not line.startswith("#") else line)
            continue
        values = [f"{float(v) * factor!r}" for v in cells[2:]]
        out.append(",".join(cells[:2] + (values[:-1] if drop_last else values)))
    path = tmp_path / "own.csv"
    path.write_text("\n".join(out) + "\n")
    return path


def test_a_design_with_its_own_hinge_table_uses_it(tmp_path):
    """``hinge_table`` in a design file (relative to it): the fast hold's moments come from that
    table, at both signs of the bend (every value 0.9 times the shipped one: every moment 0.9 times,
    the free curve unchanged); without it, the paper's design's."""
    from softhand.reduced.vocabulary.design_files import load_design
    _scaled_copy(tmp_path, 0.9)
    (tmp_path / "hand.toml").write_text('finger_model = "fem"\nhinge_table = "own.csv"\n')
    own = load_design(tmp_path / "hand.toml")
    paper = finger_hinges.fem_finger(HandDesign())
    assert own.hinge_table == str(tmp_path / "own.csv") and paper.hash() == finger_hinges.fem_finger(HandDesign()).hash()
    q = np.radians([[-2.0, -0.5, 0.3, 3.0, 9.0], [1.0, 2.0, 3.0, 4.0, 5.0]])
    for P in (0.3, 1.2):
        np.testing.assert_allclose(finger_hinges.hinge_moments(q, P, own), 0.9 * finger_hinges.hinge_moments(q, P, paper),
                                   rtol=1e-9)


def test_a_hinge_table_for_other_hinges_is_one_line(tmp_path):
    from softhand.reduced.vocabulary.design_files import load_design
    _scaled_copy(tmp_path, 1.0, drop_last=True)
    (tmp_path / "hand.toml").write_text('finger_model = "fem"\nhinge_table = "own.csv"\n')
    with pytest.raises(InputError, match="hinge_table.*4 hinges; the design has 5") as e:
        load_design(tmp_path / "hand.toml")
    assert "\n" not in str(e.value)
