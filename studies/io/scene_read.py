"""Read a VTK result (a ``.vtm`` scene, a ``.vtu``, or one step of a ``.pvd``) into named
pyvista blocks, and pick a field from them; a file that is not one is one InputError.

:mod:`.render` draws what this reads.
"""
from __future__ import annotations

import contextlib
import logging
import re
from pathlib import Path

import numpy as np
import pyvista as pv

from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.io.render_style import step_index

__all__ = ["SUFFIXES", "field_names", "field_values", "load_scene"]

SUFFIXES = (".vtu", ".vtm", ".pvd", ".vtk")


def load_scene(path: str | Path, step: int | None = None) -> tuple[pv.MultiBlock, int, int]:
    """(named blocks, step index, number of steps) of a VTK file; a single dataset is one
    block named after the file."""
    path = Path(path)
    if path.suffix not in SUFFIXES or not path.is_file():
        raise InputError("file", str(path), f"must be an existing {'/'.join(SUFFIXES)} file")
    _sniff(path)
    _check_sizes(path)
    with pv.vtk_verbosity("off"), _quiet_logging():
        try:
            reader = pv.get_reader(str(path))
            n = len(reader.time_values) if path.suffix == ".pvd" else 1
            index = step_index(step, n)
            if path.suffix == ".pvd":
                reader.set_active_time_point(index)
            data = reader.read()
        except InputError:
            raise
        except RecursionError:
            raise InputError("file", str(path), "must be a VTK file that does not name itself "
                                                "(directly or through the files it names)") from None
        except Exception as exc:  # VTK reports bad files through many exception types
            raise InputError("file", str(path), f"must be a readable VTK file: {_first_line(exc)}") from None
    scene = _flatten(data, path.stem)
    if not any(b.n_points for b in scene):
        raise InputError("file", str(path), "must be a VTK file with a mesh VTK can read (it read no "
                                            "points: none, or in a piece with an array it could not "
                                            "parse, e.g. nan in ASCII)")
    for name, block in zip(scene.keys(), scene):
        _check_block(block, name, path)
    return scene, index, n


#: most points or cells a piece of a file may declare (a result of this toolkit has < 1e7)
MAX_ENTITIES = 100_000_000
#: the file is searched for declared sizes in chunks of this many bytes [bytes]
CHUNK_BYTES = 1 << 20
#: sizes an XML file declares (NumberOfPoints="n", either quote), the files a .pvd / .vtm names
_XML_SIZE = re.compile(rb"""(NumberOf\w+)\s*=\s*["']\s*(\d+)""")
_XML_FILE = re.compile(rb"""\bfile\s*=\s*(?:"([^"]*)"|'([^']*)')""")
#: sizes a legacy .vtk declares: POINTS n, CELLS n m, POLYGONS n m, ..., DIMENSIONS nx ny nz
_LEGACY_SIZE = re.compile(rb"^[ \t]*(POINTS|CELLS|CELL_TYPES|VERTICES|LINES|POLYGONS|TRIANGLE_STRIPS|"
                          rb"POINT_DATA|CELL_DATA|OFFSETS|CONNECTIVITY)[ \t]+(\d+)(?:[ \t]+(\d+))?",
                          re.MULTILINE)
_LEGACY_DIMENSIONS = re.compile(rb"^[ \t]*DIMENSIONS[ \t]+(\d+)[ \t]+(\d+)[ \t]+(\d+)", re.MULTILINE)


def _chunks(path: Path):
    """The file's bytes in overlapping chunks (a declaration split by a chunk's end is seen
    whole in the next), up to an XML file's appended binary data, which declares nothing."""
    with path.open("rb") as f:
        tail = b""
        while True:
            chunk = f.read(CHUNK_BYTES)
            if not chunk:
                return
            text = tail + chunk
            end = text.find(b"<AppendedData")
            yield text if end < 0 else text[:end]
            if end >= 0:
                return
            tail = text[-256:]


def _declared(text: bytes):
    """(what, count) of every size the text declares, XML or legacy."""
    for key, count in _XML_SIZE.findall(text):
        yield key.decode(), int(count)
    for key, *counts in _LEGACY_SIZE.findall(text):
        for count in filter(None, counts):
            yield key.decode(), int(count)
    for dims in _LEGACY_DIMENSIONS.findall(text):
        yield "DIMENSIONS (points)", int(np.prod([float(d) for d in dims]))


