"""Bad inputs of the verbs and file types beyond tests/studies/test_bad_inputs.py's table.

Shared by tests/studies/test_bad_inputs.py (in-process) and benchmarks/bad_input_replay.py (one
``softhand`` process per case). Each case: (name, argv); its input files are EXTRA_FILES.
"""
from __future__ import annotations

#: uniaxial test of a ~0.4 MPa rubber: enough points for every model (ogden3: 6 parameters)
GOOD_MATERIAL = ("mode,stretch,stress_MPa\nuniaxial,1.2,0.203\nuniaxial,1.5,0.421\nuniaxial,1.8,0.598\n"
                 "uniaxial,2.1,0.748\nuniaxial,2.4,0.893\nuniaxial,2.7,1.024\nuniaxial,3,1.157\n")
SPACE = ('name = "sp"\nlhs = 0\n[space]\na_mm = [3.0, 6.0]\nb_mm = [3.0, 7.0]\nd_mm = [10.0, 20.0]\n'
         'l0_mm = [120.0, 200.0]\ntie_width_mm = [5.0, 15.0]\n[[design]]\na_mm = 4.0\nb_mm = 5.0\n'
         'd_mm = 15.0\nl0_mm = 180.0\ntie_width_mm = 10.0\n')
TASK = ("[object]\ndiameter_mm = 180.0\nmass_kg = 2.0\n[pump]\nmax_pressure_MPa = 2.0\n"
        "[free]\na_mm = [3.5, 4.5]\n")


def _space(extra: str = "", body: str = SPACE) -> str:
    return extra + body


def _task(extra: str = "", body: str = TASK) -> str:
    return body.replace("[object]", extra + "[object]", 1) if extra and not extra.startswith("[") \
        else body + extra


