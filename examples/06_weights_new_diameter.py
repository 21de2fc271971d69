"""The hinge weight vector w for an object the paper did not grasp, and the pressure to hold it.

The paper gives w (eqs. (21)-(23)) for a 180 mm and a 240 mm object only. For another
diameter the kinematics give one in milliseconds: place the object as the grasp FEM does,
close the finger until a pad touches it, and take the smallest hinge motion, summing to 1,
that keeps that pad rolling on the object (the hinges beyond it share equally, those
before it roll the pad). With that w, eqs. (25), (29) give the pump pressure that holds
a mass with a given normal force.

The grasp FEM computes w with the rubber's stiffness in it (minutes per diameter, cached):
``softhand weights --diameter-mm 210`` or ``studies.weights.weights(WeightsCase(diameter_mm=210))``.
"""
import math

import numpy as np

from softhand.reduced.equations import contact, grasp, kinematics
from softhand.reduced.vocabulary.design_files import load_design

design = load_design()
D, mass = 210.0, 2.0                                   # object diameter [mm], mass [kg]
depth = contact.object_depth(D, design)               # centre below the palm [mm]
theta, link = contact.contact_angle(D, design, depth=depth)   # first touch, closing freely
q = kinematics.hinge_angles(theta, np.full(design.n_s, 1.0 / design.n_s))
w = contact.rolling_weights(q, D, link, design, depth=depth)
print(f"D = {D:g} mm at depth {depth:.1f} mm: pad {link} touches at theta = "
      f"{math.degrees(theta):.2f} deg; w = {np.round(w, 3)} (sum {w.sum():.3f})")

for F_v in (0.0, 5.0):                                 # just touching; pressing with 5 N
    P = grasp.pressure_to_hold(mass, theta, w, design, F_v=F_v)
    print(f"pump pressure to hold {mass:g} kg with F_v = {F_v:g} N: {float(P):.4f} MPa")

# The check, by finite differences of the pad's gap (not the analytic gradient w is built
# from): moving the hinges along w keeps the touching pad on the object, to first order,
# while closing all hinges equally would push it into the object.
gap = lambda hinges: contact.pad_gaps(hinges, (0.0, depth), D / 2, design)[link]
h = 1e-5
rate = (gap(q + h * w) - gap(q - h * w)) / (2 * h)     # [mm/rad]
uniform = np.full(design.n_s, 1.0 / design.n_s)
rate_uniform = (gap(q + h * uniform) - gap(q - h * uniform)) / (2 * h)
print(f"d gap / d theta along w {rate:.2e} mm/rad; closing uniformly {rate_uniform:.2f} mm/rad")
assert abs(rate) < 1e-6 * abs(rate_uniform), (rate, rate_uniform)
