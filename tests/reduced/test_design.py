"""HandDesign: the paper's file equals Table I; bad input names the field."""
import math

import pytest

from softhand.reduced.equations import finger
from softhand.reduced.vocabulary.design import PUBLIC_KEYS, HandDesign
from softhand.reduced.vocabulary.design_files import design_from_dict, load_design
from softhand.reduced.vocabulary.errors import InputError


def test_paper_file_is_table_one():
    d = load_design()
    assert d == HandDesign()
    assert (d.l0, d.a, d.b, d.d, d.R, d.t, d.V0, d.n, d.n_s) == (180, 4, 5, 15, 24, 1, 17800, 4, 5)
    assert math.isclose(math.degrees(d.theta0), 20.0)
    assert d.mu_sf == d.mu_sr == 1.15
    assert sum(d.link_lengths) == pytest.approx(d.l0)


def test_toml_round_trip(tmp_path):
    d = HandDesign(V0=15000.0, hinge_s=(20, 50, 90, 130, 160))
    path = tmp_path / "d.toml"
    path.write_text(d.to_toml())
    assert load_design(path) == d
    # the hand layout's keys and a design's own hinge table are written only when set (every
    # older design keeps its hash)
    assert set(d.to_dict()) == set(PUBLIC_KEYS) - {"finger_azimuths_deg", "pad_width_mm", "hinge_table"}


@pytest.mark.parametrize("values, field", [
    ({"a_mm": -4.0}, "a_mm"),
    ({"b_mm": 0}, "b_mm"),
    ({"bogus": 1}, "bogus"),
    ({"n": 2.5}, "n"),
    ({"l0_mm": "long"}, "l0_mm"),
    ({"n_s": 4, "hinge_s_mm": [30, 60, 90, 120, 150]}, "hinge_s_mm"),
    ({"hinge_s_mm": [30, 20, 90, 120, 150]}, "hinge_s_mm"),
    ({"theta0_deg": 95}, "theta0_deg"),
    ({"reservoir_model": "balloon"}, "reservoir_model"),
])
def test_bad_input_names_the_field(values, field):
    with pytest.raises(InputError, match=field):
        design_from_dict(values)


def test_volume_check():
    d = HandDesign(V0=1000.0)
    finger.check_volume(d, math.radians(10))  # 4*pi*16*15*0.17 = 526 mm^3 < 1000
    with pytest.raises(InputError, match="V0_mm3"):
        finger.check_volume(d, math.radians(90))


def test_bad_files(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        load_design(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("a_mm = = 3")
    with pytest.raises(InputError, match="not valid TOML"):
        load_design(bad)


def test_hinges_follow_a_new_tube_length_or_hinge_count_unless_given():
    """Equal links stay equal: l0 without hinge_s_mm scales the hinges, n_s spaces them equally."""
    assert design_from_dict({"l0_mm": 160.0}).hinge_s == pytest.approx([160.0 * k / 6 for k in range(1, 6)])
    assert design_from_dict({"n_s": 3}).hinge_s == pytest.approx([45.0, 90.0, 135.0])
    given = design_from_dict({"l0_mm": 200.0, "hinge_s_mm": [30.0, 60.0, 90.0, 120.0, 150.0]})
    assert given.hinge_s == (30.0, 60.0, 90.0, 120.0, 150.0)
    uneven = HandDesign(hinge_s=(20.0, 60.0, 90.0, 120.0, 150.0))
    assert design_from_dict({"l0_mm": 135.0}, uneven).hinge_s == pytest.approx([15.0, 45.0, 67.5, 90.0, 112.5])
    assert design_from_dict({"a_mm": 4.5}).hinge_s == HandDesign().hinge_s
