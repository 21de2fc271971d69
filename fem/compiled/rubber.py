r"""The finger's rubber (mean dilatation) and windings in one compiled pass per element.

The rubber: the Neo-Hookean law, or any rubber whose energy depends on :math:`\bar I_1` alone
(Yeoh, Gent: :data:`I1_ONLY`), whose tangent is the Neo-Hookean form with :math:`\mu = 2W_1` at
each point plus the rank-one :math:`W_{11}\,(g_1 : \nabla\delta u)(g_1 : \nabla\Delta u)`,
:math:`g_1 = \partial\bar I_1/\partial F` (a first compiled pass gives :math:`\bar I_1` at the
points, the rubber's own NumPy functions W_1 and W_11 there). Mooney-Rivlin and Ogden take the
NumPy kernels.

Per element: F, J, F^{-T} at the rubber's 4 points, the mean-dilatation pressure, the windings
at their 14 points, the element's forces and its 30 x 30 stiffness, added straight into the
residual and the CSR data (no element-matrix buffer, no separate scatter). The stiffness has
the low-rank form of :mod:`softhand.fem.lowrank`: :math:`K = L^T R + \delta_{ab} S +
\varepsilon_{abc} X_c`, the rows of L and R the Neo-Hookean kernel's v and h at each rubber
point (8), the mean-dilatation vector b (1) and :math:`f_a g_n` at each taut winding point (a
slack fiber's coefficients are zero: skipped); the product is one small BLAS call (products
written as explicit loops ran at a quarter of its speed). The same matrices as the NumPy
kernels to round-off; the fibers' on/off switch at exactly zero strain may fall either way by
round-off in either implementation.

Threads: the elements are cut into as many slabs along the mesh's longest axis as there are
threads (:func:`softhand.fem.threads.count`); the elements of a slab that touch no other slab's
nodes run side by side, a slab per thread, and the few that do after them, so no two threads
ever add into the same entry.
"""
from __future__ import annotations

import numpy as np

from softhand.fem import threads
from softhand.fem.compiled import available, compiled
from softhand.fem.hyperelastic import IsochoricRubber
from softhand.fem.materials import NeoHookeanIsochoric
from softhand.reduced.materials import rubber as rubber_models

#: the rubber's quadrature points and the element's nodes the kernel is written for
_NQ, _NLOC = 4, 10
#: the rubbers whose energy depends on I1bar alone, which the kernel takes besides the
#: Neo-Hookean law (its tangent: the Neo-Hookean form with mu = 2 W_1, plus W_11 g1 g1 per point)
I1_ONLY = (rubber_models.NeoHookean, rubber_models.Yeoh, rubber_models.Gent)


