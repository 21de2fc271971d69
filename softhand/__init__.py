"""softhand: model fluid-driven soft robot hands.

Sub-packages (dependencies point down; ``tests/test_layers.py`` enforces it):

* :mod:`softhand.studies` -- the studies, batch runner, reproduce, verification, the CLI;
* :mod:`softhand.fem` -- the hyperelastic FEM core on scikit-fem, and the hand models
  built from it (:mod:`softhand.fem.hand`);
* :mod:`softhand.meshes` -- geometry as code: gmsh and the layered finger mesher;
* :mod:`softhand.reduced` -- the ground floor: the design vocabulary and the paper's
  analytical virtual-work model (NumPy/SciPy only).
"""

# Run from a source tree (a checkout on PYTHONPATH, or an editable install) the sub-packages are
# the repository's top-level folders beside this one; an installed wheel has them inside it.
from pathlib import Path as _Path

_root = _Path(__file__).resolve().parent.parent
if not (_Path(__file__).parent / "fem").is_dir() and (_root / "fem" / "__init__.py").is_file():
    __path__.append(str(_root))
del _Path, _root

from softhand.reduced.vocabulary.versions import package_version as _package_version  # noqa: E402

__version__ = _package_version()  # "unknown" in a source tree that is not installed
