"""The compiled kernels (fem.compiled) against the NumPy kernels they replace on the finger's hot path."""
import numpy as np
import pytest

from softhand.fem import threads
from softhand.fem.compiled import available, cavity, chain, rubber
from softhand.fem.hand.finger import FingerModel, FingerOptions, solve_pressures
from softhand.fem.hand.finger_sweep import softened
from softhand.fem.loads import CavityVolume
from softhand.reduced.materials import rubber as rubbers
from softhand.reduced.vocabulary.design import HandDesign

from conftest import CI_FINGER

pytestmark = pytest.mark.skipif(not available(), reason="numba is not installed")

DESIGN = HandDesign()


@pytest.fixture(scope="module")
def model():
    return FingerModel(DESIGN, FingerOptions(**CI_FINGER))


def stretched(model, seed=0, scale=0.05):
    """A displacement that makes part of the windings taut, none exactly at their kink."""
    return scale * np.random.default_rng(seed).standard_normal(model.solid.ndofs)


def numpy_rubber_and_windings(solid, windings, u):
    R, Ke = solid.residual_element_matrices(u, extra=lambda c: windings.terms(u, c))
    return R, solid.scatter.block_matrix_data(Ke)


def relative(a, b):
    return np.abs(a - b).max() / np.abs(b).max()


@pytest.mark.parametrize("toe", [0.0, 0.02])
def test_rubber_and_windings_equal_the_numpy_kernels(model, toe):
    """Forces and stiffness of the compiled pass equal the NumPy kernels' to rounding, with
    the windings' onset sharp and smooth (the toe's ramp taken by some points)."""
    m = model if toe == 0.0 else FingerModel(DESIGN, FingerOptions(**CI_FINGER, fiber_toe=toe))
    u = stretched(m)
    strain = m.windings.stretch(u)[1] - 1.0
    assert 0.1 < np.mean(strain > 0) < 0.9
    if toe:
        assert np.any((strain > 0) & (strain < toe))
    R_ref, data_ref = numpy_rubber_and_windings(m.solid, m.windings, u)
    R, data = m.kernels.residual_tangent_data(u, m.solid)
    assert relative(R, R_ref) < 1e-12
    assert relative(data, data_ref) < 1e-12
    assert relative(m.kernels.residual(u, m.solid), R_ref) < 1e-12


@pytest.mark.parametrize("material", [rubbers.Yeoh(0.44, -0.017, 0.0037), rubbers.Gent(0.9, 20.0),
                                      rubbers.MooneyRivlin(0.35, 0.1)], ids=lambda m: m.model)
def test_a_rubber_of_i1_alone_takes_the_kernel_and_equals_the_general_kernel(material):
    """Yeoh and Gent (W of I1bar alone): the compiled pass (mu = 2 W_1 per point and the W_11
    rank-one term) against the general NumPy kernel of the same law, at a stretched state where
    W_11 is far from 0; Mooney-Rivlin keeps the NumPy kernels."""
    m = FingerModel(DESIGN.replace(finger_material=material, mu_sf=material.mu0), FingerOptions(**CI_FINGER))
    if isinstance(material, rubbers.MooneyRivlin):
        assert m.kernels is None
        return
    u = stretched(m, scale=0.1)
    R_ref, data_ref = numpy_rubber_and_windings(m.solid, m.windings, u)
    R, data = m.kernels.residual_tangent_data(u, m.solid)
    assert relative(R, R_ref) < 1e-12
    assert relative(data, data_ref) < 1e-12
    assert relative(m.kernels.residual(u, m.solid), R_ref) < 1e-12


def test_a_softer_copy_of_the_model_shares_the_kernel_with_its_own_bulk_modulus(model):
    soft = softened(model, kappa_ratio=100.0)
    assert soft.kernels is model.kernels
    u = stretched(model, seed=1, scale=0.01)
    R_ref, _ = numpy_rubber_and_windings(soft.solid, soft.windings, u)
    R = soft.kernels.residual(u, soft.solid)
    assert relative(R, R_ref) < 1e-12
    assert relative(model.kernels.residual(u, model.solid), R_ref) > 1e-3


