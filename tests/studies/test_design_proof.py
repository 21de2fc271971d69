"""softhand design's FEM proof on the reduced side: the limits it checks, its mesh, the retry,
the FEM-corrected second optimisation and the Pareto knee's proof (the FEM replaced by a
stand-in where the flow, not the FEM, is under test)."""
import json

import pytest

from softhand.reduced.vocabulary.design_files import load_design
from softhand.studies.design import optimise as design_opt
from softhand.studies.design.task import task_from_dict
from test_design_task import CI_TASK, CI_TASK_TOML, _write


def test_the_proof_flags_a_fem_stretch_above_the_limit():
    """Eq. (8) sees the wall's bending strain only; the FEM's peak (tied rings, end cap) is checked
    against the task's limit by the proof, and a break is one paragraph."""
    from softhand.studies.design.proof import fem_constraints, fem_report

    task = task_from_dict(CI_TASK)  # stretch limit 1.5, pump 2 MPa
    ev = design_opt.evaluate(task.base, task)
    ok = {"rubber_stretch": 1.49, "sheet_rubber_stretch": 1.3, "P_grasp_MPa": 0.7}
    ok["constraints"] = fem_constraints(ok, task)
    assert all(c["satisfied"] for c in ok["constraints"]) and fem_report(ok, ev) is None
    bad = {"rubber_stretch": 1.54, "sheet_rubber_stretch": 1.3, "P_grasp_MPa": 0.7}
    bad["constraints"] = fem_constraints(bad, task)
    assert [c["satisfied"] for c in bad["constraints"]] == [False, True, True]
    text = fem_report(bad, ev)
    assert "rubber_stretch (FEM, verified grasp) = 1.54 above the limit 1.5" in text and "\n" not in text


def test_the_fem_meets_a_limit_to_its_tolerance():
    """A design the optimiser put on its binding limit is confirmed by an FEM value at that limit
    to FEM_TOLERANCE of it (1.50002 against 1.5, the paper task's sheet), not beyond."""
    from softhand.studies.design.proof import FEM_TOLERANCE, fem_constraints

    task = task_from_dict(CI_TASK)  # stretch limit 1.5, pump 2 MPa
    at = {"rubber_stretch": 1.2, "sheet_rubber_stretch": 1.50002, "P_grasp_MPa": 0.7}
    assert all(c["satisfied"] and c["tolerance"] == FEM_TOLERANCE for c in fem_constraints(at, task))
    beyond = {**at, "sheet_rubber_stretch": 1.5 * (1 + 1.01 * FEM_TOLERANCE)}
    assert [c["satisfied"] for c in fem_constraints(beyond, task)] == [True, False, True]


def test_the_proof_mesh_follows_the_wall():
    from softhand.studies.design.proof_sizes import proof_mesh

    task = task_from_dict(CI_TASK)
    assert proof_mesh(task.base.replace(b=4.5), 10.0) == 10.0
    assert proof_mesh(task.base.replace(b=5.0), 10.0) == 10.0
    assert proof_mesh(task.base.replace(b=5.69), 10.0) == 6.0   # the 10 mm mesh fails at b = 5.5
    assert proof_mesh(task.base.replace(b=5.69), 4.0) == 4.0    # a finer mesh is kept


