"""
Your own finger design, bent by the pump: eq. (28) without and eq. (27) with the reservoir
==========================================================================================

A design is a frozen :class:`~softhand.reduced.vocabulary.design.HandDesign`; start from the paper's Table I and change what
you change in your mould. Angles are radians inside the code, degrees only at the edges.
"""
import math

import numpy as np

from softhand.reduced import finger, hand, load_design

paper = load_design()                      # studies/designs/paper.toml: Table I
mine = paper.replace(a=3.5, b=4.0, d=12.0)  # a thinner tube, closer to the hinge plate

P = np.array([0.2, 0.5, 0.8])              # pump pressure [MPa]
for name, design in (("paper", paper), ("mine", mine)):
    free = np.degrees(hand.bend_angle(P, design, reservoir=False))
    charged = np.degrees(hand.bend_angle(P, design, reservoir=True))
    print(f"{name:>5}: theta at {P} MPa = {np.round(free, 2)} deg without, "
          f"{np.round(charged, 2)} deg with the reservoir")

# Check against something the code does not compute the same way: for small angles eq. (10)
# has a closed form, zeta_f ~ (4 pi theta / l0) [d^2 (ro^2 - a^2) + (ro^4 - a^4) / 4], so
# eq. (28) P = mu zeta_f / (a^2 pi d) is linear in theta with that slope.
theta_small = math.radians(0.05)
P_small = hand.pressure(theta_small, mine, reservoir=False)
P_closed = mine.mu_sf * finger.zeta_f_small_angle(theta_small, mine) / (mine.a**2 * math.pi * mine.d)
print(f"small angle: P = {P_small:.6e} MPa, closed form {P_closed:.6e} MPa")
assert abs(P_small / P_closed - 1) < 1e-3  # the closed form drops O(theta) terms
