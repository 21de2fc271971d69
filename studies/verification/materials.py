r"""Verification of every rubber model in the FEM: homogeneous modes and a thin balloon.

``modes``: a unit cube (P2-P0 mean-dilatation solid, :mod:`softhand.fem.solid`) under mixed
boundary conditions, stretched by lambda along x:

* uniaxial: rollers on x, y, z = 0, the other faces free;
* equibiaxial: x and y prescribed (lambda), z free;
* pure shear: x prescribed (lambda), y held (lambda_2 = 1), z free;

nominal stress from the reaction against the incompressible closed form of
:mod:`softhand.reduced.materials.rubber`. The state is homogeneous (exact in P2), so what remains is the
compressibility of the FEM material: kappa = 1e4 mu0 changes the stress by O(mu0/kappa),
measured 2.7e-5 to 2.7e-4 relative; tolerance 1e-3.

``balloon_models``: a thin sphere (A = 10 mm, B = 10.2 mm: H/A = 0.02) inflated under
volume control (axisymmetric Q2/P1disc, :mod:`softhand.fem.hand.balloon`) against the exact
incompressible thick-sphere pressure :func:`softhand.fem.hand.balloon.closed_form_pressure_general`, at
stretches before and past the pressure maximum, and the (first, local) maximum itself for
Mooney-Rivlin and Gent (parabola through the three sampled points around it, 0.05 apart in
stretch). Tolerance 1 % as for the Neo-Hookean balloon. What remains is the FEM material's
compressibility, O(sigma/kappa): the stiffening models (Yeoh, Gent) reach hoop stresses of
40 mu0 at stretch 3, hence kappa = 1e4 mu0 here (at 1e3 mu0 they were 5 % off there), and
the curved cells' geometry.
"""
from __future__ import annotations

import numpy as np
import skfem
from scipy.optimize import minimize_scalar

from softhand.fem.hand.balloon import ThickSphere, closed_form_pressure_general, inflate_sphere
from softhand.fem.hyperelastic import rubber_law
from softhand.fem.solid import Solid
from softhand.reduced.materials import rubber, rubber_base
from softhand.studies.verification.registry import Check
from softhand.studies.verification.solid import Problem, keep_map

#: one material per model, all with the initial shear modulus 1.15 MPa
MATERIALS = {
    "neo-hookean": rubber.NeoHookean(1.15),
    "mooney-rivlin": rubber.MooneyRivlin(0.5, 0.075),
    "yeoh": rubber.Yeoh(0.575, -0.02, 0.004),
    "gent": rubber.Gent(1.15, 20.0),
    "ogden": rubber.Ogden((1.1, 0.01, -0.05), (1.3, 5.0, -2.0)),
}


def homogeneous_modes(quick: bool) -> list[Check]:
    """P11 [MPa] at stretch 1.6 (and 0.8 unless quick) per model and mode."""
    mesh = skfem.MeshTet2.from_mesh(skfem.MeshTet.init_tensor(*[np.linspace(0, 1, 2)] * 3))
    faces = {a: [mesh.facets_satisfying(lambda x, a=a, v=v: np.isclose(x[a], v)) for v in (0, 1)]
             for a in range(3)}
    checks = []
    for name, material in MATERIALS.items():
        solid = Solid(mesh, rubber_law(material, 1e4 * material.mu0))
        for mode in rubber_base.MODES:
            for lam in ((1.6,) if quick else (1.6, 0.8)):
                checks.append(Check("modes", f"{name} {mode} P11 [MPa] at stretch {lam}",
                                    float(material.nominal_stress(mode, lam)),
                                    _cube_stress(solid, faces, mode, lam), 1e-3))
    return checks


def _cube_stress(solid, faces, mode, lam) -> float:
    u_D = np.zeros(solid.ndofs)
    fixed = [solid.dofs(faces[a][0], [a]) for a in range(3)]
    stretch = {"uniaxial": (lam, None, None), "equibiaxial": (lam, lam, None),
               "pure-shear": (lam, 1.0, None)}[mode]
    for a, s in enumerate(stretch):
        if s is not None:
            dofs = solid.dofs(faces[a][1], [a])
            u_D[dofs] = s - 1.0
            fixed.append(dofs)
    problem = Problem(solid, keep_map(solid.ndofs, np.unique(np.concatenate(fixed))), u_D)
    u = problem.solve(steps=3)
    return float(solid.residual(u)[solid.dofs(faces[0][1], [0])].sum())  # reaction / area 1


def balloon_models(quick: bool) -> list[Check]:
    """Thin-sphere p(lambda) per model, and the pressure maxima of Mooney-Rivlin and Gent."""
    names = ("mooney-rivlin", "gent") if quick else tuple(MATERIALS)
    lam = np.round(np.arange(1.1, 2.001 if quick else 3.001, 0.05), 10)
    checks = []
    for name in names:
        material = MATERIALS[name]
        sphere = ThickSphere(A=10.0, B=10.2, n_radial=1, n_polar=6 if quick else 8,
                             kappa_ratio=1e4, material=material)
        p, _ = inflate_sphere(sphere, lam)
        exact = closed_form_pressure_general(lam, sphere.A, sphere.B, material)
        peak = _first_peak(exact)
        shown = [0] + ([peak] if peak is not None else []) + [len(lam) - 1]
        checks += [Check("balloon_models", f"{name} p at lambda_a = {lam[k]:g} [MPa]",
                         float(exact[k]), float(p[k]), 1e-2) for k in shown]
        if name in ("mooney-rivlin", "gent"):
            checks.append(Check("balloon_models", f"{name} pressure maximum [MPa]",
                                _exact_maximum(sphere, material), _sampled_maximum(lam, p), 1e-2))
    return checks


def _exact_maximum(sphere, material) -> float:
    f = lambda x: -float(closed_form_pressure_general(x, sphere.A, sphere.B, material)[0])  # noqa: E731
    return -minimize_scalar(f, bounds=(1.05, 2.5), method="bounded", options={"xatol": 1e-10}).fun


def _first_peak(p):
    """Index of the first interior local maximum of the samples p, or None."""
    rise = np.flatnonzero((p[1:-1] > p[:-2]) & (p[1:-1] >= p[2:]))
    return int(rise[0]) + 1 if rise.size else None


def _sampled_maximum(lam, p) -> float:
    k = _first_peak(p)
    if k is None:
        return float("nan")
    c = np.polyfit(lam[k - 1:k + 2], p[k - 1:k + 2], 2)
    return float(np.polyval(c, -c[1] / (2 * c[0])))
