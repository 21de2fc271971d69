"""The docs site builds from docs/ with no warning: every page, every cross-reference to the
project's own modules and objects (nitpicky), the API reference from the docstrings and the
examples' gallery. Built from a copy, so the generated pages stay out of the checkout."""
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_the_docs_site_builds_without_a_warning(tmp_path):
    for folder in ("docs", "examples"):
        shutil.copytree(ROOT / folder, tmp_path / folder,
                        ignore=shutil.ignore_patterns("_build", "api", "auto_examples", "__pycache__"))
    out = tmp_path / "html"
    proc = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-n", "-q", "-b", "html",
                           str(tmp_path / "docs"), str(out)], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-6000:]
    pages = {p.relative_to(out).as_posix() for p in out.rglob("*.html")}
    assert {"index.html", "cli.html", "validation.html", "performance.html", "api.html",
            "auto_examples/index.html", "api/softhand.reduced.equations.hand.html"} <= pages
    assert len([p for p in pages if p.startswith("auto_examples/0")]) == len(list((ROOT / "examples").glob("0*.py")))
