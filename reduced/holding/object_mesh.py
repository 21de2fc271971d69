"""A closed triangle mesh as an object: read and checked (trimesh), its signed distance.

:func:`read_mesh` reads STL, OBJ or PLY through trimesh (imported only here, only when a mesh is
read), refuses an open, inconsistently oriented, empty, self-intersecting or self-overlapping mesh, one
of several bodies or one under :data:`MIN_EXTENT_MM` across in one line,
centres it at its centre of mass, and samples its signed distance (negative inside) on a grid of
:data:`MESH_GRID` points along its longest edge (:func:`mesh_sdf`: exact point-triangle
distances to the nearest triangles, signed by the closest face); :func:`grid_sdf` interpolates it
by cubic B-splines (smooth normals; a smooth surface's distance to ~ the step^4, a sharp edge
rounded over about a step, where :func:`mesh_support` meets pads with the exact vertices). Units: mm.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from softhand.reduced.holding.box_contact import cuboid_of
from softhand.reduced.vocabulary.errors import InputError

#: mesh files read (trimesh's loaders)
MESH_SUFFIXES = (".stl", ".obj", ".ply")
#: grid points along a mesh's longest bounding-box edge for its distance field
MESH_GRID = 40
#: the smallest object a mesh may be [mm] (below it, most likely a mesh written in metres)
MIN_EXTENT_MM = 1.0


@dataclass(frozen=True)
class MeshData:
    """A closed triangle mesh read and checked, its distance sampled on a grid (object frame:
    origin at its centre of mass)."""

    vertices: np.ndarray   #: (nv, 3) [mm], centred at the centre of mass
    faces: np.ndarray      #: (nf, 3) vertex indices, outward winding
    grid: tuple            #: (x, y, z) grid axes [mm]
    #: cubic B-spline coefficients (scipy.ndimage.spline_filter) of the signed distance sampled
    #: at the grid points, negative inside [mm]
    spline: np.ndarray
    folds: np.ndarray      #: (nv,) True at a vertex of an edge where the surface folds > FOLD_DEG
    #: a mesh that is a rectangular box (:func:`~softhand.reduced.holding.box_contact.cuboid_of`):
    #: (half edges (3,) [mm], its axes (3, 3) as columns, its centre (3,) [mm]) in the object
    #: frame; None for any other solid
    cuboid: tuple | None = None


@lru_cache(maxsize=8)
def read_mesh(path: str, field: str = "object.file") -> MeshData:
    """Read STL/OBJ/PLY with trimesh; InputError for a missing, open, self-intersecting or several-body mesh."""
    p = Path(path)
    if p.suffix.lower() not in MESH_SUFFIXES:
        raise InputError(field, path, f"must be a mesh file ending in {', '.join(MESH_SUFFIXES)}")
    if not p.is_file():
        raise InputError(field, path, "is not a regular file" if p.exists() else "no such file")
    import trimesh  # only a mesh object needs it

    try:
        mesh = trimesh.load_mesh(str(p), process=True)
    except Exception as exc:  # noqa: BLE001 -- any reader failure is bad input
        raise InputError(field, path, f"is not a readable triangle mesh ({type(exc).__name__})") from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) < 4:
        raise InputError(field, path, "is not a single triangle mesh of at least 4 triangles")
    if not mesh.is_watertight:
        raise InputError(field, path, "is not closed (open edges or edges shared by more than two "
                                      "triangles); the object must be a closed surface")
    if not mesh.is_winding_consistent:
        raise InputError(field, path, "has inconsistently oriented triangles")
    if mesh.volume < 0:
        mesh.invert()
    if not mesh.volume > 0:
        raise InputError(field, path, "encloses no volume")
    extent = float(np.ptp(mesh.vertices, axis=0).max())
    if extent < MIN_EXTENT_MM:
        raise InputError(field, path, f"spans {extent:.3g} mm; a mesh is read in mm (was it written in m?)")
    pair = self_intersection(mesh.vertices, mesh.faces)
    if pair is not None:
        raise InputError(field, path, f"intersects itself (triangles {pair[0]} and {pair[1]})")
    if mesh.body_count > 1:  # apart, or overlapping where no edge crosses a face (coplanar)
        raise InputError(field, path, f"is {mesh.body_count} separate closed surfaces; the object must be "
                                      "one body (merge them into one surface)")
    vertices = np.asarray(mesh.vertices - mesh.center_mass, float)
    faces = np.asarray(mesh.faces, int)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    step = float(np.max(hi - lo)) / (MESH_GRID - 1)
    axes = tuple(np.arange(lo[i] - 3 * step, hi[i] + 3.5 * step, step) for i in range(3))
    points = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    distance = mesh_sdf(vertices, faces, points).reshape(tuple(len(a) for a in axes))
    check_encloses_once(float(mesh.volume), float(mesh.area), distance, step, field, path)
    from scipy.ndimage import spline_filter

    return MeshData(vertices, faces, axes, spline_filter(distance, order=3, mode="nearest"),
                    fold_vertices(vertices, faces), cuboid_of(vertices, faces))



def check_encloses_once(volume: float, area: float, distance: np.ndarray, step: float, field: str, path) -> None:
    """InputError unless the solid the signed ``distance`` (sampled every ``step`` mm) encloses, a
    smoothed count of its inside points, is the surface's own ``volume`` (divergence theorem): they
    differ where the surface overlaps itself along faces the crossing test cannot see (coplanar).
    The count's error is a fraction of area x step (5 % of it on a 4 mm plate sampled every 5 mm)."""
    enclosed = float(np.clip(0.5 - distance / step, 0.0, 1.0).sum()) * step ** 3
    if abs(enclosed - volume) > 0.1 * area * step:
        raise InputError(field, path, f"overlaps itself: its surface encloses {volume:.4g} mm^3, the "
                                      f"solid it bounds {enclosed:.4g} mm^3")


