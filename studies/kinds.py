"""Case functions of the batch runner's kinds that have no module of their own.

Each has the kind signature ``fn(case_params: dict, design, outdir) -> dict of numbers``
(see :mod:`studies.studyfile`) and calls the owning library; imports stay inside the
functions so a worker only imports what its kind needs.
"""
from __future__ import annotations

import math
from pathlib import Path

from reduced.design import HandDesign
from reduced.errors import InputError


def curve(params: dict, design: HandDesign, outdir: Path) -> dict:
    """One point of the free-finger curve: eq. (27) with and (28) without reservoir.

    ``theta_deg`` -> P_MPa, P_no_reservoir_MPa, V_mm3, h_mm, lambda_r;
    ``pressure_mpa`` -> theta_deg, theta_no_reservoir_deg (the inverse).
    """
    from reduced import hand, reservoir

    if ("theta_deg" in params) == ("pressure_mpa" in params):
        raise InputError("curve", sorted(params), "give exactly one of theta_deg, pressure_mpa")
    if "theta_deg" in params:
        theta = math.radians(params["theta_deg"])
        V = reservoir.oil_volume(theta, design)
        return {"P_MPa": hand.pressure(theta, design, reservoir=True),
                "P_no_reservoir_MPa": hand.pressure(theta, design, reservoir=False),
                "V_mm3": V, "h_mm": reservoir.height(V, design),
                "lambda_r": reservoir.stretch(V, design)}
    P = params["pressure_mpa"]
    return {"theta_deg": math.degrees(hand.bend_angle(P, design, reservoir=True)),
            "theta_no_reservoir_deg": math.degrees(hand.bend_angle(P, design, reservoir=False))}
