"""
A problem of your own on the FEM core: a closed rubber tube under oil pressure
==============================================================================

A quarter of a tube (inner radius 4, outer 9, cavity 30 mm, 5 mm end cap) in a softer
rubber than the paper's, clamped at its base, inflated by a follower pressure. The pieces:
a gmsh mesh with named surfaces (:mod:`softhand.meshes.tube`), a material law, the mean-dilatation
solid, a load, Dirichlet conditions, load stepping with the mixed (u, p) Newton iteration,
and the support's reaction force.
"""
import math

import numpy as np

from softhand.fem import (FollowerPressure, MixedNewton, NeoHookean, NewtonOptions, PathOptions,
                          Restriction, Solid, make_solver, solve_path)
from softhand.meshes import Tube, tube_mesh

a, p = 4.0, 0.3                                   # cavity radius [mm], oil pressure [MPa]
mesh = tube_mesh(Tube(a, 9.0, 30.0, cap=5.0, sector="quarter"), size=3.0)
solid = Solid(mesh, NeoHookean(mu=0.8, kappa=800.0))   # your rubber: mu = 0.8 MPa
load = FollowerPressure(solid, "inner")
fixed = np.unique(np.concatenate([solid.dofs("base"),               # clamped base
                                  solid.dofs("symmetry", (1,)),     # plane y = 0
                                  solid.dofs("symmetry_x", (0,))]))  # plane x = 0
red = Restriction(solid.ndofs, solid.free_dofs(fixed))  # prescribed values: zero here
mixed = MixedNewton(solid, red.expand)


def fun_t(x, t):
    """(R, K) on the free dofs at load factor t: rubber plus follower pressure t p."""
    u = red.expand(x)
    R, data = solid.residual_tangent_data(u, anchor=mixed.anchor)
    K = solid.scatter.csr(data + load.tangent_data(u, t * p))
    return red.vector(R + load.residual(u, t * p)), red.restrict(K)


path = solve_path(fun_t, np.zeros(len(red.keep)),
                  PathOptions(steps=3, newton=NewtonOptions(merit="finite")),
                  solver=make_solver(), on_accept=mixed.accept)
u = red.expand(path.x[-1])
tip = solid.nodal(u)[2].max()
print(f"{solid.ndofs} dofs, {path.total_iterations} Newton iterations; the cap moved {tip:.3f} mm")

# The reaction at the clamped base. Equilibrium, whatever the material: the oil pushes the
# cap out with p times the cavity's cross-section at the base (which the clamp keeps at
# radius a), so the base must pull back with p pi a^2 / 4 on the quarter model.
force, _ = solid.reaction(u, "base", external=-load.residual(u, p))
print(f"base reaction {force} N; equilibrium says F_z = {-p * math.pi * a**2 / 4:.6f} N")
# (to the area error of the mesh's curved quadratic quarter circle, ~1e-4 at h = 3 mm)
assert math.isclose(force[2], -p * math.pi * a**2 / 4, rel_tol=1e-3)