EXTRA_FILES = {
    "good_material.csv": GOOD_MATERIAL,
    "m_header.csv": "mode,stretch\nuniaxial,1.5\n",
    "m_mode.csv": "mode,stretch,stress_MPa\nshear,1.5,0.5\n",
    "m_nan.csv": "mode,stretch,stress_MPa\nuniaxial,nan,0.5\nuniaxial,2,0.9\n",
    "m_inf.csv": "mode,stretch,stress_MPa\nuniaxial,1.5,inf\nuniaxial,2,0.9\n",
    "m_negative.csv": "mode,stretch,stress_MPa\nuniaxial,-1.5,0.5\nuniaxial,2,0.9\n",
    "m_huge.csv": "mode,stretch,stress_MPa\nuniaxial,1e300,0.5\nuniaxial,2,0.9\n",
    "m_text.csv": "mode,stretch,stress_MPa\nuniaxial,1.5,lots\n",
    "m_empty.csv": "",
    "m_header_only.csv": "mode,stretch,stress_MPa\n",
    "m_one_row.csv": "mode,stretch,stress_MPa\nuniaxial,1.5,0.5\n",
    "m_short.csv": "mode,stretch,stress_MPa\nuniaxial,1.5\n",
    "m_binary.csv": b"\x00\xff\xfe\x89PNG\r\n",
    "m_stretch_huge.csv": GOOD_MATERIAL.replace("uniaxial,1.2,", "uniaxial,1e250,"),
    "m_stretch_tiny.csv": GOOD_MATERIAL.replace("uniaxial,1.2,", "uniaxial,1e-250,"),
    "m_stretch_1e-5.csv": GOOD_MATERIAL.replace("uniaxial,1.2,", "uniaxial,1e-5,"),
    "m_stress_huge.csv": GOOD_MATERIAL.replace(",0.203", ",1e30"),
    "m_stress_tiny.csv": "mode,stretch,stress_MPa\n" + "".join(f"uniaxial,{l},1e-300\n" for l in range(2, 9)),
    "m_stress_zero.csv": "mode,stretch,stress_MPa\n" + "".join(f"uniaxial,{l},0\n" for l in range(2, 9)),
    "m_all_one.csv": "mode,stretch,stress_MPa\n" + "".join(f"uniaxial,1,0.{s}\n" for s in range(1, 8)),
    "m_all_same.csv": "mode,stretch,stress_MPa\n" + "".join(f"uniaxial,2,0.{s}\n" for s in range(1, 8)),
    "m_tension_negative.csv": "mode,stretch,stress_MPa\n" + "".join(f"uniaxial,{l},-0.{l}\n" for l in range(2, 9)),
    "m_tension_one_negative.csv": GOOD_MATERIAL.replace(",0.748", ",-0.748"),
    "m_compression_positive.csv": GOOD_MATERIAL.replace("uniaxial,1.2,0.203", "uniaxial,0.5,0.3"),
    "m_stretch_one_stress.csv": GOOD_MATERIAL.replace("uniaxial,1.2,0.203", "uniaxial,1,0.5"),
    "good_space.toml": SPACE,
    "sp_unknown.toml": _space("colour = 1\n"),
    "sp_lhs_text.toml": SPACE.replace("lhs = 0", 'lhs = "six"'),
    "sp_lhs_huge.toml": SPACE.replace("lhs = 0", "lhs = 1000000000"),
    "sp_lhs_neg.toml": SPACE.replace("lhs = 0", "lhs = -1"),
    "sp_seed_text.toml": _space('seed = "x"\n'),
    "sp_seed_float.toml": _space("seed = 1.5\n"),
    "sp_press_nan.toml": _space("pressures_mpa = [0.2, nan]\n"),
    "sp_press_huge.toml": _space("pressures_mpa = [0.2, 1e9]\n"),
    "sp_press_many.toml": _space("pressures_mpa = [" + ", ".join(f"{0.001 * (i + 1):.3f}"
                                                               for i in range(5000)) + "]\n"),
    "sp_press_text.toml": _space('pressures_mpa = "0.2,0.5"\n'),
    "sp_theta_huge.toml": _space("theta_target_deg = 1e9\n"),
    "sp_theta_inf.toml": _space("theta_target_deg = inf\n"),
    "sp_pmax_huge.toml": _space("p_max_mpa = 1e9\n"),
    "sp_pstep_tiny.toml": _space("p_step_mpa = 1e-12\n"),
    "sp_mesh_tiny.toml": _space("mesh_size_mm = 1e-9\n"),
    "sp_axial_tiny.toml": _space("axial_size_mm = 1e-9\n"),
    "sp_mesh_text.toml": _space('mesh_size_mm = "fine"\n'),
    "sp_prior.toml": _space('prior = "none"\n'),
    "sp_no_space.toml": 'name = "sp"\nlhs = 2\n',
    "sp_box_inverted.toml": SPACE.replace("a_mm = [3.0, 6.0]", "a_mm = [6.0, 3.0]"),
    "sp_box_nan.toml": SPACE.replace("a_mm = [3.0, 6.0]", "a_mm = [nan, 6.0]"),
    "sp_point_out.toml": SPACE.replace("a_mm = 4.0", "a_mm = 40.0"),
    "sp_point_text.toml": SPACE.replace("a_mm = 4.0", 'a_mm = "four"'),
    "sp_design_number.toml": 'name = "sp"\ndesign = 3\n' + SPACE.split("\n", 2)[2].split("[[design]]")[0],
    "sp_base_missing.toml": _space('base_design = "nope.toml"\n'),
    "sp_base_zero.toml": _space('base_design = "/dev/zero"\n'),
    "sp_name.toml": SPACE.replace('name = "sp"', 'name = "../../x"'),
    "sp_name_number.toml": SPACE.replace('name = "sp"', "name = 3"),
    "good_task.toml": TASK,
    "t_unknown.toml": _task("colour = 1\n"),
    "t_unknown_section.toml": _task("[colour]\nx = 1\n"),
    "t_diameter_nan.toml": TASK.replace("diameter_mm = 180.0", "diameter_mm = nan"),
    "t_diameter_neg.toml": TASK.replace("diameter_mm = 180.0", "diameter_mm = -180.0"),
    "t_diameter_text.toml": TASK.replace("diameter_mm = 180.0", 'diameter_mm = "big"'),
    "t_diameter_huge.toml": TASK.replace("diameter_mm = 180.0", "diameter_mm = 1e300"),
    "t_mass_inf.toml": TASK.replace("mass_kg = 2.0", "mass_kg = inf"),
    "t_mass_neg.toml": TASK.replace("mass_kg = 2.0", "mass_kg = -2.0"),
    "t_pump_zero.toml": TASK.replace("max_pressure_MPa = 2.0", "max_pressure_MPa = 0.0"),
    "t_pump_huge.toml": TASK.replace("max_pressure_MPa = 2.0", "max_pressure_MPa = 1e9"),
    "t_no_object.toml": "[pump]\nmax_pressure_MPa = 2.0\n[free]\na_mm = [3.5, 4.5]\n",
    "t_no_free.toml": "[object]\ndiameter_mm = 180.0\nmass_kg = 2.0\n[pump]\nmax_pressure_MPa = 2.0\n",
    "t_free_unknown.toml": TASK.replace("a_mm = [3.5, 4.5]", "colour_mm = [1, 2]"),
    "t_free_inverted.toml": TASK.replace("a_mm = [3.5, 4.5]", "a_mm = [4.5, 3.5]"),
    "t_free_nan.toml": TASK.replace("a_mm = [3.5, 4.5]", "a_mm = [nan, 4.5]"),
    "t_free_text.toml": TASK.replace("a_mm = [3.5, 4.5]", 'a_mm = "3.5:4.5"'),
    "t_free_huge.toml": TASK.replace("a_mm = [3.5, 4.5]", "a_mm = [3.5, 1e300]"),
    "t_free_three.toml": TASK.replace("a_mm = [3.5, 4.5]", "a_mm = [3.5, 4.0, 4.5]"),
    "t_objective.toml": _task("[grasp]\nobjective = \"speed\"\n"),
    "t_factor_neg.toml": _task("[grasp]\nforce_factor = -2.0\n"),
    "t_both_force.toml": _task("[grasp]\nforce_factor = 2.0\nmargin_N = 1.0\n"),
    "t_stretch.toml": _task("[limits]\nrubber_stretch = 0.5\n"),
    "t_wall_text.toml": _task("[limits]\nmin_wall_mm = \"one\"\n"),
    "t_material.toml": _task("[material]\nmu_sf_MPa = -1.0\n"),
    "t_design_key.toml": _task("[design]\ncolour = 1\n"),
    "t_design_bad.toml": _task("[design]\nb_mm = 30.0\n"),
    "task_tiny_object.toml": TASK.replace("diameter_mm = 180.0", "diameter_mm = 1e-300"),
    "t_free_breaks_rules.toml": TASK.replace("a_mm = [3.5, 4.5]", "t_mm = [40.0, 50.0]"),
    "t_material_twice.toml": _task("[material]\nmu_sf_MPa = 2.0\n[design]\nmu_sf_MPa = 1.0\n"),
    "t_table_unused.toml": _task('[design]\nfinger_model = "paper"\nfinger_table = "nope.csv"\n'),
    "t_hinge_table_free.toml": _task('[design]\nhinge_table = "hinges_small.csv"\n'),
    "d_hinge_missing.toml": 'finger_model = "fem"\nhinge_table = "nope.csv"\n',
    "d_hinge_not_hinges.toml": 'finger_model = "fem"\nhinge_table = "ft_long_term.csv"\n',
    "d_hinge_three.toml": 'finger_model = "fem"\nhinge_table = "hinges_small.csv"\nn_s = 3\n'
                          'hinge_s_mm = [40.0, 80.0, 120.0]\n',
    # a blocked-hinge table of five hinges at two bends (a design's own, as the hinges study writes it)
    "hinges_small.csv": "theta,P,a_1,a_2,a_3,a_4,a_5\n" + "".join(
        f"{t},{p},1.8,1.8,1.8,1.7,1.3\n" for t in (0, 0.1) for p in (0.05, 0.15)),
    "t_fem_mesh.toml": _task("[fem]\nmesh_size_mm = 1e-9\n"),
    "t_fem_ratio.toml": _task("[fem]\nedge_ratio = 50.0\n"),
    "t_fem_dp.toml": _task("[fem]\ndP_MPa = 0.0\n"),
    "t_base_missing.toml": _task('base_design = "nope.toml"\n'),
    "t_base_zero.toml": _task('base_design = "/dev/zero"\n'),
    "t_base_number.toml": _task("base_design = 3\n"),
    "t_object_number.toml": "object = 3\n[pump]\nmax_pressure_MPa = 2.0\n[free]\na_mm = [3.5, 4.5]\n",
    "good.vtu": ('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="0.1">'
                 '<UnstructuredGrid><Piece NumberOfPoints="4" NumberOfCells="1"><PointData>'
                 '<DataArray type="Float64" Name="displacement_mm" NumberOfComponents="3" '
                 'format="ascii">0 0 0 0 0 0 0 0 0 0 0 1</DataArray></PointData><Points>'
                 '<DataArray type="Float64" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 '
                 '0 1 0 0 0 1</DataArray></Points><Cells><DataArray type="Int64" Name="connectivity" '
                 'format="ascii">0 1 2 3</DataArray><DataArray type="Int64" Name="offsets" '
                 'format="ascii">4</DataArray><DataArray type="UInt8" Name="types" '
                 'format="ascii">10</DataArray></Cells></Piece></UnstructuredGrid></VTKFile>\n'),
    "bad.vtu": b"\x00\x01garbage",
    "bad.pvd": "<VTKFile type='Collection'><Collection><DataSet file='nope.vtu'/></Collection></VTKFile>",
    "trunc.vtm": "<VTKFile type='vtkMultiBlockDataSet'",
    "x.obj": "v 0 0 0\n",
    "self.pvd": "<VTKFile type='Collection'><Collection><DataSet file='self.pvd'/></Collection></VTKFile>",
    "empty_series.pvd": "<VTKFile type='Collection'><Collection></Collection></VTKFile>",
    # numbers float() reads but no data file means: '1_5' is 15, other scripts' digits
    "m_underscore.csv": GOOD_MATERIAL.replace("uniaxial,1.5,", "uniaxial,1_5,"),
    "m_fullwidth.csv": GOOD_MATERIAL.replace("uniaxial,1.5,", "uniaxial,\uff11.\uff15,"),
    "fit_underscore.csv": "P_MPa,theta_deg\n0.2,10\n0.4,2_5\n0.6,40\n0.8,55\n",
    "fit_arabic.csv": "P_MPa,theta_deg\n0.2,10\n0.4,25\n0.6,\u0664\u0660\n0.8,55\n",
    "push_underscore.csv": "t_s,force_N\n0,0\n5,1_0\n",
    # output folders holding an entry of the wrong kind where a run writes (a '/keep' file
    # makes its parent a folder)
    "kind/root_file/good_study": "a file where the study's folder goes",
    "kind/index_dir/good_study/index.csv/keep": "",
    "kind/claims_file/good_study/.claims": "a file where the claims' folder goes",
    "kind/design_json/result.json/keep": "",
    "kind/knee_file/knee": "a file where the Pareto knee's folder goes",
    "kind/rep/fig7_reduced": "a file where a section's folder goes",
    "kind/rep2/report.md/keep": "",
    "kind/ctl/summary.json/keep": "",
    "mine/rep/fig7_reduced/notes.txt": "the user's notes in a folder named like a section",
    "mine/rep2/report.md": "the user's report, named like reproduce's",
    # designs a section of the report cannot run: the fingers' oil at 90 deg, the paper's w
    "rep_small_reservoir.toml": "V0_mm3 = 100.0\n",
    "rep_three_hinges.toml": "n_s = 3\nhinge_s_mm = [40.0, 80.0, 120.0]\n",
    # a finger table the design's model would not use (finger_model = "paper")
    "st_table_unused.toml": 'kind = "curve"\n[design]\nfinger_table = "nope.csv"\n[sweep]\ntheta_deg = [10]\n',
    # outputs that are an input file (same name, or another path to it)
    "fit_data.png": "P_MPa,theta_deg\n0.2,10\n0.4,25\n0.6,40\n0.8,55\n",
    "same_design.toml": "V0_mm3 = 17800.0\n",
    "mat_data.toml": GOOD_MATERIAL,
    "st_curve_pressure.toml": 'kind = "curve"\n[sweep]\npressure_mpa = [3.7, -3.7]\n',  # -3.7: with, not without
    "st_table_swept.toml": 'kind = "curve"\n[sweep]\ntheta_deg = [10]\nfinger_table = ["nope.csv"]\n',
}


