"""A pad against a box by separating axes, checked against an independent method: the
separation of two convex bodies along a direction is their support functions' difference,
and its maximum over every direction (found here by a dense sweep of the sphere and a local
optimiser, not from the candidate axes) is their signed distance where they overlap or
touch; at touch, the pad's contact point lies on the box."""
import functools

import numpy as np
import pytest
from scipy.optimize import minimize
from scipy.spatial.transform import Rotation

from softhand.reduced.holding.box_contact import box_pad_contacts

CORNERS = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float)


def _pad(rng):
    """A pad (centre, along, across, normal, half length, half width) of random orientation."""
    R = Rotation.random(random_state=rng).as_matrix()
    return np.zeros(3), R[:, 0], R[:, 1], R[:, 2], rng.uniform(10.0, 25.0), rng.uniform(5.0, 10.0)


def _separation(u, box, pad):
    """min over the box of u.y - max over the pad of u.x, from their corners (u pad -> box;
    directions u (3,) or (k, 3))."""
    c, B, h = box
    pc, a, e, _, hl, hw = pad
    u = u / np.linalg.norm(u, axis=-1, keepdims=True)
    box_pts = c + (CORNERS * h) @ B.T
    pad_pts = pc + np.array([s * hl * a + t * hw * e for s in (-1, 1) for t in (-1, 1)])
    return np.min(box_pts @ u.T, axis=0) - np.max(pad_pts @ u.T, axis=0)


def _signed_distance(box, pad):
    """max over unit u of the separation: a Fibonacci sweep of 20 000 directions, then Nelder-Mead
    from the best 10 of them (an edge-edge maximum is a sharp ridge: one start can miss it)."""
    n = 20000
    k = np.arange(n) + 0.5
    z, phi = 1.0 - 2.0 * k / n, np.pi * (1.0 + 5 ** 0.5) * k
    U = np.c_[np.sqrt(1 - z ** 2) * np.cos(phi), np.sqrt(1 - z ** 2) * np.sin(phi), z]
    sweep = _separation(U, box, pad)
    found = [minimize(lambda u: -_separation(u, box, pad), U[i], method="Nelder-Mead",
                      options=dict(xatol=1e-12, fatol=1e-12, maxiter=20000)) for i in np.argsort(sweep)[-10:]]
    res = min(found, key=lambda r: r.fun)
    return -res.fun, res.x / np.linalg.norm(res.x)


def _box_sdf(x, box):
    c, B, h = box
    q = np.abs((x - c) @ B) - h
    return np.linalg.norm(np.maximum(q, 0.0)) + min(q.max(), 0.0)


def _contact(box, pad):
    c, B, h = box
    pc, a, e, f, hl, hw = pad
    ref = pc + np.clip((c - pc) @ a, -hl, hl) * a + np.clip((c - pc) @ e, -hw, hw) * e
    g, n, x = box_pad_contacts(c, B, h, pc[None], a[None], np.array([hl]), e[None], np.array([hw]), f[None], ref[None])
    return g[0], n[0], x[0]


@functools.lru_cache(maxsize=None)
def _case(seed):
    """A random pad, and a random box on its front at an angle, overlapping by 0 ... 2 mm or
    apart by up to 0.5 mm; with their signed distance and its direction by the sweep."""
    rng = np.random.default_rng(seed)
    pad = _pad(rng)
    B = Rotation.random(random_state=rng).as_matrix()
    h = rng.uniform(20.0, 70.0, 3)
    direction = pad[3] + 0.6 * rng.standard_normal(3)
    direction /= np.linalg.norm(direction)
    c = pad[0] + direction * 80.0
    sd, u = _signed_distance((c, B, h), pad)
    box = (c - (sd - rng.uniform(-2.0, 0.5)) * u, B, h)
    return (pad, box) + _signed_distance(box, pad)


@pytest.mark.parametrize("seed", range(12))
def test_the_gap_is_the_largest_separation_and_the_point_touches_the_box(seed):
    """Random box and pad overlapping by up to 2 mm: the gap and normal are the largest
    separation over all directions and its direction (to the optimiser's 1e-6); moved along
    the normal to touch, the gap is 0 and the pad's contact point is on the box's surface.
    Apart by up to 0.5 mm: a positive gap, at most the distance."""
    pad, box, sd, u = _case(seed)
    c, B, h = box
    g, n, x = _contact(box, pad)
    if sd > 0.0:  # apart: no candidate need be the distance's direction (a corner nearest a corner)
        assert 0.0 < g <= sd + 1e-9
        return
    assert g == pytest.approx(sd, abs=1e-6)
    np.testing.assert_allclose(-n, u, atol=1e-4)
    touching = (c - g * -n, B, h)                      # moved along the contact's normal to touch
    g0, n0, x0 = _contact(touching, pad)
    assert abs(g0) < 1e-9 and np.allclose(n0, n, atol=1e-12)
    assert abs(_box_sdf(x0, touching)) < 1e-7
    local = x0 - pad[0]
    assert abs(local @ pad[1]) <= pad[4] + 1e-12 and abs(local @ pad[2]) <= pad[5] + 1e-12


def test_the_normal_turns_smoothly_with_the_pad_edges_across_edges_too():
    """Over the random cases above, turning the pad by 1e-6 rad turns the normal by O(1e-6),
    also where a pad edge crosses a box edge (the normal their cross product; the box's own
    distance gradient at the pad's deepest point there flips between the edge's two faces);
    at least three of the twelve are such crossings."""
    crossings = 0
    for seed in range(12):
        pad, box, _, _ = _case(seed)
        B = box[1]
        n = _contact(box, pad)[1]
        turn = Rotation.from_rotvec(1e-6 * pad[1]).as_matrix()
        turned = (pad[0], turn @ pad[1], turn @ pad[2], turn @ pad[3], pad[4], pad[5])
        assert np.linalg.norm(_contact(box, turned)[1] - n) < 1e-5
        axes = np.vstack([pad[3], B.T])
        crossings += bool(np.all(1.0 - np.abs(axes @ n) > 1e-6))
    assert crossings >= 3
