"""One name per module: the installed packages are the folders, a short name fails, each layer
has a public face.

The wheel is built from a copy of the checkout (setuptools' own backend, no network) and read:
every folder with an ``__init__.py`` under fem/, reduced/, meshes/ and studies/ is a package
``softhand.<folder>``, nothing else is, and every module and data file git tracks there is in it.
"""
from __future__ import annotations

import importlib
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
LAYERS = ("fem", "reduced", "meshes", "studies")


def tracked(*paths: str) -> list[str]:
    """The files git tracks under ``paths``, relative to the checkout."""
    if not (ROOT / ".git").exists():
        pytest.skip("not a git checkout: which files belong to the package is git's list")
    out = subprocess.run(["git", "ls-files", *paths], cwd=ROOT, capture_output=True, text=True, check=True)
    return out.stdout.split()


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> zipfile.ZipFile:
    src = tmp_path_factory.mktemp("src")
    for name in tracked(*LAYERS, "src", "setup.py", "pyproject.toml", "README.md", "LICENSE"):
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / name, src / name)
    out = tmp_path_factory.mktemp("wheel")
    code = f"from setuptools import build_meta; print(build_meta.build_wheel({str(out)!r}))"
    proc = subprocess.run([sys.executable, "-c", code], cwd=src, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return zipfile.ZipFile(out / proc.stdout.split()[-1])


def test_installed_packages_are_the_folders(wheel):
    installed = {str(Path(n).parent).replace("/", ".") for n in wheel.namelist() if n.endswith("/__init__.py")}
    folders = {"softhand"} | {"softhand." + ".".join(p.parent.parts) for layer in LAYERS
                              for p in (ROOT / layer).relative_to(ROOT).rglob("__init__.py")
                              if (ROOT / p).is_file()}
    assert installed == folders


def test_every_tracked_file_of_the_layers_is_installed(wheel):
    names = set(wheel.namelist())
    # a script beside data (not in a package folder) is the data's maker, not part of the package
    wanted = [f for f in tracked(*LAYERS) if not f.endswith(".py") or (ROOT / f).with_name("__init__.py").is_file()]
    missing = [f for f in wanted if f"softhand/{f}" not in names]
    assert not missing, f"tracked but not installed (package-data in pyproject.toml?): {missing}"
    tops = {n.split("/")[0] for n in names if not n.split("/")[0].endswith(".dist-info")}
    assert tops == {"softhand"}


@pytest.mark.parametrize("layer", LAYERS)
def test_a_short_name_fails_naming_the_right_one(layer):
    """With the checkout on sys.path (a script or ``python -m pytest`` run from it) the folder is
    importable by its short name; it refuses, so one module never has two identities."""
    proc = subprocess.run([sys.executable, "-c", f"import {layer}"], cwd=ROOT, capture_output=True, text=True)
    assert proc.returncode == 1
    assert proc.stderr.strip().splitlines()[-1] == (
        f"ImportError: '{layer}' is softhand.{layer}: import softhand.{layer} (after pip install -e .)")


@pytest.mark.parametrize("layer", LAYERS)
def test_each_layer_has_a_public_face(layer):
    package = importlib.import_module(f"softhand.{layer}")
    assert package.__all__, f"softhand.{layer} exports nothing"
    for name in package.__all__:
        value = getattr(package, name)
        assert name in dir(package)
        home = getattr(value, "__name__", "") if isinstance(value, type(sys)) else value.__module__
        assert home.startswith(f"softhand.{layer}."), (name, home)


def test_faces_import_on_first_use():
    """``import softhand.reduced`` stays as quick as before: the face's modules load when used."""
    code = ("import sys, softhand.reduced, softhand.fem, softhand.studies\n"
            "loaded = [m for m in sys.modules if m.startswith('softhand.') and m.count('.') > 1]\n"
            "print(sorted(m for m in loaded if m not in ('softhand.reduced.vocabulary', "
                "'softhand.reduced.vocabulary.versions')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