def _check_sizes(path: Path, depth: int = 0) -> None:
    """No piece of the file (or of the files a .pvd / .vtm names) declares more than
    MAX_ENTITIES points or cells: VTK allocates them before reading and aborts the process
    when it cannot."""
    names, steps = [], False
    try:
        for text in _chunks(path):
            for key, count in _declared(text):
                if count > MAX_ENTITIES:
                    raise InputError("file", str(path), f"declares {key} = {count}; "
                                     f"at most {MAX_ENTITIES} (not a result of this toolkit?)")
            if b"<!DOCTYPE" in text or b"<!ENTITY" in text:  # entities expand (a "billion laughs")
                raise InputError("file", str(path), "declares XML entities (a DOCTYPE); a VTK file has none")
            steps = steps or re.search(rb"<DataSet\b", text) is not None
            names += [(a or b) for a, b in _XML_FILE.findall(text)]
    except OSError:
        return  # VTK's reader reports it
    if path.suffix == ".pvd" and depth == 0 and not steps:
        raise InputError("file", str(path), "must be a VTK series with at least one step (this .pvd "
                                            "names no DataSet)")
    if path.suffix in (".pvd", ".vtm") and depth < 2:
        for name in dict.fromkeys(names):
            child = path.parent / name.decode("utf-8", "replace")
            if child.is_file():
                _check_sizes(child, depth + 1)


#: VTK's cell type ids (pyvista.CellType)
CELL_TYPES = np.array(sorted(int(t) for t in pv.CellType))


def _check_block(block: pv.DataSet, name: str, path: Path) -> None:
    """Finite points, cells that name existing points, known cell types: VTK's renderer
    crashes the process on a cell with an index out of range."""
    if not np.all(np.isfinite(block.points)):
        raise InputError("file", str(path), f"block {name!r} has points that are not finite numbers")
    arrays = []
    if isinstance(block, pv.UnstructuredGrid):
        arrays.append(block.cell_connectivity)
        if not np.isin(block.celltypes, CELL_TYPES).all():
            bad = block.celltypes[~np.isin(block.celltypes, CELL_TYPES)][0]
            raise InputError("file", str(path), f"block {name!r} has cells of unknown VTK type {bad}")
    elif isinstance(block, pv.PolyData):
        from vtkmodules.util.numpy_support import vtk_to_numpy

        for cells in (block.GetVerts(), block.GetLines(), block.GetPolys(), block.GetStrips()):
            arrays.append(vtk_to_numpy(cells.GetConnectivityArray()))
    for ids in arrays:
        if ids.size and (ids.min() < 0 or ids.max() >= block.n_points):
            raise InputError("file", str(path), f"block {name!r} has cells naming points outside "
                             f"0..{block.n_points - 1}")


def _flatten(data, name: str) -> pv.MultiBlock:
    """Nested multiblocks (a .pvd step of a .vtm) -> one level of named non-empty datasets."""
    out = pv.MultiBlock()
    if not isinstance(data, pv.MultiBlock):
        out[name] = data
        return out
    for key, block in zip(data.keys(), data):
        if isinstance(block, pv.MultiBlock):
            inner = _flatten(block, key)
            for k, b in zip(inner.keys(), inner):
                out[k] = b
        elif block is not None and block.n_points:  # a .vtu in a .pvd: named after the file
            out[name if re.fullmatch(r"Block-\d+", key or "Block-0") else key] = block
    return out


def field_values(mesh: pv.DataSet, name: str) -> tuple[np.ndarray, str]:
    """(scalar values, "point"|"cell") of field ``name`` or ``name[i]`` on ``mesh``."""
    match = re.fullmatch(r"(.+?)(?:\[(\d+)\])?", name)
    base, component = match.group(1), match.group(2)
    for location, data in (("point", mesh.point_data), ("cell", mesh.cell_data)):
        if base in data:
            values = np.asarray(data[base], dtype=float)
            break
    else:
        raise InputError("field", name, f"allowed: {', '.join(field_names(mesh))}")
    if values.ndim == 1:
        if component not in (None, "0"):
            raise InputError("field", name, f"{base} is a scalar; use it without [i]")
        return values, location
    if component is None:
        return np.linalg.norm(values, axis=1), location
    if int(component) >= values.shape[1]:
        raise InputError("field", name, f"{base} has components [0]..[{values.shape[1] - 1}]")
    return values[:, int(component)], location


def field_names(mesh: pv.DataSet) -> list[str]:
    """The names of the point and cell arrays, each once."""
    return list(dict.fromkeys([*mesh.point_data.keys(), *mesh.cell_data.keys()]))


def _sniff(path: Path) -> None:
    """A VTK file starts with its XML header or the legacy '# vtk DataFile' line."""
    with path.open("rb") as f:
        head = f.read(256).lstrip()
    if not (head.startswith(b"<?xml") or head.startswith(b"<VTKFile")
            or head.startswith(b"# vtk DataFile")):
        raise InputError("file", str(path), "must be a VTK file (XML .vtu/.vtm/.pvd or legacy .vtk)")


@contextlib.contextmanager
def _quiet_logging():
    """pyvista forwards VTK errors to the logging module; the CLI reports one line instead."""
    logging.disable(logging.CRITICAL)
    try:
        yield
    finally:
        logging.disable(logging.NOTSET)


def _first_line(exc: Exception) -> str:
    return next((line.strip() for line in str(exc).splitlines() if line.strip()),
                type(exc).__name__)
