r"""The rubber's stretch judged as rubber engineering judges it: averaged over a small volume.

Where rubber is bonded to something rigid (the tube to the rings of the links, the sheet to
its clamp) the elastic strain is singular at the bond's edge: the largest principal stretch
at any quadrature point grows without limit as the mesh is refined, so a limit on it judges
the mesh, not the part. Rubber design instead judges the **maximum principal stretch** (the
usual crack-nucleation predictor of rubber, Mars & Fatemi, Int. J. Fatigue 24 (2002)
949-961) **averaged over a critical volume** (the volume method of the theory of critical
distances, D. Taylor, *The Theory of Critical Distances*, Elsevier 2007), with the
bell-shaped weight of non-local strain models (Bažant & Jirásek, J. Eng. Mech. 128 (2002)
1119-1149):

.. math:: \bar\lambda(x) = \frac{\int_\Omega \alpha(|x - y|)\,\lambda(y)\,dV_y}
                                {\int_\Omega \alpha(|x - y|)\,dV_y},\qquad
          \alpha(s) = \bigl\langle 1 - s^2/\rho^2 \bigr\rangle^2

over the rubber Ω only (a point near a surface averages what rubber it has), and the
measure is its largest value, ``rubber_stretch`` = max_x λ̄(x). ρ = :data:`RADIUS_MM`
(the weight's mean distance is 0.43 ρ; a linear field is reproduced exactly wherever the
ball lies inside the rubber). The singularity is integrable, so λ̄ converges as the mesh is
refined; the pointwise peak (``max_principal_stretch``) stays reported, labelled as
mesh-dependent.

The integrals are the solver's own quadrature (points and weights). The average is linear in
the field and its weights depend on the mesh only, so it is one sparse matrix, assembled once
per mesh on first use (the pairs of points closer than ρ, from a k-d tree); each state's
λ̄ at every point is then one sparse product, and the largest is exact.
"""
from __future__ import annotations

from functools import cached_property

import numpy as np
from scipy.sparse import csr_matrix
from scipy.spatial import cKDTree

from softhand.reduced.materials.rubber_parameters import CRITICAL_DISTANCE_MM

#: the averaging radius rho [mm]: the rubber's critical distance, the scale below which its
#: stretch is not judged pointwise (a property of the rubber, so a part's measure depends on
#: the part's size: the calibrated models carry it as a/rho and R/rho)
RADIUS_MM = CRITICAL_DISTANCE_MM


def bell(s, radius: float):
    """The non-local weight alpha(s) = <1 - s^2/rho^2>^2 [-]."""
    return np.clip(1.0 - (np.asarray(s) / radius) ** 2, 0.0, None) ** 2


class Averager:
    """Non-local averages of fields sampled at fixed quadrature points.

    ``points`` (N, d) [mm] and ``weights`` (N,) [mm^3] are the quadrature; ``mirror`` (a
    coordinate index) adds the mirror image in that coordinate's zero plane (a half model
    on its symmetry plane averages over both halves).
    """

    def __init__(self, points, weights, radius: float = RADIUS_MM, *, mirror: int | None = None):
        self.points = np.asarray(points, dtype=float)
        self.weights = np.asarray(weights, dtype=float).ravel()
        if not radius > 0:
            raise ValueError(f"averaging radius must be positive, got {radius}")
        self.radius, self.n = float(radius), len(self.points)
        cloud = self.points
        if mirror is not None:
            image = self.points.copy()
            image[:, mirror] *= -1.0
            cloud = np.concatenate([cloud, image])
        self.owner = np.arange(len(cloud)) % self.n  # the point each cloud member samples
        self.tree = cKDTree(cloud)

    @cached_property
    def operator(self) -> csr_matrix:
        """The average as a matrix: lambda_bar = operator @ lambda, (N, N), rows summing to 1."""
        pairs = cKDTree(self.points).sparse_distance_matrix(self.tree, self.radius, output_type="ndarray")
        i, j = pairs["i"], self.owner[pairs["j"]]
        a = bell(pairs["v"], self.radius) * self.weights[j]
        a /= np.bincount(i, weights=a, minlength=self.n)[i]  # rows summing to 1, before the matrix
        return csr_matrix((a, (i, j)), shape=(self.n, self.n))  # mirror images summed

    def subset(self, mask) -> "Averager":
        """The averages over the points ``mask`` (N,) selects alone, as an Averager of those points
        built from them would give, from this operator (no second k-d tree query): its rows and
        columns of those points, each row scaled to sum to 1 again (a row's scale cancels)."""
        keep = np.flatnonzero(np.asarray(mask, bool).ravel())
        sub = self.operator[keep][:, keep].tocsr()
        sub = csr_matrix(sub.multiply(1.0 / np.asarray(sub.sum(axis=1)).ravel()[:, None]))
        out = object.__new__(Averager)
        out.points, out.weights, out.radius, out.n = self.points[keep], self.weights[keep], self.radius, len(keep)
        out.owner = out.tree = None  # no k-d tree: the operator is given
        out.__dict__["operator"] = sub  # the cached_property, set
        return out

    def at(self, values, centres=None) -> np.ndarray:
        """lambda_bar at the points ``centres`` (indices; default all) of ``values`` (N,)."""
        values = np.asarray(values, dtype=float).ravel()
        if centres is None:
            return self.operator @ values
        centres = np.asarray(centres, dtype=int)
        return self.operator[centres] @ values if centres.size else np.zeros(0)

    def peak(self, values, where=None) -> tuple[float, int]:
        """(max lambda_bar, the point where it is) over the points ``where`` (a mask; default all)."""
        lam = self.at(values)
        if where is not None:
            lam = np.where(np.asarray(where, bool).ravel(), lam, -np.inf)
        k = int(np.argmax(lam))
        return float(lam[k]), k


def peaks_at_radii(points, weights, fields, radii, *, mirror: int | None = None) -> np.ndarray:
    """The converged stretch of each of ``fields`` (stretches at ``points``) averaged over a ball of
    each of ``radii`` [mm], (len(fields), len(radii)): how the measure depends on a part's size, the
    averaging radius being the rubber's (one Averager, one k-d tree query, per radius)."""
    columns = []
    for radius in radii:
        averager = Averager(points, weights, radius, mirror=mirror)
        columns.append([averager.peak(f)[0] for f in fields])
    return np.array(columns, float).T.reshape(len(fields), len(radii))
