"""softhand design on the reduced model: task files, the evaluation against eqs. (8), (25), (29)
called directly, the optimiser against a brute-force grid, determinism, infeasible tasks, CLI."""
import contextlib
import io
import json
import math
import numpy as np
import pytest

from softhand.reduced.equations import finger, grasp, hand, kinematics
from softhand.reduced.calibrated import finger_fem, grasp_fem
from softhand.reduced.vocabulary.design_files import load_design
from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.design import optimise as design_opt
from softhand.studies.design.task import load_task, task_from_dict

#: a CI-sized task: two free keys, so that a grid search can check the optimum
CI_TASK = {
    "object": {"diameter_mm": 180.0, "mass_kg": 2.0},
    "grasp": {"force_factor": 2.0},
    "pump": {"max_pressure_MPa": 2.0},
    "limits": {"rubber_stretch": 1.5},  # the paper's sheet at V0: 1.454 (FEM-calibrated)
    "free": {"d_mm": [10.0, 20.0], "V0_mm3": [12000.0, 30000.0]},
}
FAST = design_opt.OptimiserOptions(seed=3)


def _write(tmp_path, text, name="task.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_task_file_reads_the_paper_task():
    task = load_task("studies/designs/tasks/paper_task.toml")
    assert (task.diameter, task.mass, task.max_pressure) == (180.0, 2.0, 2.0)
    assert [k for k, _, _ in task.free] == ["a_mm", "b_mm", "d_mm", "V0_mm3"]
    assert task.required_F_v() == pytest.approx(2.0 * 2.0 * 9.80665 / 4)  # force_factor m g / n


@pytest.mark.parametrize("change, field", [
    ({"object": {"mass_kg": 2.0}}, "object.diameter_mm"),
    ({"object": {"diameter_mm": -1.0, "mass_kg": 2.0}}, "object.diameter_mm"),
    ({"free": {"a_mm": [6.0, 3.0]}}, "free.a_mm"),
    ({"free": {"n": [1, 4]}}, "free.n"),
    ({"free": {}}, "free"),
    ({"grasp": {"force_factor": 2.0, "margin_N": 1.0}}, "grasp.margin_N"),
    ({"grasp": {"objective": "cheapest"}}, "grasp.objective"),
    ({"pump": {"max_pressure_MPa": "high"}}, "pump.max_pressure_MPa"),
    ({"limits": {"rubber_stretch": 0.9}}, "limits.rubber_stretch"),
    ({"limits": {"max_principal_stretch": 1.5}}, "limits.max_principal_stretch"),  # renamed: refused
    ({"colour": "red"}, "colour"),
    ({"base_design": "nowhere.toml"}, "base_design"),
    ({"design": {"b_mm": -5.0}}, "b_mm"),
    ({"free": {"t_mm": [40.0, 50.0]}}, "free"),                       # every t >= R = 24 mm
    ({"free": {"a_mm": [5.5, 6.0], "b_mm": [5.0, 7.0], "d_mm": [10.0, 10.4]}}, "free"),  # a + b >= d everywhere
    ({"design": {"mu_sf_MPa": 1.0}, "material": {"mu_sf_MPa": 2.0}}, "design.mu_sf_MPa"),
])
def test_bad_task_files_name_the_field(change, field):
    with pytest.raises(InputError) as info:
        task_from_dict({**CI_TASK, **change})
    assert info.value.field == field


def test_evaluation_against_the_fem_informed_grasp_called_directly():
    """finger_model "fem": P_grasp is the pump pressure at which grasp_fem's equilibrium (at the
    grasp FEM's placement) presses with the required F_v, the reservoir's pressure from eq. (27)."""
    task = task_from_dict(CI_TASK)
    ev = design_opt.evaluate(task.base, task)
    # the cavity pressure of that grasp: the pump pressure plus p_r at the finger's bend
    theta = math.radians(ev.predicted()["theta_grasp_deg"])
    p_r = float(hand.pressure(theta, task.base, reservoir=False) - hand.pressure(theta, task.base))
    state = grasp_fem.grasp_state(task.base, task.diameter, ev.P_grasp + p_r, task.mass)
    assert state.F_v == pytest.approx(task.required_F_v(), rel=1e-10)
    assert state.theta == pytest.approx(theta, rel=1e-10)
    assert ev.P_contact == pytest.approx(float(hand.pressure(ev.theta_grasp, task.base)), rel=1e-12)
    # the "pressure" objective: F_v at the pump limit is the pump-pressure constraint, not asked again
    assert ev.predicted()["F_v_at_pump_limit_N"] is None
    # the tube's stretch in the grasp: the calibrated table's converged rubber stretch at the free
    # finger's bend under the grasp's cavity pressure (beyond the holding bend), above eq. (8)'s
    # largest over a grid of the tube's cross-section at the holding bend (the wall's bending strain)
    free = float(hand.bend_angle(ev.P_grasp + p_r, task.base, reservoir=False))
    assert free > theta
    assert ev.stretch == pytest.approx(float(finger_fem.rubber_stretch(free, task.base)), rel=1e-12)
    assert ev.stretch > float(finger_fem.rubber_stretch(theta, task.base))
    r, phi = np.meshgrid(np.linspace(0, task.base.b, 21), np.linspace(-math.pi, math.pi, 721))
    lam = finger.axial_stretch(theta, r, phi, task.base)
    assert ev.stretch > lam.max()
    assert ev.feasible


def test_margin_objective_asks_the_force_at_the_pump_limit():
    task = task_from_dict({**CI_TASK, "grasp": {"force_factor": 2.0, "objective": "margin"},
                           "pump": {"max_pressure_MPa": 0.6}})
    ev = design_opt.evaluate(task.base, task)
    states = [grasp_fem.grasp_state(task.base, task.diameter, P, task.mass) for P in (0.6, 0.7, 0.8)]
    pump = [s.P - float(hand.pressure(s.theta, task.base, reservoir=False) - hand.pressure(s.theta, task.base))
            for s in states]
    assert pump[0] < 0.6 < pump[-1]
    # F_v grows with the pump pressure: the limit's F_v lies between those of the states around it
    F = [s.F_v for s in states]
    assert F[0] < ev.F_v_at_limit < F[-1]
    assert ev.predicted()["margin_N"] == pytest.approx(ev.F_v_at_limit - task.required_F_v(), rel=1e-12)


def test_the_paper_finger_model_keeps_eq_25():
    task = task_from_dict({**CI_TASK, "design": {"finger_model": "paper", "reservoir_model": "ellipse"}})
    ev = design_opt.evaluate(task.base, task)
    # the pump pressure found makes eq. (25) -> (29) press with exactly the required F_v
    forces = grasp.grasp_forces(ev.P_grasp, ev.theta_grasp, task.mass, ev.w, task.base)
    assert float(forces.F_v) == pytest.approx(task.required_F_v(), rel=1e-12)
    forces = grasp.grasp_forces(task.max_pressure, ev.theta_grasp, task.mass, ev.w, task.base)
    assert ev.F_v_at_limit == pytest.approx(float(forces.F_v), rel=1e-12)
    assert ev.theta_hold == ev.theta_grasp


def test_optimum_beats_a_grid_search_and_is_deterministic():
    task = task_from_dict(CI_TASK)
    opt = design_opt.optimise(task, FAST)
    assert opt.evaluation.feasible
    again = design_opt.optimise(task, FAST)
    np.testing.assert_array_equal(opt.x, again.x)                        # same seed, same answer
    d, V0 = np.meshgrid(np.linspace(10, 20, 21), np.linspace(12000, 30000, 21))
    best = math.inf
    for x in zip(d.ravel(), V0.ravel()):
        ev = design_opt.evaluate(design_opt.design_at(task, x), task)
        if ev.feasible:
            best = min(best, ev.P_grasp)
    # the grid's spacing (0.5 mm, 900 mm^3) bounds how far the grid's best can be above
    assert opt.evaluation.P_grasp <= best + 1e-9
    assert opt.evaluation.P_grasp > best - 0.02
    base = design_opt.evaluate(task.base, task)
    assert opt.evaluation.P_grasp < base.P_grasp


def test_the_pareto_fronts_end_is_the_least_stretch_of_a_grid_search():
    """The front's far end: no feasible design on a grid over the free keys stretches the rubber
    less than the least stretch found, and the design found is feasible with that stretch."""
    from softhand.studies.design import pareto

    task = task_from_dict(CI_TASK)
    x, lam = pareto.least_stretch(task, FAST)
    ev = design_opt.evaluate(design_opt.design_at(task, x), task)
    assert ev.feasible and ev.rubber_stretch == pytest.approx(lam, rel=1e-12)
    grid = [design_opt.evaluate(design_opt.design_at(task, p), task)
            for p in zip(*(a.ravel() for a in np.meshgrid(np.linspace(10, 20, 11), np.linspace(12000, 30000, 11))))]
    best = min(g.rubber_stretch for g in grid if g.feasible)
    assert lam <= best + 1e-12
    assert lam > best - 0.05  # the grid's spacing (1 mm, 1 800 mm^3) bounds how far above it can be


def test_active_constraint_is_the_stretch_of_the_sheet():
    """With d and V0 free and nothing else in the way, the pressure falls with V0 (a fuller
    sheet pushes harder) until the sheet's stretch (16) reaches the limit; in d the calibrated
    finger has an inner optimum (eq. (28) alone would take the longest lever arm, d = 20)."""
    task = task_from_dict(CI_TASK)
    opt = design_opt.optimise(task, FAST)
    names = [c.name for c in design_opt.binding(opt.evaluation)]
    assert any(n.startswith("sheet_stretch") for n in names)
    d, V0 = opt.x
    assert 10.5 < d < 19.5
    P = [design_opt.evaluate(design_opt.design_at(task, [d + h, V0]), task).P_grasp for h in (-0.2, 0.0, 0.2)]
    assert P[1] <= min(P[0], P[2])  # a minimum in d, not a bound


def test_infeasible_task_names_the_binding_constraint_and_stops_once_its_violation_stalls():
    """SciPy's DE never converges while a member breaks a constraint: the 0.05 MPa pump's task,
    whose least violation does not move, stops after the stall window, not after 60 generations."""
    task = task_from_dict({**CI_TASK, "pump": {"max_pressure_MPa": 0.05}})
    opt = design_opt.optimise(task, FAST)
    assert not opt.evaluation.feasible
    assert opt.generations == FAST.stall + 1 < FAST.maxiter
    assert opt.message.endswith("stopped") and "no design met the constraints" in opt.message
    text = design_opt.infeasible_report(task, opt)
    assert "pump_pressure" in text or "F_v at the pump limit" in text
    assert "d_mm = " in text and "\n" not in text


def test_a_task_no_design_can_answer_is_refused_without_a_rescue():
    """An object the fingers reach in no design of the box: one InputError naming [free] and
    the model's reason, without SLSQP from a point that has no answer."""
    task = task_from_dict({**CI_TASK, "object": {"diameter_mm": 1e-3, "mass_kg": 2.0}})
    said, generations = [], []
    with pytest.raises(InputError) as info:
        design_opt.optimise(task, FAST, say=said.append, progress=generations.append)
    assert info.value.field == "free" and "does not reach the object" in str(info.value)
    assert said == [] and len(generations) <= 11


def test_the_stall_rule_judges_the_pace_of_the_least_violation():
    """Stopped only when the pace of the last ``window`` generations would leave a violation at
    the last generation; a generation with a feasible member starts the count again."""
    flat = design_opt.Stall(window=3, maxiter=60)
    assert [flat(g, 1.0) for g in range(1, 6)] == [False, False, False, True, True]
    falling = design_opt.Stall(window=3, maxiter=11)  # 0.1 a generation from 1.0 reaches 0 at 11
    assert not any(falling(g, 1.0 - 0.1 * (g - 1)) for g in range(1, 11))
    short = design_opt.Stall(window=3, maxiter=10)    # ... one generation too few
    assert [short(g, 1.0 - 0.1 * (g - 1)) for g in range(1, 5)] == [False, False, False, True]
    met = design_opt.Stall(window=3, maxiter=60)
    assert not any(met(g, v) for g, v in enumerate([1.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0], 1))
    assert met(8, 1.0) and "in 8 generations" in met.message(8)
    unbounded = design_opt.Stall(window=2, maxiter=60)  # inf - inf is no pace at all
    assert [unbounded(g, math.inf) for g in range(1, 4)] == [False, False, True]


def test_a_sliver_of_feasible_designs_is_found_not_called_infeasible():
    """A pump limit a hair above the optimum's pressure leaves a sliver of the box feasible:
    DE's first generations meet no constraint, but their violation falls fast (by orders of
    magnitude), so the stall rule lets DE go on to the sliver, or, where DE stalls all the same,
    SLSQP from the least-violating design reaches it: found, at no more than the optimum's
    pressure (the least pressure is flat in V0 here: another seed's optimum may lie 3e-4 lower)."""
    loose = {**CI_TASK, "limits": {"rubber_stretch": 2.0}}  # the pump's sliver alone
    best = design_opt.optimise(task_from_dict(loose), FAST).evaluation.P_grasp
    for factor in (1.00001, 1.001):
        task = task_from_dict({**loose, "pump": {"max_pressure_MPa": best * factor}})
        opt = design_opt.optimise(task, design_opt.OptimiserOptions(seed=1))
        assert opt.evaluation.feasible
        assert "stopped" not in opt.message or opt.message.endswith("SLSQP from the least-violating design met the constraints")
        assert best * (1 - 1e-3) < opt.evaluation.P_grasp <= best * factor
    # below it by more than the flat optimum's spread (two basins, d 16.8 and 17.5 mm, 3e-4 apart
    # in pressure; the seed decides which DE finds): no design meets it, and the stall rule ends
    # DE before its last generation
    task = task_from_dict({**loose, "pump": {"max_pressure_MPa": best * 0.999}})
    opt = design_opt.optimise(task, design_opt.OptimiserOptions(seed=1))
    assert not opt.evaluation.feasible and opt.generations < 60


def test_slsqp_is_tried_from_the_least_violating_design_when_de_meets_nothing():
    """Two generations find no design in the sliver; SLSQP from the least-violating one does."""
    best = design_opt.optimise(task_from_dict(CI_TASK), FAST).evaluation.P_grasp
    task = task_from_dict({**CI_TASK, "pump": {"max_pressure_MPa": best * 1.001}})
    opt = design_opt.optimise(task, design_opt.OptimiserOptions(seed=1, maxiter=2))
    assert opt.evaluation.feasible and opt.message.endswith("SLSQP from the least-violating design met the constraints")
    assert best * (1 - 1e-3) < opt.evaluation.P_grasp <= best * 1.001


def test_l0_scales_the_hinges():
    task = task_from_dict({**CI_TASK, "free": {"l0_mm": [150.0, 210.0]}})
    design = design_opt.design_at(task, [210.0])
    np.testing.assert_allclose(design.link_lengths, [35.0] * 6)
    assert kinematics.tip_position(np.zeros(5), design).shape == (2,)


class _Run:
    def __init__(self, returncode, stdout, stderr):
        self.returncode, self.stdout, self.stderr = returncode, stdout, stderr


def _cli(*argv):
    """``softhand ARGV`` in-process (the CLI's own error handling included)."""
    from softhand.studies.cli.main import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return _Run(code, out.getvalue(), err.getvalue())


CI_TASK_TOML = """
[object]
diameter_mm = 180.0
mass_kg = 2.0
[grasp]
force_factor = 2.0
[pump]
max_pressure_MPa = 2.0
[limits]
rubber_stretch = 1.5
[free]
d_mm = [10.0, 20.0]
V0_mm3 = [12000.0, 30000.0]
"""


def test_cli_json_no_fem_writes_a_design_every_verb_reads(tmp_path):
    task = _write(tmp_path, CI_TASK_TOML)
    out = tmp_path / "out"
    proc = _cli("design", "--task", str(task), "--no-fem", "--json", "--out", str(out), "--seed", "3")
    assert proc.returncode == 0, proc.stderr
    result = json.loads(proc.stdout)
    for key in ("design", "predicted", "fem", "constraints", "design_file"):
        assert key in result
    assert set(result["predicted"]) >= {"P_grasp_MPa", "theta_grasp_deg", "F_v_N", "rubber_stretch"}
    assert all({"name", "value", "limit", "satisfied"} <= set(c) for c in result["constraints"])
    assert result["fem"] is None
    design = load_design(result["design_file"])
    assert design.to_dict() == result["design"]
    assert json.loads((out / "result.json").read_text())["design"] == result["design"]
    curve = _cli("curve", "--design", result["design_file"], "--theta-deg", "10", "--json")
    assert curve.returncode == 0, curve.stderr


def test_cli_pareto_plot(tmp_path):
    task = _write(tmp_path, CI_TASK_TOML)
    plot = tmp_path / "front.png"
    proc = _cli("design", "--task", str(task), "--no-fem", "--pareto", "--plot", str(plot),
                "--out", str(tmp_path / "out"), "--json")
    assert proc.returncode == 0, proc.stderr
    rows = json.loads(proc.stdout)["pareto"]["rows"]
    assert plot.stat().st_size > 1000
    lam = [r["rubber_stretch"] for r in rows]
    P = [r["P_grasp_MPa"] for r in rows]
    assert np.all(np.diff(lam) < 0) and np.all(np.diff(P) >= -1e-9)  # less stretch costs pressure


def test_cli_bad_task_is_one_line_exit_2(tmp_path):
    task = _write(tmp_path, CI_TASK_TOML.replace("[10.0, 20.0]", "[20.0, 10.0]"))
    proc = _cli("design", "--task", str(task), "--no-fem")
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and proc.stderr.startswith("softhand design: error: free.d_mm")
    proc = _cli("design", "--task", str(_write(tmp_path, "[object\n", "broken.toml")), "--no-fem")
    assert proc.returncode == 2 and "not valid TOML" in proc.stderr


def test_cli_infeasible_task_is_one_paragraph_exit_1(tmp_path):
    task = _write(tmp_path, CI_TASK_TOML.replace("max_pressure_MPa = 2.0", "max_pressure_MPa = 0.05"))
    proc = _cli("design", "--task", str(task), "--no-fem", "--out", str(tmp_path / "out"))
    assert proc.returncode == 1, proc.stderr
    assert "The task cannot be met" in proc.stdout
    # the SLSQP try after DE found nothing is said, not waited through in silence
    assert "softhand design: no design met the constraints after 11 generations" in proc.stderr
    assert "# the search: no design met the constraints in 11 generations" in proc.stdout


def test_a_task_designs_on_the_fem_calibrated_models():
    task = task_from_dict(CI_TASK)
    assert (task.base.finger_model, task.base.reservoir_model) == ("fem", "fem")
    paper = task_from_dict({**CI_TASK, "design": {"finger_model": "paper", "reservoir_model": "ellipse"}})
    assert (paper.base.finger_model, paper.base.reservoir_model) == ("paper", "ellipse")
    # the two models answer differently: the calibrated finger is stiffer than eq. (28)
    assert design_opt.evaluate(task.base, task).P_contact > design_opt.evaluate(paper.base, paper).P_contact


def test_free_bounds_are_clipped_to_the_calibrated_space():
    task = task_from_dict({**CI_TASK, "free": {"d_mm": [8.0, 25.0], "V0_mm3": [12000.0, 30000.0]}})
    assert task.free == (("d_mm", 10.0, 20.0), ("V0_mm3", 12000.0, 30000.0))  # studies/finger_space.toml
    assert task.clipped == (("d_mm", 8.0, 25.0),)
    paper = task_from_dict({**CI_TASK, "free": {"d_mm": [8.0, 25.0]}, "design": {"finger_model": "paper"}})
    assert paper.free == (("d_mm", 8.0, 25.0),) and paper.clipped == ()
    with pytest.raises(InputError) as info:
        task_from_dict({**CI_TASK, "free": {"d_mm": [25.0, 30.0]}})
    assert info.value.field == "free.d_mm"


def test_outside_the_calibrated_groups_is_infeasible_and_named():
    task = task_from_dict(CI_TASK)
    ev = design_opt.evaluate(task.base.replace(a=2.5), task)  # link/a = 30 / 2.5 = 12 > 11.1
    assert not ev.feasible and not math.isfinite(ev.P_grasp)
    assert any(c.name == "calibrated range of link/a" for c in design_opt.binding(ev))


def test_oil_constraint_is_the_finger_models_oil():
    task = task_from_dict(CI_TASK)
    ev = design_opt.evaluate(task.base, task)
    oil = next(c for c in ev.constraints if c.name.startswith("reservoir_oil"))
    # the calibrated finger takes more oil than eq. (2)'s a^2 pi d theta
    # at the bend that holds the object (beyond the contact angle: the distal hinges close on)
    assert ev.theta_hold > ev.theta_grasp
    assert oil.value == pytest.approx(task.base.n * float(finger.oil_taken(ev.theta_hold, task.base)), rel=1e-12)
    assert oil.value != pytest.approx(task.base.n * task.base.a**2 * math.pi * task.base.d * ev.theta_hold,
                                      rel=1e-3)


def test_optimum_on_a_bound_is_the_bound():
    """SLSQP lands a hair beside a bound (4.500000000000008 for 4.5); the design is the bound."""
    x = design_opt.on_bounds([4.500000000000008, 4.49999999999999, 4.4], [(4.5, 6.0), (3.5, 4.5), (3.5, 4.5)])
    assert x.tolist() == [4.5, 4.5, 4.4]
    task = task_from_dict({**CI_TASK, "free": {"b_mm": [4.5, 6.0], "V0_mm3": [12000.0, 30000.0]}})
    opt = design_opt.optimise(task, FAST)
    assert opt.evaluation.design.b == 4.5  # a thinner wall is cheaper: the optimum is on the bound


# ---------------------------------------------------------------- bad and edge inputs (fuzzer)
@pytest.mark.parametrize("change, field", [
    ({"grasp": {"force_factor": 1e-300}}, "grasp.force_factor"),   # ran for minutes
    ({"grasp": {"force_factor": 0.5}}, "grasp.force_factor"),      # fingers not carrying the weight
    ({"grasp": {"margin_N": 1e-300}}, "grasp.margin_N"),
    ({"object": {"diameter_mm": 180.0, "mass_kg": 1e-300}}, "object.mass_kg"),
    ({"grasp": {"opening_mm": 1e-9}}, "grasp.opening_mm"),          # narrower than the object
    ({"pump": {"max_pressure_MPa": 1e-9}}, "pump.max_pressure_MPa"),
    ({"design": {"d_mm": 15.0}}, "design.d_mm"),                    # also in [free]
])
def test_unusable_task_numbers_and_contradictions_are_refused(change, field):
    with pytest.raises(InputError) as info:
        task_from_dict({**CI_TASK, **change})
    assert info.value.field == field


def test_zero_mass_and_margin_and_a_wider_opening_are_accepted():
    assert task_from_dict({**CI_TASK, "object": {"diameter_mm": 180.0, "mass_kg": 0.0}}).mass == 0.0
    assert task_from_dict({**CI_TASK, "grasp": {"margin_N": 0.0}}).margin == 0.0
    assert task_from_dict({**CI_TASK, "grasp": {"opening_mm": 200.0}}).opening_mm == 200.0


def test_a_massless_object_is_held_where_the_fingers_touch_it():
    """F_v = 0 is the contact itself (the hold's root finder found no sign change there and the
    varying constraint count broke differential evolution)."""
    task = task_from_dict({**CI_TASK, "object": {"diameter_mm": 180.0, "mass_kg": 0.0},
                           "free": {"a_mm": [3.5, 4.5]}})
    opt = design_opt.optimise(task, FAST)
    ev = opt.evaluation
    assert ev.feasible and ev.F_v == 0.0
    assert ev.P_grasp == ev.P_contact and ev.theta_hold == ev.theta_grasp


def test_every_point_of_the_box_has_the_same_constraints():
    """A design without an answer (V0 = 1 mm^3 holds no oil) had one constraint more than one
    with an answer: scipy's 'array returned from a Constraint has the wrong shape'."""
    task = task_from_dict({**CI_TASK, "free": {"V0_mm3": [1.0, 1e8]}, "limits": {"rubber_stretch": 2.0}})
    problem = design_opt.Problem(task)
    lengths = {len(problem.slacks([v])) for v in np.geomspace(1.0, 1e8, 12)}
    assert len(lengths) == 1
    assert all(np.isfinite(problem.slacks([1.0])))
    opt = design_opt.optimise(task, FAST)
    assert opt.evaluation.feasible


def test_free_values_the_design_rules_refuse_are_infeasible_points_not_errors():
    """a, b and d free over the calibrated box: a + b >= d at some points (the design refuses
    them) must steer the optimiser, not end the run naming a value the user never gave."""
    task = task_from_dict({**CI_TASK, "free": {"a_mm": [3.0, 6.0], "b_mm": [3.0, 7.0], "d_mm": [10.0, 20.0]}})
    problem = design_opt.Problem(task)
    bad = problem.evaluation([6.0, 7.0, 10.0])   # a + b = 13 > d = 10
    assert not bad.feasible and len(bad.constraints) == len(problem.evaluation([4.0, 5.0, 15.0]).constraints)
    opt = design_opt.optimise(task, FAST)
    d = opt.evaluation.design
    assert d.a + d.b < d.d


def test_all_eight_free_keys_at_their_full_bounds():
    from softhand.reduced.vocabulary.design import BOUNDS
    from softhand.studies.design.task_values import FREE_KEYS

    free = {k: list(BOUNDS[k]) for k in FREE_KEYS}
    task = task_from_dict({**CI_TASK, "free": free, "design": {"finger_model": "paper", "reservoir_model": "ellipse"}})
    opt = design_opt.optimise(task, FAST)  # the short fingers of l0 = 10 mm do not reach the object
    assert np.isfinite(opt.evaluation.P_grasp)


def test_cli_infeasible_task_writes_nothing(tmp_path):
    task = _write(tmp_path, CI_TASK_TOML.replace("max_pressure_MPa = 2.0", "max_pressure_MPa = 0.05"))
    out = tmp_path / "out"
    proc = _cli("design", "--task", str(task), "--no-fem", "--out", str(out))
    assert proc.returncode == 1 and "The task cannot be met" in proc.stdout
    assert "none written" in proc.stdout and not out.exists()
    proc = _cli("design", "--task", str(task), "--no-fem", "--out", str(out), "--json")
    assert proc.returncode == 1 and json.loads(proc.stdout)["design_file"] is None and not out.exists()


def test_cli_impossible_pump_is_one_line_exit_2_and_writes_nothing(tmp_path):
    task = _write(tmp_path, CI_TASK_TOML.replace("max_pressure_MPa = 2.0", "max_pressure_MPa = 1e-9"))
    out = tmp_path / "out"
    proc = _cli("design", "--task", str(task), "--no-fem", "--out", str(out))
    assert proc.returncode == 2 and not out.exists()
    assert proc.stderr.count("\n") == 1 and proc.stderr.startswith("softhand design: error: pump.max_pressure_MPa")


def test_a_free_sheet_stays_a_thin_sheet_that_the_pump_pushes():
    """R, t and V0 free over their whole bounds: the optimiser had found a 50 mm thick "sheet"
    (t/R = 0.34, far outside the membrane models and the FEM tables' 1/24-1/12) whose pump
    pressure at the grasp was negative (-0.017 MPa). Both are constraints now."""
    from softhand.reduced.vocabulary.design import BOUNDS
    from softhand.reduced.equations.reservoir import MAX_THICKNESS_RATIO

    task = task_from_dict({**CI_TASK, "free": {k: list(BOUNDS[k]) for k in ("R_mm", "t_mm", "V0_mm3")}})
    thick = design_opt.evaluate(task.base.replace(R=146.06, t=49.69, V0=5.009e6), task)
    assert not thick.feasible
    assert any(c.name.startswith("thin_sheet") for c in design_opt.binding(thick))
    opt = design_opt.optimise(task, FAST)
    d, ev = opt.evaluation.design, opt.evaluation
    assert ev.feasible and d.t / d.R <= MAX_THICKNESS_RATIO * (1 + 1e-9)
    assert 0.0 <= ev.P_contact <= ev.P_grasp <= task.max_pressure


def test_a_design_run_stopped_mid_proof_leaves_none_of_its_files_and_the_earlier_whole(tmp_path, monkeypatch):
    """Ctrl-C during the FEM proof had left design.toml without result.json, next to an
    earlier run's result.json that no longer matched it. The run writes into a staging folder:
    stopped, the earlier run's record stays whole and none of the stopped run's files (design,
    VTK) shows; other files stay."""
    from softhand.studies.cli import main as cli
    from softhand.studies.design import workflow
    from softhand.studies.io.outputs import MANIFEST

    task, out = _write(tmp_path, CI_TASK_TOML), tmp_path / "out"
    out.mkdir()
    (out / "result.json").write_text('{"design_file": "design.toml"}\n')  # an earlier run's record
    (out / MANIFEST).write_text('{"run": "earlier", "outputs": ["result.json"]}\n')
    (out / "notes.txt").write_text("mine\n")

    def stopped_proof(ev, task, mesh_size_mm, out, say, **options):
        (out / "grasp").mkdir()
        (out / "grasp" / "step_0.vtu").write_text("half a VTK")
        raise KeyboardInterrupt

    monkeypatch.setattr(workflow, "prove_on_meshes", stopped_proof)
    assert cli.main(["design", "--task", str(task), "--out", str(out), "--seed", "3"]) == 130
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "notes.txt", "result.json"]
    assert (out / "result.json").read_text() == '{"design_file": "design.toml"}\n'
    fresh = tmp_path / "fresh" / "out"  # a folder the stopped run made goes too
    assert cli.main(["design", "--task", str(task), "--out", str(fresh), "--seed", "3"]) == 130
    assert not fresh.exists()


