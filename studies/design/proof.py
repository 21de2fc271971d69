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
"""
from __future__ import annotations

import math
import time
from pathlib import Path
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.interpolate import PchipInterpolator

from softhand.reduced.equations import hand, reservoir
from softhand.studies.design.optimise import Evaluation
from softhand.studies.design.task import Task


@dataclass(frozen=True)
class ProofOptions:
    mesh_size_mm: float = 6.0   #: finger element size (gmsh, graded as the grasp FEM) [mm]
    dP_mpa: float = 0.05        #: first secant step of the grasp's cavity pressure [MPa]
    rtol: float = 0.01          #: the verified grasp's F_v within this of the requirement
    max_secant: int = 2         #: secant steps at most
    max_step_mpa: float = 0.2   #: largest cavity-pressure step of the continuation from contact [MPa]
    edge_ratio: float = 0.5     #: finger mesh grading at the ring edges (1: uniform)
    sheet: dict = field(default_factory=dict)  #: sheet FEM mesh keywords (fem.reservoir.SheetModel)
    bend_factors: tuple = (1.0, 1.25, 1.5, 1.75, 2.0, 2.5, 3.0, 4.0)  #: free bend: x eq. (28)'s pressure
    pump_tol_mpa: float = 1e-3  #: margin: the state's pump pressure within this of the margin's [MPa]
    max_corrections: int = 4    #: margin: secant corrections of the cavity pressure at most


class _Past(Exception):
    """Raised by the free-bend callback once the finger has bent past the grasp angle."""


def sheet_pressure(sheet):
    """The sheet FEM's p(V) [MPa] along its path from flat to V0, linear between its converged
    states (exact at them; steps <= R^2 t / 2): the reservoir of :func:`softhand.reduced.equations.reservoir.pump_pressure`."""
    return lambda V: np.interp(V, sheet.path_volume, sheet.path_pressure)


def free_bend(finger, theta_g: float, options: ProofOptions, tick=None) -> dict:
    """The free finger FEM up to theta_g [rad]: cavity pressure, dQ, stretch at theta_g;
    ``tick(text)`` is told each converged state's bend."""
    from softhand.fem.hand.finger import solve_pressures
    from softhand.fem.newton import NotConverged

    design = finger.design
    P28 = float(hand.pressure(theta_g, design, reservoir=False))
    states = []

    def keep(state):
        states.append(state)
        if tick is not None:
            tick(f"free bend {math.degrees(state.theta):.1f} of {math.degrees(theta_g):.1f} deg")
        if state.theta > theta_g:
            raise _Past

    t0 = time.perf_counter()
    try:
        targets = P28 * np.asarray(options.bend_factors)
        ramp = np.arange(options.max_step_mpa, targets[0], options.max_step_mpa)  # no big first step
        solve_pressures(finger, np.concatenate([ramp, targets]), callback=keep)
    except _Past:
        pass
    except NotConverged as exc:
        last = states[-1] if states else None
        reached = f"{math.degrees(last.theta):.1f} deg at {last.P:.3g} MPa" if last else "nothing"
        raise RuntimeError(f"free-bend FEM: Newton failed on the way to the grasp angle "
                           f"{math.degrees(theta_g):.1f} deg (converged: {reached}): "
                           f"{str(exc).split(';')[0]}") from None
    if not states or states[-1].theta <= theta_g:
        raise RuntimeError(f"free-bend FEM: {math.degrees(states[-1].theta) if states else 0:.2f} deg "
                           f"at {states[-1].P if states else 0:.3g} MPa, below the grasp angle")
    theta = np.array([0.0, *(s.theta for s in states)])
    at = lambda values: float(PchipInterpolator(theta, values)(theta_g))  # noqa: E731
    share = np.array([s.q / s.theta for s in states])  # the hinges' shares of the bend
    return {"P_finger_MPa": at([0.0, *(s.P for s in states)]),
            "hinge_share": [at([share[0, i], *share[:, i]]) for i in range(share.shape[1])],
            "dQ_mm3": at([0.0, *(s.dQ for s in states)]),
            "rubber_stretch": at([1.0, *(s.rubber_stretch for s in states)]),
            "max_principal_stretch": at([1.0, *(s.max_principal_stretch for s in states)]),
            "pressures_MPa": [s.P for s in states], "theta_deg": np.degrees(theta[1:]).tolist(),
            "seconds": time.perf_counter() - t0}


