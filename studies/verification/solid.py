r"""Verification cases of the 3D solid (uniaxial tension, tubes in plane strain,
locking, a fiber-wound tube, convergence rates): closed form vs FEM.

All cases use the mean-dilatation P2-P0 solid of :mod:`softhand.fem.solid` on quadratic
(isoparametric) tetrahedra, the follower pressure of :mod:`softhand.fem.loads` and Newton with
load stepping of :mod:`softhand.fem.newton_path`. The tube has the finger's radii R_i = 4, R_o = 9 mm and
μ = 1.15 MPa. Plane strain is a quarter-annulus slice with u_z = 0 on both faces and
symmetry planes x = 0, y = 0 (exact for the plane-strain solution, which has u_z = 0 and
no hoop displacement). Closed forms: :mod:`softhand.studies.verification.closed_forms`.

What bounds each tolerance:

* uniaxial: the state is homogeneous (linear u, exact in P2; J̄ = J), so only the Newton
  tolerance (1e-10 relative residual) remains: 1e-6;
* tube: discretisation (P2-P0, 1.2-2 mm elements: a few 1e-5) plus compressibility against
  the incompressible closed form (κ = 1000 μ: about 3e-4): the target 0.5 %;
* locking: κ/μ from 1e2 to 1e5 on the same mesh: within the target 1 % (κ/μ = 1e2 is
  itself compressible by p/κ ≈ 0.3 %);
* fiber tube (hoop fibers through the wall, k = 1000 μ): hoop stretch 1 up to the fiber
  strain p R_o/(k b) ≈ 0.1 %: the target 1 %;
* ring tube (closed end, inextensible hoop ring on the outer surface as a constraint
  u_r = 0): discretisation, O(p/κ) and the end cap's disturbance at the measuring section
  (three wall thicknesses away): 1 %;
* convergence: observed order of the tube's L2 displacement error under refinement, at
  least 2 (P2-P0: O(h^2) in L2 norm).

The tangent and Newton's order on these problems: :mod:`.newton_checks`.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import skfem
from scipy.optimize import brentq

from softhand.fem.linsolve import make_solver
from softhand.fem.loads import FollowerPressure
from softhand.fem.materials import Fibers, NeoHookean
from softhand.fem.newton import NewtonOptions
from softhand.fem.newton_path import PathOptions, solve_path
from softhand.fem.mixed import MixedNewton
from softhand.fem.solid import Solid
from softhand.meshes.tube import Tube, tube_mesh
from softhand.studies.verification import closed_forms as cf
from softhand.studies.verification.registry import Check

MU = 1.15  #: shear modulus of the finger's rubber [MPa]
R_I, R_O = 4.0, 9.0  #: tube radii [mm] (the finger's a and a + b)
#: atol [N]: above the round-off floor of the kappa terms (about 2e-10 N at kappa = 1e5 mu)
NEWTON = NewtonOptions(rtol=1e-10, atol=1e-9)


@dataclass
class Problem:
    """u = t u_D + T q: prescribed displacement u_D (scaled by the load factor t) and the
    reduced coordinates q through the sparse map T (Dirichlet zeros and ties eliminated)."""

    solid: Solid
    T: sp.csr_matrix
    u_D: np.ndarray
    pressure: FollowerPressure | None = None
    p: float = 0.0  #: inner pressure at t = 1 [MPa]

    def u(self, q, t=1.0):
        return t * self.u_D + self.T @ q

    def fun(self, q, t=1.0, anchor=None):
        """Reduced (R, K) at load factor t; with ``anchor`` the mixed (u, p) iteration's tangent."""
        u = self.u(q, t)
        with np.errstate(invalid="ignore"):  # J < 0 in a rejected trial: Newton backtracks
            R, data = self.solid.residual_tangent_data(u, anchor=anchor)
        if self.pressure is not None:
            R = R + self.pressure.residual(u, t * self.p)
            data = data + self.pressure.tangent_data(u, t * self.p)
        K = self.solid.scatter.csr(data)
        return self.T.T @ R, (self.T.T @ K @ self.T).tocsr()

    def solve(self, steps: int = 4) -> np.ndarray:
        """The displacement at t = 1 by load stepping with the mixed (u, p) Newton iteration of
        :class:`softhand.fem.mixed.MixedNewton` (κ-independent convergence); raises NotConverged."""
        t_now = [0.0]
        mixed = MixedNewton(self.solid, expand=lambda q: self.u(q, t_now[0]))

        def fun_t(q, t):
            t_now[0] = t
            return self.fun(q, t, anchor=mixed.anchor)

        res = solve_path(fun_t, np.zeros(self.T.shape[1]),
                         PathOptions(steps=steps, newton=NEWTON),
                         solver=linear_solver(), on_accept=mixed.accept)
        return self.u(res.x[-1])


