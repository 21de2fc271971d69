"""The finger's rubber tube as a half model, with the bands where the shell holds it.

Finger frame (mm): x along the undeformed finger from its base (x = 0) to its tip
(x = length); y from the tube axis towards the hinge plate (the plate is at y = +d,
so the finger curls towards +y); z normal to the bending plane. The bending plane
z = 0 is a symmetry plane and the model keeps z >= 0.

The tube has inner radius ``a``, outer radius ``a + b``; its cavity runs from x = 0
(open: the oil inlet in the fixed base) to x = length - cap, where an end cap of
thickness ``cap`` closes it. The outer cylinder is split at the edges of the tie
bands, so each band is a union of whole facets.

Physical groups: volume ``wall``; surfaces ``cavity`` (inner cylinder and the cap's
inner face), ``base`` (x = 0), ``tip`` (x = length), ``symmetry`` (z = 0),
``tie<k>`` (the outer surface inside band k, held by link k) and ``outer`` (the rest
of the outer cylinder). The groups are disjoint.

Grading (``edge_ratio`` < 1): the stress is singular along the circles where a tie band
ends on the outer surface (a kinematic constraint edge) and along the cavity's corner
at the cap; there the element size is ``edge_ratio * size``, growing linearly back to
``size`` over ``edge_reach`` mm (gmsh Distance + Threshold fields). Both enter the mesh
cache key with the other fields of :class:`FingerTube`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import skfem

from softhand.meshes.cache import load_mesh


@dataclass(frozen=True)
class FingerTube:
    """Dimensions of the half tube and its tie bands [mm]."""

    a: float                              #: inner radius [mm]
    b: float                              #: wall thickness [mm]
    length: float                         #: overall length, cap included [mm]
    cap: float                            #: end-cap thickness at the tip [mm]
    bands: tuple[tuple[float, float], ...]  #: (x_start, x_end) of each link's tie band [mm]
    edge_ratio: float = 1.0               #: element size at the singular edges / size (1: uniform)
    edge_reach: float = 5.0               #: distance over which the size grows back to size [mm]

    def __post_init__(self):
        if not (self.a > 0 and self.b > 0 and 0 < self.cap < self.length):
            raise ValueError(f"need a, b > 0 and 0 < cap < length: {self}")
        if not (0 < self.edge_ratio <= 1 and self.edge_reach > 0):
            raise ValueError(f"need 0 < edge_ratio <= 1 and edge_reach > 0: {self}")
        edges = np.ravel(self.bands)
        if np.any(np.diff(edges) <= 0) or edges[0] < 0 or edges[-1] > self.length:
            raise ValueError(f"bands must be disjoint, increasing, within [0, length]: {self}")

    def cuts(self) -> np.ndarray:
        """Sorted x positions where the tube is split into segments [mm]."""
        x = np.concatenate(([0.0, self.length - self.cap, self.length], np.ravel(self.bands)))
        return np.unique(np.round(x, 9))


def finger_geometry(model, tube: FingerTube, size: float) -> None:
    """gmsh geometry function (see :mod:`softhand.meshes.gmsh_io`) of a :class:`FingerTube`."""
    occ = model.occ
    r_out, cavity_end = tube.a + tube.b, tube.length - tube.cap
    cuts = tube.cuts()
    pieces = []
    for x0, x1 in zip(cuts[:-1], cuts[1:]):
        body = [(3, occ.addCylinder(x0, 0, 0, x1 - x0, 0, 0, r_out))]
        if x1 <= cavity_end + 1e-9:
            hole = [(3, occ.addCylinder(x0, 0, 0, x1 - x0, 0, 0, tube.a))]
            body, _ = occ.cut(body, hole)
        box = [(3, occ.addBox(x0 - 1, -2 * r_out, 0, x1 - x0 + 2, 4 * r_out, 2 * r_out))]
        body, _ = occ.intersect(body, box)
        pieces += body
    pieces, _ = occ.fragment(pieces[:1], pieces[1:])
    occ.synchronize()
    model.addPhysicalGroup(3, [tag for _, tag in pieces], name="wall")
    for name, tags in _classify_surfaces(model, tube).items():
        if tags:
            model.addPhysicalGroup(2, tags, name=name)
    if tube.edge_ratio < 1:
        _grade(model, _singular_edges(model, tube), size * tube.edge_ratio, size, tube.edge_reach)


def _singular_edges(model, tube: FingerTube) -> list[int]:
    """Curves x = const on the outer surface at the tie bands' ends, and the cavity's cap corner."""
    eps = 1e-6 * tube.length
    ends, corner = np.ravel(tube.bands), tube.length - tube.cap
    tags = []
    for _, tag in model.getEntities(1):
        x0, y0, z0, x1, y1, z1 = model.getBoundingBox(1, tag)
        r = max(abs(y0), abs(y1), abs(z1))
        if abs(x1 - x0) < eps and r > 0.5 * tube.a and (
                (abs(r - tube.a - tube.b) < eps and np.any(np.abs(ends - x0) < eps))
                or (abs(r - tube.a) < eps and abs(x0 - corner) < eps)):
            tags.append(tag)
    return tags


def _grade(model, curves: list[int], fine: float, coarse: float, reach: float) -> None:
    """Background size field: ``fine`` on ``curves``, growing linearly to ``coarse`` at ``reach``."""
    field = model.mesh.field
    dist = field.add("Distance")
    field.setNumbers(dist, "CurvesList", curves)
    field.setNumber(dist, "Sampling", 100)
    ramp = field.add("Threshold")
    field.setNumber(ramp, "InField", dist)
    field.setNumber(ramp, "SizeMin", fine)
    field.setNumber(ramp, "SizeMax", coarse)
    field.setNumber(ramp, "DistMin", 0.0)
    field.setNumber(ramp, "DistMax", reach)
    field.setAsBackgroundMesh(ramp)


def _classify_surfaces(model, tube: FingerTube) -> dict[str, list[int]]:
    eps = 1e-6 * tube.length
    r_mid = tube.a + 0.5 * tube.b
    groups = {"cavity": [], "base": [], "tip": [], "symmetry": [], "outer": []}
    groups.update({f"tie{k}": [] for k in range(len(tube.bands))})
    for _, tag in model.getEntities(2):
        x0, y0, z0, x1, y1, z1 = model.getBoundingBox(2, tag)
        extent = max(abs(y0), abs(y1), abs(z1))
        if abs(z1) < eps:
            groups["symmetry"].append(tag)
        elif abs(x1 - x0) < eps:  # a plane x = const
            if abs(x0) < eps:
                groups["base"].append(tag)
            elif abs(x0 - tube.length) < eps:
                groups["tip"].append(tag)
            elif extent < r_mid:
                groups["cavity"].append(tag)
            # else: an interface between two segments, inside the wall
        elif extent < r_mid:
            groups["cavity"].append(tag)
        else:
            groups[_band_of(tube, 0.5 * (x0 + x1))].append(tag)
    return groups


def _band_of(tube: FingerTube, x: float) -> str:
    for k, (x0, x1) in enumerate(tube.bands):
        if x0 < x < x1:
            return f"tie{k}"
    return "outer"


def finger_tube_mesh(tube: FingerTube, *, size: float, refine: int = 0) -> skfem.MeshTet2:
    """The cached quadratic (curved) tetrahedral mesh of ``tube``, element size ``size`` [mm],
    each element then split ``refine`` times (size / 2**refine; see :func:`softhand.meshes.gmsh_io.generate_msh`)."""
    return load_mesh(finger_geometry, tube, size=size, order=2, refine=refine)


def layered_radii(a: float, b: float, first: float, ratio: float) -> np.ndarray:
    """Radii of the wall's layers from the cavity (r = a) out to r = a + b: thicknesses
    growing geometrically by ``ratio`` from about ``first``, scaled to fill the wall exactly."""
    n = 1
    while first * np.sum(ratio ** np.arange(n)) < 0.999 * b:
        n += 1
    t = first * ratio ** np.arange(n)
    return a + np.concatenate(([0.0], np.cumsum(t * b / t.sum())))


def _halve(v: np.ndarray, times: int) -> np.ndarray:
    """Insert the midpoints of a sorted array ``times`` times (nested subdivision)."""
    for _ in range(times):
        v = np.sort(np.concatenate((v, 0.5 * (v[1:] + v[:-1]))))
    return v


def _layered_grid(tube: FingerTube, n_phi: int, layer_first: float, layer_ratio: float, axial_size: float,
                  core_rings: int, refine: int) -> tuple[np.ndarray, np.ndarray, int]:
    """The layered mesh's planes x, radii (core rings, then the wall's) and sectors."""
    if not (n_phi >= 2 and core_rings >= 1 and layer_first > 0 and layer_ratio >= 1 and axial_size > 0):
        raise ValueError("need n_phi >= 2, core_rings >= 1, layer_first > 0, layer_ratio >= 1, "
                         f"axial_size > 0; got {n_phi}, {core_rings}, {layer_first}, {layer_ratio}, {axial_size}")
    wall = _halve(layered_radii(tube.a, tube.b, layer_first, layer_ratio), refine)
    rings = np.concatenate((_halve(np.linspace(0.0, tube.a, core_rings + 1), refine)[1:-1], wall))
    cuts = tube.cuts()
    x = np.concatenate([cuts[:1]] + [np.linspace(c0, c1, int(np.ceil((c1 - c0) / axial_size - 1e-9)) + 1)[1:]
                                     for c0, c1 in zip(cuts[:-1], cuts[1:])])
    return _halve(x, refine), rings, n_phi * 2 ** refine


def layered_tets(tube: FingerTube, *, n_phi: int, layer_first: float, layer_ratio: float,
                 axial_size: float, core_rings: int = 1, refine: int = 0) -> int:
    """The number of tetrahedra :func:`layered_tube_mesh` makes with these arguments, counted
    from its grid alone (no mesh built): three a prism, the wall's prisms in every slice and
    the core's in the end cap's."""
    x, rings, n_phi = _layered_grid(tube, n_phi, layer_first, layer_ratio, axial_size, core_rings, refine)
    wall = 2 * n_phi * int(np.sum(rings[1:] > tube.a + 1e-12))  # triangles outside the cavity
    everything = n_phi * (2 * len(rings) - 1)
    in_cap = int(np.sum(x[:-1] >= tube.length - tube.cap - 1e-9))
    return 3 * ((len(x) - 1 - in_cap) * wall + in_cap * everything)


def layered_tube_mesh(tube: FingerTube, *, n_phi: int, layer_first: float, layer_ratio: float,
                      axial_size: float, core_rings: int = 1, refine: int = 0) -> skfem.MeshTet2:
    """A structured, layered quadratic tetrahedral mesh of ``tube`` (no gmsh).

    The half cross-section (z >= 0) is a polar grid: ``n_phi`` sectors over 180 deg; in the
    wall, layers whose thickness grows geometrically from ``layer_first`` at the cavity
    (ratio ``layer_ratio``); in the end cap, also ``core_rings`` rings inside r = a around
    the axis. It is extruded along x in slices of at most ``axial_size`` that start and end
    at every cut of :meth:`FingerTube.cuts` (band ends, cavity end), and every prism is split
    into three tetrahedra by the lowest-index rule (conforming). Mid-edge nodes are the
    midpoints in (x, r, phi), so every layer is a true cylinder and the cavity, the outer
    surface and the cap are exact up to the P2 interpolation. ``refine`` halves every
    spacing (sectors, layers, rings, slices) that many times: nested meshes.

    Why this mesh: the bend angle's discretisation error is dominated by the axial spacing
    (the ring edges), while the cross-section needs few elements (docs/finger.md: mesh
    convergence); an unstructured mesh refines all three directions together.
    Boundaries as in :func:`finger_geometry`.
    """
    a, b, length = tube.a, tube.b, tube.length
    x_end = length - tube.cap
    x, rings, n_phi = _layered_grid(tube, n_phi, layer_first, layer_ratio, axial_size, core_rings, refine)

    # the half cross-section: node 0 on the axis, node 1 + i (n_phi + 1) + j on ring i, angle j
    na = n_phi + 1
    rho2 = np.concatenate(([0.0], np.repeat(rings, na)))
    phi2 = np.concatenate(([0.0], np.tile(np.linspace(0.0, np.pi, na), len(rings))))
    j = np.arange(n_phi)
    tris, core = [np.stack([np.zeros(n_phi, dtype=np.int64), 1 + j, 2 + j], axis=1)], [np.ones(n_phi, bool)]
    for i in range(len(rings) - 1):
        q0, q1 = 1 + i * na + j, 1 + (i + 1) * na + j
        tris += [np.stack([q0, q0 + 1, q1 + 1], axis=1), np.stack([q0, q1 + 1, q1], axis=1)]
        core += [np.full(n_phi, rings[i + 1] <= a + 1e-12)] * 2
    tris, core = np.sort(np.vstack(tris), axis=1), np.concatenate(core)  # sorted: conforming splits

    # extrude: slice k joins planes k and k + 1 (the core only inside the cap)
    n2 = len(rho2)
    in_cap = x[:-1] >= x_end - 1e-9
    lo = np.concatenate([k * n2 + (tris if in_cap[k] else tris[~core]) for k in range(len(x) - 1)])
    # lo: (n_prisms, 3) bottom vertices a0 < b0 < c0; one Python step per slice, not per element
    hi = lo + n2
    t = np.concatenate([np.stack([lo[:, 0], lo[:, 1], lo[:, 2], hi[:, 2]]),
                        np.stack([lo[:, 0], lo[:, 1], hi[:, 1], hi[:, 2]]),
                        np.stack([lo[:, 0], hi[:, 0], hi[:, 1], hi[:, 2]])], axis=1)
    used, t = np.unique(t, return_inverse=True)
    t = t.reshape(4, -1)
    X, R, PHI = np.repeat(x, n2)[used], np.tile(rho2, len(x))[used], np.tile(phi2, len(x))[used]
    p = _cylindrical(X, R, PHI)
    d = p[:, t[1:]] - p[:, t[:1]]
    flip = np.einsum("ij,ij->j", d[:, 0], np.cross(d[:, 1], d[:, 2], axis=0)) < 0
    t[2, flip], t[3, flip] = t[3, flip], t[2, flip].copy()

    # P2: mid-edge nodes at the (x, r, phi) midpoints (an edge to the axis keeps its other phi)
    m1 = skfem.MeshTet1(p, t)
    straight = skfem.MeshTet2.from_mesh(m1)
    e0, e1 = m1.edges
    if not np.allclose(straight.doflocs[:, p.shape[1]:], 0.5 * (p[:, e0] + p[:, e1])):
        raise RuntimeError("scikit-fem's P2 node order is not vertices, then edges in mesh.edges order")
    phim = np.where(R[e0] == 0, PHI[e1], np.where(R[e1] == 0, PHI[e0], 0.5 * (PHI[e0] + PHI[e1])))
    doflocs = np.hstack((p, _cylindrical(0.5 * (X[e0] + X[e1]), 0.5 * (R[e0] + R[e1]), phim)))
    mesh = skfem.MeshTet2(doflocs, straight.t)

    # boundaries, from the vertices' (x, r, phi)
    bf = mesh.boundary_facets()
    fx, fr, fphi = (v[mesh.facets[:, bf]] for v in (X, R, PHI))
    tol = 1e-9 * length
    sym = np.all((fr < tol) | (np.abs(fphi) < 1e-12) | (np.abs(fphi - np.pi) < 1e-12), axis=0)
    groups = {
        "symmetry": sym,
        "base": ~sym & np.all(fx < tol, axis=0),
        "tip": ~sym & np.all(np.abs(fx - length) < tol, axis=0),
        "cavity": ~sym & ((np.all(np.abs(fr - a) < tol, axis=0) & (fx.max(axis=0) <= x_end + tol))
                          | (np.all(np.abs(fx - x_end) < tol, axis=0) & np.all(fr <= a + tol, axis=0))),
    }
    outer = ~sym & np.all(np.abs(fr - a - b) < tol, axis=0)
    xc = fx.mean(axis=0)
    for n, (x0, x1) in enumerate(tube.bands):
        groups[f"tie{n}"] = outer & (xc > x0) & (xc < x1)
    groups["outer"] = outer & ~np.any([groups[f"tie{n}"] for n in range(len(tube.bands))], axis=0)
    count = np.sum(list(groups.values()), axis=0)
    if not np.all(count == 1):
        raise RuntimeError(f"{np.sum(count != 1)} boundary facets in no group or in several")
    return skfem.MeshTet2(doflocs, mesh.t, _boundaries={name: bf[sel] for name, sel in groups.items()})


def _cylindrical(x, r, phi) -> np.ndarray:
    """Points (3, n) of the finger frame from cylindrical coordinates about the x axis."""
    return np.array([x, r * np.cos(phi), r * np.sin(phi)])
