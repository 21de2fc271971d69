"""A thick spherical shell in the r–z half plane (quarter annulus), for the balloon check.

Inner radius A, outer radius B; polar angle φ from the axis (φ = 0, r = 0) to the equator
(φ = π/2, z = 0), which is a symmetry plane. Quadratic geometry (``MeshQuad2``): the nodes of
a structured (ρ, φ) grid mapped to r = ρ sin φ, z = ρ cos φ, so the circles are followed to
O(h³). Named boundaries: ``axis``, ``equator``, ``inner`` (the cavity), ``outer``.
"""
from __future__ import annotations

import numpy as np
from skfem import MeshQuad, MeshQuad2

__all__ = ["shell_mesh"]


def shell_mesh(A: float, B: float, *, n_radial: int = 2, n_polar: int = 16) -> MeshQuad2:
    """Quarter annulus A <= ρ <= B, 0 <= φ <= π/2 with n_radial x n_polar curved Q2 cells."""
    if not 0 < A < B or n_radial < 1 or n_polar < 1:
        raise ValueError(f"bad shell mesh A={A}, B={B}, n_radial={n_radial}, n_polar={n_polar}")
    grid = MeshQuad2.from_mesh(MeshQuad.init_tensor(np.linspace(A, B, n_radial + 1),
                                                    np.linspace(0.0, np.pi / 2, n_polar + 1)))
    rho, phi = grid.doflocs
    tol, half = 1e-9 * B, 0.5 * (B - A) / n_radial  # chord midpoints lie inside their circle
    curved = lambda x: (x[0] > tol) & (x[1] > tol)  # noqa: E731 (not the axis or equator)
    return MeshQuad2(np.array([rho * np.sin(phi), rho * np.cos(phi)]), grid.t).with_boundaries({
        "axis": lambda x: x[0] < tol,
        "equator": lambda x: x[1] < tol,
        "inner": lambda x: curved(x) & (np.hypot(x[0], x[1]) < A + half),
        "outer": lambda x: curved(x) & (np.hypot(x[0], x[1]) > B - half),
    })
