"""Every bad input of every verb and file type: exit 2, one stderr line, nothing written.

Run in-process (``studies.cli.main``) in a scratch folder; each case asserts exit code 2,
exactly one line on stderr that names an option or field, no traceback, nothing on
stdout, and no file created or changed anywhere under the scratch folder (outputs, the
cache, results).
"""
import math
from pathlib import Path

import pytest

from bad_input_cases import EXTRA_FILES, replay_cases
from softhand.reduced.vocabulary.design import BOUNDS, HandDesign
from softhand.studies.cli.main import main

# ---------------------------------------------------------------- input files of the cases
GOOD_CSV = "P_MPa,theta_deg\n0.2,10\n0.4,25\n0.6,40\n0.8,55\n"
FILES = {
    "bad_toml.toml": "a_mm = = 3\n",
    "binary.toml": b"\xff\xfe\x00bad",
    "huge_hinges.toml": "hinge_s_mm = [" + ", ".join(["1.0"] * 200_000) + "]\n",
    "good.csv": GOOD_CSV,
    "empty.csv": "",
    "header_only.csv": "P_MPa,theta_deg\n",
    "unknown_col.csv": "P_MPa,theta_deg,colour\n0.2,10,1\n0.4,20,2\n",
    "theta600.csv": "P_MPa,theta_deg\n0.2,10\n0.4,600\n0.6,700\n",
    "nan_row.csv": "P_MPa,theta_deg\n0.2,10\n0.4,nan\n0.6,40\n",
    "short_row.csv": "P_MPa,theta_deg\n0.2,10\n0.4\n0.6,40\n",
    "pressure_big.csv": "P_MPa,theta_deg\n0.2,10\n40,20\n0.6,40\n",
    "push_bad_header.csv": "time,force\n0,1\n",
    "push_no_rows.csv": "t_s,force_N\n",
    "push_decreasing.csv": "t_s,force_N\n0,1\n2,1\n1,1\n",
    "push_nan.csv": "t_s,force_N\n0,1\n1,nan\n",
    "push_text.csv": "t_s,force_N\n0,one\n",
    "push_huge.csv": "t_s,force_N\n0,0\n1,1e300\n",
    "a_file": "not a folder",
    "result.vtu": "<VTKFile>",
    "deep.toml": "a_mm = " + "[" * 5000 + "]" * 5000 + "\n",  # the parser's recursion limit
    "dotted.toml": "a_mm" + ".x" * 20_000 + " = 1\n",  # nested 20 000 deep without recursion
}
#: VTK files that VTK reads but whose rendering crashed or aborted the process
_VTU = EXTRA_FILES["good.vtu"]
FILES.update({
    "v_negative_id.vtu": _VTU.replace(">0 1 2 3<", ">0 1 2 -5<"),  # was a segmentation fault
    "v_id_past_end.vtu": _VTU.replace(">0 1 2 3<", ">0 1 2 99<"),
    "v_cell_type.vtu": _VTU.replace('format="ascii">10<', 'format="ascii">255<'),
    "v_nan_point.vtu": _VTU.replace(">0 0 0 1 0 0 ", ">nan 0 0 1 0 0 "),
    "v_huge_count.vtu": _VTU.replace('NumberOfPoints="4"', 'NumberOfPoints="1000000000000"'),  # bad_alloc
})
#: designs each of whose numbers passes its own check, but whose model has no finite answer
FILES.update({
    "x_hinge_nan.toml": "hinge_s_mm = [30.0, nan, 90.0, 120.0, 150.0]\n",  # nan < x is False
    "x_gent_locked.toml": '[finger.material]\nmodel = "gent"\nmu_MPa = 1.0\nJm = 1e-6\n',
    "x_gent_sheet.toml": '[reservoir.material]\nmodel = "gent"\nmu_MPa = 1.0\nJm = 1e-6\n',
    "x_three_hinges.toml": "n_s = 3\n",  # the paper's w have five
    "x_v0_balloon.toml": "V0_mm3 = 1.0e7\n",  # eq. (16): the sheet stretched 344-fold
    # materials with a positive initial modulus, unstable or locked where a hand's rubber goes
    "x_mr_unstable.toml": '[finger.material]\nmodel = "mooney-rivlin"\nC10_MPa = 0.5\nC01_MPa = -0.4\n',
    "x_yeoh_unstable.toml": '[reservoir.material]\nmodel = "yeoh"\nC10_MPa = 0.5\nC20_MPa = -5\n',
    "x_ogden_alpha.toml": '[finger.material]\nmodel = "ogden"\nmu1_MPa = 0.01\nalpha1 = 300\n',
    "x_table_unused.toml": 'finger_table = "nope.csv"\nfinger_model = "paper"\n',  # was ignored
    "x_steel.toml": '[finger.material]\nmodel = "steel"\n',
    "x_tiny_sheet.toml": "R_mm = 1.0\nt_mm = 0.01\n",
})
#: design spaces whose load path no FEM run should take (the FEM started on each)
_SPACE = EXTRA_FILES["good_space.toml"]
FILES.update({
    "sp_pair_huge.toml": _SPACE + "[mesh_pair]\na_mm = 4.0\nb_mm = 5.0\nd_mm = 15.0\nl0_mm = 180.0\n"
                                  "tie_width_mm = 10.0\npressures_mpa = [0.2, 1e9]\n",
    "sp_design_pmax.toml": _SPACE.replace("tie_width_mm = 10.0\n", "tie_width_mm = 10.0\np_max_mpa = 1e9\n"),
    "sp_design_pstep.toml": _SPACE.replace("tie_width_mm = 10.0\n", "tie_width_mm = 10.0\np_step_mpa = 1e-9\n"),
    "sp_past_pmax.toml": "pressures_mpa = [0.2, 3.0]\np_max_mpa = 1.0\n" + _SPACE,
})
#: a file name longer than any file system allows (255 bytes), and a path past PATH_MAX
LONG, DEEP_PATH = "x" * 300, "/".join(["y" * 200] * 25)
#: design tasks (softhand design --task): a good one, and each of its mistakes
GOOD_TASK = ("[object]\ndiameter_mm = 180.0\nmass_kg = 2.0\n[pump]\nmax_pressure_MPa = 2.0\n"
             "[free]\nd_mm = [12.0, 18.0]\n")
