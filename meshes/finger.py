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

from meshes.cache import load_mesh


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
    """gmsh geometry function (see :mod:`meshes.gmsh_io`) of a :class:`FingerTube`."""
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
    each element then split ``refine`` times (size / 2**refine; see :func:`meshes.gmsh_io.generate_msh`)."""
    return load_mesh(finger_geometry, tube, size=size, order=2, refine=refine)