def grasp_secant(model, ladder, F_req: float, options: ProofOptions, say=None) -> dict:
    """Grasp states up the cavity pressures ``ladder`` [MPa] (each from the last; the last is
    the start), then a secant on F_v_fem(P) = F_req [N]."""
    from softhand.fem.hand.grasp import weight_vector

    t0 = time.perf_counter()

    def solve(P, start=None):
        state = model.solve(P, start=start)
        if say is not None:
            say(f"  grasp state: cavity {state.P:.4g} MPa, theta {math.degrees(state.theta):.2f} deg, "
                f"F_v {state.F_v:.4g} N ({time.perf_counter() - t0:.0f} s)")
        return state

    P_start, first, known = ladder[-1], None, []
    for P in ladder:  # continuation through contact: the Uzawa loop fails on big jumps
        first = solve(P, start=first)
        known.append(first)
    second = solve(P_start + options.dP_mpa, start=first)
    pair, steps = [first, second], 0
    while abs(pair[-1].F_v - F_req) > options.rtol * F_req and steps < options.max_secant:
        a, b = pair[-2], pair[-1]
        if b.F_v == a.F_v:
            break
        P = max(b.P + (F_req - b.F_v) * (b.P - a.P) / (b.F_v - a.F_v), 0.5 * b.P)
        below = [s for s in known + pair if s.P <= P]  # continue from the nearest state below P
        pair.append(solve(P, start=max(below, key=lambda s: s.P) if below else None))
        steps += 1
    best = min(pair, key=lambda s: abs(s.F_v - F_req))
    near = min((s for s in pair if s is not best), key=lambda s: abs(s.P - best.P))
    w = weight_vector(*sorted((best, near), key=lambda s: s.P))
    return {"first": first, "best": best, "w": w, "states": pair, "secant_steps": steps,
            "seconds": time.perf_counter() - t0}


def grasp_at_pump(model, pump, start, P_pump: float, options: ProofOptions, say=None):
    """The grasp FEM state whose pump pressure ``pump(state)`` [MPa] is ``P_pump``: continued
    from the converged state ``start`` in cavity steps of at most ``max_step_mpa`` to P_pump
    plus the reservoir's pressure at ``start``, then secant corrections of the cavity pressure
    on the last two states (the pump pressure grows with the cavity's, at a slope near 1: the
    reservoir's pressure changes little with the oil the fingers take). RuntimeError if the
    pump pressure is not within ``pump_tol_mpa`` after ``max_corrections``."""
    t0 = time.perf_counter()
    states = [start]

    def solve(P):
        near = min(states, key=lambda s: abs(s.P - P))  # the nearest converged state
        state = model.solve(P, start=near)
        states.append(state)
        if say is not None:
            say(f"  grasp state: cavity {state.P:.4g} MPa, pump {pump(state):.4g} MPa, "
                f"F_v {state.F_v:.4g} N ({time.perf_counter() - t0:.0f} s)")
        return state

    target = P_pump + start.P - pump(start)  # the reservoir's pressure as at start
    steps = max(1, math.ceil(abs(target - start.P) / options.max_step_mpa - 1e-9))
    prev, state = None, start
    for P in np.linspace(start.P, target, steps + 1)[1:]:
        prev, state = state, solve(P)
    for _ in range(options.max_corrections):
        miss = pump(state) - P_pump
        if abs(miss) <= options.pump_tol_mpa:
            return state
        slope = (pump(state) - pump(prev)) / (state.P - prev.P) if state.P != prev.P else 1.0
        prev, state = state, solve(state.P - miss / (slope if slope > 0.5 else 1.0))
    if abs(pump(state) - P_pump) > options.pump_tol_mpa:
        raise RuntimeError(f"grasp FEM: the pump pressure {P_pump:.4g} MPa not reached within "
                           f"{options.pump_tol_mpa:g} MPa after {options.max_corrections} corrections "
                           f"(last {pump(state):.6g} MPa)")
    return state


