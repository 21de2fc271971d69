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
    assert len(held) == 44 and all(0.0 <= c["fem_weight_share"] <= 1.0 for c in cases if c not in held)
    # the re-run with the pull drawn keeps the stepped limit beside the drawn one; only held cases are re-run
    drawn = [c for c in cases if "fem_limit_stepped_N" in c]
    assert len(drawn) == 38 and all(c in held for c in drawn)


def test_the_verdicts_agree_with_the_fems_wherever_its_margin_exceeds_five_percent(rows):
    """All 61 agree but one, and that one within the FEM's 5 %: design A's 130 mm cube turned 15 deg,
    which the FEM's hand holds with 0.021 N to spare, 0.7 % of its weight, once let go along a path
    (turned 5.4 deg back) and its pull drawn (none to spare with its pull stepped as a force).
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
    assert s["within_10_percent"] >= 36, s
    assert s["median_percent"] <= 3.1, s
    # the load borne (weight + limit): what a margin of "hold k times the weight" asks for
    assert s["load_within_5_percent"] >= 35 and s["load_within_10_percent"] >= 39, s
    assert s["load_median_percent"] <= 1.7, s
    worst = max((r for r in rows if np.isfinite(r.error)), key=lambda r: abs(r.error))
    # hold_ball's optimum: the ball settles onto pads that barely touch it (their normal force a
    # fraction of a degree of bend), so where it rests and where it slips out follow the finger's
    # ~1 % bend error; the fast ball slips out past the fingertip's crease, the FEM's before it
    assert worst.name.startswith("hold_ball's optimum") and abs(worst.error) < 0.42, worst
    rest = [r for r in rows if np.isfinite(r.error) and r is not worst]
    # the next: the 180 mm sphere at mu 0.5, whose fast walk stops at the grasp's dip (-24 %)
    assert max(abs(r.error) for r in rest) < 0.25
    assert 100 * np.sqrt(np.mean([r.error ** 2 for r in rest])) <= 8.1


def test_the_reference_meshes_are_built_as_their_recipes_say(tmp_path):
    import trimesh

    for name, vertices in (("icosphere", 2562), ("scanned", 10242)):
        mesh = trimesh.load(hold_reference.build_mesh(name, tmp_path))
        assert len(mesh.vertices) == vertices and mesh.is_watertight
        r = (mesh.vertices ** 2).sum(axis=1) ** 0.5
        assert 87.0 < r.min() and r.max() < 93.0  # a 180 mm ball, bumps of 1.5 mm and 0.2 mm noise
    with pytest.raises(ValueError):
        hold_reference.build_mesh("teapot", tmp_path)