def test_the_optimiser_reports_each_generation():
    """The design verb's progress bar: one call per differential-evolution generation, with
    the model evaluations so far, and the same optimum as without it."""
    task = task_from_dict(CI_TASK)
    calls = []
    opt = design_opt.optimise(task, FAST, progress=calls.append)
    assert len(calls) == opt.generations > 0
    assert calls == sorted(calls) and calls[-1] <= opt.evaluations
    assert np.array_equal(opt.x, design_opt.optimise(task, FAST).x)


def test_the_hand_at_rest_does_not_reach_into_the_objects_place():
    """A charged reservoir can bend the fingers past the grasp angle with the pump off: the
    object could pass the open tips but not reach its grasp place (pad 2 in the way) unless
    the pump sucked oil out. Such a design (P_contact = -0.033 MPa, a thin 3 mm wall, a thick
    sheet) was reported feasible; the free hand's pump pressure at the grasp angle is now >= 0."""
    task = task_from_dict({**CI_TASK, "limits": {"min_wall_mm": 3.0, "rubber_stretch": 2.0},  # contact alone
                           "free": {"a_mm": [3.0, 6.0], "b_mm": [3.0, 7.0], "d_mm": [10.0, 20.0],
                                    "t_mm": [0.5, 3.0], "V0_mm3": [10000.0, 40000.0]}})
    pre_bent = design_opt.evaluate(task.base.replace(a=6.0, b=3.0, d=20.0, t=2.0, V0=22000.0), task)
    assert pre_bent.P_contact < 0.0 and not pre_bent.feasible
    assert [c.name for c in design_opt.binding(pre_bent)] == [
        next(c.name for c in pre_bent.constraints if c.name.startswith("contact:"))]  # the only one
    ev = design_opt.optimise(task, FAST).evaluation
    assert ev.feasible and ev.P_contact >= -1e-9 and ev.P_grasp > ev.P_contact


