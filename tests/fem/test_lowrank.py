"""The low-rank element kernel of the Neo-Hookean solid (fem.lowrank) against the general
kernel (the 81-component tangent and fem.solid_kernels.element_matrices) and against finite
differences of the residual."""
import numpy as np
import pytest
import skfem as fe

from softhand.fem.lowrank import write_matrices
from softhand.fem.materials import NeoHookean, NeoHookeanIsochoric
from softhand.fem.solid import Solid

RNG = np.random.default_rng(7)


def solid_and_state(chunk=11):
    mesh = fe.MeshTet.init_tensor(*(np.linspace(0, s, k + 1) for k, s in zip((2, 2, 3), (1.0, 1.0, 2.0))))
    solid = Solid(mesh.with_defaults(), NeoHookean(1.15, 60.0), chunk=chunk)  # several chunks
    # a large deformation: 20 % stretch, shear and noise
    X = solid.dof_locations
    u = np.stack((0.2 * X[0] + 0.1 * X[2], -0.05 * X[1], 0.15 * X[0])).T.ravel()
    return solid, u + 0.01 * RNG.standard_normal(solid.ndofs)


def general(solid, u, p_geo=None):
    """Element residuals and matrices of the whole mesh by the general kernel."""
    nel, nloc = solid.scatter.dofs.shape
    Ke = np.empty((nel, nloc, 3, 3, nloc))
    re = solid._general_kernels(u, slice(None), Ke, p_geo)
    return re, Ke


@pytest.mark.parametrize("anchored", [False, True])
def test_low_rank_kernel_equals_general_kernel(anchored):
    """Same element matrices to rounding (1e-13 of the largest entry: sums of ~40 products of
    order-one terms), with the element pressures of the mixed iteration or without."""
    solid, u = solid_and_state()
    assert type(solid._dev) is NeoHookeanIsochoric  # the low-rank path is the one taken
    anchor = solid.anchor(u + 0.002 * RNG.standard_normal(solid.ndofs)) if anchored else None
    R, Ke = solid.residual_element_matrices(u, anchor=anchor)
    p_geo = None if anchor is None else anchor.pressure(u, slice(None), solid.scatter.vector_dofs())
    re, Ke_ref = general(solid, u, p_geo)
    assert np.abs(Ke - Ke_ref).max() < 1e-13 * np.abs(Ke_ref).max()
    R_ref = np.zeros(solid.ndofs)
    solid.scatter.add_chunk_vectors(R_ref, [re])
    assert np.abs(R - R_ref).max() < 1e-13 * np.abs(R_ref).max()


def test_low_rank_tangent_is_the_derivative_of_the_residual():
    """K d against central differences of R: O(h^2) truncation and round-off ~1e-16 |R| / h."""
    solid, u = solid_and_state()
    R, K = solid.residual_tangent(u)
    d, h = RNG.standard_normal(solid.ndofs), 1e-6
    dR = (solid.residual(u + h * d) - solid.residual(u - h * d)) / (2 * h)
    np.testing.assert_allclose(K @ d, dR, atol=1e-7 * np.abs(K @ d).max())
    assert abs(K - K.T).max() < 1e-12 * abs(K).max()


def test_extra_terms_enter_as_written():
    """Terms of another energy (``extra=``) are added to the residual and to the matrices as
    sum_k L R + delta_ab S, in either kernel."""
    solid, u = solid_and_state()
    nel, nloc = solid.scatter.dofs.shape
    re = RNG.standard_normal((nel, 3 * nloc))
    L, Rk = RNG.standard_normal((nel, 3 * nloc, 5)), RNG.standard_normal((nel, 5, 3 * nloc))
    S = RNG.standard_normal((nel, nloc, nloc))
    R0, K0 = solid.residual_element_matrices(u)
    R0, K0 = R0.copy(), K0.copy()
    R1, K1 = solid.residual_element_matrices(u, extra=lambda c: (re[c], L[c], Rk[c], S[c]))
    expected = K0 + np.matmul(L, Rk).reshape(K0.shape)
    for a in range(3):
        expected[:, :, a, a, :] += S
    assert np.abs(K1 - expected).max() < 1e-12 * np.abs(expected).max()
    R_extra = np.zeros(solid.ndofs)
    solid.scatter.add_chunk_vectors(R_extra, [re])
    np.testing.assert_allclose(R1, R0 + R_extra, rtol=0, atol=1e-12 * np.abs(R0 + R_extra).max())
    Kw = np.zeros_like(K0)
    write_matrices(Kw, L, Rk, S)
    assert np.abs(Kw - (expected - K0)).max() < 1e-12 * np.abs(expected).max()