def _table(fit_line: str) -> str:
    """The package's finger table with its '# fit:' line replaced."""
    from softhand.reduced.calibrated.finger_fem_table import TABLE_FILE

    return "\n".join(fit_line if line.startswith("# fit:") else line
                     for line in TABLE_FILE.read_text().splitlines()) + "\n"


_NUL = '"a\\u0000b"'  # a TOML string with a NUL character: no file system has such a name
_BIG_CELL = "1" * 200_000  # beyond the csv module's field size limit (131 072)
_VTU = EXTRA_FILES["good.vtu"]
EXTRA_FILES.update({
    # NUL characters in the file names that files give
    "d_nul_table.toml": f'finger_model = "fem"\nfinger_table = {_NUL}\n',
    "st_nul_design.toml": f'kind = "curve"\ndesign = {_NUL}\n[sweep]\ntheta_deg = [10]\n',
    "st_nul_file.toml": f'kind = "curve"\n[design]\nfile = {_NUL}\n[sweep]\ntheta_deg = [10]\n',
    "st_nul_table.toml": f'kind = "curve"\n[design]\nfinger_model = "fem"\nfinger_table = {_NUL}\n'
                         '[sweep]\ntheta_deg = [10]\n',
    "sp_nul_base.toml": f"base_design = {_NUL}\n" + SPACE,
    "t_nul_table.toml": TASK + f"[design]\nfinger_table = {_NUL}\n",
    "t_missing_table.toml": TASK + '[design]\nfinger_table = "nope.csv"\n',
    # cells beyond the csv module's limit
    "fit_big_cell.csv": "P_MPa,theta_deg\n0.2," + _BIG_CELL + "\n",
    "m_big_cell.csv": "mode,stretch,stress_MPa\nuniaxial,1.5," + _BIG_CELL + "\n",
    "push_big_cell.csv": "t_s,force_N\n0,0\n5," + _BIG_CELL + "\n",
    # finger tables whose fit line asks for what no fit can be
    "ft_degree_huge.csv": _table("# fit: prior=rings, design_degree=1, theta_degree=100000000"),
    "ft_design_degree_huge.csv": _table("# fit: prior=rings, design_degree=200, theta_degree=1"),
    "ft_long_term.csv": _table("# fit: prior=rings, p_terms=" + "*".join(["th"] * 20_000) + ", q_terms=lb"),
    "ft_many_terms.csv": _table("# fit: prior=rings, p_terms=" + " ".join(["lb*th"] * 101) + ", q_terms=lb"),
    "ft_product_feature.csv": _table("# fit: prior=rings, kernel=cubic, features=lb*ld lb ld lL lt s2"),
    "d_ft_degree_huge.toml": 'finger_model = "fem"\nfinger_table = "ft_degree_huge.csv"\n',
    "d_ft_design_degree_huge.toml": 'finger_model = "fem"\nfinger_table = "ft_design_degree_huge.csv"\n',
    "d_ft_long_term.toml": 'finger_model = "fem"\nfinger_table = "ft_long_term.csv"\n',
    "d_ft_many_terms.toml": 'finger_model = "fem"\nfinger_table = "ft_many_terms.csv"\n',
    "d_ft_product_feature.toml": 'finger_model = "fem"\nfinger_table = "ft_product_feature.csv"\n',
    # material tables: one parameter in two spellings; a bad modulus the table overrides
    "d_mat_twice.toml": '[finger.material]\nmodel = "yeoh"\nC10_MPa = 0.5\nc10_mpa = 0.05\n',
    "d_mat_ogden_twice.toml": '[finger.material]\nmodel = "ogden"\nmu1_MPa = 0.5\nMU1_MPA = 0.5\nalpha1 = 2.0\n',
    "d_mu_nan_overridden.toml": 'mu_sf_MPa = nan\n[finger.material]\nmodel = "neo-hookean"\nmu_MPa = 0.5\n',
    "d_mu_negative_overridden.toml": 'mu_sf_MPa = -1.0\n[finger.material]\nmodel = "neo-hookean"\nmu_MPa = 0.5\n',
    "d_mu_sr_inf_overridden.toml": 'mu_sr_MPa = inf\n[reservoir.material]\nmodel = "neo-hookean"\nmu_MPa = 0.5\n',
    # VTK files declaring sizes VTK would try to allocate
    "v_huge.vtu": _VTU.replace('NumberOfPoints="4"', 'NumberOfPoints="1000000000000"'),
    "v_huge_single_quotes.pvd": "<VTKFile type='Collection'><Collection><DataSet timestep='0' "
                                "file='v_huge.vtu'/></Collection></VTKFile>",
    "v_huge_single_quotes.vtm": "<VTKFile type='vtkMultiBlockDataSet'><vtkMultiBlockDataSet><DataSet "
                                "index='0' file='v_huge.vtu'/></vtkMultiBlockDataSet></VTKFile>",
    "v_huge_after_comment.vtu": _VTU.replace("<UnstructuredGrid>", "<!--" + "x" * 1_100_000 + "-->"
                                             "<UnstructuredGrid>", 1).replace('NumberOfPoints="4"',
                                                                              'NumberOfPoints="1000000000000"'),
    "v_legacy_dimensions.vtk": "# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_POINTS\n"
                               "DIMENSIONS 100000 100000 100000\nORIGIN 0 0 0\nSPACING 1 1 1\n",
    "v_legacy_points.vtk": "# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                           "POINTS 1000000000000 float\n0 0 0\n",
    "ft_id_huge.csv": _table("# fit: prior=rings, kernel=cubic, features=lb ld lL lt s2").replace(
        "\n0,", "\n1e300,", 1),
    "st_grasp_bad_table.toml": 'kind = "grasp"\n[design]\nfinger_model = "fem"\nfinger_table = "ft_product_feature.csv"\n'
                               '[params]\npressure_mpa = 0.8\n[sweep]\ntheta_deg = [10, 20]\n',
    "d_ft_id_huge.toml": 'finger_model = "fem"\nfinger_table = "ft_id_huge.csv"\n',
    "v_legacy_no_fields.vtk": "# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 float\n"
                              "0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n",
    "v_many_steps.pvd": "<VTKFile type='Collection'><Collection>" + "".join(
        f"<DataSet timestep='{k}' file='good.vtu'/>" for k in range(1001)) + "</Collection></VTKFile>",
    # study cases the kinds' checks refuse when the study is read, not as failed or endless cases
    "st_control_three_hinges.toml": 'kind = "control"\n[sweep]\nn_s = [3]\n',
    "st_grasp_three_hinges.toml": 'kind = "grasp"\n[params]\npressure_mpa = 0.8\ntheta_deg = 30\n[sweep]\nn_s = [3]\n',
    "st_bend_past_pmax.toml": 'kind = "finger_bend"\n[params]\npressures_mpa = [0.2, 3.0]\ntheta_target_deg = 60\n'
                              'p_max_mpa = 1\np_step_mpa = 0.5\n[sweep]\nmu_sf_MPa = [1.15]\n',
    "st_bend_tiny_pressure.toml": 'kind = "finger_bend"\n[params]\npressures_mpa = [1e-300]\ntheta_target_deg = 60\n'
                                  'p_max_mpa = 1\np_step_mpa = 0.5\n[sweep]\nmu_sf_MPa = [1.15]\n',
    "st_reservoir_fine.toml": 'kind = "reservoir"\nmesh_size_mm = 0.05\n[sweep]\nR_mm = [500.0]\nt_mm = [1.0]\n',
    "sp_press_tiny.toml": "pressures_mpa = [1e-300]\n" + SPACE,
})