@pytest.mark.parametrize("outcome, code, proven", [("met", 0, True), ("not met", 1, False), ("no fem", 0, None)])
def test_proven_says_in_one_word_what_the_exit_code_says(tmp_path, monkeypatch, outcome, code, proven):
    """A proof whose FEM fails (or breaks a limit) exits 1 but writes the design for a look;
    "feasible" (the reduced model's word) stayed true, so a script reading it took an unproven
    design. The proof itself is stood in for: its FEM is tested in test_design_fem.py."""
    from softhand.studies.cli import main as cli
    from softhand.studies.design import workflow

    def proof(result, *rest):
        return result if outcome == "met" else {**result, "fem_report": "the FEM failed"}

    monkeypatch.setattr(workflow, "prove_and_correct", proof)
    task, out = _write(tmp_path, CI_TASK_TOML), tmp_path / "out"
    argv = ["design", "--task", str(task), "--out", str(out), "--seed", "3", "--no-progress"]
    assert cli.main(argv + (["--no-fem"] if outcome == "no fem" else [])) == code
    result = json.loads((out / "result.json").read_text())
    assert result["feasible"] is True and result["proven"] is proven


def test_an_object_wider_than_the_open_hand_names_its_widest_span():
    """260 mm: the straight hand's tips span 2 (base_offset + l0 sin theta0) = 243.1 mm; the
    report said only 'opening ... = -inf against the limit 0'."""
    task = task_from_dict({**CI_TASK, "object": {"diameter_mm": 260.0, "mass_kg": 1.0}})
    opt = design_opt.optimise(task, FAST)
    assert not opt.evaluation.feasible
    base = task.base
    widest = 2.0 * (base.base_offset + base.l0 * math.sin(base.theta0))
    assert design_opt.open_span(base) == pytest.approx(widest, rel=1e-12)
    assert f"straight, its tips span {widest:.4g} mm" in design_opt.infeasible_report(task, opt)