TASKS = {
    "t_good.toml": GOOD_TASK,
    "t_bounds.toml": GOOD_TASK.replace("[12.0, 18.0]", "[18.0, 12.0]"),
    "t_outside.toml": GOOD_TASK.replace("[12.0, 18.0]", "[25.0, 30.0]"),  # the calibrated d: 10-20 mm
    "t_key.toml": GOOD_TASK.replace("[free]", "[free]\nn = [2, 4]"),
    "t_no_free.toml": GOOD_TASK.replace("d_mm = [12.0, 18.0]\n", ""),
    "t_mass.toml": GOOD_TASK.replace("2.0\n[pump]", "-2.0\n[pump]"),
    "t_no_diameter.toml": GOOD_TASK.replace("diameter_mm = 180.0\n", ""),
    "t_pump.toml": GOOD_TASK.replace("max_pressure_MPa = 2.0", 'max_pressure_MPa = "high"'),
    "t_objective.toml": GOOD_TASK + '[grasp]\nobjective = "cheap"\n',
    "t_both.toml": GOOD_TASK + "[grasp]\nforce_factor = 2.0\nmargin_N = 1.0\n",
    "t_stretch.toml": GOOD_TASK + "[limits]\nrubber_stretch = 0.9\n",
    "t_old_stretch.toml": GOOD_TASK + "[limits]\nmax_principal_stretch = 1.5\n",  # renamed: refused
    "t_model.toml": GOOD_TASK + '[design]\nfinger_model = "magic"\n',
    "t_base.toml": 'base_design = "nowhere.toml"\n' + GOOD_TASK,
    "t_unknown.toml": GOOD_TASK + 'colour = "red"\n',
    "t_section.toml": GOOD_TASK + "[fem]\nmesh = 3\n",
    "t_table.toml": "object = 3\n" + GOOD_TASK.split("\n", 3)[3],
    "t_not_toml.toml": "[object\n",
}
FILES.update(TASKS)

#: design key -> values outside its table bounds or of the wrong type (TOML literals)
BAD_DESIGN_VALUES = ["-1e9", "1e9", "nan", "inf", '"ten"', "true"]
DESIGN_KEYS = [k for k in BOUNDS if k not in ("n", "n_s")]


def _design_files() -> dict:
    files = {f"d_{key}_{i}.toml": f"{key} = {value}\n"
             for key in DESIGN_KEYS for i, value in enumerate(BAD_DESIGN_VALUES)}
    files.update({
        "d_tube_wider.toml": "b_mm = 30.0\n",            # a + b = 34 > d = 15
        "d_d_below_a.toml": "d_mm = 3.0\n",               # d < a
        "d_sheet_thick.toml": "t_mm = 50.0\n",            # t > R = 24
        "d_tiny_R.toml": "R_mm = 1e-6\n",
        "d_tiny_mu.toml": "mu_sf_MPa = 1e-300\n",
        "d_offset.toml": "base_offset_mm = -1e308\n",
        "d_n_half.toml": "n = 2.5\n",
        "d_n_zero.toml": "n = 0\n",
        "d_n_many.toml": "n = 1000\n",
        "d_ns_zero.toml": "n_s = 0\nhinge_s_mm = []\n",
        "d_hinge_count.toml": "hinge_s_mm = [30.0, 60.0]\n",
        "d_hinge_order.toml": "hinge_s_mm = [30.0, 20.0, 90.0, 120.0, 150.0]\n",
        "d_hinge_beyond.toml": "hinge_s_mm = [30.0, 60.0, 90.0, 120.0, 190.0]\n",
        "d_hinge_text.toml": 'hinge_s_mm = "30,60"\n',
        "d_unknown.toml": "colour = 3\n",
        "d_model.toml": 'reservoir_model = "balloon"\n',
        "d_theta0.toml": "theta0_deg = 90.0\n",
    })
    return files


