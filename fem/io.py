r"""VTK output of a solid's state: ``.vtu`` per state, ``.pvd`` over load steps.

Fields written (3D displacement bases ``ElementVector`` of P1/P2 tetrahedra):

* point data: ``displacement_mm``, ``principal_stretches`` (λ1 ≥ λ2 ≥ λ3, the square
  roots of the eigenvalues of :math:`C = F^T F`), ``cauchy_stress_MPa`` (the 9 components,
  row-major), ``von_mises_MPa`` (:math:`\sqrt{3/2\, s:s}`, s = dev σ), ``J`` and, when the
  law has a fiber family, ``fiber_stretch`` :math:`|F a_0|` (the name carries the unit;
  stretches and J have none); a model may add its own (the finger: ``rubber_stretch``, the
  principal stretch averaged over a ball, :mod:`softhand.fem.rubber_stretch`);
* cell data: the same stress-like quantities averaged over each element's quadrature points.

Quadratic meshes are written as **quadratic cells** (``tetra10``), so ParaView and pyvista
draw the curved P2 geometry; the points are the P2 nodes (vertices and edge midpoints).
Gradients are discontinuous between elements: point values are the lumped P1 L2 projection
of the quadrature-point values onto the vertices (edge midpoints: the mean of their two
vertices), so a field is never evaluated where the state is not known to be valid. Cauchy stress is
:math:`σ = P F^T / J`; with ``J_bar`` (per element, the mean dilatation of a
mean-dilatation solid) its volumetric part is :math:`U'(\bar J)\,I`, as in that formulation.

A *scene* (:func:`write_scene`, :class:`SceneSeries`) is a ``.vtm`` multiblock file of
named blocks (:class:`softhand.fem.hand.scene.Block`: the tube, the links, the object, ...), each a
``.vtu`` in a folder next to it; a :class:`SceneSeries` lists one scene per load step in
a ``.pvd``. All files are written atomically (temporary name + rename).
"""
from __future__ import annotations

from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
from skfem import Basis, ElementTetP1

from softhand.fem import kinematics as kin
from softhand.meshes.atomic import atomic_path
from softhand.meshes.convert import write_vtu

#: scikit-fem scalar element -> VTK cell type (scikit-fem's local node order is VTK's)
CELL_TYPES = {
    "ElementTetP2": "tetra10", "ElementTetP1": "tetra",
    "ElementTriP2": "triangle6", "ElementTriP1": "triangle",
    "ElementQuad2": "quad9", "ElementQuad1": "quad",
}


def state_fields(basis: Basis, u: np.ndarray, law=None, *, J_bar=None, extra=None) -> tuple[dict, dict]:
    """(point_data, cell_data) of displacement ``u`` on the vector ``basis`` (see module doc);
    ``extra``: more fields by name, given at the basis' quadrature points (nel, nqp)."""
    scalar = basis.split(u)[0][1]
    point_data = {"displacement_mm": _nodal_vector(basis, u)}
    if law is None:
        return point_data, {}
    qp_values = {**_measures(basis, u, _per_element(law, basis.mesh.nelements), J_bar), **(extra or {})}
    vertex_basis = basis.with_element(ElementTetP1())
    for name, value in qp_values.items():
        point_data[name] = _extend_to_nodes(_lumped_projection(value, vertex_basis), scalar)
    cell_data = {name: _average_cells(value, basis.dx) for name, value in qp_values.items()}
    return point_data, cell_data


def write_state(path: str | Path, basis: Basis, u: np.ndarray, law=None, *, J_bar=None,
                point_data: dict | None = None, cell_data: dict | None = None) -> Path:
    """Write one ``.vtu``: the state's fields plus any extra point data (per P2 node or per
    vertex; vertex data are extended to edge midpoints by averaging) and cell data."""
    scalar = basis.split(u)[0][1]
    points, cells = _geometry(scalar)
    fields_p, fields_c = state_fields(basis, u, law, J_bar=J_bar)
    for name, value in (point_data or {}).items():
        fields_p[name] = _extend_to_nodes(np.asarray(value), scalar)
    fields_c.update({k: np.asarray(v) for k, v in (cell_data or {}).items()})
    return write_vtu(path, points, cells, point_data=fields_p, cell_data=fields_c)


