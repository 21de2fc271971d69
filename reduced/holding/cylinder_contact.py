r"""Contact of the hold's flat pads with a cylinder, by the largest separation over directions.

A pad (a rectangle) and a cylinder are convex. Their signed distance is the largest separation
over unit directions u (oriented from the pad to the cylinder, D the centres' offset)

.. math:: s(u) = |u \cdot D| - r |u - (u\cdot k) k| - h |u \cdot k| - \tfrac{L}{2} |u \cdot a| - \tfrac{w}{2} |u \cdot e|,

the difference of the two support functions (k the axis, r the radius, h the half length; a,
L and e, w the pad's axis and length along the link and across it, f its normal). The pad's
part of the maximiser's support is its face (u = f), an edge (u on the great circle normal to
a: a side; normal to e: an end) or a corner; every maximiser is among those candidates: the
face, each circle's maximum (golden-section search from the best of a sampled circle, to
round-off), and each corner's own (the cylinder's signed distance at the corner and its
normal). The largest is the gap (where the two touch or overlap: exactly), its direction the
contact normal. Where a pad's side lies across the rim, the normal is the common normal of the
side and the rim, which turns smoothly with the pad -- the distance's own gradient at the pad's
deepest point flips between the cap's and the side's (as :mod:`~softhand.reduced.holding.box_contact`
has it for a box's edge).
"""
from __future__ import annotations

import numpy as np

from softhand.reduced.holding.object_geometry import support_point

#: a direction's component below this is a tie (the pad's edge or face is its support)
TIE = 1e-9
#: samples of each candidate circle before its golden-section search, and the search's steps
SAMPLES, STEPS = 72, 60
_GOLD = 0.5 * (np.sqrt(5.0) - 1.0)


def _separation(U, D, k, r, h, a, hl, e, hw):
    """s(u) with its orientation (sign of u . D) for directions U (m, ..., 3)."""
    extra = (None,) * (U.ndim - 2)
    dot = lambda v: np.einsum("m...i,mi->m...", U, v)  # noqa: E731
    uk = U @ k
    perp = np.linalg.norm(U - uk[..., None] * k, axis=-1)
    radius = r * perp + h * np.abs(uk) + hl[(...,) + extra] * np.abs(dot(a)) + hw[(...,) + extra] * np.abs(dot(e))
    along = dot(D)
    return np.abs(along) - radius, np.where(along < 0.0, -1.0, 1.0)


def _circle_max(v1, v2, D, k, r, h, a, hl, e, hw, steps=None):
    """The largest separation on each great circle of v1, v2 (m, 3) and its oriented direction."""
    args = (D, k, r, h, a, hl, e, hw)
    theta = np.linspace(0.0, np.pi, SAMPLES, endpoint=False)
    U = np.cos(theta)[None, :, None] * v1[:, None] + np.sin(theta)[None, :, None] * v2[:, None]
    best = np.argmax(_separation(U, *args)[0], axis=1)
    step = np.pi / SAMPLES
    lo, hi = theta[best] - step, theta[best] + step
    x = np.stack([hi - _GOLD * (hi - lo), lo + _GOLD * (hi - lo)])          # (2, m): the two probes
    V1, V2 = np.stack([v1, v1]), np.stack([v2, v2])
    at = lambda t: np.cos(t)[..., None] * V1 + np.sin(t)[..., None] * V2  # noqa: E731
    fx = _separation(at(x).transpose(1, 0, 2), *args)[0].T                # (2, m)
    for _ in range(STEPS if steps is None else steps):  # golden section: keep the bracket of the larger probe
        left = fx[0] >= fx[1]
        lo, hi = np.where(left, lo, x[0]), np.where(left, x[1], hi)
        new = np.where(left, hi - _GOLD * (hi - lo), lo + _GOLD * (hi - lo))
        fn = _separation(np.cos(new)[:, None] * v1 + np.sin(new)[:, None] * v2, *args)[0]
        x = np.where(left, np.stack([new, x[0]]), np.stack([x[1], new]))
        fx = np.where(left, np.stack([fn, fx[0]]), np.stack([fx[1], fn]))
    u = np.cos(0.5 * (lo + hi))[:, None] * v1 + np.sin(0.5 * (lo + hi))[:, None] * v2
    s, sign = _separation(u, *args)
    return s, u * sign[:, None]