def _study(body: str) -> str:
    return body if body.startswith("kind") else 'kind = "curve"\n' + body


STUDIES = {
    "s_code.toml": 'kind = "os:getcwd"\n[sweep]\nx = [1]\n',
    "s_module.toml": 'kind = "softhand.studies.batch.kinds:curve"\n[sweep]\ntheta_deg = [1]\n',
    "s_unknown_kind.toml": 'kind = "curl"\n[sweep]\ntheta_deg = [1]\n',
    "s_no_kind.toml": '[sweep]\ntheta_deg = [1]\n',
    "s_million.toml": _study('[sweep]\ntheta_deg = "0:99:1"\nmu_sf_MPa = "1:1.99:0.01"\n'
                             'V0_mm3 = "17000:17990:10"\n'),
    "s_nan.toml": _study("[sweep]\ntheta_deg = [10, nan]\n"),
    "s_inf_range.toml": _study('[sweep]\ntheta_deg = "0:inf:1"\n'),
    "s_strings.toml": _study('[sweep]\ntheta_deg = ["ten", "twenty"]\n'),
    "s_range.toml": _study("[sweep]\ntheta_deg = [10, 400]\n"),
    "s_both.toml": _study("[sweep]\ntheta_deg = [10]\npressure_mpa = [0.5]\n"),
    "s_neither.toml": _study("[sweep]\nmu_sf_MPa = [1.0, 1.2]\n"),
    "s_grasp_missing.toml": 'kind = "grasp"\n[sweep]\npressure_mpa = [0.8]\n',
    "s_grasp_d.toml": 'kind = "grasp"\n[params]\ntheta_deg = 40\ndiameter_mm = 200\n'
                      '[sweep]\npressure_mpa = [0.8]\n',
    "s_grasp_weights.toml": 'kind = "grasp"\n[params]\nweights = [1, 2]\n[sweep]\n'
                            'pressure_mpa = [0.8]\ntheta_deg = [40]\n',
    "s_control_push.toml": 'kind = "control"\n[params]\npush_at_s = 50\n[sweep]\nmass_kg = [1]\n',
    "s_little_oil.toml": _study("[sweep]\nV0_mm3 = [100.0]\ntheta_deg = [80]\n"),
    "s_control_long.toml": 'kind = "control"\n[params]\nt_end_s = 1e6\n[sweep]\nmass_kg = [1]\n',
    "s_weights_mesh.toml": 'kind = "weights"\nmesh_size_mm = 1e-9\n[sweep]\ndiameter_mm = [180]\n',
    "s_weights_d.toml": 'kind = "weights"\n[sweep]\ndiameter_mm = [1, 180]\n',
    "s_mesh_reduced.toml": _study("mesh_size_mm = 2\n[sweep]\ntheta_deg = [1]\n"),
    "s_unknown_param.toml": _study("[params]\ncolour = 1\n[sweep]\ntheta_deg = [1]\n"),
    "s_unknown_top.toml": _study("colour = 1\n[sweep]\ntheta_deg = [1]\n"),
    "s_bad_design_axis.toml": _study("[sweep]\ntheta_deg = [10]\nb_mm = [5.0, 30.0]\n"),
    "s_design_file.toml": _study('design = "nope.toml"\n[sweep]\ntheta_deg = [1]\n'),
    "s_design_zero.toml": _study('design = "/dev/zero"\n[sweep]\ntheta_deg = [1]\n'),
    "s_design_key.toml": _study("[design]\nl0 = 3\n[sweep]\ntheta_deg = [1]\n"),
    "s_name.toml": _study('name = "../../escape"\n[sweep]\ntheta_deg = [1]\n'),
    "s_long_name.toml": _study(f'name = "{"n" * 5000}"\n[sweep]\ntheta_deg = [1]\n'),
    "s_description.toml": _study("description = 3\n[sweep]\ntheta_deg = [1]\n"),
    "s_params_number.toml": _study("params = 3\n[sweep]\ntheta_deg = [1]\n"),
    "s_no_sweep.toml": 'kind = "curve"\n',
    "s_empty_axis.toml": _study("[sweep]\ntheta_deg = []\n"),
    "s_both_places.toml": _study("[params]\ntheta_deg = 1\n[sweep]\ntheta_deg = [1]\n"),
    "s_not_toml.toml": "kind = curve\n",
    "s_empty.toml": "",
    "good_study.toml": _study("[sweep]\ntheta_deg = [10, 20]\n"),
}