@functools.cache
def linear_solver():
    """One solver for the suite (creating a PARDISO handle costs ~0.5 s)."""
    return make_solver()


def keep_map(n: int, fixed: np.ndarray) -> sp.csr_matrix:
    """T selecting the dofs not in ``fixed`` (their prescribed values are in u_D)."""
    free = np.setdiff1d(np.arange(n), fixed)
    return sp.csr_matrix((np.ones(free.size), (free, np.arange(free.size))), shape=(n, free.size))


def hoop_directions(mesh) -> np.ndarray:
    """e_theta at the solid's quadrature points (P2, intorder 2), shape (3, nel, nqp)."""
    x = np.asarray(skfem.Basis(mesh, skfem.ElementTetP2(), intorder=2).global_coordinates())
    r = np.hypot(x[0], x[1])
    return np.stack([-x[1] / r, x[0] / r, 0 * r])


def tube_law(mesh, kappa_ratio=1e3, fiber_ratio=None):
    """Rubber (κ = kappa_ratio μ), plus hoop fibers (k = fiber_ratio μ) through the wall."""
    law = NeoHookean(MU, kappa_ratio * MU)
    if fiber_ratio is not None:
        law = law + Fibers(fiber_ratio * MU, hoop_directions(mesh))
    return law


def plane_strain_tube(size: float, p: float, *, kappa_ratio=1e3, fiber_ratio=None) -> Problem:
    """Quarter-annulus slice of thickness ``size`` under inner pressure ``p`` [MPa]."""
    mesh = tube_mesh(Tube(R_I, R_O, size, sector="quarter"), size=size)
    solid = Solid(mesh, tube_law(mesh, kappa_ratio, fiber_ratio))
    fixed = np.concatenate([solid.dofs("base", [2]), solid.dofs("tip", [2]),
                            solid.dofs("symmetry", [1]), solid.dofs("symmetry_x", [0])])
    return Problem(solid, keep_map(solid.ndofs, np.unique(fixed)), np.zeros(solid.ndofs),
                   FollowerPressure(solid, mesh.boundaries["inner"]), p)


def inner_stretch(problem: Problem, u: np.ndarray) -> float:
    """Mean deformed radius of the inner surface's nodes over R_i."""
    s = problem.solid.sbasis.get_dofs(problem.solid.mesh.boundaries["inner"]).all()
    x = problem.solid.dof_locations[:, s] + problem.solid.nodal(u)[:, s]
    return float(np.mean(np.hypot(x[0], x[1])) / R_I)


def tube_error(size: float, p: float, kappa_ratio: float) -> tuple[float, float]:
    """(closed-form p at the FEM's inner stretch, applied p) of the plane-strain tube."""
    problem = plane_strain_tube(size, p, kappa_ratio=kappa_ratio)
    lam = inner_stretch(problem, problem.solve())
    return cf.tube_pressure_plane_strain(lam, R_I, R_O, MU), p