#: an edge whose two faces' normals differ by more than this [deg] is an edge of the object (a
#: box's), not a facet of a smooth surface
FOLD_DEG = 20.0


def fold_vertices(vertices, faces) -> np.ndarray:
    """(nv,) True at the vertices of the edges where the closed surface folds by more than
    :data:`FOLD_DEG`: the object's own edges and corners."""
    V, F = np.asarray(vertices, float), np.asarray(faces, int)
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    owner = np.tile(np.arange(len(F)), 3)
    order = np.lexsort((edges[:, 1], edges[:, 0]))
    e, o = edges[order], owner[order]
    pair = np.all(e[:-1] == e[1:], axis=1)                  # closed mesh: each edge twice
    fold = np.einsum("ij,ij->i", n[o[:-1][pair]], n[o[1:][pair]]) < np.cos(np.radians(FOLD_DEG))
    out = np.zeros(len(V), dtype=bool)
    out[e[:-1][pair][fold].ravel()] = True
    return out


#: triangles whose centroids are nearest a point, among which its closest triangle is sought
MESH_CANDIDATES = 24


def mesh_sdf(vertices, faces, points, *, block: int = 8192) -> np.ndarray:
    """Signed distance [mm] (negative inside) of points (m, 3) to a closed triangle mesh: exact
    point-triangle distances to the :data:`MESH_CANDIDATES` triangles of nearest centroid (a
    k-d tree), the sign from the closest triangle's face normal (among equally close ones, the
    one most aligned with the point's offset: the right side at edges and corners)."""
    from scipy.spatial import cKDTree

    V, F, P = np.asarray(vertices, float), np.asarray(faces, int), np.asarray(points, float)
    T = V[F]
    n = np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    k = min(MESH_CANDIDATES, len(F))
    tree = cKDTree(T.mean(axis=1))
    out = np.empty(len(P))
    for start in range(0, len(P), block):
        p = P[start:start + block]
        _, idx = tree.query(p, k=k)
        idx = idx.reshape(len(p), k)
        c = closest_on_triangles(p[:, None, :], T[idx])                 # (b, k, 3)
        off = p[:, None, :] - c
        dist = np.linalg.norm(off, axis=-1)
        best = dist.min(axis=1, keepdims=True)
        cos = np.einsum("bki,bki->bk", off, n[idx]) / np.maximum(dist, 1e-300)
        tie = dist <= best * (1 + 1e-9) + 1e-12
        j = np.argmax(np.where(tie, np.abs(cos), -1.0), axis=1)
        sign = np.sign(cos[np.arange(len(p)), j])
        out[start:start + block] = np.where(sign < 0, -1.0, 1.0) * best[:, 0]
    return out


