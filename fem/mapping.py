"""Facet bases on curved (isoparametric) meshes whose inverse map scikit-fem cannot find.

scikit-fem locates a facet's quadrature points inside their element by Newton's method on
the element map, started from the point (0.5, 0.5, 0.5) (outside the reference
tetrahedron) and clipped to the unit box at every step. On thin, long elements (the layered
finger mesh: 0.2 mm radially, 4 mm axially) it does not converge although the elements
are valid. :class:`RobustIsoparametric` starts instead from the inverse of the straight
element through the same vertices (exact for straight elements) and does not clip.
"""
from __future__ import annotations

import numpy as np
from skfem import FacetBasis
from skfem.mapping import MappingIsoparametric


class RobustIsoparametric(MappingIsoparametric):
    """scikit-fem's isoparametric mapping with a better-started inverse (see the module)."""

    def invF(self, x, tind=None, newton_max_iters=50, newton_tol=1e-12):
        t = self.mesh.t if tind is None else self.mesh.t[:, tind]
        p = self.mesh.p[:, t]                                   # (dim, nverts, n)
        A = np.moveaxis(p[:, 1:] - p[:, :1], -1, 0)             # (n, dim, dim): edge vectors as columns
        X = np.linalg.solve(A, np.moveaxis(x - p[:, 0, :, None], 1, 0)).transpose(1, 0, 2)
        for _ in range(newton_max_iters):
            dX = np.einsum("ijkl,jkl->ikl", self.invDF(X, tind), x - self.F(X, tind))
            X = X + dX
            if np.abs(dX).max() < newton_tol:
                return X
        raise RuntimeError(f"inverse isoparametric map did not converge (|dX| = {np.abs(dX).max():.1e})")


def facet_basis(mesh, element, **kwargs) -> FacetBasis:
    """``FacetBasis(mesh, element, **kwargs)``, with :class:`RobustIsoparametric` on curved
    simplex meshes (its starting guess needs simplices; other meshes keep scikit-fem's)."""
    if getattr(mesh, "affine", True) or mesh.t.shape[0] != mesh.dim() + 1:
        return FacetBasis(mesh, element, **kwargs)
    return FacetBasis(mesh, element, mapping=RobustIsoparametric(mesh, mesh.elem(), mesh.bndelem), **kwargs)


#: how deep an element's map may fold before the element is refused: det J anywhere below
#: -FOLD_DEPTH x its largest det J (measured on the finger's gmsh meshes: the ones whose FEM
#: converges to the right bend have at most a sliver, -0.11 at uniform h = 4 mm; the ones
#: whose Newton stops, or converges to a ballooned tube, -1.36 to -1.49)
FOLD_DEPTH = 0.5


def folded_elements(mesh, lattice: int = 5) -> np.ndarray:
    """Indices of the curved tetrahedra whose map folds over itself (see :data:`FOLD_DEPTH`):
    det J on a lattice of ``lattice`` points per reference edge (35 for 5, the vertices
    among them; the quadrature points alone miss a fold between them). Straight meshes: none."""
    if getattr(mesh, "affine", True):
        return np.zeros(0, dtype=int)
    g = np.linspace(0.0, 1.0, lattice)
    X = np.array([(x, y, z) for x in g for y in g for z in g if x + y + z <= 1.0 + 1e-12]).T
    J = mesh.mapping().detDF(X)                              # (elements, points)
    return np.flatnonzero(J.min(axis=1) < -FOLD_DEPTH * J.max(axis=1))