@compiled
def _kernel(u, sd, G, W, m1, m11, rank1, kappa, gw, Ww, a0, kw, toe, elems, pos, data, R, tangent, scratch):
    """Adds the elements ``elems``' forces into R and (``tangent``) their stiffness into data; m1 =
    2 W_1 and m11 = W_11 at each rubber point (nel, nq) (the Neo-Hookean law: mu and 0; ``rank1``:
    some m11 is not 0)."""
    ue, Fq, Fi, Jq, Lt, Rm, K, re, b, St, Sr, X = scratch
    nq, nw = G.shape[1], gw.shape[1]
    for idx in range(elems.shape[0]):
        e = elems[idx]
        for n in range(10):
            for a in range(3):
                ue[n, a] = u[3 * sd[e, n] + a]
        Ve = 0.0
        JW = 0.0
        for q in range(nq):
            for a in range(3):
                for k in range(3):
                    s = 0.0
                    for n in range(10):
                        s += ue[n, a] * G[e, q, n, k]
                    Fq[a, k, q] = s + (1.0 if a == k else 0.0)
            for a in range(3):  # cof F = J F^{-T}
                a1, a2 = (a + 1) % 3, (a + 2) % 3
                for k in range(3):
                    k1, k2 = (k + 1) % 3, (k + 2) % 3
                    Fi[a, k, q] = Fq[a1, k1, q] * Fq[a2, k2, q] - Fq[a1, k2, q] * Fq[a2, k1, q]
            J = Fq[0, 0, q] * Fi[0, 0, q] + Fq[0, 1, q] * Fi[0, 1, q] + Fq[0, 2, q] * Fi[0, 2, q]
            Jq[q] = J
            for a in range(3):
                for k in range(3):
                    Fi[a, k, q] /= J
            Ve += W[e, q]
            JW += W[e, q] * J
        p = kappa * (JW / Ve - 1.0)  # U'(Jbar), U = kappa/2 (J - 1)^2
        re[:] = 0.0
        b[:] = 0.0
        X[:] = 0.0
        for q in range(nq):
            J, w = Jq[q], W[e, q]
            I1 = 0.0
            for a in range(3):
                for k in range(3):
                    I1 += Fq[a, k, q] * Fq[a, k, q]
            j23 = J ** (-2.0 / 3.0)
            muj = m1[e, q] * j23 * w
            pJ = p * J * w
            for n in range(10):
                for a in range(3):
                    sv = 0.0
                    sh = 0.0
                    for k in range(3):
                        sv += Fq[a, k, q] * G[e, q, n, k]
                        sh += Fi[a, k, q] * G[e, q, n, k]
                    i = 3 * n + a
                    Lt[q, i] = sv
                    Lt[nq + q, i] = sh
                    re[i] += muj * (sv - I1 / 3.0 * sh) + pJ * sh
                    b[i] += w * J * sh
            if not tangent:
                continue
            cvh, chh, b3 = -2.0 / 3.0 * muj, 5.0 / 9.0 * I1 * muj, I1 / 3.0 * muj - pJ
            if rank1:  # W_11 (g1 : grad du)(g1 : grad Du), g1 = dI1bar/dF = j (2 F - 2/3 I1 F^-T)
                c11 = m11[e, q] * w
                for i in range(30):
                    t = j23 * (2.0 * Lt[q, i] - 2.0 / 3.0 * I1 * Lt[nq + q, i])
                    Lt[2 * nq + 1 + q, i] = t
                    Rm[2 * nq + 1 + q, i] = c11 * t
            for i in range(30):
                Rm[q, i] = cvh * Lt[nq + q, i]
                Rm[nq + q, i] = cvh * Lt[q, i] + chh * Lt[nq + q, i]
            for k in range(3):
                for n in range(10):
                    St[3 * q + k, n] = G[e, q, n, k]
                    Sr[3 * q + k, n] = muj * G[e, q, n, k]
            for n in range(10):  # X_c[n, m] += b3 (h_m x h_n)_c, antisymmetric in (n, m)
                h0, h1, h2 = Lt[nq + q, 3 * n], Lt[nq + q, 3 * n + 1], Lt[nq + q, 3 * n + 2]
                for m in range(n + 1, 10):
                    g0, g1, g2 = Lt[nq + q, 3 * m], Lt[nq + q, 3 * m + 1], Lt[nq + q, 3 * m + 2]
                    X[0, n, m] += b3 * (g1 * h2 - g2 * h1)
                    X[1, n, m] += b3 * (g2 * h0 - g0 * h2)
                    X[2, n, m] += b3 * (g0 * h1 - g1 * h0)
        rows, srows = 2 * nq, 3 * nq
        if tangent:
            cb = kappa / Ve  # U''(Jbar) / V_e
            for i in range(30):
                Lt[rows, i] = b[i]
                Rm[rows, i] = cb * b[i]
            rows += 1 + (nq if rank1 else 0)
        for q in range(nw):  # the windings: f = F a0 at their own points
            f0, f1, f2 = 0.0, 0.0, 0.0
            for n in range(10):
                g = gw[e, q, n]
                f0 += ue[n, 0] * g
                f1 += ue[n, 1] * g
                f2 += ue[n, 2] * g
            f0 += a0[e, q, 0]
            f1 += a0[e, q, 1]
            f2 += a0[e, q, 2]
            lam = np.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
            strain = lam - 1.0
            if strain < 0.0 or (toe > 0.0 and strain == 0.0):
                continue  # slack: no force, no stiffness
            if toe == 0.0:
                G1, G2 = strain, 1.0
            elif strain < toe:
                G1, G2 = strain * strain / (2.0 * toe), strain / toe
            else:
                G1, G2 = strain - 0.5 * toe, 1.0
            c1 = Ww[e, q] * kw * (G2 / lam ** 2 - G1 / lam ** 3)
            c2 = Ww[e, q] * kw * G1 / lam
            for n in range(10):
                g = gw[e, q, n]
                re[3 * n] += c2 * f0 * g
                re[3 * n + 1] += c2 * f1 * g
                re[3 * n + 2] += c2 * f2 * g
                if tangent:
                    Lt[rows, 3 * n], Lt[rows, 3 * n + 1], Lt[rows, 3 * n + 2] = f0 * g, f1 * g, f2 * g
                    Rm[rows, 3 * n], Rm[rows, 3 * n + 1], Rm[rows, 3 * n + 2] = c1 * f0 * g, c1 * f1 * g, c1 * f2 * g
                    St[srows, n] = g
                    Sr[srows, n] = c2 * g
            rows += 1
            srows += 1
        for n in range(10):
            for a in range(3):
                R[3 * sd[e, n] + a] += re[3 * n + a]
        if not tangent:
            continue
        np.dot(Lt[:rows].T, Rm[:rows], K)
        S = np.dot(St[:srows].T, Sr[:srows])
        for n in range(10):
            for m in range(10):
                s = S[n, m]
                K[3 * n, 3 * m] += s
                K[3 * n + 1, 3 * m + 1] += s
                K[3 * n + 2, 3 * m + 2] += s
                sign = 1.0 if m > n else -1.0  # X_c[n, m] = -X_c[m, n]
                lo, hi = min(n, m), max(n, m)
                x0, x1, x2 = sign * X[0, lo, hi], sign * X[1, lo, hi], sign * X[2, lo, hi]
                K[3 * n, 3 * m + 1] += x2
                K[3 * n + 1, 3 * m] -= x2
                K[3 * n + 1, 3 * m + 2] += x0
                K[3 * n + 2, 3 * m + 1] -= x0
                K[3 * n + 2, 3 * m] += x1
                K[3 * n, 3 * m + 2] -= x1
        for i in range(30):
            for j in range(30):
                data[pos[e, i, j]] += K[i, j]