def test_a_failed_proof_mesh_is_retried_on_the_next_finer_one(monkeypatch):
    from softhand.reduced.vocabulary.errors import InputError, MeshRejected
    from softhand.studies.design import workflow
    from softhand.studies.design import proof

    tried, works = [], 6.0

    def prove(ev, task, options, out=None, progress=None, tick=None):
        tried.append(options.mesh_size_mm)
        if options.mesh_size_mm == 10.0:  # the FEM refuses the mesh: the proof's choice, not the user's
            raise MeshRejected("gmsh 10 mm", "has 39 curved elements that fold over themselves")
        if options.mesh_size_mm > works:
            raise RuntimeError("free-bend FEM: Newton failed")
        return {"P_grasp_MPa": 0.5}

    monkeypatch.setattr(proof, "prove", prove)
    task = task_from_dict({**CI_TASK, "fem": {"mesh_size_mm": 10.0}})
    ev = design_opt.evaluate(task.base, task)
    fem = workflow.prove_on_meshes(ev, task, None, None, lambda text: None)
    assert tried == [10.0, 6.0] and fem["P_grasp_MPa"] == 0.5
    assert fem["failed_meshes"][0]["mesh_size_mm"] == 10.0
    tried.clear()
    fem = workflow.prove_on_meshes(ev, task, 6.0, None, lambda text: None)
    assert tried == [6.0] and "failed_meshes" not in fem
    tried.clear()
    works = 4.0  # a thin wall: the 10 and 6 mm meshes stall, 4 mm bends it
    fem = workflow.prove_on_meshes(ev, task, None, None, lambda text: None)
    assert tried == [10.0, 6.0, 4.0] and [m["mesh_size_mm"] for m in fem["failed_meshes"]] == [10.0, 6.0]
    tried.clear()
    works = 3.0  # none works: the last error, every mesh named
    fem = workflow.prove_on_meshes(ev, task, None, None, lambda text: None)
    assert tried == [10.0, 6.0, 4.0] and "error" in fem and len(fem["failed_meshes"]) == 3
    tried.clear()
    fem = workflow.prove_on_meshes(ev, task, 3.5, None, lambda text: None)
    assert tried == [3.5]  # a finer mesh of the user's is the only one

    def refuses(*args, **kwargs):
        raise InputError("--pressure-mpa", -1.0, "must be positive")

    monkeypatch.setattr(proof, "prove", refuses)
    with pytest.raises(InputError):  # any other bad input is the user's: it ends the run
        workflow.prove_on_meshes(ev, task, None, None, lambda text: None)


def test_a_proof_mesh_too_large_for_the_optimum_is_not_retried_finer(monkeypatch):
    """The box's smallest finger fitted the memory, the optimum's does not: no finer mesh is
    tried (it would be larger still) and the report asks for a coarser one."""

    from softhand.reduced.vocabulary.errors import MeshTooLarge
    from softhand.studies.design import workflow
    from softhand.studies.design import proof

    tried = []

    def prove(ev, task, options, out=None, progress=None, tick=None):
        tried.append(options.mesh_size_mm)
        raise MeshTooLarge("gmsh mesh_size=10", "has at least 900,000 unknowns; choose a coarser mesh")

    monkeypatch.setattr(proof, "prove", prove)
    task = task_from_dict({**CI_TASK, "fem": {"mesh_size_mm": 10.0}})
    ev = design_opt.evaluate(task.base, task)
    fem = workflow.prove_on_meshes(ev, task, None, None, lambda text: None)
    assert tried == [10.0] and fem["too_large"]
    assert "try --mesh-size-mm with a coarser mesh" in proof.fem_report(fem, ev)


def test_the_proof_mesh_is_bounded_on_the_boxs_thinnest_shortest_tube(monkeypatch):
    """check_proof_size takes a, b, l0 at their lower bounds (free) or the base's, whether or
    not that corner is a valid design (d below a + b there), and the finest mesh the proof may
    try: the bound of a uniform gmsh tube of that size."""
    from softhand.fem.hand import finger_options as fo
    from softhand.reduced.vocabulary.errors import MeshTooLarge
    from softhand.studies.design import proof_sizes

    seen = []
    monkeypatch.setattr(fo, "check_unknowns", lambda least, mesh, memory=None: seen.append((least, mesh)))
    task = task_from_dict({**CI_TASK, "design": {"a_mm": 5.0, "b_mm": 5.0},
                           "free": {"d_mm": [10.0, 18.0], "l0_mm": [150.0, 200.0]}})
    proof_sizes.check_proof_size(task, 10.0)
    assert seen == [(int(4 * fo.gmsh_least_tets(5.0, 5.0, 150.0, 5.0, 4.0)), "gmsh mesh_size=4 (the proof's)")]
    monkeypatch.undo()
    monkeypatch.setattr(fo, "memory_bytes", lambda: 24 * 2 ** 30)
    with pytest.raises(MeshTooLarge, match="at least 2,8"):  # ~2.9 million unknowns
        proof_sizes.check_proof_size(task, 0.5)


