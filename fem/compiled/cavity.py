r"""The cavity volume's gradient and Hessian (:class:`softhand.fem.loads.CavityVolume`), compiled.

Per wall facet and quadrature point, with x = X + u, F the solid's deformation gradient, N the
reference normal, y = D x (D diagonal, diag d) and :math:`w_n = F (N \times \nabla\phi_n)`:

.. math::
    -\partial V/\partial u_{na} = \sum_q W\,[(D\,\mathrm{cof}F\,N)_a \phi_n + (w_n \times y)_a],

    -\partial^2 V/\partial u_{na}\partial u_{mc} = \sum_q W\,[\phi_n d_a \varepsilon_{ack} w_{mk}
        + \phi_m d_c \varepsilon_{cak} w_{nk} + \varepsilon_{bac} y_b\, N\cdot(\nabla\phi_n \times \nabla\phi_m)],

the NumPy forms of :mod:`softhand.fem.loads` with the derivative of cof F N applied to a shape
function's gradient written out: :math:`\partial(\mathrm{cof}F\,N)_b/\partial F_{jK}\,\nabla\phi_K =
\varepsilon_{bjk} w_k`. Facets are few (a thin layer of the mesh): one thread.
"""
from __future__ import annotations

import numpy as np

from softhand.fem.compiled import available, compiled

__all__ = ["CompiledCavity", "available"]


@compiled
def _kernel(u, vdofs, phi, G, N, X, W, d, pos, data, factor, g, tangent):
    """g += -dV/du per facet dof (nf, 3 nloc) [gathered by the caller]; with ``tangent``,
    data[pos] += factor * d2V/du2 (the caller's sign convention: see CavityVolume)."""
    nf, nq, nloc = phi.shape
    ue = np.empty((nloc, 3))
    w = np.empty((nloc, 3))
    K = np.empty((3 * nloc, 3 * nloc))
    F, x, cofN = np.empty((3, 3)), np.empty(3), np.empty(3)
    for f in range(nf):
        for n in range(nloc):
            for a in range(3):
                ue[n, a] = u[vdofs[f, 3 * n + a]]
        K[:] = 0.0
        for q in range(nq):
            for a in range(3):
                s = X[a, f, q]
                for n in range(nloc):
                    s += ue[n, a] * phi[f, q, n]
                x[a] = s
                for k in range(3):
                    s = 1.0 if a == k else 0.0
                    for n in range(nloc):
                        s += ue[n, a] * G[f, q, n, k]
                    F[a, k] = s
            n0, n1, n2 = N[0, f, q], N[1, f, q], N[2, f, q]
            for a in range(3):
                cofN[a] = 0.0
                a1, a2 = (a + 1) % 3, (a + 2) % 3
                for k in range(3):
                    k1, k2 = (k + 1) % 3, (k + 2) % 3
                    cofN[a] += (F[a1, k1] * F[a2, k2] - F[a1, k2] * F[a2, k1]) * N[k, f, q]
            y0, y1, y2 = d[0] * x[0], d[1] * x[1], d[2] * x[2]
            wq = W[f, q]
            for n in range(nloc):
                G0, G1, G2 = G[f, q, n, 0], G[f, q, n, 1], G[f, q, n, 2]
                c0, c1, c2 = n1 * G2 - n2 * G1, n2 * G0 - n0 * G2, n0 * G1 - n1 * G0  # N x grad phi_n
                for a in range(3):
                    w[n, a] = F[a, 0] * c0 + F[a, 1] * c1 + F[a, 2] * c2
                p = phi[f, q, n]
                g[f, 3 * n] += wq * (d[0] * cofN[0] * p + w[n, 1] * y2 - w[n, 2] * y1)
                g[f, 3 * n + 1] += wq * (d[1] * cofN[1] * p + w[n, 2] * y0 - w[n, 0] * y2)
                g[f, 3 * n + 2] += wq * (d[2] * cofN[2] * p + w[n, 0] * y1 - w[n, 1] * y0)
            if not tangent:
                continue
            for n in range(nloc):
                pn = wq * phi[f, q, n]
                for m in range(nloc):
                    # H1[na, mc] = phi_n d_a eps_ack w_mk, and its transpose
                    wm0, wm1, wm2 = w[m, 0], w[m, 1], w[m, 2]
                    i, j = 3 * n, 3 * m
                    K[i, j + 1] += pn * d[0] * wm2
                    K[i, j + 2] -= pn * d[0] * wm1
                    K[i + 1, j] -= pn * d[1] * wm2
                    K[i + 1, j + 2] += pn * d[1] * wm0
                    K[i + 2, j] += pn * d[2] * wm1
                    K[i + 2, j + 1] -= pn * d[2] * wm0
                    K[j + 1, i] += pn * d[0] * wm2
                    K[j + 2, i] -= pn * d[0] * wm1
                    K[j, i + 1] -= pn * d[1] * wm2
                    K[j + 2, i + 1] += pn * d[1] * wm0
                    K[j, i + 2] += pn * d[2] * wm1
                    K[j + 1, i + 2] -= pn * d[2] * wm0
                    # H2[na, mc] = eps_bac y_b N . (grad phi_n x grad phi_m)
                    s = wq * (n0 * (G[f, q, n, 1] * G[f, q, m, 2] - G[f, q, n, 2] * G[f, q, m, 1])
                              + n1 * (G[f, q, n, 2] * G[f, q, m, 0] - G[f, q, n, 0] * G[f, q, m, 2])
                              + n2 * (G[f, q, n, 0] * G[f, q, m, 1] - G[f, q, n, 1] * G[f, q, m, 0]))
                    K[i + 1, j + 2] += s * y0  # eps_012 = 1: (a, c) = (1, 2) with b = 0
                    K[i + 2, j + 1] -= s * y0
                    K[i + 2, j] += s * y1
                    K[i, j + 2] -= s * y1
                    K[i, j + 1] += s * y2
                    K[i + 1, j] -= s * y2
        if tangent:
            for i in range(3 * nloc):
                for j in range(3 * nloc):
                    data[pos[f, i, j]] += factor * K[i, j]


class CompiledCavity:
    """The compiled gradient and Hessian of a :class:`softhand.fem.loads.CavityVolume` (its facet
    data ``facets``, a ``_Facets``, and the diagonal of its D)."""

    def __init__(self, facets, d):
        self.f = facets
        self.d = np.ascontiguousarray(d, dtype=float)
        self.pos = np.ascontiguousarray(facets.solid.scatter.positions(facets.elements))
        self.args = tuple(np.ascontiguousarray(a) for a in (facets.vdofs, facets.phi, facets.G, facets.N,
                                                            facets.X, facets.W))

    def gradient(self, u, data=None, factor: float = 1.0) -> np.ndarray:
        """dV/du (ndofs,); with ``data`` (CSR data in the solid's pattern), also data += factor *
        d2V/du2, in the same pass."""
        g = np.zeros(self.f.vdofs.shape)
        tangent = data is not None
        _kernel(np.ascontiguousarray(u, dtype=float), *self.args, self.d, self.pos,
                data if tangent else np.zeros(0), -float(factor), g, tangent)
        return -self.f.vector(g)