def test_threads_never_add_into_the_same_entry(model, monkeypatch):
    """The slabs a thread each: their elements share no node; every element is in one list;
    two threads give one thread's forces and stiffness to rounding."""
    centroids = model.mesh.p[:, model.mesh.t[:4]].mean(axis=1).T
    dofs = model.solid.scatter.dofs
    for parts in (2, 3):
        lists = threads.slabs(centroids, dofs, parts)
        assert np.array_equal(np.sort(np.concatenate(lists)), np.arange(len(dofs)))
        nodes = [set(dofs[e].ravel()) for e in lists[:-1]]
        assert all(not (nodes[i] & nodes[j]) for i in range(parts) for j in range(i + 1, parts))
        assert len(lists[-1]) < 0.3 * len(dofs)
    u = stretched(model, seed=2)
    results = []
    for n in ("1", "2"):
        monkeypatch.setenv("OMP_NUM_THREADS", n)
        kernels = rubber.CompiledAssembly(model.solid, model.windings)
        assert len(kernels.parts) == int(n) + 1
        results.append(kernels.residual_tangent_data(u, model.solid))
    assert relative(results[1][0], results[0][0]) < 1e-12
    assert relative(results[1][1], results[0][1]) < 1e-12


@pytest.mark.parametrize("symmetry_normal", [0, None])
def test_cavity_gradient_and_hessian_equal_the_numpy_forms(model, symmetry_normal):
    facets = model.mesh.boundaries["cavity"]
    fast = CavityVolume(model.solid, facets, symmetry_normal=symmetry_normal)
    slow = CavityVolume(model.solid, facets, symmetry_normal=symmetry_normal, compiled=False)
    assert isinstance(fast.kernels, cavity.CompiledCavity) and slow.kernels is None
    u = stretched(model, seed=3)
    data, data_ref = np.zeros(model.solid.scatter.nnz), np.zeros(model.solid.scatter.nnz)
    slow.add_hessian_data(data_ref, u, -0.7)
    assert relative(fast.gradient(u, data, -0.7), slow.gradient(u)) < 1e-12
    assert relative(data, data_ref) < 1e-12


def test_the_chains_reduction_equals_the_general_path(model):
    """The one-pass reduction of a symmetric tangent against the general (unsymmetric) path."""
    y = 0.02 * np.random.default_rng(4).standard_normal(model.ndofs)
    u = model.constraint.expand(y)
    R, data = model.kernels.residual_tangent_data(u, model.solid)
    K = model.solid.scatter.csr(data)
    r1, K1 = model.constraint.reduce(y, R, K, np.eye(DESIGN.n_s), symmetric=True)
    assert isinstance(model.constraint._reduced_pattern(K, None)["compiled"], chain.SymmetricReduction)
    r2, K2 = model.constraint.reduce(y, R, K, np.eye(DESIGN.n_s), symmetric=False)
    assert np.array_equal(K1.indices, K2.indices) and np.array_equal(K1.indptr, K2.indptr)
    assert relative(K1.data, K2.data) < 1e-13
    assert np.array_equal(r1, r2)


def test_the_finger_curve_is_the_numpy_kernels_curve(model, monkeypatch):
    """The same sweep with every compiled kernel and with none: theta and dQ equal to the
    Newton tolerance."""
    fast, _ = solve_pressures(model, (0.4, 0.8))
    for module in (rubber, cavity, chain):
        monkeypatch.setattr(module, "available", lambda: False)
    numpy_model = FingerModel(DESIGN, FingerOptions(**CI_FINGER))
    assert numpy_model.kernels is None and numpy_model.cavity.kernels is None
    slow, _ = solve_pressures(numpy_model, (0.4, 0.8))
    for a, b in zip(fast, slow):
        assert a.theta == pytest.approx(b.theta, rel=1e-8)
        assert a.dQ == pytest.approx(b.dQ, rel=1e-8)