# -- case 1 -----------------------------------------------------------------------------
def uniaxial_tension(quick: bool) -> list[Check]:
    """Unit cube stretched by λ along x, lateral faces free (rollers on x, y, z = 0):
    nominal stress from the reaction vs the Neo-Hookean closed form; with a fiber family
    along x (k = 20 μ) the closed form adds k (λ - 1) in tension and nothing in compression."""
    mesh = skfem.MeshTet2.from_mesh(skfem.MeshTet.init_tensor(*[np.linspace(0, 1, 3)] * 3))
    cases = [(1.5, None)] if quick else [(1.5, None), (0.7, None), (1.5, 20.0), (0.7, 20.0)]
    checks = []
    for lam, k in cases:
        law = NeoHookean(MU) + Fibers(k * MU, np.array([1.0, 0, 0])) if k else NeoHookean(MU)
        solid = Solid(mesh, law)
        faces = {a: [mesh.facets_satisfying(lambda x, a=a, v=v: np.isclose(x[a], v)) for v in (0, 1)]
                 for a in range(3)}
        pulled = solid.dofs(faces[0][1], [0])
        fixed = np.concatenate([solid.dofs(faces[a][0], [a]) for a in range(3)] + [pulled])
        u_D = np.zeros(solid.ndofs)
        u_D[pulled] = lam - 1.0
        problem = Problem(solid, keep_map(solid.ndofs, np.unique(fixed)), u_D)
        P11 = float(solid.residual(problem.solve(steps=2))[pulled].sum())  # reaction / area 1
        exact = cf.uniaxial_nominal_stress(lam, MU, 1e3 * MU) + (k or 0) * MU * max(lam - 1, 0)
        label = f"P11 [MPa] at stretch {lam}" + (f", fiber k = {k:g} mu" if k else "")
        checks.append(Check("uniaxial", label, exact, P11, 1e-6))
    return checks


# -- case 2 -----------------------------------------------------------------------------
def tube_plane_strain(quick: bool) -> list[Check]:
    """Thick-walled tube in plane strain under follower pressure: p vs p(λ_i) closed form."""
    size = 2.0 if quick else 1.2
    pressures = (0.4,) if quick else (0.2, 0.4, 0.6)
    checks = []
    for p in pressures:
        exact, fem = tube_error(size, p, 1e3)
        checks.append(Check("tube", f"p [MPa] at the FEM inner stretch, h = {size} mm", exact, fem, 5e-3))
    return checks


def tube_locking(quick: bool) -> list[Check]:
    """The same tube (p = 0.4 MPa) for κ/μ = 1e2 .. 1e5: no volumetric locking."""
    ratios = (1e2, 1e5) if quick else (1e2, 1e3, 1e4, 1e5)
    return [Check("locking", f"p [MPa] at the inner stretch, kappa/mu = {r:.0e}", *tube_error(2.0, 0.4, r), 1e-2)
            for r in ratios]


# -- case 3 -----------------------------------------------------------------------------
def fiber_tube(quick: bool) -> list[Check]:
    """Hoop fibers: (a) plane-strain tube with fibers through the wall at 0.8 MPa, inner hoop
    stretch vs 1 (inextensible fibers); (b) closed-end tube with an inextensible hoop ring on
    its outer surface at 0.8 MPa, axial stretch vs the closed form."""
    size = 2.0 if quick else 1.5
    problem = plane_strain_tube(size, 0.8, fiber_ratio=1e3)
    lam = inner_stretch(problem, problem.solve())
    checks = [Check("fiber_tube", "inner hoop stretch, fibers k = 1000 mu, p = 0.8 MPa", 1.0, lam, 1e-2)]
    problem, length = ring_tube(3.0 if quick else 2.0, 0.8)
    u = problem.solve(steps=4)
    exact = cf.ring_tube_axial_stretch(0.8, R_I, R_O, MU)
    checks.append(Check("fiber_tube", "axial stretch, closed end + outer hoop ring, p = 0.8 MPa",
                        exact, axial_stretch(problem, u, length / 2), 1e-2))
    return checks


