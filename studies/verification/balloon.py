"""Verification case 4: a thick Neo-Hookean balloon inflated under volume control past its
pressure maximum, against the exact incompressible thick-sphere p(λ_a) (:mod:`softhand.fem.hand.balloon`).

Tolerance 1 %; what remains is the O(μ/κ) = 1e-3 compressibility of the FEM
material (the closed form is incompressible) and the O(h³) geometry of the curved Q2 cells.
"""
from __future__ import annotations

import numpy as np

from softhand.fem.hand.balloon import ThickSphere, closed_form_pressure, inflate_sphere
from softhand.studies.verification.registry import Check

#: inner stretches a/A: before, at (1.426 for B/A = 1.1) and past the pressure maximum
STRETCHES = (1.2, 1.426, 1.8, 2.5)


def balloon(quick: bool) -> list[Check]:
    """p [MPa] of a sphere A = 10 mm, B = 11 mm, μ = 1.15 MPa, κ = 1000 μ at four inner stretches."""
    sphere = ThickSphere(n_polar=6 if quick else 8)
    lam = np.array(STRETCHES)
    p, _ = inflate_sphere(sphere, lam)
    exact = closed_form_pressure(lam, sphere.A, sphere.B, sphere.mu)
    return [Check("balloon", f"p at lambda_a = {x:g} [MPa]", float(e), float(f), 1e-2)
            for x, e, f in zip(lam, exact, p)]
