"""The thick-walled tube: the finger's rubber tube and the verification cases' specimen.

Axis along z, base at z = 0, cavity from z = 0 to ``length``; with ``cap`` > 0 an end cap
of that thickness closes the cavity (the tube then ends at z = length + cap).
``sector`` cuts the model on symmetry planes: ``"half"`` keeps y >= 0, ``"quarter"``
keeps x >= 0 and y >= 0.

Physical groups: volume ``wall``; surfaces ``inner`` (the cavity: inner cylinder and
the cap's inner face), ``outer`` (outer cylinder), ``base`` (z = 0), ``tip`` (the end face
at z = length + cap), ``symmetry`` (the plane y = 0, half and quarter models) and
``symmetry_x`` (the plane x = 0, quarter model).
"""
from __future__ import annotations

from dataclasses import dataclass

import skfem

from softhand.meshes.cache import load_mesh
from softhand.meshes.gmsh_io import name_groups

SECTORS = ("full", "half", "quarter")


@dataclass(frozen=True)
class Tube:
    inner_radius: float  #: cavity radius [mm]
    outer_radius: float  #: outer radius [mm]
    length: float        #: cavity length [mm]
    cap: float = 0.0     #: end-cap thickness at z = length [mm]; 0: open end
    sector: str = "full"  #: "full", "half" (y >= 0) or "quarter" (x, y >= 0)

    def __post_init__(self):
        if not 0 < self.inner_radius < self.outer_radius or not self.length > 0:
            raise ValueError(f"need 0 < inner_radius < outer_radius and length > 0: {self}")
        if self.cap < 0 or self.sector not in SECTORS:
            raise ValueError(f"need cap >= 0 and sector in {SECTORS}: {self}")


def tube_geometry(model, tube: Tube, size: float) -> None:
    """gmsh geometry function (see :mod:`softhand.meshes.gmsh_io`) of a :class:`Tube`."""
    occ = model.occ
    top = tube.length + tube.cap
    body = [(3, occ.addCylinder(0, 0, 0, 0, 0, top, tube.outer_radius))]
    hole = [(3, occ.addCylinder(0, 0, 0, 0, 0, tube.length, tube.inner_radius))]
    body, _ = occ.cut(body, hole)
    if tube.sector != "full":
        r = 2 * tube.outer_radius
        x0 = 0.0 if tube.sector == "quarter" else -r
        box = [(3, occ.addBox(x0, 0, -1, r - x0, r, top + 2))]
        body, _ = occ.intersect(body, box)
    occ.synchronize()
    name_groups(model, 3, {"wall": [tag for _, tag in body]})
    name_groups(model, 2, _classify_surfaces(model, tube))


def _classify_surfaces(model, tube: Tube) -> dict[str, list[int]]:
    top = tube.length + tube.cap
    eps = 1e-6 * tube.outer_radius
    mid_radius = 0.5 * (tube.inner_radius + tube.outer_radius)
    groups = {"inner": [], "outer": [], "base": [], "tip": [], "symmetry": [], "symmetry_x": []}
    for _, tag in model.getEntities(2):
        x0, y0, z0, x1, y1, z1 = model.getBoundingBox(2, tag)
        if abs(z1 - z0) < eps:  # a plane z = const
            z = 0.5 * (z0 + z1)
            name = "base" if abs(z) < eps else "tip" if abs(z - top) < eps else "inner"
        elif abs(y1 - y0) < eps:
            name = "symmetry"
        elif abs(x1 - x0) < eps:
            name = "symmetry_x"
        else:  # a cylinder: its extent tells which
            extent = max(abs(x0), abs(x1), abs(y0), abs(y1))
            name = "outer" if extent > mid_radius else "inner"
        groups[name].append(tag)
    return groups


def tube_mesh(tube: Tube, *, size: float, order: int = 2, refine: int = 0) -> skfem.Mesh:
    """The cached mesh of ``tube`` with element size ``size`` [mm] (MeshTet2 for order 2),
    each element split ``refine`` times (see :func:`softhand.meshes.gmsh_io.generate_msh`)."""
    return load_mesh(tube_geometry, tube, size=size, order=order, refine=refine)
