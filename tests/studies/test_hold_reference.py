"""The fast hold model against the whole-hand FEM's stored holding limits (studies/data/hold_fem_limits.json).

The FEM ran each case for minutes; these limits are its, not the fast model's, and nothing in the
fast model was fitted to them. The bounds are the accuracy docs/grasp.md reports, so a change that
takes the fast model further from the FEM fails here, one that brings it closer passes.
"""
import numpy as np
import pytest

from softhand.studies import hold_reference


@pytest.fixture(scope="module")
def rows():
    return hold_reference.compare()


def test_the_reference_set_covers_the_shapes_designs_and_pulls_it_claims():
    data = hold_reference.load()
    cases = data["cases"]
    assert len(cases) == 61
    assert {c["object"]["shape"] for c in cases} == {"sphere", "cylinder", "box", "capsule", "mesh"}
    assert {c["design"] for c in cases} == set(data["designs"])
    assert any(c.get("pull", [0, 1, 0]) != [0, 1, 0] for c in cases)  # the sideways pull
    held = [c for c in cases if c["fem_limit_N"] > 0]
    assert len(held) == 43 and all(0.0 <= c["fem_weight_share"] <= 1.0 for c in cases if c not in held)


def test_the_verdicts_agree_with_the_fems_wherever_its_margin_exceeds_five_percent(rows):
    """All 61 agree but one, and that one within the FEM's 5 %: design A's 130 mm cube turned 15 deg,
    which the FEM's hand holds with no pull to spare once let go along a path (turned 5.4 deg back).
    (Design A's 160 x 110 x 140 mm box turned 25 deg, which the FEM holds with 45 % to spare after
    turning 3 deg back while let go, fell in the fast model until its let-go turned it too; the 180 mm
    and design B's 165 mm cubes turned 30 deg, 'not held' by the FEM until its symmetric letting go
    was followed as a path, are held by both.)"""
    s = hold_reference.summary(rows)
    assert s["verdicts_agree"] >= 60, s
    assert all(abs(margin) <= 0.05 for _, margin in s["differ"]), s


def test_the_fast_limits_are_as_close_to_the_fem_as_documented(rows):
    s = hold_reference.summary(rows)
    assert s["both_held"] >= 43, s
    assert s["within_5_percent"] >= 27, s
    assert s["within_10_percent"] >= 38, s
    assert s["median_percent"] <= 2.6, s
    # the load borne (weight + limit): what a margin of "hold k times the weight" asks for
    assert s["load_within_5_percent"] >= 38 and s["load_within_10_percent"] >= 41, s
    assert s["load_median_percent"] <= 2.0, s
    worst = max((r for r in rows if np.isfinite(r.error)), key=lambda r: abs(r.error))
    # the 180 mm cube turned 15 deg: the fast model's slide catches it on the next pads 12 mm down
    # (the FEM, the cube placed there, holds 5.67 N; fast 5.43 N), the FEM's pull passes over that
    # pose in one step and catches it 25 mm down (docs/grasp.md): +151 %
    assert worst.name.startswith("cube 180 mm turned 15 deg") and abs(worst.error) < 1.6, worst
    rest = [r for r in rows if np.isfinite(r.error) and r is not worst]
    assert max(abs(r.error) for r in rest) < 0.45
    assert 100 * np.sqrt(np.mean([r.error ** 2 for r in rest])) <= 9.6


def test_the_reference_meshes_are_built_as_their_recipes_say(tmp_path):
    import trimesh

    for name, vertices in (("icosphere", 2562), ("scanned", 10242)):
        mesh = trimesh.load(hold_reference.build_mesh(name, tmp_path))
        assert len(mesh.vertices) == vertices and mesh.is_watertight
        r = (mesh.vertices ** 2).sum(axis=1) ** 0.5
        assert 87.0 < r.min() and r.max() < 93.0  # a 180 mm ball, bumps of 1.5 mm and 0.2 mm noise
    with pytest.raises(ValueError):
        hold_reference.build_mesh("teapot", tmp_path)
