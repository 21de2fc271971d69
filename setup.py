"""The package layout, computed so it cannot drift from the folders.

The repository's top-level folders fem/, reduced/, meshes/ and studies/ are the sub-packages
softhand.fem, softhand.reduced, softhand.meshes and softhand.studies; src/softhand holds the
top package. Every folder with an ``__init__.py`` under the four is a package, and nothing else
(tests/project/test_packaging.py builds the wheel and checks it). Everything else is in
pyproject.toml.
"""
from setuptools import find_packages, setup

LAYERS = ("fem", "reduced", "meshes", "studies")

setup(
    package_dir={"softhand": "src/softhand", **{f"softhand.{layer}": layer for layer in LAYERS}},
    packages=["softhand", *(f"softhand.{name}" for name in
                            find_packages(include=[p for layer in LAYERS for p in (layer, f"{layer}.*")]))],
)