class VtkSeries:
    """A ``.pvd`` collection over load steps; each ``write()`` adds a ``.vtu`` and rewrites
    the ``.pvd`` (atomically), so after an interruption every listed state is complete."""

    def __init__(self, pvd_path: str | Path):
        self.path = Path(pvd_path)
        self.entries: list[tuple[float, str]] = []

    def write(self, time: float, basis: Basis, u: np.ndarray, law=None, **extra) -> Path:
        """Write the state at load parameter ``time`` (e.g. pressure in MPa); see :func:`write_state`."""
        vtu = self.path.with_name(f"{self.path.stem}_{len(self.entries):04d}.vtu")
        write_state(vtu, basis, u, law, **extra)
        self.entries.append((float(time), vtu.name))
        write_pvd(self.path, self.entries)
        return vtu


def write_scene(path: str | Path, blocks, field_data: dict | None = None) -> Path:
    """Write the blocks (:class:`softhand.fem.hand.scene.Block`) as ``<stem>/<name>.vtu`` and the ``.vtm``
    listing them by name; every block gets ``field_data`` (numbers, e.g. the pressure)."""
    path = Path(path)
    rows = []
    for index, block in enumerate(blocks):
        name = f"{path.stem}/{block.name}.vtu"
        write_vtu(path.parent / name, block.points, block.cells, point_data=block.point_data,
                  cell_data=block.cell_data, field_data=field_data)
        rows.append(f'    <DataSet index="{index}" name={quoteattr(block.name)} file={quoteattr(name)}/>\n')
    text = ('<?xml version="1.0"?>\n<VTKFile type="vtkMultiBlockDataSet" version="1.0">\n'
            f"  <vtkMultiBlockDataSet>\n{''.join(rows)}  </vtkMultiBlockDataSet>\n</VTKFile>\n")
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    return path


class SceneSeries:
    """A ``.pvd`` of scenes over load steps (like :class:`VtkSeries`), the ``.vtm`` of step k
    and its blocks in the folder ``<stem>/`` next to it: ``<stem>_<k>.vtm``, ``<stem>_<k>/*.vtu``."""

    def __init__(self, pvd_path: str | Path):
        self.path = Path(pvd_path)
        self.entries: list[tuple[float, str]] = []

    def write(self, time: float, blocks, field_data: dict | None = None) -> Path:
        """Write the scene at load parameter ``time`` (the pressure [MPa], or the volume [mm³])."""
        name = f"{self.path.stem}/{self.path.stem}_{len(self.entries):04d}.vtm"
        write_scene(self.path.parent / name, blocks, {"step": len(self.entries), **(field_data or {})})
        self.entries.append((float(time), name))
        write_pvd(self.path, self.entries)
        return self.path.parent / name


def write_pvd(path: str | Path, entries: list[tuple[float, str]]) -> Path:
    """A ParaView collection file listing (time, file name relative to the .pvd)."""
    rows = "".join(f'    <DataSet timestep="{t!r}" part="0" file={quoteattr(name)}/>\n'
                   for t, name in entries)
    text = ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
            f"  <Collection>\n{rows}  </Collection>\n</VTKFile>\n")
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    return Path(path)


def _measures(basis: Basis, u, law, J_bar) -> dict:
    """Stretch and stress measures at the basis' points, each shape (nel, npts[, ncomp])."""
    F = kin.deformation_gradient(basis.interpolate(u).grad)
    J = kin.det(F)
    sigma = _cauchy(F, J, law, J_bar)
    s = sigma - np.trace(sigma) / 3.0 * kin.identity(J.shape)
    C = kin.right_cauchy_green(F)
    eig = np.linalg.eigvalsh(np.moveaxis(C, (0, 1), (-2, -1)))
    out = {
        "principal_stretches": np.sqrt(np.clip(eig, 0.0, None))[..., ::-1],
        "cauchy_stress_MPa": np.moveaxis(sigma, (0, 1), (-2, -1)).reshape(J.shape + (9,)),
        "von_mises_MPa": np.sqrt(1.5 * np.einsum("ab...,ab...->...", s, s)),
        "J": J,
    }
    fibers = [p for p in getattr(law, "parts", (law,)) if hasattr(p, "stretch")]
    if fibers:
        out["fiber_stretch"] = fibers[0].stretch(F)
    return out