@compiled
def _isochoric_I1(u, sd, G, elems, out):
    """out[e, q] = J^{-2/3} tr(F^T F) at the rubber's points of the elements ``elems`` (where W_1,
    W_11 are evaluated)."""
    F = np.empty((3, 3))
    for idx in range(elems.shape[0]):
        e = elems[idx]
        for q in range(G.shape[1]):
            for a in range(3):
                for k in range(3):
                    s = 1.0 if a == k else 0.0
                    for n in range(10):
                        s += u[3 * sd[e, n] + a] * G[e, q, n, k]
                    F[a, k] = s
            J = (F[0, 0] * (F[1, 1] * F[2, 2] - F[1, 2] * F[2, 1]) - F[0, 1] * (F[1, 0] * F[2, 2] - F[1, 2] * F[2, 0])
                 + F[0, 2] * (F[1, 0] * F[2, 1] - F[1, 1] * F[2, 0]))
            I1 = 0.0
            for a in range(3):
                for k in range(3):
                    I1 += F[a, k] * F[a, k]
            out[e, q] = I1 * J ** (-2.0 / 3.0)


def _scratch(nw):
    rows = 3 * _NQ + 1 + nw
    return (np.empty((_NLOC, 3)), np.empty((3, 3, _NQ)), np.empty((3, 3, _NQ)), np.empty(_NQ),
            np.zeros((rows, 30)), np.zeros((rows, 30)), np.empty((30, 30)), np.empty(30), np.empty(30),
            np.zeros((3 * _NQ + nw, _NLOC)), np.zeros((3 * _NQ + nw, _NLOC)), np.zeros((3, _NLOC, _NLOC)))


