r"""The FEM proof of a design: free bend with the reservoir, and the grasp at the task's object.

Three FEM models check the reduced model's answer (:class:`softhand.studies.design.evaluate.Evaluation`):

1. **Free bend** (finger FEM, :mod:`softhand.fem.hand.finger`): cavity pressures in steps of at most
   ``max_step_mpa`` up to eq. (28)'s pressure at the grasp angle theta_g, then 1.25, 1.5, ...
   times it, until the finger bends past theta_g; the
   cavity pressure p_finger, the cavity volume change dQ and the rubber's stretch (the converged
   ``rubber_stretch`` and the corner peak ``max_principal_stretch``) at theta_g are interpolated (monotone cubic in theta).
2. **Reservoir** (sheet FEM, :mod:`softhand.fem.hand.reservoir`, one path from flat to V0): p_r at the oil
   left, V = V0 - n dQ (at the grasp: interpolated on the path), so that the hand's pump
   pressure at contact is
   P_contact = p_finger(theta_g) - p_r(V) -- as :func:`softhand.studies.compare.whole_hand`.
3. **Grasp** (:mod:`softhand.fem.hand.grasp`, the finger closing on the rigid object with its weight share):
   first at the cavity pressure that the *predicted* pump pressure gives with the FEM
   reservoir (F_v there is the FEM's answer to the prediction), then secant steps in the
   cavity pressure until the FEM's F_v is the required one within ``rtol``: that state is the
   verified grasp (its pump pressure P_grasp, bend, w, rubber stretch, VTK).
4. **Margin** (the "margin" objective only): the grasp FEM continued from the verified grasp
   to the pump pressure of the reduced model's margin (the pump limit, or where the reduced
   model's one-pad grasp ends below it), in cavity-pressure steps of at most ``max_step_mpa``,
   then secant corrections of the cavity pressure until the state's pump pressure,
   cavity pressure less p_r at the oil left, is that pressure within ``pump_tol_mpa``: its
   F_v less the required one is the FEM's margin. Where the reduced margin ends below the pump
   limit, the FEM goes on to the limit (it has no one-pad restriction: the margin the task
   asks for, which the reduced model does not reach).

The finger mesh is the grasp FEM's (:func:`softhand.studies.weights.finger_options`) for both finger
runs, so that the free bend and the grasp share one discretisation.

Here: :func:`prove`, which builds the models and chains the runs, and the verdict on its numbers
(the task's limits, the report, the corrected task). The runs are in
:mod:`softhand.studies.design.proof_steps`, the finger meshes tried in :mod:`softhand.studies.design.proof_sizes`.
"""
from __future__ import annotations

import math
import time
from pathlib import Path
from dataclasses import replace

import numpy as np

from softhand.reduced.equations import reservoir
from softhand.studies.design.evaluate import Evaluation, calibrated_tube
from softhand.studies.design.proof_steps import ProofOptions, free_bend, grasp_secant, margin, sheet_pressure
from softhand.studies.design.task import Task


def _touch(bend: dict, ev: Evaluation, task: Task) -> float | None:
    """The bend [deg] at which the FEM finger, closing with its own hinge shares (at theta_g),
    touches the object in the reduced model's geometry (None: it does not reach it)."""
    from softhand.reduced.equations import contact
    from softhand.reduced.vocabulary.errors import InputError

    try:
        theta, _ = contact.contact_angle(task.diameter, ev.design, depth=ev.depth, w=bend["hinge_share"])
    except InputError:
        return None
    return math.degrees(theta)


#: the FEM confirms a limit to this share of it: the optimiser puts a design on its binding
#: limit to the reduced model's accuracy, and the FEM's measures there are converged to a few
#: tenths of a per cent at best (the sheet's rubber_stretch 0.4 % between its two finest meshes),
#: so a strict comparison would make the verdict on a binding limit a coin toss (the paper
#: task's sheet: 1.50002 by FEM against its limit 1.5)
FEM_TOLERANCE = 1e-3


