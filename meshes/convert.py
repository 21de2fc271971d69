"""Mesh files <-> memory, through meshio (the one module of the project that imports it).

* :func:`read_mesh`: a gmsh ``.msh`` (or any meshio-readable file) -> a scikit-fem mesh
  whose ``boundaries`` and ``subdomains`` carry the file's physical-group names.
  ``tetra10``/``tetra`` -> :class:`skfem.MeshTet2`/:class:`skfem.MeshTet1`,
  ``triangle6``/``triangle`` -> ``MeshTri2``/``MeshTri1``, ``quad9``/``quad`` -> ``MeshQuad2``/
  ``MeshQuad1``. Quadratic meshes keep their curved (isoparametric) geometry.
* :func:`write_vtu`: points + cells + fields -> a ``.vtu`` file, atomically.

A physical group of the top dimension becomes a subdomain (element indices); one of the
dimension below becomes a boundary (facet indices, matched by the facets' vertices).
"""
from __future__ import annotations

import contextlib
import io
from pathlib import Path

import meshio
import numpy as np
import skfem

from softhand.meshes.atomic import atomic_path
from softhand.reduced.vocabulary.errors import InputError

#: meshio cell type -> (scikit-fem mesh class, meshio facet types that bound it)
_VOLUME_TYPES = {
    "tetra10": (skfem.MeshTet2, ("triangle6", "triangle")),
    "tetra": (skfem.MeshTet1, ("triangle",)),
    "triangle6": (skfem.MeshTri2, ("line3", "line")),
    "triangle": (skfem.MeshTri1, ("line",)),
    "quad9": (skfem.MeshQuad2, ("line3", "line")),
    "quad": (skfem.MeshQuad1, ("line",)),
}


def read_mesh(path: str | Path) -> skfem.Mesh:
    """Read a mesh file into a scikit-fem mesh with named boundaries and subdomains."""
    raw = _read_meshio(path)
    cell_type = next((t for t in _VOLUME_TYPES if t in raw.cells_dict), None)
    if cell_type is None:
        raise InputError("mesh file", str(path), "has no tetrahedra, triangles or quads")
    mesh_class, facet_types = _VOLUME_TYPES[cell_type]
    cells = raw.cells_dict[cell_type]
    dim = mesh_class.elem.refdom.dim()
    mesh = mesh_class(np.ascontiguousarray(raw.points[:, :dim].T), np.ascontiguousarray(cells.T))
    vertices = np.unique(cells[:, :mesh_class.elem.refdom.nnodes])  # old ids of the new 0..n-1
    subdomains, boundaries = {}, {}
    for name, blocks in raw.cell_sets_dict.items():
        if name.startswith("gmsh:"):
            continue
        if cell_type in blocks:
            subdomains[name] = np.sort(blocks[cell_type]).astype(np.int64)
        facet_type = next((t for t in facet_types if t in blocks), None)
        if facet_type is not None:
            corners = raw.cells_dict[facet_type][blocks[facet_type]][:, :dim]
            boundaries[name] = _match_facets(mesh, np.searchsorted(vertices, corners.T))
    return mesh.with_boundaries(boundaries).with_subdomains(subdomains)


def write_vtu(path: str | Path, points: np.ndarray, cells: dict[str, np.ndarray], *,
              point_data: dict | None = None, cell_data: dict | None = None,
              field_data: dict | None = None) -> Path:
    """Write a ``.vtu`` atomically; ``cells`` maps a meshio cell type to (ncells, nnodes);
    ``field_data``: numbers of the whole dataset (e.g. the pressure), as VTK FieldData."""
    mesh = meshio.Mesh(
        np.asarray(points, dtype=float),
        [(cell_type, np.asarray(conn)) for cell_type, conn in cells.items()],
        point_data={k: np.asarray(v) for k, v in (point_data or {}).items()},
        cell_data={k: [np.asarray(v)] for k, v in (cell_data or {}).items()},
    )
    with atomic_path(path) as tmp:
        meshio.write(tmp, mesh, file_format="vtu")
        if field_data:  # meshio reads VTK FieldData but does not write it
            tmp.write_text(tmp.read_text().replace(
                "<UnstructuredGrid>", "<UnstructuredGrid>" + _field_data_xml(field_data), 1))
    return Path(path)


def _field_data_xml(field_data: dict) -> str:
    arrays = "".join(
        f'<DataArray type="Float64" Name="{name}" NumberOfTuples="{np.size(value)}" '
        f'format="ascii">{" ".join(repr(float(v)) for v in np.ravel(value))}</DataArray>'
        for name, value in field_data.items())
    return f"<FieldData>{arrays}</FieldData>"


def _read_meshio(path: str | Path):
    path = Path(path)
    if not path.is_file():
        raise InputError("mesh file", str(path), "must be an existing mesh file")
    file_format = "gmsh" if path.suffix == ".msh" else None  # not ANSYS' .msh
    chatter = io.StringIO()
    try:  # meshio prints failed attempts and may even sys.exit(1) on a file it cannot read
        with contextlib.redirect_stdout(chatter), contextlib.redirect_stderr(chatter):
            return meshio.read(path, file_format=file_format)
    except (Exception, SystemExit) as exc:
        lines = (str(exc) if not isinstance(exc, SystemExit) else chatter.getvalue()).split("\n")
        reason = next((line.strip() for line in lines if line.strip()), type(exc).__name__)
        raise InputError("mesh file", str(path),
                         f"must be a mesh meshio can read (gmsh .msh, .vtu, ...): {reason}") from None


def _match_facets(mesh: skfem.Mesh, corners: np.ndarray) -> np.ndarray:
    """Indices into ``mesh.facets`` of the facets with vertex ids ``corners`` (nverts, n)."""
    n = np.int64(mesh.nvertices)
    keys_of = lambda f: np.ravel_multi_index(np.sort(f, axis=0).astype(np.int64),  # noqa: E731
                                             (n,) * f.shape[0])
    facet_keys = keys_of(mesh.facets)
    order = np.argsort(facet_keys)
    wanted = keys_of(corners)
    pos = np.searchsorted(facet_keys, wanted, sorter=order)
    found = order[np.minimum(pos, len(order) - 1)]
    if not np.all(facet_keys[found] == wanted):
        raise InputError("mesh file", "boundary group",
                         "every boundary element must be a facet of a volume element")
    return np.unique(found)
