"""The hinge weight vector w for an object the paper did not grasp, and the force it predicts.

The paper gives w (eqs. (21)-(23)) for a 180 mm and a 240 mm object only. For another
diameter the grasp FEM closes the finger on the rigid object at a cavity pressure P and at
P + dP; w is how the hinges share the extra bend between the two contact states,
w = dq / sum(dq). With it the reduced model's eq. (25) -> (29) gives the grasping force F_v.
Results are cached on disk by their inputs, so a second run takes about a second.
"""
import math
from dataclasses import replace

import numpy as np

from softhand.reduced.design import load_design
from softhand.reduced.grasp import KGF, grasp_forces
from softhand.studies.weights import WeightsCase, weights

design = load_design()
case = WeightsCase(design=design, diameter_mm=210.0, mass_kg=3.0, pressure_mpa=0.8,
                   dP_mpa=0.05, mesh_size_mm=10.0)    # the coarse CI mesh (~4 400 unknowns)
r = weights(case)
w = np.array(r["w"])
print(f"D = {case.diameter_mm:g} mm, P = {r['P_MPa']} MPa: theta = {r['theta_deg']:.2f} deg, "
      f"w = {np.round(w, 3)} (sum {w.sum():.3f}); contact forces {np.round(r['contact_force_N'], 2)} N")

# The reduced model with this w, at the FEM's own (P, theta); eq. (25) without the reservoir
# term at the cavity pressure, as the FEM has none.
F = grasp_forces(r["P_MPa"], math.radians(r["theta_deg"]), case.mass_kg, w, design, reservoir=False)
print(f"F_v: eq. (25) with the FEM's w {F.F_v / KGF:.3f} kgf, grasp FEM {r['F_v_fem_N'] / KGF:.3f} kgf")

# w is a derivative, dq/dtheta along the grasp, taken by a forward difference in P. Halving
# dP must change it by a small amount that shrinks with dP (first order); a w that moved a
# lot would mean the contact changed between the two states and the difference is no
# derivative at all. The check is independent of how w is then used.
half = np.array(weights(replace(case, dP_mpa=case.dP_mpa / 2))["w"])
change = float(np.max(np.abs(half - w)))
print(f"w with dP / 2 = {np.round(half, 3)}: largest change {change:.4f}")
assert change < 0.02, change