CURVE, STUDY = ["curve", "--theta-deg", "10"], "good_study.toml"
GRASP = ["grasp", "--pressure-mpa", "0.8", "--theta-deg", "40", "--mass-kg", "1"]
CONTROL = ["control", "--theta-ref-deg", "50", "--mass-kg", "1"]
FIT = ["fit", "--data", "good.csv", "--params", "V0_mm3"]
WEIGHTS = ["weights", "--diameter-mm", "180"]


def _cases():
    cases = []
    verbs = [CURVE, GRASP + ["--weights", "paper180"], CONTROL, FIT, ["bend"], WEIGHTS,
             ["reservoir"], ["reproduce", "--quick"]]
    for i, name in enumerate(sorted(_design_files())):  # every design file, across the verbs
        cases.append((f"design-{name}", verbs[i % len(verbs)] + ["--design", name]))
    for name in ("missing.toml", "/dev/zero", ".", "bad_toml.toml", "binary.toml",
                 "huge_hinges.toml", "a_file/x.toml"):
        cases.append((f"design-file-{name}", CURVE + ["--design", name]))
    options = {
        "curve": [["--theta-deg", v] for v in ("nan", "inf", "-inf", "0:inf:1", "0:90:1e-9",
                                               "0:90:0", "90:0:10", "abc", "500", "1e400",
                                               "0:90", "0:90:10:5", "1,2,x")]
                 + [["--pressure-mpa", v] for v in ("10", "0:1:1e-7", "nan", "-20")]
                 + [["--theta-deg", "10", "--plot", p] for p in ("x.txt", "x", "adir/", ".",
                                                                 "/proc/x.png", "a_file/x.png")]
                 + [[], ["--theta-deg", "1", "--pressure-mpa", "1"], ["--theta-deg"]],
        "grasp": [["--pressure-mpa", "0.8", "--theta-deg", "40", "--mass-kg", "1"] + extra
                  for extra in (["--weights", "1,2"], ["--weights", "nan,1,1,1,1"],
                                ["--weights", ",".join(["0.1"] * 5000)], ["--weights", "paper999"],
                                ["--weights=-inf,0,0,0,1"], ["--diameter-mm", "1"],
                                ["--diameter-mm", "-5"], ["--diameter-mm", "1e6"],
                                ["--diameter-mm", "nan"], ["--diameter-mm", "180,200"],
                                ["--weights", "0,0,0,0,0", "--normalise"],
                                ["--weights", "paper180", "--diameter-mm", "180"])]
                 + [["--pressure-mpa", p, "--theta-deg", t, "--mass-kg", m, "--weights", "paper180"]
                    for p, t, m in (("nan", "40", "1"), ("inf", "40", "1"), ("x", "40", "1"),
                                    ("1,2", "40", "1"), ("0.8", "500", "1"), ("0.8", "nan", "1"),
                                    ("0.8", "40", "-1"), ("0.8", "40", "inf"), ("0.8", "40", "1e9"),
                                    ("50", "40", "1"))],
        "control": [CONTROL[1:] + extra for extra in (
            ["--kp", "nan"], ["--ki", "-1"], ["--kp", "1e9"], ["--t-end-s", "1e6"],
            ["--t-end-s", "1"], ["--push-N", "inf"], ["--push-N", "1e9"], ["--push-at-s", "0"],
            ["--push-at-s", "20"], ["--push-rise-s", "-1"], ["--sample-hz", "0"],
            ["--sample-hz", "1e9"], ["--seed", "-1"], ["--tau-f-s", "0"], ["--tau-m-s", "-1"],
            ["--q-max-mm3-s", "0"], ["--p-max-mpa", "100"], ["--diameter-mm", "200"],
            ["--noise-deg", "-1"], ["--noise-mpa", "nan"], ["--plant-mu-scale", "0"],
            ["--push-azimuth-deg", "inf"], ["--push-elevation-deg", "100"], ["--mode", "speed"],
            ["--disturbance", "missing.csv"], ["--disturbance", "."], ["--disturbance", "/dev/zero"],
            ["--disturbance", "push_bad_header.csv"], ["--disturbance", "push_no_rows.csv"],
            ["--disturbance", "push_decreasing.csv"], ["--disturbance", "push_nan.csv"],
            ["--disturbance", "push_text.csv"], ["--disturbance", "push_huge.csv"], ["--out", "a_file"], ["--out", "/proc/out"],
            ["--plot", "x.gif"], ["--plot", "a_file/x.png"])]
                   + [["--theta-ref-deg", "nan", "--mass-kg", "1"],
                      ["--theta-ref-deg", "200", "--mass-kg", "1"],
                      ["--theta-ref-deg", "50", "--mass-kg", "-1"],
                      ["--theta-ref-deg", "fifty", "--mass-kg", "1"]],
        "fit": [["--data", d, "--params", "V0_mm3"] for d in (
            "missing.csv", ".", "/dev/zero", "empty.csv", "header_only.csv", "unknown_col.csv",
            "theta600.csv", "nan_row.csv", "short_row.csv", "pressure_big.csv")]
               + [FIT[1:3] + extra for extra in (
                   ["--params", "colour_mm"], ["--params", ""], ["--params", "V0_mm3,V0_mm3"],
                   ["--params", "n"], ["--params", "V0_mm3", "--bounds", "V0_mm3=3:1"],
                   ["--params", "V0_mm3", "--bounds", "V0_mm3"],
                   ["--params", "V0_mm3", "--bounds", "mu_sf_MPa=1:2"],
                   ["--params", "mu_sf_MPa", "--shore-a", "500"],
                   ["--params", "mu_sf_MPa", "--shore-a", "nan"],
                   ["--params", "V0_mm3", "--diameter-mm", "200"],
                   ["--params", "V0_mm3", "--model", "fem"],
                   ["--params", "V0_mm3", "--out", "."], ["--params", "V0_mm3", "--out", "/proc/d.toml"],
                   ["--params", "V0_mm3", "--plot", "fit.txt"])],
        "bend": [[*extra] for extra in (
            ["--pressure-mpa", "0:0.8:1e-7"], ["--pressure-mpa", "10"], ["--pressure-mpa", "-1"],
            ["--pressure-mpa", "0.5,0.2"],
            ["--pressure-mpa", "nan"], ["--pressure-mpa", "0:inf:0.1"], ["--mesh-size-mm", "inf"],
            ["--mesh-size-mm", "0"], ["--mesh-size-mm", "100"], ["--fiber-intorder", "0"],
            ["--fiber-intorder", "1"], ["--fiber-intorder", "3"], ["--fiber-intorder", "99"],
            ["--refine", "9"], ["--refine", "-1"], ["--axial-size-mm", "0"],
            ["--axial-size-mm", "1e9"], ["--edge-ratio", "2"], ["--edge-ratio", "0"],
            ["--tie-width-mm", "50"], ["--tie-width-mm", "0"], ["--peak-mpa", "100"],
            ["--peak-mpa", "-1"], ["--out", "a_file"], ["--out", "/proc/bend"],
            ["--plot", "bend.txt"], ["--mesher", "layered", "--mesh-size-mm", "3"],
            ["--mesher", "gmsh", "--axial-size-mm", "2"], ["--mesher", "tet"], ["--tie", "glue"])],
        "weights": [[*extra] for extra in (
            ["--diameter-mm", "1"], ["--diameter-mm", "-180"], ["--diameter-mm", "0"],
            ["--diameter-mm", "inf"], ["--diameter-mm", "100:300:0.001"], ["--diameter-mm", "1e6"],
            ["--diameter-mm", "abc"])]
                   + [WEIGHTS[1:] + extra for extra in (
                       ["--mass-kg", "-1"], ["--mass-kg", "1e6"], ["--pressure-mpa", "0"],
                       ["--pressure-mpa", "100"], ["--dp-mpa", "0"], ["--dp-mpa", "10"],
                       ["--mesh-size-mm", "0.01"], ["--mesh-size-mm", "1e3"], ["--mesh-size-mm", "inf"],
                       ["--depth-mm", "nan"], ["--fig8", "0:1:1e-5"], ["--fig8", "nan"],
                       ["--out", "a_file"], ["--plot", "w.txt"])]
                   + [["--diameter-mm", "120:300:60", "--check-mm", "500"]],
        "reservoir": [[*extra] for extra in (
            ["--n-radial", "0"], ["--n-radial", "100000"], ["--n-thick", "0"], ["--n-thick", "1000"],
            ["--volume-mm3", "-1"], ["--volume-mm3", "1e-300"], ["--volume-mm3", "5e5"], ["--volume-mm3", "0:1e9:1"], ["--volume-mm3", "nan"],
            ["--volume-mm3", "1e12"], ["--plot", "r.doc"], ["--out", "a_file"],
            ["--write-calibration", "."], ["--n-radial", "two"])],
        "study": [["run", s] for s in sorted(STUDIES) if s != STUDY]
                 + [["run", f] for f in ("missing.toml", ".", "/dev/zero", "binary.toml")]
                 + [["run", STUDY, *extra] for extra in (
                     ["--workers", "0"], ["--workers", "100000"], ["--max-cases", "0"],
                     ["--results", "a_file"], ["--results", "/proc/results"], ["--scheduler"])]
                 + [["status", "s_code.toml"], ["status", "missing.toml"], ["report", "/dev/zero"],
                    ["report", STUDY, "--results", "a_file"], ["walk", STUDY], []],
        "inspect": [["missing.vtu"], ["good.csv"], ["/dev/zero"], ["."], ["result.vtu", "--out", "x.txt"]],
        "verify": [["--case", "bogus"], ["--case"]],
        "reproduce": [["--only", "bogus"], ["--only", ","], ["--out", "a_file"]],
        "design": [["--task", t, "--no-fem"] for t in sorted(TASKS) if t != "t_good.toml"]
                  + [["--task", t, "--no-fem"] for t in ("missing.toml", ".", "/dev/zero", "binary.toml")]
                  + [["--task", "t_good.toml", "--no-fem", *extra] for extra in (
                      ["--seed", "-1"], ["--mesh-size-mm", "0"], ["--mesh-size-mm", "nan"])],
    }
    for verb, variants in options.items():
        for k, extra in enumerate(variants):
            cases.append((f"{verb}-{k}-{' '.join(extra)[:40]}", [verb, *extra]))
    cases += [("verb-unknown", ["bnd"]), ("verb-huge", ["x" * 100_000])]
    nested = [["curve", "--theta-deg", "10", "--design", f] for f in ("deep.toml", "dotted.toml")]
    nested += [["design", "--task", "deep.toml", "--no-fem"], ["study", "run", "dotted.toml"],
               ["calibrate", "finger", "--space", "deep.toml", "--out", "t.csv"], ["study", "run", "deep.toml"]]
    paths = [["curve", "--theta-deg", "10", "--plot", f"{LONG}.png"],
             ["curve", "--theta-deg", "10", "--plot", f"{DEEP_PATH}/p.png"],
             ["curve", "--theta-deg", "10", "--plot", f"adir/{LONG}/p.png"],
             ["control", "--theta-ref-deg", "50", "--mass-kg", "1", "--out", LONG],
             ["reproduce", "--quick", "--out", LONG], ["study", "run", STUDY, "--results", LONG],
             ["material", "fit", "--data", "good_material.csv", "--model", "yeoh", "--out", f"{LONG}.toml"],
             ["inspect", "good.vtu", "--out", f"{LONG}.png"], ["inspect", "good.vtu", "--animate", f"{LONG}.gif"],
             ["reservoir", "--write-calibration", f"{LONG}.csv"], ["curve", "--theta-deg", "10", "--design", LONG]]
    flags = [["inspect", "good.vtu", "--out", "o.PNG"], ["inspect", "good.vtu", "--fields", "--out", "o.png"],
             ["inspect", "good.vtu", "--fields", "--animate", "o.gif"],
             ["inspect", "good.vtu", "--animate", "o.gif", "--out", "o.png"],
             ["inspect", "good.vtu", "--animate", "o.GIF"]]
    flags += [["curve", "--theta-deg", v] for v in ("1,,2", "1,", "1_0", "\u0661\u0660", "0x10")]
    flags += [["fit", "--data", "good.csv", *extra] for extra in (
        ["--params", "V0_mm3,"], ["--params", "V0_mm3", "--bounds", ""],
        ["--params", "V0_mm3", "--bounds", "V0_mm3=1e4:2e4,V0_mm3=1e4:3e4"],
        ["--params", "V0_mm3", "--diameter-mm", "180"], ["--params", "V0_mm3", "--normalise"],
        ["--params", "V0_mm3", "--bounds", "V0_mm3=1:2"])]  # no V0 there holds the fingers' oil
    grasp = ["grasp", "--pressure-mpa", "0.8", "--theta-deg", "40", "--mass-kg", "1"]
    flags += [[*verb, "--design", f] for f in ("x_hinge_nan.toml", "x_gent_locked.toml", "x_gent_sheet.toml")
              for verb in (["curve", "--theta-deg", "10,45"], [*grasp, "--weights", "paper180"],
                           ["fit", "--data", "good.csv", "--params", "V0_mm3"])]
    flags += [["curve", "--theta-deg", "10", "--design", f] for f in (
        "x_v0_balloon.toml", "x_tiny_sheet.toml", "x_mr_unstable.toml", "x_yeoh_unstable.toml", "x_ogden_alpha.toml",
        "x_table_unused.toml", "x_steel.toml")]
    control = ["control", "--theta-ref-deg", "50", "--mass-kg", "1"]
    flags += [[*control, "--kp", "0", "--ki", "0"], [*control, "--push-rise-s", "600"],
              [*control, "--push-at-s", "9.99"], ["fit", "--data", "good.csv", "--params", "V0_mm3", "--no-reservoir"]]
    flags += [["control", "--theta-ref-deg", "50", "--mass-kg", "1", "--design", "x_three_hinges.toml"],
              [*grasp, "--weights", "paper180", "--design", "x_three_hinges.toml"],
              [*grasp, "--weights", "1e308,1e308,0,0,0"], [*grasp, "--weights", "1e308,1e308,0,0,0", "--normalise"]]
    flags += [["design", "--task", "t_good.toml", *extra] for extra in (
        ["--plot", "p.png"], ["--no-fem", "--mesh-size-mm", "4"], ["--no-fem", "--no-correct"])]
    flags += [["bend", "--peak-mpa", "0.3"], ["bend", "--tie", "full", "--tie-width-mm", "10"],
              # ~1.5e9 unknowns: more than any machine's memory, refused before gmsh runs
              ["bend", "--mesh-size-mm", "0.5", "--refine", "3"],
              ["weights", "--diameter-mm", "120:300:60", "--fig8", "0.5"],
              ["weights", "--diameter-mm", "180,180"], ["weights", "--diameter-mm", "180", "--fig8", "0.5,0.5"],
              ["weights", "--diameter-mm", "120:300:60", "--check-mm", "180"]]
    flags += [["fit", "--data", "good.csv", "--params", "mu_sf_MPa", "--shore-a", "99.9"]]
    flags += [["calibrate", "finger", "--space", f, "--out", "t.csv"] for f in (
        "sp_pair_huge.toml", "sp_design_pmax.toml", "sp_design_pstep.toml", "sp_past_pmax.toml")]
    flags += [["verify", "--case", "uniaxial", "--case", "uniaxial"], ["reproduce", "--only", "fig7_reduced, ,table2_reduced"],
              ["reproduce", "--only", "fig7_reduced,fig7_reduced"]]
    flags += [["calibrate", "finger", "--space", "", "--out", "t.csv"], ["fit", "--data", "", "--params", "V0_mm3"],
              ["design", "--task", " ", "--no-fem"], ["inspect", ""]]
    flags += [["calibrate", "finger", "--check", "good_space.toml", "--finished"],
              ["calibrate", "finger", "--check", "good_space.toml", "--out", "t.csv"],
              ["calibrate", "finger", "--space", "good_space.toml", "--finished", "--out", "t.csv"]]
    flags += [["inspect", f, *extra] for f in sorted(FILES) if f.startswith("v_")
              for extra in ([], ["--fields"])]
    cases += [(f"file-{k}-{' '.join(argv)[:40]}", argv) for k, argv in enumerate(nested + paths + flags)]
    return cases + replay_cases()  # calibrate, design, material, inspect, ranges, ...