def margin(model, sheet, best, ev: Evaluation, task: Task, options: ProofOptions, say=None) -> tuple[dict, list]:
    """The FEM's margin (see the module doc, 4.) from the verified grasp ``best``: the grasp at
    the reduced margin's pump pressure ev.P_margin, and at the pump limit if that is above it;
    (the record, those states). A grasp FEM that fails on the way is reported (``"error"``),
    not raised: the margin is the task's objective, which the verified grasp has already met
    (its F_v at P_grasp)."""
    from softhand.fem.newton import NotConverged

    finger, design = model.finger, model.design

    oil = {}  # id(state) -> (state, V): the cavity's volume integral once a state (the state kept: its id stays its own)

    def oil_left(state):
        if id(state) not in oil:
            oil[id(state)] = (state, float(reservoir.oil_left(finger.dQ(state.y), design)))
        V = oil[id(state)][1]
        if not V > 0:
            raise RuntimeError(f"grasp FEM: the fingers take all the oil (V0 = {design.V0:.0f} mm^3) "
                               f"at the cavity pressure {state.P:.4g} MPa")
        return V

    def pump(state):  # the hand's pump pressure: the cavity's less the reservoir's at the oil left
        return float(reservoir.pump_pressure(state.P, oil_left(state), design, sheet_pressure(sheet)))

    def row(state):
        return {"P_pump_MPa": pump(state), "P_cavity_MPa": state.P, "F_v_N": state.F_v,
                "oil_left_mm3": oil_left(state),
                "theta_deg": math.degrees(state.theta),
                "links_in_contact": [int(k) for k in np.flatnonzero(state.N > 0)],
                "contact_force_N": state.N.tolist()}

    F_req = task.required_F_v()
    try:
        at = grasp_at_pump(model, pump, best, ev.P_margin, options, say)
    except (NotConverged, RuntimeError) as exc:  # the margin is the objective, not a limit: reported
        return {"margin": {"error": str(exc).split(";")[0], "predicted_F_v_N": ev.F_v_at_limit,
                           "below_pump_limit": ev.margin_edge}}, []
    out = {"margin_N": at.F_v - F_req, "F_v_at_pump_limit_N": None if ev.margin_edge else at.F_v,
           "margin": {**row(at), "predicted_F_v_N": ev.F_v_at_limit, "below_pump_limit": ev.margin_edge}}
    if not ev.margin_edge:
        return out, [at]
    try:  # the FEM goes on to the pump limit, where the reduced model does not reach
        limit = grasp_at_pump(model, pump, at, task.max_pressure, options, say)
    except (NotConverged, RuntimeError) as exc:
        out["at_pump_limit"] = {"error": str(exc).split(";")[0]}
        return out, [at]
    out["F_v_at_pump_limit_N"] = limit.F_v
    out["at_pump_limit"] = {**row(limit), "margin_N": limit.F_v - F_req}
    return out, [at, limit]


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


#: walls above this [mm] get at most PROOF_MESH_THICK_WALL: on the 10 mm finger mesh the FEM is
#: wrong there (b = 5.5 mm: Newton fails below 0.2 MPa; b = 6 mm: a cavity volume change larger
#: than the cavity), on 6 mm elements it is right up to b = 6 mm
THICK_WALL_MM, PROOF_MESH_THICK_WALL = 5.0, 6.0
#: a proof that fails on its meshes is tried once more on this finer one [mm]: a thin wall with
#: little room in the links (a 6, b 3, d 10, l0 200 mm) stalls on the 10 and 6 mm meshes (0.17
#: and 0.30 MPa); on 4 mm it bends to 139 deg at 0.9 MPa, as the calibration's layered mesh does
#: (140 deg), and its proof ends with a verdict (8.5 min instead of "could not be completed")
PROOF_MESH_FINEST = 4.0