def _few_designs_table() -> str:
    """The package's finger table cut to its first 4 designs, still declaring the whole box
    (as a table of a few designs of a wide space did), fitted in terms 4 designs can carry."""
    from softhand.reduced.calibrated.finger_fem_table import TABLE_FILE

    lines = TABLE_FILE.read_text().splitlines()
    keep = [line for line in lines if line.startswith(("#", "design")) or line.split(",")[0] in "0123"]
    return "\n".join("# fit: prior=rings, p_terms=lb th, q_terms=lb" if line.startswith("# fit:") else line
                     for line in keep) + "\n"


#: outputs and inputs the outputs rule protects (docs/outputs.md): a folder of the user's
#: where a run writes one, an input or a user's file where calibrate writes its design
EXTRA_FILES.update({
    "own/grasp/thesis.tex": "the user's", "own/knee/thesis.tex": "the user's",
    "own/finger/thesis.tex": "the user's", "own/sheet/thesis.tex": "the user's",
    "own/result.json": "the user's, not a run's",
    "cal.toml": "# my finger\na_mm = 4.0\n", "cal_dir_fem.toml/keep": "a folder where the design goes",
    "users_fem.toml": "my own file\n", "x_fem.toml": "a_mm = 4.0\n",
    "...toml": TASK,
    "fit_repeated.csv": "P_MPa,theta_deg\n" + "0.3,40\n" * 4,
    "fit_zeros.csv": "P_MPa,theta_deg\n" + "0,0\n" * 3,
    "few_designs.csv": _few_designs_table(),
    "d_few_designs.toml": 'finger_model = "fem"\nfinger_table = "few_designs.csv"\nb_mm = 3.0\n',
    "st_weights_folded.toml": 'kind = "weights"\nmesh_size_mm = 10.0\n[sweep]\ndiameter_mm = [180.0, 200.0]\n',
    "tables/st_table_here.toml": 'kind = "curve"\n[design]\nfinger_model = "fem"\nfinger_table = "few_designs.csv"\n'
                                 'b_mm = 3.0\n[sweep]\ntheta_deg = [10]\n',
    "tables/few_designs.csv": _few_designs_table(),
})

GOOD_TASK, GOOD_SPACE = "good_task.toml", "good_space.toml"

#: an open triangle mesh (one facet): not a closed surface, so no object
OPEN_STL = ("solid t\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 10 0 0\n  vertex 0 10 0\n"
            " endloop\nendfacet\nendsolid t\n")