#: the task's finger on the paper's model: its tube stretch is eq. (8)'s, which the FEM corrects
PAPER_FINGER = '[design]\nfinger_model = "paper"\n'


def test_a_fem_stretch_above_the_limit_reoptimises_with_the_fems_factor(tmp_path, monkeypatch, capsys):
    """On the paper's finger model the proof's rubber stretch 1.51 breaks the limit 1.5: the verb
    optimises again with eq. (8)'s
    strain scaled by (1.51 - 1) / (lambda_pred - 1), proves that design (here: the FEM stand-in
    gives its scaled prediction), keeps the first under "rejected" and exits 0. At 2.5 no design
    meets the scaled limit if l0 is fixed (at 1.7 one still does): one paragraph naming it and the
    nearest design, exit 1."""
    from softhand.studies.cli.main import main
    from softhand.studies.design import proof
    from softhand.studies.design import evaluate
    from softhand.studies.design.proof import fem_constraints

    seen = []

    def prove(ev, task, options, out=None, progress=None, tick=None):
        seen.append((ev, task))
        stretch = first if len(seen) == 1 else 1 + 0.999 * (ev.stretch - 1)  # the second: as the factor says
        fem = {"rubber_stretch": stretch, "sheet_rubber_stretch": 1.0, "P_grasp_MPa": ev.P_grasp, "F_v_N": ev.F_v}
        return {**fem, "constraints": fem_constraints(fem, task)}

    monkeypatch.setattr(proof, "prove", prove)
    task = _write(tmp_path, CI_TASK_TOML + "l0_mm = [150.0, 200.0]\n" + PAPER_FINGER)  # a longer finger stretches less
    first = 1.51
    assert main(["design", "--task", str(task), "--json", "--out", str(tmp_path / "out"), "--seed", "3"]) == 0
    result = json.loads(capsys.readouterr().out)
    (ev1, task1), (ev2, task2) = seen
    factor = 0.51 / (ev1.stretch - 1.0)
    assert task1.stretch_factor == 1.0 and task2.stretch_factor == pytest.approx(factor, rel=1e-12)
    assert result["stretch_factor"] == pytest.approx(factor, rel=1e-12)
    # the new optimum's predicted stretch is eq. (8) x the factor, and within the limit
    eq8 = evaluate.peak_stretch(ev2.theta_hold, ev2.design)
    assert ev2.stretch == pytest.approx(1 + factor * (eq8 - 1), rel=1e-12) and ev2.stretch <= 1.5 + 1e-9
    assert ev2.design != ev1.design  # it moved: the first would be 1.51
    assert result["rejected"]["fem"]["rubber_stretch"] == 1.51 and "fem_report" not in result
    assert load_design(result["design_file"]).to_dict() == result["design"] == ev2.design.to_dict()
    assert load_design(result["rejected"]["design_file"]).to_dict() == ev1.design.to_dict()
    seen.clear()  # with l0 fixed the bend at the grasp, so eq. (8), hardly moves: 2.5 cannot be met
    first, fixed_l0 = 2.5, _write(tmp_path, CI_TASK_TOML + PAPER_FINGER, "fixed_l0.toml")
    assert main(["design", "--task", str(fixed_l0), "--json", "--out", str(tmp_path / "o1"), "--seed", "3"]) == 1
    result = json.loads(capsys.readouterr().out)
    assert len(seen) == 1 and result["report"].startswith("The task cannot be met")
    assert "binding constraint is rubber_stretch of the tube" in result["report"] and "nearest design" in result["report"]
    # --no-correct keeps the first optimum and its exit code 1
    seen.clear()
    assert main(["design", "--task", str(task), "--json", "--out", str(tmp_path / "o2"), "--seed", "3",
                 "--no-correct"]) == 1
    assert len(seen) == 1 and "rejected" not in json.loads(capsys.readouterr().out)