def proof_meshes(design, mesh_size_mm: float) -> list[float]:
    """The finger element sizes [mm] the proof tries in turn: :func:`proof_mesh`'s, then the
    thick walls' and the finest one where they are finer."""
    h = proof_mesh(design, mesh_size_mm)
    return [h] + [s for s in (PROOF_MESH_THICK_WALL, PROOF_MESH_FINEST) if s < h]


def proof_mesh(design, mesh_size_mm: float) -> float:
    """The finger element size [mm] of the proof for this design: ``mesh_size_mm``, at most
    PROOF_MESH_THICK_WALL for a wall b above THICK_WALL_MM."""
    return min(mesh_size_mm, PROOF_MESH_THICK_WALL) if design.b > THICK_WALL_MM else mesh_size_mm


def check_proof_size(task: Task, mesh_size_mm: float) -> None:
    """Refuse (MeshTooLarge) a proof mesh too large for this machine's memory whatever the design:
    bounded on the task's thinnest, shortest tube (a, b, l0 at their lower bounds where free) and
    the finest mesh the proof may try, before the optimiser runs, not after it."""
    from softhand.fem.hand.finger_options import UNKNOWNS_PER_TET, check_unknowns, gmsh_least_tets

    low = {key: lo for key, lo, _ in task.free}
    a, b, l0 = (low.get(key, default) for key, default in
                (("a_mm", task.base.a), ("b_mm", task.base.b), ("l0_mm", task.base.l0)))
    h = min(mesh_size_mm, PROOF_MESH_FINEST)
    check_unknowns(int(UNKNOWNS_PER_TET * gmsh_least_tets(a, b, l0, b, h)), f"gmsh mesh_size={h:g} (the proof's)")


def fem_constraints(fem: dict, task: Task) -> list[dict]:
    """The task's limits on the FEM's verified grasp: its converged rubber stretch (the tube's,
    fem.rubber_stretch: where the tied rings and the end cap concentrate it, which eq. (8) of the
    reduced model does not see; and the sheet's at V0) and its pump pressure."""
    rows = [("rubber_stretch (FEM, verified grasp)", fem["rubber_stretch"], task.max_stretch),
            ("sheet rubber_stretch at V0 (FEM)", fem["sheet_rubber_stretch"], task.max_stretch),
            ("pump_pressure at the grasp (FEM) [MPa]", fem["P_grasp_MPa"], task.max_pressure)]
    return [{"name": name, "value": value, "limit": limit, "sense": "<=", "satisfied": bool(value <= limit)}
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
    return (f"The FEM proof does not confirm the design: {names}. The reduced model's estimate of the "
            f"rubber stretch (eq. (8), the wall's bending strain) is {ev.stretch:.4g}; the FEM's sits "
            f"at the tied rings and the end cap, which the reduced model does not see.")


def corrected_task(task: Task, ev: Evaluation, fem: dict) -> Task | None:
    """The task with eq. (8)'s strain scaled to the FEM's, if the FEM's rubber stretch at the
    verified grasp broke the task's limit (None otherwise): stretch_factor x (lambda_FEM - 1) /
    (lambda_predicted - 1), so that the reduced model predicts this design's FEM stretch and a
    new optimum keeps its FEM stretch near the limit. The FEM's converged stretch grows with the
    bend as eq. (8) does (both are the wall's strain at the hinge), so one factor carries to
    nearby designs."""
    stretch = fem.get("rubber_stretch")
    if stretch is None or stretch <= task.max_stretch or not ev.stretch > 1.0:
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