def closest_on_triangles(p, T) -> np.ndarray:
    """The point of each triangle T (..., 3, 3) closest to p (..., 3) (Ericson's regions, vectorised)."""
    a, b, c = T[..., 0, :], T[..., 1, :], T[..., 2, :]
    ab, ac, ap = b - a, c - a, p - a
    dot = lambda u, v: np.einsum("...i,...i", u, v)  # noqa: E731
    d1, d2 = dot(ab, ap), dot(ac, ap)
    bp, cp = p - b, p - c
    d3, d4, d5, d6 = dot(ab, bp), dot(ac, bp), dot(ab, cp), dot(ac, cp)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    safe = lambda x: np.where(np.abs(x) > 1e-300, x, 1e-300)  # noqa: E731
    denom = safe(va + vb + vc)
    v, w = vb / denom, vc / denom
    out = a + v[..., None] * ab + w[..., None] * ac                          # inside the face
    e_bc = (d4 - d3) / safe((d4 - d3) + (d5 - d6))
    out = np.where(((va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0))[..., None], b + e_bc[..., None] * (c - b), out)
    e_ac = d2 / safe(d2 - d6)
    out = np.where(((vb <= 0) & (d2 >= 0) & (d6 <= 0))[..., None], a + e_ac[..., None] * ac, out)
    e_ab = d1 / safe(d1 - d3)
    out = np.where(((vc <= 0) & (d1 >= 0) & (d3 <= 0))[..., None], a + e_ab[..., None] * ab, out)
    out = np.where(((d6 >= 0) & (d5 <= d6))[..., None], c, out)
    out = np.where(((d3 >= 0) & (d4 <= d3))[..., None], b, out)
    out = np.where(((d1 <= 0) & (d2 <= 0))[..., None], a, out)
    return out


def mesh_support(mesh: MeshData, u, ref, tie) -> np.ndarray:
    """The mesh's point deepest along -u (argmin of X . u over the closed surface: a vertex), rows
    (m, 3), object frame; where vertices tie within ``tie`` (m,) [mm] (a face or an edge normal
    to u), the point of the tied faces and edges nearest ``ref`` (m, 3), as the primitives'
    :func:`softhand.reduced.holding.object_geometry.support_point`. NaN where none of the deepest
    vertices is on an edge or a corner of the object (:func:`fold_vertices`): there the surface is
    a smooth one's facets, met by its smooth distance instead (:func:`grid_sdf`)."""
    V, F = mesh.vertices, mesh.faces
    u, ref = np.atleast_2d(np.asarray(u, float)), np.atleast_2d(np.asarray(ref, float))
    if not mesh.folds.any():  # a smooth surface: no edge or corner to meet
        return np.full((len(u), 3), np.nan)
    depth = u @ V.T                                                     # (m, nv)
    k = np.argmin(depth, axis=1)
    out = V[k].copy()
    tied = depth <= depth[np.arange(len(u)), k][:, None] + np.asarray(tie, float).reshape(-1, 1)
    smooth = ~np.any(tied & mesh.folds, axis=1)  # no edge or corner among the deepest: a smooth patch
    out[smooth] = np.nan
    tied[smooth] = False
    for r in np.flatnonzero(tied.sum(axis=1) > 1):  # a face or an edge against the pad: rare rows
        on = tied[r][F]                                                 # (nf, 3)
        T = V[F[on.all(axis=1)]]                                        # tied faces
        two = on.sum(axis=1) == 2                                       # tied edges of the others
        E = V[F[two]][on[two]].reshape(-1, 2, 3)
        cand = [V[tied[r]]]
        if len(T):
            cand.append(closest_on_triangles(ref[r], T))
        if len(E):
            d = E[:, 1] - E[:, 0]
            t = np.clip(np.einsum("ki,ki->k", ref[r] - E[:, 0], d) / np.einsum("ki,ki->k", d, d), 0.0, 1.0)
            cand.append(E[:, 0] + t[:, None] * d)
        cand = np.concatenate(cand)
        out[r] = cand[np.argmin(np.linalg.norm(cand - ref[r], axis=1))]
    return out