def test_a_calibrated_tube_stretch_is_not_corrected_by_the_proof(tmp_path, monkeypatch, capsys):
    """On the FEM-calibrated finger (the task's default models, the packaged table holding the
    converged stretch) the tube's stretch is the table's prediction of the FEM's: a proof that
    finds 1.51 above the limit 1.5 is reported (exit 1), not turned into a factor and a second
    optimisation."""
    from softhand.studies.cli.main import main
    from softhand.studies.design import proof
    from softhand.studies.design.proof import fem_constraints

    seen = []

    def prove(ev, task, options, out=None, progress=None, tick=None):
        seen.append(ev)
        fem = {"rubber_stretch": 1.51, "sheet_rubber_stretch": 1.0, "P_grasp_MPa": ev.P_grasp, "F_v_N": ev.F_v}
        return {**fem, "constraints": fem_constraints(fem, task)}

    monkeypatch.setattr(proof, "prove", prove)
    task = _write(tmp_path, CI_TASK_TOML + "l0_mm = [150.0, 200.0]\n")
    assert main(["design", "--task", str(task), "--json", "--out", str(tmp_path / "out"), "--seed", "3"]) == 1
    result = json.loads(capsys.readouterr().out)
    assert result["models"]["tube_stretch"] == "FEM-calibrated rubber_stretch"
    assert len(seen) == 1 and "rejected" not in result and "stretch_factor" not in result
    assert "rubber_stretch (FEM, verified grasp) = 1.51 above the limit 1.5" in result["fem_report"]


def test_the_pareto_knee_goes_through_the_fem_too(tmp_path, monkeypatch, capsys):
    """With --pareto the proof runs for the optimum and for the front's knee (its design file in
    knee/, its prediction at the knee's stretch limit beside the FEM's answer)."""
    from softhand.studies.cli.main import main
    from softhand.studies.design import proof
    from softhand.studies.design.proof import fem_constraints

    seen = []

    def prove(ev, task, options, out=None, progress=None, tick=None):
        seen.append((ev, out))
        fem = {"rubber_stretch": ev.stretch, "sheet_rubber_stretch": 1.0, "P_grasp_MPa": ev.P_grasp, "F_v_N": ev.F_v}
        return {**fem, "constraints": fem_constraints(fem, task)}

    monkeypatch.setattr(proof, "prove", prove)
    task = _write(tmp_path, CI_TASK_TOML + "l0_mm = [150.0, 200.0]\n")
    out = tmp_path / "out"
    assert main(["design", "--task", str(task), "--json", "--pareto", "--out", str(out), "--seed", "3"]) == 0
    pareto = json.loads(capsys.readouterr().out)["pareto"]
    knee = pareto["rows"][pareto["knee"]]
    # the knee's VTK goes to knee/ of the run's staging folder in out, renamed to out/knee/ when whole
    assert pareto["knee"] > 0 and len(seen) == 2 and seen[1][1].name == "knee" and seen[1][1].parent.parent == out
    proof_of_knee = pareto["knee_proof"]
    predicted = proof_of_knee["predicted"]  # the front's axis: the larger of the tube's and the sheet's
    assert max(predicted["rubber_stretch"], predicted["sheet_stretch"]) == \
        pytest.approx(knee["rubber_stretch"], rel=1e-9)
    assert proof_of_knee["fem"]["P_grasp_MPa"] == pytest.approx(knee["P_grasp_MPa"], rel=1e-9)
    assert load_design(proof_of_knee["design_file"]).to_dict() == seen[1][0].design.to_dict()


def test_a_proof_that_fails_on_every_mesh_is_not_a_proven_design(tmp_path, monkeypatch, capsys):
    """The FEM failing on the task's mesh and on the retry mesh: one paragraph saying the
    design is not proven, the meshes tried, exit 1 (not a silent success without FEM)."""
    from softhand.studies.cli.main import main
    from softhand.studies.design import proof

    def prove(ev, task, options, out=None, progress=None, tick=None):
        raise RuntimeError("free-bend FEM: Newton failed at 0.2 MPa")

    monkeypatch.setattr(proof, "prove", prove)
    task = _write(tmp_path, CI_TASK_TOML.replace("[free]", "[fem]\nmesh_size_mm = 10.0\n[free]"))
    assert main(["design", "--task", str(task), "--json", "--out", str(tmp_path / "out"), "--seed", "3"]) == 1
    result = json.loads(capsys.readouterr().out)
    assert result["fem_report"].startswith("The FEM proof could not be completed (finger mesh 10 mm")
    assert "Newton failed at 0.2 MPa" in result["fem_report"] and "rejected" not in result


