"""Sizing the reservoir: which initial oil volume V0 gives a 0.08 MPa pressure offset?

Eq. (27): the charged rubber sheet pushes oil into the fingers, so the pump needs
p_r(V) less. The offset at rest is p_r(V0); find V0 for a target with a root finder,
using the paper's ellipse model and the FEM-calibrated sheet (``reservoir_model = "fem"``).
"""
import math

from scipy.optimize import brentq

from softhand.reduced.equations import hand, reservoir
from softhand.reduced.vocabulary.design_files import load_design

design = load_design()
target = 0.08  # [MPa]

for model in ("ellipse", "fem"):
    d = design.replace(reservoir_model=model)
    V0 = brentq(lambda V: reservoir.pressure(V, d) - target, 2000.0, 40000.0, xtol=1e-6)
    sized = d.replace(V0=V0)
    offset = -float(hand.pressure(0.0, sized))   # P(0) = -p_r(V0): the pump pulls at rest
    print(f"{model:>7}: V0 = {V0:8.0f} mm^3 gives p_r(V0) = {offset:.4f} MPa")
    assert abs(offset - target) < 1e-6

# Independent check of the model's physics: the pressure is the derivative of the sheet's
# strain energy (eq. (11)) with respect to the oil volume, p = dW/dV; central differences:
V, dV = 17800.0, 1.0
dWdV = (reservoir.strain_energy(V + dV, design) - reservoir.strain_energy(V - dV, design)) / (2 * dV)
print(f"dW/dV = {dWdV:.6f} MPa, p_r = {reservoir.pressure(V, design):.6f} MPa")
assert math.isclose(dWdV, reservoir.pressure(V, design), rel_tol=1e-6)