def cylinder_pad_contacts(centre, axis, radius, half_length, pc, a, hl, e, hw, facing, ref, sdf, steps=None):
    """Contacts of m pads with one cylinder (centre (3,), unit axis (3,), radius and half length
    [mm], hand frame now); pads as :func:`softhand.reduced.holding.box_contact.box_pad_contacts`,
    ``sdf(points (n, 3)) -> (d, outward normal)`` the cylinder's own signed distance (for the
    corners). Returns (gap (m,) [mm], the cylinder's outward normal (m, 3), the pad's contact
    point (m, 3))."""
    c, k = np.asarray(centre, float), np.asarray(axis, float)
    D = c - pc
    args = (D, k, float(radius), float(half_length), a, hl, e, hw)
    m = len(pc)
    corners = np.array([(1, 1), (1, -1), (-1, 1), (-1, -1)], float)
    cpts = pc[:, None] + corners[None, :, :1] * (hl[:, None, None] * a[:, None]) \
        + corners[None, :, 1:] * (hw[:, None, None] * e[:, None])          # (m, 4, 3)
    _, n_c = sdf(cpts.reshape(-1, 3))
    cand_u = [facing[:, None], -np.asarray(n_c).reshape(m, 4, 3)]       # face; each corner's own
    s_face, sign = _separation(facing[:, None], *args)
    s_corner, sign_c = _separation(cand_u[1], *args)
    both = _circle_max(np.concatenate([facing, facing]), np.concatenate([e, a]), np.concatenate([D, D]), k,
                       float(radius), float(half_length), np.concatenate([a, a]), np.concatenate([hl, hl]),
                       np.concatenate([e, e]), np.concatenate([hw, hw]), steps)   # the sides' circles, then the ends'
    (s_side, s_end), (u_side, u_end) = np.split(both[0], 2), np.split(both[1], 2)
    S = np.concatenate([s_face, s_side[:, None], s_end[:, None], s_corner], axis=1)   # (m, 7)
    U = np.concatenate([facing[:, None] * sign[..., None], u_side[:, None], u_end[:, None],
                        cand_u[1] * sign_c[..., None]], axis=1)
    scale = 1e-9 * (1.0 + float(radius) + float(half_length))
    pick = np.argmax(S >= S.max(axis=1, keepdims=True) - scale, axis=1)   # the first of the ties
    rows = np.arange(m)
    u = U[rows, pick]
    # the cylinder's point deepest towards the pad (its own frame: axis along y), ties nearest ref
    frame = cylinder_frame(k)
    y = c + support_point("cylinder", (2.0 * radius, 2.0 * half_length), u @ frame, (ref - c) @ frame) @ frame.T
    # the pad's point deepest along u: its support feature, ties (an edge, the face) nearest y
    ua, ue = np.einsum("mi,mi->m", u, a), np.einsum("mi,mi->m", u, e)
    s = np.where(np.abs(ua) > TIE, np.sign(ua) * hl, np.clip(np.einsum("mi,mi->m", y - pc, a), -hl, hl))
    w = np.where(np.abs(ue) > TIE, np.sign(ue) * hw, np.clip(np.einsum("mi,mi->m", y - pc, e), -hw, hw))
    return S[rows, pick], -u, pc + s[:, None] * a + w[:, None] * e


def cylinder_distance(r, e, R, h):
    """(signed distance (m,) [mm], outward unit normal (m, 3)) of points r (m, 3) relative to the centre
    of a cylinder of unit axis e, radius R and half length h (closed form)."""
    a = r @ e
    radial = r - a[:, None] * e
    rho = np.linalg.norm(radial, axis=1)
    er = radial / np.where(rho > 0, rho, 1.0)[:, None]
    dr, da = rho - R, np.abs(a) - h
    ea = np.sign(a)[:, None] * e
    out = (dr > 0) & (da > 0)
    d = np.where(out, np.hypot(np.maximum(dr, 0), np.maximum(da, 0)), np.maximum(dr, da))
    n_out = (dr[:, None] * er + da[:, None] * ea) / np.where(out, d, 1.0)[:, None]
    n = np.where(out[:, None], n_out, np.where((dr >= da)[:, None], er, ea))
    return d, n


def cylinder_frame(k):
    """Columns: a unit vector normal to k, k, and their cross product (the cylinder's own frame)."""
    u = np.cross(k, [1.0, 0.0, 0.0] if abs(k[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    return np.column_stack([u, k, np.cross(u, k)])
