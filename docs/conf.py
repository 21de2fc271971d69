"""Sphinx configuration of the docs site: the Markdown pages (MyST), the API reference from the
docstrings (autosummary, one page per module) and the examples as a gallery (not executed).

Build: ``sphinx-build -W -n docs docs/_build``; the test suite builds it too
(tests/project/test_docs.py), failing on any warning or unresolved reference.
"""
from pathlib import Path

import softhand

HERE = Path(__file__).resolve().parent

project = "softhand"
author = "the softhand authors"
copyright = "softhand authors, MIT licence"
release = softhand.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx_gallery.gen_gallery",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "auto_examples/*.ipynb", "auto_examples/*.py", "auto_examples/*.zip",
                    "auto_examples/*.json", "auto_examples/*.md5"]
myst_enable_extensions = ["dollarmath"]
myst_heading_anchors = 3


autosummary_generate = True
autosummary_imported_members = False
#: a package page describes its public face in its docstring; the objects are documented once,
#: on their module's page
autodoc_default_options = {"members": True, "undoc-members": True, "ignore-module-all": True}
autodoc_typehints = "none"  # signatures stay short; units and shapes are in the docstrings
autodoc_member_order = "bysource"
add_module_names = False

#: nitpicky on the project's own references: a :mod:, :class:, :func: naming a softhand
#: object that does not exist fails the build; names of other libraries are not checked
#: (no network for their inventories)
nitpicky = True
nitpick_ignore_regex = [(r"py:.*", r"(np|numpy|scipy|skfem|meshio|pyvista|matplotlib|dask|gmsh|pathlib|typing|"
                                  r"collections|argparse|concurrent|subprocess|threading|os|io|enum|"
                                  r"dataclasses|functools|abc|tqdm|threadpoolctl|Path)(\..*)?"),
                        (r"py:(class|obj)", r"(float|int|str|bytes|bool|dict|list|tuple|set|callable|"
                                            r"object|None|Callable|Any|Iterable|Sequence|Mapping)"),
                        # pieces of type annotations autodoc shows as text, not references
                        (r"py:class", r"('.*|.*\]'?|string)")]

sphinx_gallery_conf = {
    "examples_dirs": str(HERE.parent / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"^$",  # no script is executed: the test suite runs them
    "plot_gallery": "False",
    "download_all_examples": False,
    "write_computation_times": False,
    "show_signature": False,
}

html_theme = "alabaster"
html_title = "softhand"
