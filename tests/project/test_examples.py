"""The examples/ gallery: each literate script runs in a fresh interpreter and asserts its number."""
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[2] / "examples").glob("[0-9][0-9]_*.py"))


def test_the_gallery_is_there():
    assert len(EXAMPLES) >= 4


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs(script, tmp_path):
    out = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True,
                         text=True, timeout=900)
    assert out.returncode == 0, f"{script.name} failed:\n{out.stdout[-2000:]}\n{out.stderr[-3000:]}"


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_examples_import_the_layers_public_faces(script):
    """What an example imports is what a user is meant to import: softhand.<layer>, not its modules."""
    deep = [line for line in script.read_text().splitlines()
            if line.startswith(("from softhand.", "import softhand.")) and line.split()[1].count(".") > 1]
    assert not deep, deep