CASES = _cases()


@pytest.fixture
def scratch(tmp_path, monkeypatch):
    for name, text in {**FILES, **_design_files(), **STUDIES, **EXTRA_FILES}.items():
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(text if isinstance(text, bytes) else text.encode())
    (tmp_path / "adir").mkdir()
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SOFTHAND_CACHE", str(tmp_path / "cache"))
    return tmp_path


def _snapshot(root: Path) -> dict:
    return {p: p.stat().st_mtime_ns for p in root.rglob("*")}


def _run(argv) -> int:
    try:
        return main(argv)
    except SystemExit as exc:  # argparse's usage errors
        return exc.code


def test_there_are_enough_cases():
    assert len(CASES) >= 150
    assert {argv[0] for _, argv in CASES} >= {"curve", "grasp", "control", "fit", "bend", "weights",
                                              "reservoir", "study", "inspect", "verify", "reproduce",
                                              "calibrate", "design", "material"}


@pytest.mark.parametrize("argv", [argv for _, argv in CASES], ids=[name for name, _ in CASES])
def test_bad_input_is_one_line_exit_2_and_nothing_written(argv, scratch, capsys):
    before = _snapshot(scratch)
    code = _run(argv)
    out, err = capsys.readouterr()
    assert code == 2, err
    assert err.count("\n") == 1 and err.endswith("\n"), err
    assert err.startswith("softhand") and "error:" in err and "Traceback" not in err
    assert len(err) < 1500  # bounded, whatever the size of the value
    assert out == ""
    assert _snapshot(scratch) == before  # nothing written, not even the cache or an output folder