EXTRA_FILES.update({
    "obj_open.stl": OPEN_STL,
    "obj_open.toml": '[object]\nshape = "mesh"\nfile = "obj_open.stl"\nmass_kg = 0.5\n',
    "obj_missing_file.toml": '[object]\nshape = "mesh"\nfile = "no_such.stl"\nmass_kg = 0.5\n',
    "obj_negative_mu.toml": '[object]\nshape = "sphere"\ndiameter_mm = 150.0\nmass_kg = 0.5\nfriction = -0.2\n',
    "obj_unknown_key.toml": '[object]\nshape = "sphere"\ndiameter_mm = 150.0\ncolour = "red"\n',
    "obj_in_palm.toml": '[object]\nshape = "sphere"\ndiameter_mm = 150.0\noffset_mm = [0.0, -500.0, 0.0]\n',
    "obj_cone.toml": '[object]\nshape = "cone"\ndiameter_mm = 150.0\n',
    "obj_no_table.toml": 'shape = "sphere"\ndiameter_mm = 150.0\n',
    "obj_binary.toml": b"\x00\xff\xfe\x89PNG\r\n",
    "m_kpa.csv": "mode,stretch,stress_MPa\n" + "".join(  # kPa under a stress_MPa header
        f"uniaxial,{lam},{1000 * float(v):g}\n" for lam, v in (r.split(",")[1:] for r in GOOD_MATERIAL.split()[1:])),
    "d_material_stiff.toml": '[finger.material]\nmodel = "neo-hookean"\nmu_MPa = 400.0\n',
    "v_entities.vtu": '<?xml version="1.0"?><!DOCTYPE x [<!ENTITY a "aaaa"><!ENTITY b "&a;&a;&a;&a;">]>'
                      '<VTKFile type="UnstructuredGrid">&b;</VTKFile>\n',
    "obj_task_tables.toml": '[object]\nshape = "sphere"\ndiameter_mm = 150.0\nmass_kg = 0.5\n[hold]\nmargin = 2.0\n',
    "task_hold_in_palm.toml": TASK.replace("[object]\ndiameter_mm = 180.0\n",
                                           '[object]\nshape = "sphere"\ndiameter_mm = 150.0\n'
                                           'offset_mm = [0.0, -500.0, 0.0]\n'),
    "task_hold_force_factor.toml": TASK.replace("[object]\ndiameter_mm = 180.0\n",
                                                '[object]\nshape = "sphere"\ndiameter_mm = 150.0\n')
    + "[grasp]\nforce_factor = 2.0\n",
    "task_open_mesh.toml": TASK.replace("[object]\ndiameter_mm = 180.0\n",
                                        '[object]\nshape = "mesh"\nfile = "obj_open.stl"\n'),
})


def hold_cases() -> list[tuple[str, list[str]]]:
    """The whole-hand hold's inputs: objects (tables, short forms, mesh files), pulls, maps; each
    refused before any computation."""
    at = ["--pressure-mpa", "1.2", "--no-progress"]
    cases = [["hold", "--object", f, *at] for f in (
        "obj_open.toml", "obj_missing_file.toml", "obj_negative_mu.toml", "obj_unknown_key.toml",
        "obj_in_palm.toml", "obj_cone.toml", "obj_no_table.toml", "obj_binary.toml", "obj_open.stl",
        "obj_task_tables.toml",
        "missing.toml", "sphere:abc", "sphere:-150", "box:400x50x400", "cylinder:120")]
    cases += [["hold", "--object", "sphere:150", "--pull", "0,0,0", *at],
              ["hold", "--object", "sphere:150", "--pull", "sideways", *at],
              ["hold", "--object", "sphere:150", "--friction", "nan", *at],
              ["hold", "--object", "sphere:150", "--mass-kg", "-1", *at],
              ["hold", "--object", "sphere:150", "--max-pump-mpa", "1", *at],   # above the pump's limit
              ["hold", "--object", "cylinder:180x1e-300", *at],                 # thinner than a millimetre
              *(["hold", "--object", "sphere:150", "--design", d, *at] for d in (
                  "d_hinge_missing.toml", "d_hinge_not_hinges.toml", "d_hinge_three.toml")),
              ["design", "--task", "t_hinge_table_free.toml", "--no-fem", "--no-progress"],
              ["hold", "--object", "sphere:150", "--map", "pressure=0:2:0.001", "mass=0:5:0.001"],
              ["hold", "--object", "sphere:150", "--map", "pressure=0.5:1:0.5", "colour=1,2"],
              ["hold", "--object", "sphere:150", "--check"],
              ["hold", "--object", "sphere:150", "--pull-control", "displacement", *at],  # the FEM's option
              ["hold", "--object", "sphere:150", "--model", "fem", "--margin", "2", "--no-progress"],
              ["design", "--task", "task_open_mesh.toml", "--no-fem", "--no-progress"],
              ["design", "--task", "task_hold_force_factor.toml", "--no-fem", "--no-progress"],
              # the object fits no design: found by the optimiser's tries (seconds), then one line
              ["design", "--task", "task_hold_in_palm.toml", "--no-fem", "--no-progress"]]
    grid = ["--map", "pressure=0.5,1", "mass=0.5,1", "--no-progress"]  # what a map does not use: refused
    cases += [["hold", "--object", "sphere:150", *grid, *extra] for extra in (
        ["--model", "fem"], ["--margin", "3"], ["--pull-n", "2"], ["--pressure-mpa", "1"],
        ["--cavity-pressure-mpa", "1"])]
    cases += [["hold", "--object", "sphere:150", "--map", "pull=0,10", "mass=0.5,1", "--pressure-mpa", "1",
               "--pull", "x", "--no-progress"],
              ["hold", "--object", "sphere:150", "--map", "pull=0,1e300", "mass=0.5", "--pressure-mpa", "1"],
              ["hold", "--object", "sphere:150", "--map", "pressure=-10,1", "mass=1,2"],
              ["hold", "--object", "sphere:150", "--map", "pressure=0.5,1", "mass=0,1"],
              ["hold", "--object", "sphere:150", "--map", "pressure=0.5,1", "friction=0.5,1"]]  # no mass
    return [("hold", c) for c in cases]


def mixed_cases() -> list[tuple[str, list[str]]]:
    """Values that parse but mean nothing (units, reach, a sum near zero), options a mode ignores,
    a file named under the option that gave it."""
    cases = [["weights", "--diameter-mm", "180", "--depth-mm", d] for d in ("-1000", "5", "1000")]
    cases += [["weights", "--diameter-mm", "180,180"], ["reservoir", "--volume-mm3", "17800,17800"]]
    cases += [["reservoir", "--write-calibration", "cal.csv", *extra] for extra in (
        ["--json"], ["--plot", "p.png"], ["--out", "rr"], ["--volume-mm3", "17800"])]
    cases += [["grasp", "--pressure-mpa", "0.8", "--theta-deg", "45", "--mass-kg", "1",
               "--weights=1,-1,0,0,1e-12", "--normalise"],
              ["material", "fit", "--data", "m_kpa.csv", "--model", "neo-hookean", "--out", "kpa.toml"],
              ["curve", "--theta-deg", "30", "--design", "d_material_stiff.toml"],
              ["curve", "--theta-deg", "30", "--compare", "missing.toml"],
              ["inspect", "v_entities.vtu", "--out", "o.png"],
              ["control", "--theta-ref-deg", "50", "--mass-kg", "1", "--out", "same.png", "--plot", "same.png"]]
    return [("mixed", c) for c in cases]


