"""The architecture, enforced: dependencies point down, and no module imports itself in a circle.

Layers, bottom up (docs/architecture.md describes them):

* ``softhand.reduced`` -- the design vocabulary and the paper's model; NumPy/SciPy only;
* ``softhand.meshes`` -- geometry as code; may use ``reduced`` (design, errors);
* ``softhand.fem`` -- the FEM core and the hand models; may use ``meshes`` and ``reduced``;
* ``softhand.studies`` -- studies, batch, reproduce, verification, the CLI; may use all.

Every import counts, also those inside functions (a lazy import is still a dependency).
Cycles are looked for among module-level imports, the ones that run at import time, and
through every import (none is accepted). No private name (``_x``) is imported from another module.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
LAYERS = ("reduced", "meshes", "fem", "studies")
#: third-party packages each layer may not import (reduced stays light: ~0.2 s start-up)
FORBIDDEN = {"reduced": ("skfem", "gmsh", "pyvista", "meshio", "matplotlib", "dask")}


def modules():
    """(dotted name under softhand, path) of every module of the four packages."""
    for layer in LAYERS:
        for path in sorted((ROOT / layer).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            if parts[-1] == "__init__":
                parts = parts[:-1]
            yield ".".join(("softhand", *parts)), path


def imports(name: str, path: Path, *, top_level_only: bool = False):
    """Absolute names of the modules that ``name`` imports (relative imports resolved)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    nodes = tree.body if top_level_only else ast.walk(tree)
    for node in nodes:
        if isinstance(node, ast.Import):
            yield from (alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*anchor, base] if base else anchor)
            yield base
            yield from (f"{base}.{alias.name}" for alias in node.names)


def layer_of(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if parts[0] == "softhand" and len(parts) > 1 and parts[1] in LAYERS else None


ALL = dict(modules())


@pytest.mark.parametrize("name", sorted(ALL))
def test_dependencies_point_down(name):
    own = layer_of(name)
    for target in imports(name, ALL[name]):
        assert not target.split(".")[0] in LAYERS, f"{name} imports {target}: use softhand.{target}"
        other = layer_of(target)
        if other is not None:
            assert LAYERS.index(other) <= LAYERS.index(own), f"{name} ({own}) imports {target} ({other})"
        assert target.split(".")[0] not in FORBIDDEN.get(own, ()), f"{name} imports {target}"


def test_no_import_cycles():
    graph = {name: {t for t in imports(name, path, top_level_only=True) if t in ALL and t != name}
             for name, path in ALL.items()}
    state: dict[str, int] = {}

    def visit(node, trail):
        state[node] = 1
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                raise AssertionError("import cycle: " + " -> ".join([*trail, node, nxt]))
            if nxt not in state:
                visit(nxt, [*trail, node])
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node, [])


def test_the_checks_see_a_violation(tmp_path):
    """The import scanner itself: a lazy, a relative and an absolute import are all seen."""
    path = tmp_path / "mod.py"
    path.write_text("from . import design\nimport numpy\n\ndef f():\n    from softhand.fem import solid\n")
    found = set(imports("softhand.reduced.mod", path))
    assert {"softhand.reduced.design", "numpy", "softhand.fem.solid"} <= found
    assert set(imports("softhand.reduced.mod", path, top_level_only=True)) >= {"softhand.reduced.design"}


def test_no_cycles_through_lazy_imports_either():
    graph = {name: {t for t in imports(name, path) if t in ALL and t != name}
             for name, path in ALL.items()}

    def reachable(start):
        seen, todo = set(), [start]
        while todo:
            for nxt in graph[todo.pop()] - seen:
                seen.add(nxt)
                todo.append(nxt)
        return seen

    reach = {name: reachable(name) for name in graph}
    cycles = {frozenset({n} | {m for m in reach[n] if n in reach[m]}) for n in graph if n in reach[n]}
    assert not cycles, sorted(sorted(c) for c in cycles)


def private_imports(path: Path) -> list[str]:
    """``module.name`` of every ``from module import _name`` in the file (dunders aside)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    return [f"{node.module}.{alias.name}" for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)
            for alias in node.names if alias.name.startswith("_") and not alias.name.startswith("__")]


@pytest.mark.parametrize("name", sorted(ALL))
def test_no_private_name_crosses_a_module(name):
    """``from x import _y`` of another module's private name: it needs a public name, or it
    belongs in the module that uses it."""
    private = private_imports(ALL[name])
    assert not private, f"{name} imports {', '.join(private)}"


def test_the_private_name_check_sees_one(tmp_path):
    """A private name inside a multi-line import, and inside a function, is seen."""
    path = tmp_path / "mod.py"
    path.write_text("from softhand.reduced.vocabulary.errors import (\n    InputError,\n    _hidden,\n)\n\n"
                    "def f():\n    from softhand.fem.newton import _step, __all__\n")
    assert private_imports(path) == ["softhand.reduced.vocabulary.errors._hidden", "softhand.fem.newton._step"]


#: a module a reader takes in whole: past this many lines, it holds more than one concern
MAX_LINES = 300


def test_every_module_is_one_concern_a_reader_takes_in_whole():
    """Rooms cut by concern keep modules short; a module past the mark is due a split (by
    concern, not by size), not a higher mark."""
    long = {name: n for name, path in ALL.items()
            if (n := len(path.read_text().splitlines())) > MAX_LINES}
    assert not long, f"modules over {MAX_LINES} lines: {long}"