def self_intersection(vertices, faces):
    """A pair of triangles (i, j) that cross each other (sharing no vertex), or None: every edge
    tested (Moller-Trumbore) against the triangles whose centroid lies within reach of its
    midpoint (a k-d tree; reach = half the longest edge + the largest centroid-to-corner distance)."""
    from scipy.spatial import cKDTree

    V, F = np.asarray(vertices, float), np.asarray(faces, int)
    T = V[F]
    centroid = T.mean(axis=1)
    edges = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    owner = np.tile(np.arange(len(F)), 3)
    mid = 0.5 * (V[edges[:, 0]] + V[edges[:, 1]])
    reach = 0.5 * np.max(np.linalg.norm(V[edges[:, 1]] - V[edges[:, 0]], axis=1)) \
        + np.max(np.linalg.norm(T - centroid[:, None], axis=-1))
    near = cKDTree(centroid).query_ball_point(mid, reach)
    counts = np.fromiter((len(n) for n in near), int, len(near))
    ei = np.repeat(np.arange(len(edges)), counts)
    ti = np.fromiter((t for n in near for t in n), int, int(counts.sum()))
    shares = np.any(edges[ei][:, :, None] == F[ti][:, None, :], axis=(1, 2))
    ei, ti = ei[~shares], ti[~shares]
    O, D = V[edges[ei, 0]], V[edges[ei, 1]] - V[edges[ei, 0]]
    A, E1, E2 = T[ti, 0], T[ti, 1] - T[ti, 0], T[ti, 2] - T[ti, 0]
    h = np.cross(D, E2)
    det = np.einsum("ij,ij->i", E1, h)
    ok = np.abs(det) > 1e-12 * np.linalg.norm(E1, axis=1) * np.linalg.norm(E2, axis=1) * np.linalg.norm(D, axis=1)
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = O - A
    u = np.einsum("ij,ij->i", s, h) * inv
    q = np.cross(s, E1)
    v = np.einsum("ij,ij->i", D, q) * inv
    t = np.einsum("ij,ij->i", E2, q) * inv
    eps = 1e-9
    hit = ok & (u > eps) & (v > eps) & (u + v < 1 - eps) & (t > eps) & (t < 1 - eps)
    if np.any(hit):
        k = int(np.flatnonzero(hit)[0])
        return int(owner[ei[k]]), int(ti[k])
    return None


def grid_sdf(mesh: MeshData, p) -> np.ndarray:
    """The mesh's grid distance at p (..., 3): its cubic B-spline (C2: the normal turns smoothly
    from cell to cell); outside the grid, plus the distance to it."""
    from scipy.ndimage import map_coordinates

    p = np.asarray(p, float)
    axes = mesh.grid
    lo = np.array([a[0] for a in axes])
    hi = np.array([a[-1] for a in axes])
    step = np.array([a[1] - a[0] for a in axes])
    inside = np.clip(p, lo, hi)
    outside = np.linalg.norm(p - inside, axis=-1)
    x = ((inside - lo) / step).reshape(-1, 3).T
    out = map_coordinates(mesh.spline, x, order=3, mode="nearest", prefilter=False)
    return out.reshape(p.shape[:-1]) + outside