@pytest.mark.parametrize("argv, named", [
    (["curve", "--theta-deg", "30", "--compare", "missing.toml"], "--compare = 'missing.toml'"),
    (["curve", "--theta-deg", "30", "--design", "d_material_stiff.toml"], "finger.material"),
    (["material", "fit", "--data", "m_kpa.csv", "--model", "neo-hookean"], "are the stresses in MPa?"),
    (["hold", "--object", "sphere:150", "--pressure-mpa", "1", "--margin", "0"], "--margin = 0.0"),
    (["hold", "--object", "sphere:150", "--map", "pressure=0:3000:1", "mass=1"], "at most 2500 allowed\n"),
])
def test_a_refusal_names_what_the_user_gave(argv, named, scratch, capsys):
    """The option or table the user wrote, its value, no hint of an option the verb lacks."""
    assert _run(argv) == 2
    assert named in capsys.readouterr().err


def test_every_number_of_a_design_has_bounds():
    """A new numeric design key needs a line in reduced.vocabulary.design.BOUNDS."""
    numeric = [k for k, v in HandDesign().to_dict().items()
               if isinstance(v, (int, float)) and not isinstance(v, bool)]
    assert set(numeric) <= set(BOUNDS)
    for key, (lo, hi) in BOUNDS.items():
        assert math.isfinite(lo) and math.isfinite(hi) and lo < hi, key