def test_the_fem_margin_is_printed_with_the_pads_on_the_object(capsys):
    """The text output's lines for the FEM's margin, at the pump limit beyond the one-pad grasp,
    and where the FEM did not reach the limit."""
    from types import SimpleNamespace

    from softhand.studies.design.summary import margin_lines

    def print_margin(fem, task):  # what softhand design prints
        print(*margin_lines(fem, task), sep="\n")

    at = {"F_v_N": 40.19, "P_pump_MPa": 2.8143, "P_cavity_MPa": 2.861,
          "links_in_contact": [3], "predicted_F_v_N": 38.13}
    limit = {"F_v_N": 43.16, "margin_N": 28.45, "links_in_contact": [3, 5]}
    print_margin({"margin": at, "at_pump_limit": limit}, SimpleNamespace(max_pressure=3.2))
    out = capsys.readouterr().out.splitlines()
    assert out == ["# FEM margin: F_v 40.19 N at the pump pressure 2.814 MPa (cavity 2.861 MPa, on the "
                   "object: link 3 (0 = base)), predicted 38.13 N",
                   "# FEM at the pump limit 3.2 MPa, beyond the reduced model's one-pad grasp: F_v 43.16 N, "
                   "margin 28.45 N (on the object: links 3, 5 (0 = base))"]
    print_margin({"margin": at, "at_pump_limit": {"error": "Newton stopped at P = 3.1 MPa"}},
                  SimpleNamespace(max_pressure=3.2))
    assert capsys.readouterr().out.splitlines()[1] == \
        "# FEM at the pump limit 3.2 MPa: not reached (Newton stopped at P = 3.1 MPa)"


class _LinearGrasp:
    """A stand-in for the grasp FEM (fem.hand.grasp.GraspModel) with closed-form states: the
    fingers take dQ = 2000 P mm^3 each, F_v = 30 P N; Newton fails above ``fails_above`` MPa."""

    def __init__(self, fails_above=float("inf")):
        from types import SimpleNamespace

        self.design = SimpleNamespace(V0=20000.0, n=4)
        self.finger = SimpleNamespace(dQ=lambda y: 2000.0 * y)
        self.fails_above, self.solves = fails_above, []

    def solve(self, P, start=None):
        from types import SimpleNamespace

        import numpy as np
        from softhand.fem.newton import NotConverged

        self.solves.append(P)
        if P > self.fails_above:
            raise NotConverged(f"Newton stopped at P = {self.fails_above:g} MPa on the way to {P:.4g} MPa",
                               [1.0], None)
        return SimpleNamespace(P=P, y=P, F_v=30.0 * P, theta=0.5, N=np.array([0.0, 0.0, 30.0 * P]))