def fem_constraints(fem: dict, task: Task) -> list[dict]:
    """The task's limits on the FEM's verified grasp: its converged rubber stretch (the tube's,
    fem.rubber_stretch: where the tied rings and the end cap concentrate it; and the sheet's at
    V0) and its pump pressure, each met to within :data:`FEM_TOLERANCE` of the limit."""
    rows = [("rubber_stretch (FEM, verified grasp)", fem["rubber_stretch"], task.max_stretch),
            ("sheet rubber_stretch at V0 (FEM)", fem["sheet_rubber_stretch"], task.max_stretch),
            ("pump_pressure at the grasp (FEM) [MPa]", fem["P_grasp_MPa"], task.max_pressure)]
    return [{"name": name, "value": value, "limit": limit, "sense": "<=", "tolerance": FEM_TOLERANCE,
             "satisfied": bool(value <= limit * (1.0 + FEM_TOLERANCE))}
            for name, value, limit in rows]


def fem_report(fem: dict, ev: Evaluation) -> str | None:
    """One paragraph if the FEM proof failed (``fem["error"]``, on every mesh it tried) or its
    grasp breaks a limit of the task, else None."""
    if "error" in fem:
        meshes = ", ".join(f"{m['mesh_size_mm']:g} mm" for m in fem.get("failed_meshes", ()))
        finer = "a coarser" if fem.get("too_large") else "a finer"
        return (f"The FEM proof could not be completed (finger mesh {meshes}): {fem['error']}. "
                f"The design is not proven; try --mesh-size-mm with {finer} mesh.")
    broken = [c for c in fem.get("constraints", ()) if not c["satisfied"]]
    if not broken:
        return None
    names = "; ".join(f"{c['name']} = {c['value']:.4g} above the limit {c['limit']:.4g}" for c in broken)
    if calibrated_tube(ev.design):
        return (f"The FEM proof does not confirm the design: {names}. The calibrated models predicted a "
                f"rubber stretch of {ev.stretch:.4g} for the tube and {ev.sheet_stretch:.4g} for the sheet "
                f"(their fits of the FEM's converged stretch) and a pump pressure of {ev.P_grasp:.4g} MPa.")
    return (f"The FEM proof does not confirm the design: {names}. The reduced model's estimate of the "
            f"rubber stretch (eq. (8), the wall's bending strain) is {ev.stretch:.4g}; the FEM's sits "
            f"at the tied rings and the end cap, which the reduced model does not see.")


def corrected_task(task: Task, ev: Evaluation, fem: dict) -> Task | None:
    """The task with eq. (8)'s strain scaled to the FEM's, if the FEM's rubber stretch at the
    verified grasp broke the task's limit (None otherwise): stretch_factor x (lambda_FEM - 1) /
    (lambda_predicted - 1), so that the reduced model predicts this design's FEM stretch and a
    new optimum keeps its FEM stretch near the limit. The FEM's converged stretch grows with the
    bend as eq. (8) does (both are the wall's strain at the hinge), so one factor carries to
    nearby designs. None as well where the design's tube stretch is the FEM-calibrated one
    (finger_model "fem" with a table that holds it): that prediction is calibrated, not
    corrected, and no factor would change it."""
    stretch = fem.get("rubber_stretch")
    if stretch is None or stretch <= task.max_stretch or not ev.stretch > 1.0:
        return None
    if calibrated_tube(ev.design):
        return None
    return replace(task, stretch_factor=task.stretch_factor * (stretch - 1.0) / (ev.stretch - 1.0))


