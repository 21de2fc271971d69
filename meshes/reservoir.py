"""The reservoir sheet in the r–z half plane: a structured quadrilateral mesh.

The sheet is the rectangle 0 <= r <= R, 0 <= z <= t (the oil-wetted underside at z = 0,
the clamp plane). A rectangle needs no gmsh: a tensor-product mesh gives exact
through-thickness layers and a radial spacing graded towards the clamp, where the sheet
bends most. Named boundaries (``mesh.boundaries``): ``axis`` (r = 0), ``clamp`` (r = R),
``wet`` (z = 0, oil side), ``dry`` (z = t). Building it takes milliseconds, so there is
nothing to cache.
"""
from __future__ import annotations

import numpy as np
from skfem import MeshQuad

__all__ = ["graded", "sheet_mesh"]


def graded(length: float, n: int, ratio: float) -> np.ndarray:
    """n + 1 node positions on [0, length] whose element sizes shrink geometrically by ``ratio``
    (first / last element) from 0 towards ``length``."""
    q = ratio ** (-1.0 / max(n - 1, 1))
    sizes = q ** np.arange(n)
    return length * np.concatenate([[0.0], np.cumsum(sizes) / sizes.sum()])


def sheet_mesh(R: float, t: float, *, n_radial: int = 40, n_thick: int = 2,
               clamp_ratio: float = 3.0) -> MeshQuad:
    """Sheet of radius R [mm] and thickness t [mm]: n_radial x n_thick quadrilaterals.

    Radial elements shrink by ``clamp_ratio`` from the axis to the clamp; layers are even.
    """
    if n_radial < 1 or n_thick < 1 or not R > 0 or not t > 0:
        raise ValueError(f"bad sheet mesh R={R}, t={t}, n_radial={n_radial}, n_thick={n_thick}")
    r = graded(R, n_radial, clamp_ratio)
    z = np.linspace(0.0, t, n_thick + 1)
    tol = 1e-9 * max(R, t)
    return MeshQuad.init_tensor(r, z).with_boundaries({
        "axis": lambda x: x[0] < tol,
        "clamp": lambda x: x[0] > R - tol,
        "wet": lambda x: x[1] < tol,
        "dry": lambda x: x[1] > t - tol,
    })