def ring_tube(size: float, p: float, *, length: float = 30.0) -> tuple[Problem, float]:
    """Quarter tube with an end cap (thickness R_o - R_i), u_z = 0 at the base, and the
    outer surface held at its radius (u_r = 0: the inextensible ring) but free to slide."""
    mesh = tube_mesh(Tube(R_I, R_O, length, cap=R_O - R_I, sector="quarter"), size=size)
    solid = Solid(mesh, tube_law(mesh))
    ring = solid.sbasis.get_dofs(mesh.boundaries["outer"]).all()
    X = solid.dof_locations[:, ring]
    on_plane = np.isclose(X[0], 0, atol=1e-9) | np.isclose(X[1], 0, atol=1e-9)
    fixed = np.concatenate([solid.dofs("base", [2]), solid.dofs("symmetry", [1]),
                            solid.dofs("symmetry_x", [0]), 3 * ring, 3 * ring + 1])
    sliding, Xs = ring[~on_plane], X[:, ~on_plane]
    r = np.hypot(Xs[0], Xs[1])
    cols = np.arange(sliding.size)
    slide = sp.csr_matrix((np.concatenate([-Xs[1] / r, Xs[0] / r]),
                           (np.concatenate([3 * sliding, 3 * sliding + 1]), np.concatenate([cols, cols]))),
                          shape=(solid.ndofs, sliding.size))
    T = sp.hstack([keep_map(solid.ndofs, np.unique(fixed)), slide]).tocsr()
    return Problem(solid, T, np.zeros(solid.ndofs),
                   FollowerPressure(solid, mesh.boundaries["inner"]), p), length


def axial_stretch(problem: Problem, u: np.ndarray, z_max: float) -> float:
    """1 + d u_z/dz fitted over the nodes with z <= z_max (away from the cap)."""
    X, U = problem.solid.dof_locations, problem.solid.nodal(u)
    near = X[2] <= z_max
    return 1.0 + float(np.polyfit(X[2, near], U[2, near], 1)[0])


# -- case 5 -----------------------------------------------------------------------------
def tube_convergence(quick: bool) -> list[Check]:
    """Observed order of the plane-strain tube's relative L2 displacement error (p = 0.1 MPa,
    κ = 1e4 μ: compressibility O(p/κ) ≈ 1e-5 stays below the discretisation error) under
    mesh refinement, by a least-squares fit of log(error) on log(h); P2-P0 gives at least
    2 (O(h^2) in L2, the element-constant pressure limiting it below P2's 3)."""
    sizes = (4.0, 2.8, 2.0) if quick else (4.0, 2.8, 2.0, 1.4, 1.0)
    errors = []
    for h in sizes:
        problem = plane_strain_tube(h, 0.1, kappa_ratio=1e4)
        errors.append(displacement_error(problem, problem.solve()))
    order = float(np.polyfit(np.log(sizes), np.log(errors), 1)[0])
    label = f"observed L2 order, h = {'/'.join(f'{h:g}' for h in sizes)} mm, errors " + \
        "/".join(f"{e:.1e}" for e in errors)
    return [Check("convergence", label, 2.0, order, 0.0, at_least=True)]


def displacement_error(problem: Problem, u: np.ndarray) -> float:
    """||u - u_exact|| / ||u_exact|| (L2) for the plane-strain tube under its pressure, with
    u_exact = (r/R - 1) X, r^2 = R^2 + c and c from the closed form's inner stretch."""
    lam = brentq(lambda l: cf.tube_pressure_plane_strain(l, R_I, R_O, MU) - problem.p, 1.0, 10.0,
                 xtol=1e-15)
    c = (lam ** 2 - 1.0) * R_I ** 2
    basis = skfem.Basis(problem.solid.mesh, skfem.ElementVector(skfem.ElementTetP2()), intorder=4)
    x = np.asarray(basis.global_coordinates())
    R = np.hypot(x[0], x[1])
    exact = (np.sqrt(R ** 2 + c) / R - 1.0) * np.stack([x[0], x[1], 0 * x[2]])
    error = np.asarray(basis.interpolate(u)) - exact
    return float(np.sqrt(np.sum(error ** 2 * basis.dx) / np.sum(exact ** 2 * basis.dx)))
