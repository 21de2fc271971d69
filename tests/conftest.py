"""Shared by every test folder: the CI mesh presets, named once.

The tests mirror the code (``tests/fem``, ``tests/reduced``, ``tests/meshes``, ``tests/studies``;
``tests/project`` for what spans them). This folder is on ``sys.path`` while they run, so the
helper modules beside this file (``bad_input_cases``) import by their plain names.
"""

#: the finger FEM's CI mesh: gmsh, 6 mm, uniform (9 677 unknowns; theta(0.8 MPa) 3.6 % below the
#: converged value, docs/validation.md), as FingerOptions(**CI_FINGER) keywords
CI_FINGER = {"mesher": "gmsh", "mesh_size": 6.0, "edge_ratio": 1.0, "mesh_refine": 0}
#: the same mesh on the command line (``softhand bend``, ``weights``)
CI_MESH_ARGS = ["--mesh-size-mm", "6"]
#: the coarsest finger mesh the FEM builds (gmsh, 10 mm, uniform): the grasp FEM and the scene
COARSEST_FINGER = {**CI_FINGER, "mesh_size": 10.0}
#: the reservoir sheet's coarse CI mesh, as SheetModel keywords
CI_SHEET = {"n_radial": 24, "n_thick": 2}
