"""Is a model ingredient behind gmsh meshes' slow convergence? theta(0.8 MPa) on nested
gmsh levels 0 and 1 (the CI mesh, split once) for variants of the model, one ingredient
changed at a time.

On gmsh's nested meshes theta converged at an apparent order of 1.25 in h. If one model
ingredient caused it, changing that ingredient would change the relative increase of theta
from level 0 to level 1 (2.6 % for the default model) a lot. None does (+1.4 ... +4 %; the
rubber's 4-point rule for the windings -4.9 %, from above; the two-sided windings lock,
+43 %); the cause was the mesh (docs/finger.md, "What the error
was": the axial spacing, cancelled in part by the cross-section's error of opposite sign).

Variants: the rubber's bulk modulus (``kappa``: volumetric locking, the P0 pressure), the
windings' stiffness and onset (``fibers``, ``toe``: locking by the hoop constraint, the
tension-only kink), the windings' quadrature (``rule``), grading at the ring edges and cap
corner (``graded``), the whole link length tied (``tie_full``) and windings that also
resist compression (``two_sided``: a hoop-inextensible wall, the model the paper's
lambda2 = 1 describes).

Run: ``python benchmarks/finger_error_sources.py [--variants NAME ...] [--levels 0 1] [--out DIR]``.
Each (variant, level) is written to DIR/<variant>-level<n>.json and reused (resumable;
two processes with disjoint ``--variants`` share the work). Level 1 takes 1.5-4.5 min per
variant on this 2-core machine, level 0 10-30 s; all variants ~35 min.
"""
from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

from softhand.fem.hand.finger import WindingFibers
from finger_convergence import BASE, theta_case


class TwoSidedFibers(WindingFibers):
    """Windings that resist compression too: psi = k (lambda_f - 1)^2 / 2 everywhere."""

    def _g(self, e):
        return 0.5 * e * e, e, 1.0 + 0.0 * e


def two_sided(model) -> None:
    law = model.windings.law
    model.windings.law = TwoSidedFibers(law.k, law.a0, 0.0)


#: name -> (FingerOptions changes, model change or None)
VARIANTS = {
    "default": ({}, None),
    "kappa100": ({"kappa_ratio": 100.0}, None),
    "kappa10": ({"kappa_ratio": 10.0}, None),
    "fibers100": ({"fiber_ratio": 100.0}, None),
    "fibers10": ({"fiber_ratio": 10.0}, None),
    "toe0.01": ({"fiber_toe": 0.01}, None),
    "rule6": ({"fiber_intorder": 6}, None),
    "rule7": ({"fiber_intorder": 7}, None),
    "rule2": ({"fiber_intorder": 2}, None),
    "graded": ({"edge_ratio": 0.5, "edge_reach": 3.0}, None),
    "tie_full": ({"tie": "full"}, None),
    "two_sided": ({}, two_sided),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variants", nargs="+", choices=list(VARIANTS), default=list(VARIANTS))
    parser.add_argument("--levels", type=int, nargs=2, default=[0, 1], metavar=("COARSE", "FINE"))
    parser.add_argument("--out", type=Path, default=Path("results/finger_error_sources"))
    args = parser.parse_args()
    coarse, fine = args.levels
    print(f"{'variant':10s}  {'unknowns':>17s}  {'theta_0.8 [deg]':>17s}  increase  newton its")
    for name in args.variants:
        changes, prepare = VARIANTS[name]
        r = [theta_case(args.out / f"{name}-level{n}.json", replace(BASE, mesh_refine=n, **changes), prepare)
             for n in (coarse, fine)]
        print(f"{name:10s}  {r[0]['ndofs']:7d} -> {r[1]['ndofs']:7d}  {r[0]['theta_deg']:7.3f} -> "
              f"{r[1]['theta_deg']:7.3f}  {100 * (r[1]['theta_deg'] / r[0]['theta_deg'] - 1):+7.2f} %  "
              f"{r[0]['newton_iterations']:4d} {r[1]['newton_iterations']:4d}", flush=True)


if __name__ == "__main__":
    main()