def test_a_margin_beyond_the_one_pad_grasp_is_measured_where_it_ends():
    """A 4 MPa pump on the paper's object at 1 kg: a second pad touches it near 2.8 MPa, where the
    FEM-informed grasp ends. The margin is F_v there (reduced.calibrated.grasp_hold.at_pump), flagged, not
    -inf (every such design was infeasible), and F_v at the pump limit is not claimed."""
    from softhand.reduced.calibrated import grasp_hold, grasp_hold_solve

    task = task_from_dict({**CI_TASK, "object": {"diameter_mm": 180.0, "mass_kg": 1.0},
                           "grasp": {"force_factor": 2.0, "objective": "margin"},
                           "pump": {"max_pressure_MPa": 4.0}})
    ev = design_opt.evaluate(task.base, task)
    end = grasp_hold.at_pump(task.base, 180.0, 1.0, 4.0)
    assert end.edge == grasp_hold_solve.ONE_PAD_END and 2.0 < end.P_pump < 4.0
    assert (ev.margin_edge, ev.P_margin, ev.F_v_at_limit) == (end.edge, end.P_pump, end.F_v)
    predicted = json.loads(json.dumps(ev.predicted()))
    assert predicted["F_v_at_pump_limit_N"] is None
    assert predicted["margin_N"] == pytest.approx(end.F_v - task.required_F_v(), rel=1e-12)
    assert predicted["margin_at_pump_pressure_MPa"] == end.P_pump
    force = [c for c in ev.constraints if c.name.startswith("F_v at the pump limit")]
    assert len(force) == 1 and force[0].value == end.F_v and force[0].satisfied
    assert ev.feasible
    report = design_opt.infeasible_report(task, design_opt.Optimum(np.array([task.base.d, task.base.V0]), ev, 0, 0.0, 0, ""))
    assert f"at {end.P_pump:.4g} MPa, below the pump limit 4 MPa, where one pad no longer holds" in report


