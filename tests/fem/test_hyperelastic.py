"""FEM laws of every rubber model: stress = dpsi/dF, tangent = dP/dF (finite differences),
NH reproduced exactly, the isochoric/volumetric split, homogeneous modes vs reduced/materials/rubber.py."""
import numpy as np
import pytest
from scipy.optimize import brentq

from softhand.fem import kinematics as kin
from softhand.fem.hyperelastic import IsochoricRubber, RubberLaw, rubber_law
from softhand.fem.materials import NeoHookean, NeoHookeanIsochoric, Sum, Volumetric
from softhand.reduced.materials import rubber, rubber_base
from test_materials import F_BATCH, fd_derivative

MODELS = {
    "mooney-rivlin": rubber.MooneyRivlin(0.4, 0.08),
    "yeoh": rubber.Yeoh(0.3, -0.01, 4e-3),
    "gent": rubber.Gent(0.55, 12.0),
    "ogden": rubber.Ogden((0.62, 0.0012, -0.01), (1.3, 5.0, -2.0)),
}
F_DIAG = np.zeros((3, 3, 3))  # principal stretches with two and three coincident
F_DIAG[[0, 1, 2], [0, 1, 2], 0] = (1.2, 1.2, 0.75)
F_DIAG[[0, 1, 2], [0, 1, 2], 1] = (1.0, 1.0, 1.0)
F_DIAG[[0, 1, 2], [0, 1, 2], 2] = (0.9, 1.3, 1.3 + 1e-8)


@pytest.mark.parametrize("name", list(MODELS))
@pytest.mark.parametrize("F", [F_BATCH, F_DIAG], ids=["random", "coincident"])
def test_stress_and_tangent_are_exact(name, F):
    law = RubberLaw(MODELS[name], kappa=20.0)
    P = law.stress(F)
    np.testing.assert_allclose(P, fd_derivative(law.energy, F), atol=2e-7 * np.abs(P).max())
    A = law.tangent(F)
    A_fd = np.moveaxis(fd_derivative(law.stress, F), (0, 1), (2, 3))
    np.testing.assert_allclose(A, A_fd, atol=3e-6 * np.abs(A).max())
    np.testing.assert_allclose(A, np.swapaxes(np.swapaxes(A, 0, 2), 1, 3), atol=1e-10 * np.abs(A).max())


def test_neo_hookean_through_the_general_law_is_the_closed_form():
    for material in (rubber.NeoHookean(1.15), rubber.Ogden((1.15,), (2.0,)), rubber.MooneyRivlin(0.575, 0.0)):
        general, closed = IsochoricRubber(material), NeoHookeanIsochoric(1.15)
        np.testing.assert_allclose(general.stress(F_BATCH), closed.stress(F_BATCH), rtol=1e-11, atol=1e-12)
        np.testing.assert_allclose(general.tangent(F_BATCH), closed.tangent(F_BATCH), rtol=1e-9, atol=1e-10)
    assert isinstance(rubber_law(rubber.NeoHookean(1.15), 1150.0), NeoHookean)


def test_isochoric_plus_volumetric_is_split():
    """The sum of an isochoric law and a volumetric part runs the mean-dilatation formulation."""
    dev, vol = (NeoHookeanIsochoric(1.0) + Volumetric(1000.0)).split()
    assert vol == Volumetric(1000.0) and isinstance(dev, Sum) and dev.parts == (NeoHookeanIsochoric(1.0),)
    dev, vol = (IsochoricRubber(MODELS["yeoh"]) + Volumetric(10.0)).split()
    assert vol == Volumetric(10.0)
    with pytest.raises(ValueError, match="volumetric"):
        (NeoHookean(1.0) + Volumetric(5.0)).split()


@pytest.mark.parametrize("name", list(MODELS))
@pytest.mark.parametrize("mode", rubber_base.MODES)
def test_homogeneous_modes_match_the_incompressible_closed_forms(name, mode):
    """Mixed boundary conditions: the free lateral stretch solves P_22 = 0 (P_33 = 0 too in
    uniaxial); as kappa -> inf the nominal stress tends to the incompressible mode's."""
    material = MODELS[name]
    lam = 1.6
    kappa = 1e5 * material.mu0
    law = RubberLaw(material, kappa)
    P = _mode_stress(law, mode, lam)
    assert P == pytest.approx(float(material.nominal_stress(mode, lam)), rel=2e-4)


def _mode_stress(law, mode, lam):
    def F_of(free):
        if mode == "uniaxial":
            return np.diag([lam, free, free])[:, :, None]
        if mode == "equibiaxial":
            return np.diag([lam, lam, free])[:, :, None]
        return np.diag([lam, 1.0, free])[:, :, None]
    lateral = 2 if mode != "uniaxial" else 1
    guess = {"uniaxial": lam**-0.5, "equibiaxial": lam**-2, "pure-shear": 1 / lam}[mode]
    free = brentq(lambda s: law.stress(F_of(s))[lateral, lateral, 0], 0.8 * guess, 1.2 * guess, xtol=1e-15)
    return float(law.stress(F_of(free))[0, 0, 0])


def test_thick_sphere_pressure_for_any_model():
    """The quadrature form reproduces the Neo-Hookean closed form and the thin-wall limit."""
    from softhand.fem.hand.balloon import closed_form_pressure, closed_form_pressure_general

    lam = np.array([1.2, 1.5, 2.5])
    np.testing.assert_allclose(closed_form_pressure_general(lam, 10.0, 11.0, rubber.NeoHookean(1.15)),
                               closed_form_pressure(lam, 10.0, 11.0, 1.15), rtol=1e-10)
    mr, H = MODELS["mooney-rivlin"], 1e-4
    thin = H / 10.0 * 2 * mr.nominal_stress("equibiaxial", lam) / lam**2
    np.testing.assert_allclose(closed_form_pressure_general(lam, 10.0, 10.0 + H, mr), thin, rtol=1e-4)


def test_reservoir_sheet_takes_the_designs_material():
    from softhand.fem.hand.reservoir import SheetModel
    from softhand.reduced.vocabulary.design import HandDesign

    mr = rubber.MooneyRivlin(0.46, 0.115)
    model = SheetModel.from_design(HandDesign().replace(reservoir_material=mr, mu_sr=mr.mu0), n_radial=4,
                                   n_thick=1)
    solid, _, _ = model.build()
    assert solid.iso == IsochoricRubber(mr) and solid.vol == Volumetric(1000.0 * mr.mu0)
    assert SheetModel.from_design(HandDesign()).material is None  # Neo-Hookean: the closed form
    doubled = SheetModel.from_design(HandDesign().replace(reservoir_material=mr, mu_sr=2 * mr.mu0))
    assert doubled.rubber.parameters() == pytest.approx({"C10_MPa": 0.92, "C01_MPa": 0.23})