def outputs_cases() -> list[tuple[str, list[str]]]:
    """The outputs rule's refusals: before any work, one line, nothing written."""
    no_fem = ["--no-fem", "--no-progress"]
    cases = [["design", "--task", GOOD_TASK, *no_fem, "--out", "own"], ["design", "--task", "...toml", *no_fem],
             ["bend", "--pressure-mpa", "0.1", "--out", "own"], ["weights", "--diameter-mm", "180", "--out", "own"],
             ["reservoir", "--volume-mm3", "16000", "--out", "own"],
             ["calibrate", "finger", "--design", "cal.toml", "--out", "cal_dir.csv"],
             ["calibrate", "finger", "--design", "cal.toml", "--out", "users.csv"],
             ["calibrate", "finger", "--design", "x_fem.toml", "--out", "x.csv"],
             ["grasp", "--pressure-mpa", "0.5", "--theta-deg", "40", "--mass-kg", "1", "--weights", "0:1:0.25"],
             ["fit", "--data", "fit_repeated.csv", "--params", "mu_sf_MPa"],
             ["fit", "--data", "fit_zeros.csv", "--params", "mu_sf_MPa"],
             ["curve", "--theta-deg", "10", "--design", "d_few_designs.toml"],
             ["study", "run", "tables/st_table_here.toml", "--workers", "1"],
             ["study", "run", "st_weights_folded.toml", "--workers", "1"]]
    return [("outputs", c) for c in cases]