def for_finger(solid, windings) -> "CompiledAssembly | None":
    """The compiled kernel of a finger's rubber and windings where it applies (numba installed,
    a Neo-Hookean or :data:`I1_ONLY` rubber in the mean-dilatation formulation on quadratic
    tetrahedra with the 4-point rule), else None: the NumPy kernels serve."""
    dev, vol = solid.parts
    law = type(dev) is NeoHookeanIsochoric or (type(dev) is IsochoricRubber and type(dev.material) in I1_ONLY)
    if not (available() and vol is not None and law and solid.G.shape[1:] == (_NQ, _NLOC, 3)):
        return None
    return CompiledAssembly(solid, windings)


class CompiledAssembly:
    """The finger's rubber (Neo-Hookean or :data:`I1_ONLY`, mean dilatation) and windings by the compiled kernel.

    ``solid``: the :class:`softhand.fem.solid.Solid` (its mesh, quadrature and CSR pattern; the
    solid is passed again per call for its moduli, so a copy with another bulk modulus
    (:meth:`softhand.fem.solid.Solid.with_bulk_modulus`) shares this object);
    ``windings``: the :class:`softhand.fem.hand.windings.Windings` on the same mesh.
    """

    def __init__(self, solid, windings):
        scatter = solid.scatter
        self.n, self.nnz = scatter.n, scatter.nnz
        self.sd = np.ascontiguousarray(scatter.dofs, dtype=np.int64)
        self.G, self.W = np.ascontiguousarray(solid.G), np.ascontiguousarray(solid.W)
        self.gw, self.Ww = np.ascontiguousarray(windings.g), np.ascontiguousarray(windings.W)
        self.a0 = np.ascontiguousarray(windings.a0q)
        self.kw, self.toe = float(windings.law.k), float(windings.law.toe)
        nel = len(self.W)
        itype = np.int32 if self.nnz < 2 ** 31 else np.intp
        pos = np.empty((nel, 30, 30), dtype=itype)  # (n a), (m b): the block layout's last two swapped
        for i in range(0, nel, 2048):
            c = slice(i, min(i + 2048, nel))
            pos[c] = scatter.positions(c)
        self.pos = pos
        mesh = solid.mesh
        centroids = mesh.p[:, mesh.t[:4]].mean(axis=1).T
        self.threads = threads.count()
        self.parts = threads.slabs(centroids, self.sd, self.threads)

    def residual(self, u: np.ndarray, solid) -> np.ndarray:
        """The rubber's and the windings' internal force (ndofs,) [N]; ``solid``: this mesh's
        solid with the moduli to use."""
        return self._run(u, solid, tangent=False)[0]

    def residual_tangent_data(self, u: np.ndarray, solid):
        """(internal force (ndofs,), the tangent's CSR data in the solid's pattern)."""
        return self._run(u, solid, tangent=True)

    def _run(self, u, solid, tangent):
        dev, vol = solid.parts
        u = np.ascontiguousarray(u, dtype=float)
        if isinstance(dev, NeoHookeanIsochoric):
            m1, m11 = np.full(self.W.shape, float(dev.mu)), np.zeros(self.W.shape)
        else:  # a rubber of I1 alone: its W_1, W_11 at the points' I1bar
            I1b = np.empty(self.W.shape)
            threads.map_chunks(lambda elems: _isochoric_I1(u, self.sd, self.G, elems, I1b), self.parts)
            zero = np.zeros_like(I1b)
            m1, m11 = (np.ascontiguousarray(np.broadcast_to(c, I1b.shape), dtype=float)
                       for c in (2.0 * np.asarray(dev.material.dI(I1b, zero)[0]), dev.material.d2I(I1b, zero)[0]))
        rank1 = bool(np.any(m11))
        R = np.zeros(self.n)
        data = np.zeros(self.nnz if tangent else 0)
        nw = self.gw.shape[1]

        def run(elems):
            _kernel(u, self.sd, self.G, self.W, m1, m11, rank1, float(vol.kappa), self.gw, self.Ww, self.a0,
                    self.kw, self.toe, elems, self.pos, data, R, tangent, _scratch(nw))

        threads.map_chunks(run, self.parts[:-1])
        run(self.parts[-1])
        return R, data