def prove(ev: Evaluation, task: Task, options: ProofOptions = ProofOptions(), *, out=None,
          progress=None, tick=None) -> dict:
    """Run the three FEM models for the evaluated design; the FEM's numbers (see module doc).
    ``progress(text)`` is told each phase, ``tick(text)`` each converged free-bend state."""
    from softhand.fem.hand.finger import FingerModel
    from softhand.fem.hand.grasp import GraspModel
    from softhand.fem.hand.reservoir import SheetModel, inflate
    from softhand.studies.weights import write_vtk, finger_options

    say = progress or (lambda text: None)
    design = ev.design
    t0 = time.perf_counter()
    finger = FingerModel(design, replace(finger_options(options.mesh_size_mm), edge_ratio=options.edge_ratio))
    say(f"free bend FEM to the grasp angle {math.degrees(ev.theta_grasp):.2f} deg "
        f"({finger.ndofs} unknowns)")
    bend = free_bend(finger, ev.theta_grasp, options, tick)
    touch = _touch(bend, ev, task)
    say("reservoir sheet FEM at the oil left at contact")
    V_contact = float(reservoir.oil_left(bend["dQ_mm3"], design))
    if not V_contact > 0:
        raise RuntimeError(f"the FEM fingers take {design.n * bend['dQ_mm3']:.0f} mm^3 of oil to reach "
                           f"the grasp angle, more than V0 = {design.V0:.0f} mm^3 (eq. (2) says "
                           f"{design.n * design.a**2 * math.pi * design.d * ev.theta_grasp:.0f})")
    sheet_model = SheetModel.from_design(design, **options.sheet)
    sheet = inflate(sheet_model, [V_contact, design.V0])
    p_contact = sheet.states[0].pressure
    at_contact = lambda _: p_contact  # noqa: E731 -- the sheet FEM solved at exactly that oil
    model = GraspModel(finger, task.diameter, mass=task.mass)
    P_cav = ev.P_grasp + p_contact  # the cavity pressure of the predicted pump pressure, FEM reservoir
    P_touch = bend["P_finger_MPa"] + 0.5 * options.dP_mpa  # just past the FEM's contact
    P_start = max(P_cav, P_touch)
    say(f"grasp FEM from the cavity pressure {P_start:.4g} MPa (object depth {model.depth:.1f} mm)")
    steps = max(1, math.ceil((P_start - P_touch) / options.max_step_mpa - 1e-9))
    near = P_start - P_touch < 0.5 * options.dP_mpa  # no continuation needed
    g = grasp_secant(model, [P_start] if near else np.linspace(P_touch, P_start, steps + 1),
                     ev.F_v, options, say)
    best = g["best"]
    fs = finger.state(best.y, best.P)
    V_grasp = float(reservoir.oil_left(fs.dQ, design))
    # the sheet's path from flat to V0 passes V_grasp (steps <= R^2 t / 2): interpolated
    p_grasp = float(sheet_pressure(sheet)(V_grasp))
    first = g["first"]
    fem = {
        "P_grasp_MPa": float(reservoir.pump_pressure(best.P, V_grasp, design, sheet_pressure(sheet))),
        "P_contact_MPa": float(reservoir.pump_pressure(bend["P_finger_MPa"], V_contact, design, at_contact)),
        "P_finger_at_contact_MPa": bend["P_finger_MPa"],
        "theta_touch_deg": touch,
        "reservoir_pressure_at_contact_MPa": p_contact,
        "theta_grasp_deg": math.degrees(best.theta),
        # below the FEM's contact pressure the finger does not reach the object: F_v = 0
        "F_v_N": first.F_v if P_start == P_cav else 0.0,
        "touches_at_predicted_pressure": P_start == P_cav,
        "F_v_at_P_grasp_N": best.F_v,
        "w": g["w"].tolist(),
        "rubber_stretch": fs.rubber_stretch,
        "max_principal_stretch": fs.max_principal_stretch,
        "rubber_stretch_at_contact": bend["rubber_stretch"],
        "max_principal_stretch_at_contact": bend["max_principal_stretch"],
        "sheet_rubber_stretch": sheet.states[1].rubber_stretch,
        "sheet_max_principal_stretch": sheet.states[1].max_principal_stretch,
        "contact_force_N": best.N.tolist(),
        "P_cavity_MPa": best.P,
        "reservoir_pressure_MPa": p_grasp,
        "reservoir_offset_MPa": sheet.states[1].pressure,
        "reservoir_pressure_maximum": sheet.pressure_max,
        "depth_mm": model.depth,
        "free_bend": bend,
        "grasp_states": [{"P_cavity_MPa": s.P, "theta_deg": math.degrees(s.theta), "F_v_N": s.F_v}
                         for s in g["states"]],
        "finger_ndofs": finger.ndofs, "sheet_ndofs": sheet.ndofs,
        "mesh_size_mm": options.mesh_size_mm,
        "wall_seconds": time.perf_counter() - t0,
    }
    states = [best]
    if task.objective == "margin" and math.isfinite(ev.F_v_at_limit):
        say(f"grasp FEM at the margin's pump pressure {ev.P_margin:.4g} MPa")
        record, more = margin(model, sheet, best, ev, task, options, say)
        fem.update(record)
        states += more
        fem["wall_seconds"] = time.perf_counter() - t0
    if out is not None:  # the verified grasp, then the margin's states (by cavity pressure)
        from softhand.studies.io.files import kept_if_unwritable

        with kept_if_unwritable(Path(out) / "grasp.pvd", "design"):
            write_vtk(out, model, sorted(states, key=lambda s: s.P))
    fem["constraints"] = fem_constraints(fem, task)
    return fem
