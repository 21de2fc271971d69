"""Run gmsh on a geometry given as a Python function and write a ``.msh`` file.

A *geometry function* has the signature ``geometry(model, params, size) -> None``: it
builds the CAD with ``model.occ`` (``model`` is ``gmsh.model``), synchronises, and names
its parts with ``model.addPhysicalGroup(dim, tags, name=...)``; ``params`` is a frozen
dataclass (or a mapping) of its dimensions in mm, ``size`` the target element size in mm
(it may refine locally with gmsh mesh size fields; point sizes are ignored). Only elements in physical groups are saved, so a
geometry without a group of its top dimension gets one named ``"domain"``.

gmsh is imported only inside ``meshes/``; callers use :mod:`softhand.meshes.cache`.
"""
from __future__ import annotations

import signal
from pathlib import Path
from typing import Any, Callable

import gmsh

from softhand.meshes.atomic import atomic_path

Geometry = Callable[[Any, Any, float], None]

GMSH_VERSION = gmsh.__version__


def generate_msh(geometry: Geometry, params, path: str | Path, *, size: float,
                 order: int = 2, refine: int = 0) -> Path:
    """Mesh ``geometry(model, params, size)`` with elements of ``order`` (1 or 2); write ``path``.

    ``refine`` > 0 splits every element into 8 (tetrahedra; 4 for triangles) that many times
    after meshing: a nested family for convergence studies (h halves per level, the shape of
    any size field is kept). gmsh places the new vertices on the curved CAD surfaces.
    """
    if not size > 0 or order not in (1, 2) or refine not in range(0, 4):
        raise ValueError(f"size must be > 0, order 1 or 2 and refine 0..3, "
                         f"got size={size}, order={order}, refine={refine}")
    started_here = not gmsh.isInitialized()
    if started_here:
        handlers = _signal_handlers()
        gmsh.initialize(readConfigFiles=False, interruptible=False)
        _restore(handlers)
    try:
        gmsh.model.add(getattr(geometry, "__name__", "geometry"))
        _set_options(size)
        geometry(gmsh.model, params, size)
        gmsh.model.occ.synchronize()
        dim = gmsh.model.getDimension()
        _ensure_domain_group(dim)
        gmsh.model.mesh.generate(dim)
        for _ in range(refine):
            gmsh.model.mesh.refine()
        if order == 2:
            gmsh.model.mesh.setOrder(2)
        with atomic_path(path) as tmp:
            gmsh.write(str(tmp))
        return Path(path)
    finally:
        gmsh.model.remove()
        if started_here:
            gmsh.finalize()
            _restore(handlers)


#: the signals whose Python handlers gmsh's C++ library replaces at the C level (a SIGTERM then
#: killed the process outright, skipping the CLI's clean-up of a stopped run)
_SIGNALS = (signal.SIGINT, signal.SIGTERM)


def _signal_handlers() -> dict:
    return {s: signal.getsignal(s) for s in _SIGNALS}


def _restore(handlers: dict) -> None:
    """Install the Python handlers again (at the C level too); only the main thread can."""
    for sig, handler in handlers.items():
        if handler is not None:
            try:
                signal.signal(sig, handler)
            except ValueError:  # not the main thread: nothing was installed from here either
                return


def _set_options(size: float) -> None:
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    # gmsh otherwise also caps sizes at the OCC points' default size (~ bounding box / 10),
    # which made ``size`` ineffective above that; local refinement: use mesh size fields
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 1)
    gmsh.option.setNumber("Mesh.SaveAll", 0)


def _ensure_domain_group(dim: int) -> None:
    if not gmsh.model.getPhysicalGroups(dim):
        tags = [tag for _, tag in gmsh.model.getEntities(dim)]
        gmsh.model.addPhysicalGroup(dim, tags, name="domain")


def name_groups(model, dim: int, groups: dict[str, list[int]]) -> None:
    """Add a physical group per non-empty entry of ``groups`` (name -> entity tags of ``dim``)."""
    for name, tags in groups.items():
        if tags:
            model.addPhysicalGroup(dim, list(tags), name=name)