def test_the_margin_state_is_the_pump_pressure_asked():
    """grasp_at_pump against the closed form of the stand-in: the reservoir's p_r(V) = 1e-5 V MPa
    at the oil left V = V0 - n dQ(P), so the cavity pressure P of pump pressure p solves
    P - 1e-5 (20000 - 8000 P) = p: P = (p + 0.2) / 1.08."""
    from types import SimpleNamespace

    import numpy as np
    from softhand.studies.design.proof_steps import ProofOptions, margin

    model, options = _LinearGrasp(), ProofOptions(pump_tol_mpa=1e-9)
    sheet = SimpleNamespace(path_volume=np.array([0.0, 30000.0]), path_pressure=np.array([0.0, 0.3]))
    ev = SimpleNamespace(P_margin=1.5, margin_edge="", F_v_at_limit=50.0)
    task = SimpleNamespace(required_F_v=lambda: 10.0, max_pressure=1.5)
    best = model.solve(0.5)
    out, states = margin(model, sheet, best, ev, task, options)
    assert [s.P for s in states] == [out["margin"]["P_cavity_MPa"]]
    P = (1.5 + 0.2) / 1.08
    assert out["margin"]["P_cavity_MPa"] == pytest.approx(P, abs=1e-9)
    assert out["margin"]["P_pump_MPa"] == pytest.approx(1.5, abs=1e-9)
    assert out["margin_N"] == pytest.approx(30.0 * P - 10.0, abs=1e-7) and out["F_v_at_pump_limit_N"] == out["margin"]["F_v_N"]
    assert max(np.diff(model.solves[1:6])) <= options.max_step_mpa + 1e-12  # continued in steps
    # below the pump limit (a second pad touches in the reduced model) the FEM goes on to the limit
    model = _LinearGrasp()
    out, states = margin(model, sheet, model.solve(0.5), SimpleNamespace(P_margin=1.2, margin_edge="a second pad",
                         F_v_at_limit=40.0), task, options)
    assert len(states) == 2 and states[1].P == out["at_pump_limit"]["P_cavity_MPa"]
    assert out["margin"]["P_pump_MPa"] == pytest.approx(1.2, abs=1e-9)
    assert out["at_pump_limit"]["P_cavity_MPa"] == pytest.approx(P, abs=1e-9)
    assert out["F_v_at_pump_limit_N"] == pytest.approx(30.0 * P, abs=1e-7)


def test_a_margin_the_grasp_fem_does_not_reach_is_reported_not_raised(capsys):
    """The margin is the objective, met already by the verified grasp: a grasp FEM that fails on
    the way to it is one line in the result, and the proof stands."""
    from types import SimpleNamespace

    import numpy as np
    from softhand.studies.design.summary import margin_lines

    def print_margin(fem, task):  # what softhand design prints
        print(*margin_lines(fem, task), sep="\n")
    from softhand.studies.design.proof_steps import ProofOptions, margin

    sheet = SimpleNamespace(path_volume=np.array([0.0, 30000.0]), path_pressure=np.array([0.0, 0.3]))
    task = SimpleNamespace(required_F_v=lambda: 10.0, max_pressure=1.5)
    model = _LinearGrasp(fails_above=1.0)
    out, states = margin(model, sheet, model.solve(0.5), SimpleNamespace(P_margin=1.5, margin_edge="",
                         F_v_at_limit=50.0), task, ProofOptions())
    assert states == [] and out == {"margin": {"error": "Newton stopped at P = 1 MPa on the way to 1.08 MPa",
                              "predicted_F_v_N": 50.0, "below_pump_limit": ""}}
    print_margin(out, task)
    assert capsys.readouterr().out == ("# FEM margin: not computed (Newton stopped at P = 1 MPa on the way to "
                                       "1.08 MPa); predicted F_v 50 N\n")
    # past the reduced margin, on the way to the pump limit: the margin stands, the limit is reported
    model = _LinearGrasp(fails_above=1.45)
    out, states = margin(model, sheet, model.solve(0.5), SimpleNamespace(P_margin=1.2, margin_edge="a second pad",
                         F_v_at_limit=40.0), task, ProofOptions())
    assert len(states) == 1 and out["margin"]["P_pump_MPa"] == pytest.approx(1.2, abs=1e-3)
    assert out["F_v_at_pump_limit_N"] is None and "error" in out["at_pump_limit"]


def test_the_knee_line_gives_the_fem_margin_where_the_proof_has_one():
    from softhand.studies.design.summary import knee_line as _knee_line

    knee = {"predicted": {"P_grasp_MPa": 0.52, "F_v_N": 9.81, "margin_N": 4.13},
            "fem": {"P_grasp_MPa": 0.53, "F_v_N": 9.41}, "design_file": "knee/design.toml"}
    assert _knee_line(knee) == ("knee: P_grasp 0.52 MPa predicted, 0.53 MPa FEM; F_v 9.81 N predicted, "
                                "9.41 N FEM; design knee/design.toml")
    knee["fem"]["margin_N"] = 3.68
    assert "9.41 N FEM; margin 4.13 N predicted, 3.68 N FEM; design knee/design.toml" in _knee_line(knee)
