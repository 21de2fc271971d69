"""The hinge weight vector w for an object the paper did not grasp, and the force it predicts.

The paper gives w (eqs. (21)-(23)) for a 180 mm and a 240 mm object only. For another
diameter the grasp FEM closes the finger on the rigid object at a cavity pressure P and at
P + dP; w is how the hinges share the extra bend between the two contact states,
w = dq / sum(dq). With it the reduced model's eq. (25) -> (29) gives the grasping force F_v.
Results are cached on disk by their inputs, so a second run takes about a second.
"""
import math

import numpy as np

from softhand.reduced import contact
from softhand.reduced.design import load_design
from softhand.reduced.grasp import KGF, grasp_forces
from softhand.studies.weights import WeightsCase, weights

design = load_design()
case = WeightsCase(design=design, diameter_mm=210.0, mass_kg=0.0, pressure_mpa=0.8,
                   dP_mpa=0.05, mesh_size_mm=10.0)    # the coarse CI mesh (~4 400 unknowns)
r = weights(case)
w = np.array(r["w"])
N = np.array(r["contact_force_N"])                    # per link pad, base .. tip [N]
link = int(np.argmax(N))
print(f"D = {case.diameter_mm:g} mm, P = {r['P_MPa']} MPa: theta = {r['theta_deg']:.2f} deg, "
      f"pad {link} touches (N = {N[link]:.2f} N); w = {np.round(w, 3)}")

# The reduced model with this w, at the FEM's own (P, theta); eq. (25) without the reservoir
# term at the cavity pressure, as the FEM has none.
F = grasp_forces(r["P_MPa"], math.radians(r["theta_deg"]), case.mass_kg, w, design, reservoir=False)
print(f"F_v: eq. (25) with the FEM's w {F.F_v / KGF:.3f} kgf, grasp FEM {r['F_v_fem_N'] / KGF:.3f} kgf")

# An independent estimate of w from kinematics alone: the least hinge motion, summing to 1,
# that keeps the touching pad rolling on the object (no FEM, no rubber, no pressure) at the
# FEM's hinge angles and object placement. The FEM's tube is not equally stiff at every
# hinge, so the two differ by a few hundredths where the contact regime is the same.
rolling = contact.rolling_weights(np.radians(r["hinge_deg"]), case.diameter_mm, link, design,
                                  depth=r["depth_mm"])
difference = float(np.max(np.abs(rolling - w)))
print(f"rolling kinematics: w = {np.round(rolling, 3)}; largest difference {difference:.3f}")
assert difference < 0.05, difference
