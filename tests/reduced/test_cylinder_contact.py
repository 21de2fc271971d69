"""A pad against a cylinder, checked against an independent method: the separation of two convex
bodies along a direction is their support functions' difference (the cylinder's from 2 000 points
on each rim, the pad's from its corners), and its maximum over every direction (a dense sweep of
the sphere, then Nelder-Mead from the best) is their signed distance where they overlap or touch;
at touch, the pad's contact point lies on the cylinder."""
import functools

import numpy as np
import pytest
from scipy.optimize import minimize
from scipy.spatial.transform import Rotation

from softhand.fem.hand.hold_body import Body
from softhand.reduced.holding.cylinder_contact import cylinder_pad_contacts


def _rims(c, k, r, h, n=2000):
    u = np.cross(k, [1.0, 0.0, 0.0] if abs(k[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(k, u)
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    ring = r * (np.cos(t)[:, None] * u + np.sin(t)[:, None] * v)
    return np.concatenate([c + h * k + ring, c - h * k + ring])


def _separation(U, rims, pad):
    pc, a, e, _, hl, hw = pad
    U = np.atleast_2d(U)
    U = U / np.linalg.norm(U, axis=1, keepdims=True)
    pad_pts = pc + np.array([s * hl * a + t * hw * e for s in (-1, 1) for t in (-1, 1)])
    return np.min(rims @ U.T, axis=0) - np.max(pad_pts @ U.T, axis=0)


def _signed_distance(rims, pad):
    n = 20000
    i = np.arange(n) + 0.5
    z, phi = 1.0 - 2.0 * i / n, np.pi * (1.0 + 5 ** 0.5) * i
    U = np.c_[np.sqrt(1 - z ** 2) * np.cos(phi), np.sqrt(1 - z ** 2) * np.sin(phi), z]
    sweep = _separation(U, rims, pad)
    found = [minimize(lambda u: -_separation(u, rims, pad)[0], U[j], method="Nelder-Mead",
                      options=dict(xatol=1e-12, fatol=1e-12, maxiter=20000)) for j in np.argsort(sweep)[-10:]]
    res = min(found, key=lambda r: r.fun)
    return -res.fun, res.x / np.linalg.norm(res.x)


def _contact(cyl, pad):
    c, k, r, h = cyl
    pc, a, e, f, hl, hw = pad
    body = Body("cylinder", tuple(c), (2 * r, 2 * h), axis=tuple(k))
    ref = pc + np.clip((c - pc) @ a, -hl, hl) * a + np.clip((c - pc) @ e, -hw, hw) * e
    g, n, x = cylinder_pad_contacts(c, k, r, h, pc[None], a[None], np.array([hl]), e[None], np.array([hw]),
                                    f[None], ref[None], body.signed_distance)
    return g[0], n[0], x[0], body


@functools.lru_cache(maxsize=None)
def _case(seed):
    """A random pad, and a random cylinder on its front (at an angle: rims, sides and caps),
    overlapping by 0 ... 2 mm or apart by up to 0.5 mm; with the sweep's signed distance."""
    rng = np.random.default_rng(100 + seed)
    R = Rotation.random(random_state=rng).as_matrix()
    pad = (np.zeros(3), R[:, 0], R[:, 1], R[:, 2], rng.uniform(10.0, 25.0), rng.uniform(5.0, 10.0))
    k = Rotation.random(random_state=rng).as_matrix()[:, 0]
    r, h = rng.uniform(30.0, 70.0), rng.uniform(30.0, 90.0)
    direction = pad[3] + 0.6 * rng.standard_normal(3)
    direction /= np.linalg.norm(direction)
    c = pad[0] + direction * 120.0
    sd, u = _signed_distance(_rims(c, k, r, h), pad)
    c = c - (sd - rng.uniform(-2.0, 0.5)) * u
    return (pad, (c, k, r, h)) + _signed_distance(_rims(c, k, r, h), pad)


@pytest.mark.parametrize("seed", range(12))
def test_the_gap_is_the_largest_separation_and_the_point_touches_the_cylinder(seed):
    pad, cyl, sd, u = _case(seed)
    g, n, x, _ = _contact(cyl, pad)
    if sd > 0.0:  # apart: the candidates' separation is at most the distance
        assert 0.0 < g <= sd + 1e-4
        return
    assert g == pytest.approx(sd, abs=2e-4)           # the sweep's rims are 2 000-gons
    np.testing.assert_allclose(-n, u, atol=2e-3)
    c, k, r, h = cyl
    touching = (c - g * -n, k, r, h)
    g0, n0, x0, body = _contact(touching, pad)
    assert abs(g0) < 1e-9
    assert abs(body.signed_distance(x0[None])[0][0]) < 1e-6
    local = x0 - pad[0]
    assert abs(local @ pad[1]) <= pad[4] + 1e-12 and abs(local @ pad[2]) <= pad[5] + 1e-12


def test_the_normal_turns_smoothly_with_the_pad():
    """Turning the pad by 1e-6 rad turns the normal by O(1e-6) on every case, also where a pad
    side lies across a rim; at least three of the twelve touch at a rim."""
    rims = 0
    for seed in range(12):
        pad, cyl, _, _ = _case(seed)
        g, n, x, body = _contact(cyl, pad)
        turn = Rotation.from_rotvec(1e-6 * pad[1]).as_matrix()
        turned = (pad[0], turn @ pad[1], turn @ pad[2], turn @ pad[3], pad[4], pad[5])
        assert np.linalg.norm(_contact(cyl, turned)[1] - n) < 1e-4
        c, k, r, h = cyl
        along = abs((x + g * -n - c) @ k)
        radial = np.linalg.norm((x + g * -n - c) - ((x + g * -n - c) @ k) * k)
        rims += bool(abs(along - h) < 1e-3 and abs(radial - r) < 1e-3)
    assert rims >= 3