@pytest.mark.parametrize("text", [
    "a_mm" + ".x" * 400_000 + " = 1\n",                 # a dotted key: parsing it took an hour
    "[a" + ".x" * 400_000 + "]\n",                       # a table header
    "[[a" + ".x" * 400_000 + "]]\n",                     # an array of tables
    "x = {y = 1, a" + ".x" * 400_000 + " = 1}\n",        # a key of an inline table
    "a" + '."x"' * 200_000 + " = 1\n",                   # quoted parts
])
def test_a_deeply_dotted_key_is_refused_before_the_parser_reads_it(text, tmp_path, monkeypatch):
    """tomllib takes time quadratic in a dotted key's parts (20 000 parts: 1-8 s, 400 000 in a
    1 MB file: about an hour); such a key is refused by a scan of the text, without parsing."""
    from softhand.reduced.vocabulary import inputfiles
    from softhand.reduced.vocabulary.errors import InputError

    path = tmp_path / "d.toml"
    path.write_text(text)
    monkeypatch.setattr(inputfiles.tomllib, "loads", lambda s: pytest.fail("parsed"))
    with pytest.raises(InputError, match="more than 16 deep"):
        inputfiles.read_toml(path, "--design", "a design TOML file")


def test_dotted_keys_within_the_nesting_limit_are_read(tmp_path):
    """Sixteen parts (the limit) in a key and a header's inner key; dots after commas inside
    strings and comments are not keys."""
    from softhand.reduced.vocabulary import inputfiles

    key = ".".join(f"k{i}" for i in range(16))
    path = tmp_path / "d.toml"
    dots = ",b.c.d.e.f.g.h.i.j.k.l.m.n.o.p.q.r.s.t"
    path.write_text(f'{key} = 1\ndescription = "a{dots}"\nnote = \'\'\'\n{dots}\'\'\'  # {dots}\n'
                    f'["q.{key}"]\nz = {{ {".".join(f"p{i}" for i in range(13))} = 2 }}\n')
    table = inputfiles.read_toml(path, "--design", "a design TOML file")
    assert inputfiles.nesting_depth(table) == 16  # the top level holds k0 .. k15 = 1: 16 tables
    assert table[f"q.{key}"]["z"]["p0"]["p1"]["p2"]["p3"]["p4"]["p5"]["p6"]["p7"]["p8"]["p9"]["p10"]["p11"]["p12"] == 2


