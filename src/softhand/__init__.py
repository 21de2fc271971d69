"""softhand: model fluid-driven soft robot hands.

Sub-packages (dependencies point down; ``tests/project/test_layers.py`` enforces it):

* :mod:`softhand.studies` -- the studies, batch runner, reproduce, verification, the CLI;
* :mod:`softhand.fem` -- the hyperelastic FEM core on scikit-fem, and the hand models
  built from it (:mod:`softhand.fem.hand`);
* :mod:`softhand.meshes` -- geometry as code: gmsh and the layered finger mesher;
* :mod:`softhand.reduced` -- the ground floor: the design vocabulary and the paper's
  analytical virtual-work model (NumPy/SciPy only).

They are the repository's top-level folders fem/, reduced/, meshes/ and studies/; installed
(``pip install -e .``), they import under this one name only.
"""
from softhand.reduced.vocabulary.versions import package_version

__version__ = package_version()  # "unknown" when the package is not installed
del package_version
