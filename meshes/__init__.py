"""gmsh geometry as code, meshes with named physical groups, and a mesh cache.

Its public face: the test tube (:class:`~softhand.meshes.tube.Tube`, :func:`~softhand.meshes.tube.tube_mesh`), imported on first use; the
finger's and the reservoir's meshers are in :mod:`softhand.meshes.finger` and
:mod:`softhand.meshes.reservoir`.
"""
if __name__ != "softhand.meshes":  # the folder on sys.path, imported by its short name
    raise ImportError(f"'{__name__}' is softhand.meshes: import softhand.meshes (after pip install -e .)")

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