@pytest.mark.parametrize("argv", [["curve", "--theta-deg", "10", "--design", "pipe"],
                                  ["material", "fit", "--data", "pipe", "--model", "yeoh"]])
def test_a_named_pipe_is_refused_not_waited_on(argv, tmp_path):
    """Opening a FIFO waits for a writer: it is refused before it is opened. In a subprocess,
    so that a regression fails on the timeout instead of hanging the suite."""
    import os
    import subprocess
    import sys

    os.mkfifo(tmp_path / "pipe")
    proc = subprocess.run([sys.executable, "-m", "softhand.studies.cli", *argv], cwd=tmp_path,
                          capture_output=True, text=True, timeout=60,
                          env={**os.environ, "SOFTHAND_CACHE": str(tmp_path / "cache")})
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1, proc.stderr
    assert "pipe = 'pipe': is not a regular file" in proc.stderr or "= 'pipe': is not a regular file" in proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pipe"]


@pytest.mark.parametrize("argv", [["control", "--theta-ref-deg", "50", "--mass-kg", "1", "--out", "link"],
                                  ["bend", "--out", "link"], ["reservoir", "--out", "link"]])
def test_a_broken_link_as_an_output_folder_is_refused_before_the_work(argv, tmp_path, monkeypatch, capsys):
    (tmp_path / "link").symlink_to(tmp_path / "nowhere" / "x")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SOFTHAND_CACHE", str(tmp_path / "cache"))
    assert _run(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "'link': is a broken symbolic link" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link"]


def test_a_current_folder_that_was_removed_is_one_line(tmp_path, monkeypatch, capsys):
    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    assert _run(["curve", "--theta-deg", "10", "--plot", "p.png"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err == "softhand curve: error: the current folder no longer exists; change to one that does\n"


def test_designs_default_output_folder_is_checked_before_the_optimiser(tmp_path, monkeypatch, capsys):
    """Without --out the design goes to results/design/TASK: a file named results is refused
    before the search, as a given --out is."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SOFTHAND_CACHE", str(tmp_path / "cache"))
    (tmp_path / "results").write_text("a file")
    (tmp_path / "task.toml").write_text(EXTRA_FILES["good_task.toml"])
    import softhand.studies.design.optimise as design_opt

    monkeypatch.setattr(design_opt, "optimise", lambda *a, **k: pytest.fail("the optimiser ran"))
    assert _run(["design", "--task", "task.toml", "--no-fem"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "--out = 'results/design/task': cannot be created" in err