def _cauchy(F, J, law, J_bar):
    if J_bar is None:
        return np.einsum("aK...,bK...->ab...", law.stress(F), F) / J
    dev, vol = law.split()
    sigma = np.einsum("aK...,bK...->ab...", dev.stress(F), F) / J
    p = vol.dU(np.asarray(J_bar, dtype=float))[:, None] * np.ones_like(J)
    return sigma + p * kin.identity(J.shape)


def _per_element(law, nel: int):
    """The law with per-quadrature-point fiber directions averaged per element (3, nel),
    so it can be evaluated at any points of the elements (nodes for the point data)."""
    parts = getattr(law, "parts", None)
    if parts is not None:
        return type(law)(tuple(_per_element(p, nel) for p in parts))
    a0 = getattr(law, "a0", None)
    if a0 is not None and a0.ndim == 3:
        return type(law)(law.k, a0.mean(axis=2))
    return law


def _lumped_projection(value: np.ndarray, vertex_basis: Basis) -> np.ndarray:
    """Vertex values of quadrature-point values (nel, nqp[, ncomp]) by the lumped P1 L2
    projection: sum_e int phi_i f dV / sum_e int phi_i dV (exact for constants, no
    evaluation outside the quadrature points, where the state is known to be valid)."""
    n = vertex_basis.mesh.nvertices
    phi = np.stack([vertex_basis.basis[i][0] for i in range(vertex_basis.Nbfun)])  # (nloc, nel, nqp)
    weights = phi * np.asarray(vertex_basis.dx)[None]
    vertices = vertex_basis.element_dofs.ravel()  # (nloc * nel,), matching weights' order
    flat = value.reshape(value.shape[:2] + (-1,))
    numerators = np.einsum("leq,eqc->lec", weights, flat).reshape(len(vertices), -1)
    denominator = np.bincount(vertices, weights=weights.sum(axis=2).ravel(), minlength=n)
    out = np.stack([np.bincount(vertices, weights=numerators[:, c], minlength=n)
                    for c in range(numerators.shape[1])], axis=1) / denominator[:, None]
    return out.reshape((n,) + value.shape[2:])


def _average_cells(value: np.ndarray, dx: np.ndarray) -> np.ndarray:
    """Volume-weighted mean over each element's quadrature points."""
    weights = dx / dx.sum(axis=1, keepdims=True)
    return np.einsum("eq,eq...->e...", weights, value)


def _nodal_vector(basis: Basis, u: np.ndarray) -> np.ndarray:
    """A vector field's nodal values as (n_nodes, dim)."""
    return np.stack([part for part, _ in basis.split(u)], axis=1)


def _geometry(scalar: Basis) -> tuple[np.ndarray, dict]:
    points = scalar.doflocs.T
    if points.shape[1] == 2:
        points = np.hstack([points, np.zeros((points.shape[0], 1))])
    cell_type = CELL_TYPES[type(scalar.elem).__name__]
    return points, {cell_type: scalar.element_dofs.T}


def _extend_to_nodes(value: np.ndarray, scalar: Basis) -> np.ndarray:
    """Point data given per vertex -> per node (edge midpoints get their end points' mean)."""
    if value.shape[0] == scalar.N:
        return value
    mesh = scalar.mesh
    if value.shape[0] != mesh.nvertices or scalar.N != mesh.nvertices + mesh.nedges:
        raise ValueError(f"point data of length {value.shape[0]}: need {scalar.N} nodes "
                         f"or {mesh.nvertices} vertices")
    return np.concatenate([value, 0.5 * (value[mesh.edges[0]] + value[mesh.edges[1]])])


def solid_output(solid, u: np.ndarray) -> dict:
    """Keyword arguments of :func:`write_state` / :meth:`VtkSeries.write` for a
    :class:`softhand.fem.solid.Solid` (its vector basis, law and, if mean-dilatation, J_bar)."""
    from skfem import ElementVector

    basis = Basis(solid.mesh, ElementVector(solid.element), intorder=2)
    J_bar = None
    if getattr(solid, "formulation", None) == "mean_dilatation":
        J = kin.det(solid.F(u))
        J_bar = (solid.W * J).sum(axis=1) / solid.W.sum(axis=1)
    return {"basis": basis, "u": u, "law": solid.law, "J_bar": J_bar}
