"""The text of a design run's record: the lines ``softhand design`` prints beside its tables."""
from __future__ import annotations

import math


def knee_line(knee: dict) -> str:
    """The Pareto knee's prediction beside its FEM proof (and the margin, if the proof has one)."""
    predicted, fem = knee["predicted"], knee["fem"]
    margin = "" if fem.get("margin_N") is None else \
        f"margin {predicted['margin_N']:.4g} N predicted, {fem['margin_N']:.4g} N FEM; "
    return (f"knee: P_grasp {predicted['P_grasp_MPa']:.4g} MPa predicted, {fem['P_grasp_MPa']:.4g} MPa FEM; "
            f"F_v {predicted['F_v_N']:.4g} N predicted, {fem['F_v_N']:.4g} N FEM; {margin}"
            f"design {knee['design_file']}")


def margin_lines(fem: dict, task) -> list[str]:
    """The FEM's grasp at the margin's pump pressure, and at the pump limit if it went on to it."""
    def on(row):
        links = row["links_in_contact"]
        return f"on the object: link{'s' if len(links) > 1 else ''} {', '.join(map(str, links)) or 'none'} (0 = base)"

    m = fem["margin"]
    if "error" in m:
        return [f"# FEM margin: not computed ({m['error']}); predicted F_v {m['predicted_F_v_N']:.4g} N"]
    lines = [f"# FEM margin: F_v {m['F_v_N']:.4g} N at the pump pressure {m['P_pump_MPa']:.4g} MPa "
             f"(cavity {m['P_cavity_MPa']:.4g} MPa, {on(m)}), predicted {m['predicted_F_v_N']:.4g} N"]
    limit = fem.get("at_pump_limit")
    if limit and "error" in limit:
        lines.append(f"# FEM at the pump limit {task.max_pressure:g} MPa: not reached ({limit['error']})")
    elif limit:
        lines.append(f"# FEM at the pump limit {task.max_pressure:g} MPa, beyond the reduced model's one-pad "
                     f"grasp: F_v {limit['F_v_N']:.4g} N, margin {limit['margin_N']:.4g} N ({on(limit)})")
    return lines


def relative_difference(a, b):
    """a / b - 1 where both are numbers and b is finite and not 0, else None."""
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and b and math.isfinite(b):
        return a / b - 1.0
    return None