def replay_cases() -> list[tuple[str, list[str]]]:
    """The cases of the verbs with their own files: calibrate, design, material, inspect, ...;
    range limits of every verb that takes ranges."""
    cases = []
    calibrate = [["--space", s, "--out", "t.csv"] for s in sorted(EXTRA_FILES) if s.startswith("sp_")]
    calibrate += [["--space", f, "--out", "t.csv"] for f in ("missing.toml", ".", "/dev/zero",
                                                            "binary.toml", "bad_toml.toml",
                                                            "a_file/x.toml", "good.csv")]
    calibrate += [["--space", GOOD_SPACE, "--out", o] for o in (".", "a_file/t.csv", "/proc/t.csv", "adir")]
    calibrate += [["--space", GOOD_SPACE, "--out", "t.csv", *extra] for extra in (
        ["--workers", "0"], ["--workers", "-3"], ["--workers", "100000"], ["--results", "a_file"],
        ["--results", "/proc/r"], ["--scheduler", "nowhere:1"], ["--workers", "two"])]
    calibrate += [["--space", GOOD_SPACE], ["--design", "missing.toml", "--out", "t.csv"],
                  ["--design", "d_tube_wider.toml", "--out", "t.csv"],
                  ["--design", "/dev/zero", "--out", "t.csv"],
                  ["--check", "missing.toml"], ["--check", GOOD_SPACE, "--table", "missing.csv"],
                  ["--check", GOOD_SPACE, "--table", "/dev/zero"], ["--check", GOOD_SPACE, "--table", "."],
                  ["--check", GOOD_SPACE, "--table", "good.csv"],
                  ["--space", GOOD_SPACE, "--check", GOOD_SPACE], [],
                  ["--space", GOOD_SPACE, "--out", "t.csv", "--table", "good.csv"]]
    cases += [("calibrate", ["calibrate", "finger", *c]) for c in calibrate]
    cases += [("calibrate", ["calibrate"]), ("calibrate", ["calibrate", "thumb"])]
    design = [["--task", t, "--no-fem"] for t in sorted(EXTRA_FILES) if t.startswith("t_")]
    design += [["--task", f, "--no-fem"] for f in ("missing.toml", ".", "/dev/zero", "binary.toml",
                                                   "bad_toml.toml", "a_file/x.toml", "s_empty.toml")]
    design += [["--task", GOOD_TASK, *extra] for extra in (
        ["--seed", "-1"], ["--seed", "1e30"], ["--seed", "x"], ["--mesh-size-mm", "0"],
        ["--mesh-size-mm", "nan"], ["--mesh-size-mm", "1e-9"], ["--mesh-size-mm", "1e9"],
        ["--out", "a_file"], ["--out", "/proc/d"], ["--plot", "p.txt"], ["--plot", "a_file/p.png"],
        ["--plot", "adir"])] + [[]]
    # every design the optimiser's first generation tries has no answer: one line after it
    design += [["--task", "task_tiny_object.toml", "--no-fem", "--no-progress"]]
    cases += [("design", ["design", *d]) for d in design]
    material = [["--data", d, "--model", "yeoh"] for d in sorted(EXTRA_FILES) if d.startswith("m_")]
    material += [["--data", d, "--model", "yeoh"] for d in ("missing.csv", ".", "/dev/zero",
                                                            "good.csv", "a_file/x.csv")]
    material += [["--data", "good_material.csv", *extra] for extra in (
        ["--model", "steel"], ["--model", ""], ["--model", "yeoh", "--stability-range", "5:0.2"],
        ["--model", "yeoh", "--stability-range", "0:5"], ["--model", "yeoh", "--stability-range", "nan:5"],
        ["--model", "yeoh", "--stability-range", "1:inf"], ["--model", "yeoh", "--stability-range", "x"],
        ["--model", "yeoh", "--stability-range", "0.2:5:1"], ["--model", "yeoh", "--stability-range", "1e-300:1e300"],
        ["--model", "yeoh", "--stability-range", "1:1e6"], ["--model", "yeoh", "--stability-range", "0.001:5"],
        ["--model", "yeoh", "--out", "."], ["--model", "yeoh", "--out", "a_file/m.toml"],
        ["--model", "yeoh", "--out", "/proc/m.toml"], ["--model", "yeoh", "--plot", "m.txt"],
        ["--model", "yeoh", "--plot", "adir"])]
    material += [["--data", d, "--model", m] for m in ("gent", "ogden3", "neo-hookean")
                 for d in ("m_stretch_huge.csv", "m_stretch_tiny.csv", "m_stress_huge.csv",
                           "m_stress_tiny.csv", "m_all_one.csv", "m_tension_negative.csv")]
    material += [["--data", "m_all_same.csv", "--model", m] for m in ("mooney-rivlin", "gent", "ogden2")]
    cases += [("material", ["material", "fit", *m]) for m in material]
    cases += [("material", ["material"]), ("material", ["material", "unfit"])]
    inspect = [[f] for f in ("bad.vtu", "bad.pvd", "self.pvd", "empty_series.pvd", "trunc.vtm", "x.obj", "a_file/x.vtu", "adir",
                             "binary.toml", "empty.csv")]
    inspect += [["good.vtu", *extra] for extra in (
        ["--field", "colour"], ["--field", "displacement_mm[9]"], ["--field", "displacement_mm[x]"],
        ["--field", ""], ["--step", "99"], ["--step", "-99"], ["--view", "under"],
        ["--out", "."], ["--out", "a_file/x.png"], ["--out", "/proc/x.png"], ["--out", "x.gif"],
        ["--animate", "x.txt"], ["--animate", "a_file/x.gif"], ["--animate", "."],
        ["--fields", "--step", "99"], ["--step", "x"])]
    cases += [("inspect", ["inspect", *i]) for i in inspect]
    cases += [("verify", ["verify", *v]) for v in (["--case", ""], ["--case", "x" * 5000], ["--quick", "--case", "nope"])]
    cases += [("reproduce", ["reproduce", *r]) for r in (
        ["--only", ""], ["--only", "x" * 5000], ["--out", "/proc/r"], ["--out", "a_file/r"],
        ["--design", "missing.toml"], ["--design", "/dev/zero"], ["--design", "d_sheet_thick.toml"],
        ["--design", "rep_small_reservoir.toml", "--only", "fig7_reduced"],
        ["--design", "rep_three_hinges.toml", "--only", "table2_reduced"], ["--only", "verify", "--quick"],
        ["--workers", "0"], ["--workers", "100000"], ["--workers", "two"])]
    cases += [("study", ["study", *s]) for s in (
        ["run", "good_study.toml", "--max-cases", "-1"], ["run", "good_study.toml", "--max-cases", "x"],
        ["run", "good_study.toml", "--max-cases", "1"], ["status", "good_study.toml", "--max-cases", "1"],
        ["run", "good_study.toml", "--workers", "-1"], ["run", "good_study.toml", "--results", "."
         "/a_file/r"], ["run", "a_file/x.toml"], ["report", "good_study.toml", "--results", "/proc/r"],
        ["run", "good_study.toml", "--scheduler", "tcp://nowhere.invalid:1"],
        ["status", "good_study.toml", "--results", "a_file"], ["report", "missing.toml"],
        ["run", "good_study.toml", "--workers", "2", "--scheduler", "local", "--max-cases", "0"])]
    ranges = [
        ["curve", "--theta-deg", "0:90:0.0001"], ["curve", "--theta-deg", "0:90:1", "--max-cases", "10"],
        ["curve", "--theta-deg", "0:90:1", "--max-cases", "0"], ["curve", "--theta-deg", "1", "--max-cases", "-5"],
        ["curve", "--theta-deg", "1", "--max-cases", "1e3"], ["curve", "--pressure-mpa", "0:1:1e-300"],
        ["curve", "--theta-deg", "-1e308:1e308:1e307"], ["curve", "--theta-deg", "0:90:1e-320"],
        ["bend", "--pressure-mpa", "0:0.8:0.001"], ["bend", "--pressure-mpa", "0:0.8:0.1", "--max-cases", "3"],
        ["bend", "--max-cases", "0"], ["weights", "--diameter-mm", "100:300:1"],
        ["weights", "--diameter-mm", "100:300:10", "--max-cases", "5"],
        ["weights", "--diameter-mm", "180", "--fig8", "0.1:1:0.01"],
        ["reservoir", "--volume-mm3", "10000:20000:1"],
        ["reservoir", "--volume-mm3", "10000:20000:1000", "--max-cases", "3"],
        ["reservoir", "--max-cases", "0"],
        ["curve", "--theta-deg", ",".join(["1"] * 60_000)], ["curve", "--theta-deg", "1" * 120_000],
        ["grasp", "--pressure-mpa", "0:1:0.1", "--theta-deg", "40", "--mass-kg", "1", "--weights", "paper180"],
        ["control", "--theta-ref-deg", "0:50:1", "--mass-kg", "1"],
        ["curve", "--theta-deg", "10", "--design", "adir"], ["curve", "--theta-deg", "10", "--design", ""],
        ["curve", "--theta-deg", "10", "--design", "good.csv"],
        ["curve", "--theta-deg", "10", "--plot", ""], ["curve", "--theta-deg", "10", "--plot", "x.PNG/"],
        ["curve", "--theta-deg", "10", "--plot", "/dev/null/x.png"],
        ["fit", "--data", "good.csv", "--params", "V0_mm3", "--out", "x.txt"],
        ["fit", "--data", "good.csv", "--params", "V0_mm3", "--out", "adir"],
        ["fit", "--data", "good.csv", "--params", "V0_mm3", "--bounds", "V0_mm3=nan:1"],
        ["fit", "--data", "good.csv", "--params", "V0_mm3", "--bounds", "V0_mm3=1:inf"],
        ["fit", "--data", "good.csv", "--params", "V0_mm3", "--bounds", "V0_mm3=-1e9:1e9"],
        ["material", "fit", "--data", "good_material.csv", "--model", "yeoh", "--out", "m.txt"],
        ["calibrate", "finger", "--space", GOOD_SPACE, "--out", "t.txt"],
        ["reservoir", "--write-calibration", "r.txt"], ["reservoir", "--volume-mm3", "20000", "--max-cases", "0"],
        ["fit", "--data", "binary.toml", "--params", "V0_mm3"],
        ["control", "--theta-ref-deg", "50", "--mass-kg", "1", "--disturbance", "binary.toml"],
        ["control", "--theta-ref-deg", "50", "--mass-kg", "1", "--out", "/dev/null"],
        ["reservoir", "--write-calibration", "a_file/x.csv"], ["reservoir", "--write-calibration", "/proc/x.csv"],
        ["bend", "--out", "/dev/null"], ["weights", "--diameter-mm", "180", "--out", "/dev/null"],
        ["weights", "--diameter-mm", "180", "--check-mm", "200"],
        ["weights", "--diameter-mm", "180", "--check-mm", "180"], ["weights", "--diameter-mm", "120:300:60", "--out", "w"],
        ["weights", "--diameter-mm", "180", "--fig8", "0.5", "--check-mm", "180"],
    ]
    cases += [("range", r) for r in ranges]
    control = ["control", "--theta-ref-deg", "50", "--mass-kg", "1"]
    forms = [  # numbers as float() and int() read them but nobody means them
        ["material", "fit", "--data", "m_underscore.csv", "--model", "yeoh"],
        ["material", "fit", "--data", "m_fullwidth.csv", "--model", "yeoh"],
        ["material", "fit", "--data", "good_material.csv", "--model", "yeoh", "--stability-range", "0.2:1_0"],
        ["fit", "--data", "fit_underscore.csv", "--params", "V0_mm3"],
        ["fit", "--data", "fit_arabic.csv", "--params", "V0_mm3"],
        ["fit", "--data", "good.csv", "--params", "V0_mm3", "--bounds", "V0_mm3=1_000:40_000"],
        [*control, "--disturbance", "push_underscore.csv"], [*control, "--seed", "1_0"],
        ["control", "--theta-ref-deg", "5_0", "--mass-kg", "1"],
        ["control", "--theta-ref-deg", "\u0665\u0660", "--mass-kg", "1"],
        ["design", "--task", GOOD_TASK, "--seed", "1_0"], ["reservoir", "--n-radial", "1_0"],
        ["inspect", "good.vtu", "--step", "0_0"], ["curve", "--theta-deg", "10", "--max-cases", "\uff11\uff10"],
    ]
    forms += [  # '--option=--': Python 3.11's argparse gives the option [], not a string
        ["curve", "--theta-deg=--"], ["bend", "--mesher=--"], ["bend", "--out=--"],
        ["study", "run", "good_study.toml", "--scheduler=--"], [*control, "--mode=--"], [*control, "--out=--"],
        ["design", "--task", GOOD_TASK, "--no-fem", "--out=--"], ["reservoir", "--out=--"],
        ["weights", "--diameter-mm", "180", "--out=--"], ["material", "fit", "--data=--", "--model", "yeoh"],
        ["calibrate", "finger", "--space", GOOD_SPACE, "--out", "t.csv", "--scheduler=--"],
        ["grasp", "--weights=--"], ["inspect", "good.vtu", "--field=--"], ["verify", "--case=--"],
        ["reproduce", "--only=--"], ["fit", "--data", "good.csv", "--params=--"],
    ]
    cases += [("form", f) for f in forms]
    kinds = [["study", "run", "good_study.toml", "--workers", "1", "--results", f"kind/{r}"]
             for r in ("root_file", "index_dir", "claims_file")]
    kinds += [["study", "report", "good_study.toml", "--results", "kind/index_dir"],
              ["design", "--task", GOOD_TASK, "--no-fem", "--out", "kind/design_json"],
              ["design", "--task", GOOD_TASK, "--no-fem", "--pareto", "--out", "kind/knee_file"],
              ["reproduce", "--only", "fig7_reduced", "--out", "kind/rep"],
              ["reproduce", "--only", "fig7_reduced", "--out", "kind/rep2"], [*control, "--out", "kind/ctl"],
              ["reproduce", "--only", "fig7_reduced", "--out", "mine/rep"],
              ["reproduce", "--only", "fig7_reduced", "--out", "mine/rep2"]]
    cases += [("kind", k) for k in kinds]
    cases += [("study", ["study", "run", s, "--workers", "1"]) for s in ("st_table_unused.toml", "st_table_swept.toml",
                                                                          "st_curve_pressure.toml")]
    cases += [("same", s) for s in (
        ["fit", "--data", "fit_data.png", "--params", "V0_mm3", "--plot", "./fit_data.png"],
        ["fit", "--data", "fit_data.png", "--params", "V0_mm3", "--design", "same_design.toml",
         "--out", "same_design.toml"],
        ["material", "fit", "--data", "mat_data.toml", "--model", "yeoh", "--out", "mat_data.toml"])]
    cases += [("place", ["weights", "--diameter-mm", d, "--depth-mm", y]) for d, y in (("180", "0"), ("180", "-5"),
                                                                                      ("120,240", "100"))]
    cases += [("range", ["curve", "--pressure-mpa", "-3.7"]), ("range", ["curve", "--pressure-mpa", "3.78"])]
    files = [["curve", "--theta-deg", "10", "--design", d] for d in (
        "d_nul_table.toml", "d_ft_degree_huge.toml", "d_ft_design_degree_huge.toml", "d_ft_long_term.toml",
        "d_ft_many_terms.toml", "d_ft_product_feature.toml", "d_mat_twice.toml", "d_mat_ogden_twice.toml",
        "d_mu_nan_overridden.toml", "d_mu_negative_overridden.toml", "d_mu_sr_inf_overridden.toml")]
    files += [["study", "run", s, "--workers", "1"] for s in ("st_nul_design.toml", "st_nul_file.toml",
                                                             "st_nul_table.toml")]
    files += [["study", "status", "st_nul_file.toml"], ["calibrate", "finger", "--space", "sp_nul_base.toml",
                                                         "--out", "t.csv"]]
    files += [["design", "--task", t, "--no-fem"] for t in ("t_nul_table.toml", "t_missing_table.toml")]
    files += [["calibrate", "finger", "--check", GOOD_SPACE, "--table", t] for t in (
        "ft_product_feature.csv", "ft_degree_huge.csv")]
    files += [["fit", "--data", "fit_big_cell.csv", "--params", "V0_mm3"],
              ["material", "fit", "--data", "m_big_cell.csv", "--model", "yeoh"],
              [*control, "--disturbance", "push_big_cell.csv"]]
    files += [["inspect", v, "--out", "o.png"] for v in (
        "v_huge.vtu", "v_huge_single_quotes.pvd", "v_huge_single_quotes.vtm", "v_huge_after_comment.vtu",
        "v_legacy_dimensions.vtk", "v_legacy_points.vtk")]
    files += [["study", "run", s, "--workers", "1"] for s in (
        "st_control_three_hinges.toml", "st_grasp_three_hinges.toml", "st_bend_past_pmax.toml",
        "st_bend_tiny_pressure.toml", "st_reservoir_fine.toml")]
    files += [["calibrate", "finger", "--space", "sp_press_tiny.toml", "--out", "t.csv"]]
    files += [["curve", "--theta-deg", "10", "--design", "d_ft_id_huge.toml"],
              ["inspect", "v_legacy_no_fields.vtk", "--out", "o.png"],
              ["inspect", "v_many_steps.pvd", "--animate", "o.gif"],
              ["study", "run", "st_grasp_bad_table.toml", "--workers", "1"],
              ["weights", "--diameter-mm", "180", "--plot", "w.png"]]
    cases += [("files", f) for f in files]
    cases += outputs_cases()
    cases += hold_cases()
    cases += mixed_cases()
    return [(f"{name}-{k}-{' '.join(argv[1:])[:40]}", argv) for k, (name, argv) in enumerate(cases)]