def test_a_force_one_pad_cannot_give_leaves_the_rest_of_the_evaluation_standing():
    """20 kg on the paper's hand: F_v = 98 N is more than one pad gives before a second one
    touches (~83 N). P_grasp has no value, and says why; the free hand's pressures (the contact
    and opening constraints) are still the design's, not "inf" as for a design the model has
    no answer for (the report named them and an opening no bend reaches)."""
    task = task_from_dict({**CI_TASK, "object": {"diameter_mm": 180.0, "mass_kg": 20.0},
                           "pump": {"max_pressure_MPa": 4.0}})
    ev = design_opt.evaluate(task.base, task)
    assert ev.P_grasp == math.inf and "not reached by the finger on one pad" in ev.no_grasp
    assert ev.P_contact == pytest.approx(float(hand.pressure(ev.theta_grasp, task.base)), rel=1e-12)
    failed = [c.name.split(" ")[0] for c in ev.constraints if not c.satisfied]
    assert failed == ["pump_pressure"]
    assert json.loads(json.dumps(ev.predicted()["no_P_grasp"])) == ev.no_grasp
    report = design_opt.infeasible_report(task, design_opt.Optimum(np.array([task.base.d, task.base.V0]), ev, 0,
                                                                   0.0, 0, ""))
    assert f"has no pump pressure for F_v = {ev.F_v:.4g} N (the pump limit 4 MPa): not reached" in report
    assert "no bend opens" not in report
    # the optimiser sees how far short of F_v the finger comes (F_v where one pad stops holding
    # the object alone), not the -1e3 of a design the model has no answer for
    from softhand.reduced.calibrated import grasp_hold_end

    end = grasp_hold_end.one_pad_end(task.base, 180.0, 20.0)
    pump = next(c for c in ev.constraints if c.name.startswith("pump_pressure"))
    assert pump.slack == pytest.approx(-1.0 - (1.0 - end.F_v / ev.F_v), rel=1e-6)
    assert -2.0 < pump.slack < -1.0 and not pump.satisfied


def test_only_a_force_not_reached_is_reported_as_no_grasp(monkeypatch):
    """An error of another model inside the grasp (here: more oil than the reservoir holds) is
    not "F_v not reached": the design has no answer at all, as before (every pressure inf)."""
    from softhand.reduced.calibrated import grasp_hold

    task = task_from_dict(CI_TASK)

    def too_much_oil(*args, **kwargs):
        raise InputError("V_mm3", -1.0, "reservoir volume must be positive")

    monkeypatch.setattr(grasp_hold, "hold", too_much_oil)
    ev = design_opt.evaluate(task.base, task)
    assert ev.no_grasp == "" and ev.P_grasp == math.inf and ev.P_contact == math.inf
