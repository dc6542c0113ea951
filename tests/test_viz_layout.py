"""orrc.viz is organised one concept per module: no module over 400 lines, imports that
run one way (no circle, also not through an import inside a function), and the public import paths
of the split modules kept."""
from __future__ import annotations

import ast
import importlib
from pathlib import Path

import orrc.viz

VIZ = Path(orrc.viz.__file__).parent
MAX_LINES = 400


def _imports(path: Path) -> set[str]:
    """The orrc.viz modules that ``path`` imports, at module level or inside a function."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.level == 1:
            if node.module:
                found.add(node.module.split(".")[0])
            else:
                found |= {a.name for a in node.names}
    return {m for m in found if (VIZ / f"{m}.py").is_file()}


def test_no_module_is_over_400_lines():
    long = {p.name: n for p in VIZ.glob("*.py") if (n := len(p.read_text(encoding="utf-8").splitlines())) > MAX_LINES}
    assert not long, f"orrc.viz modules over {MAX_LINES} lines: {long}"


def test_imports_run_one_way():
    graph = {p.stem: _imports(p) - {p.stem} for p in VIZ.glob("*.py") if p.stem != "__init__"}
    assert "kernel" in graph["live"] and "explore" not in graph["live"], "live must not import explore"
    done, stack = set(), []

    def visit(m):
        if m in stack:
            raise AssertionError(f"import circle: {' -> '.join(stack[stack.index(m):] + [m])}")
        if m in done:
            return
        stack.append(m)
        for n in sorted(graph.get(m, ())):
            visit(n)
        stack.pop()
        done.add(m)

    for m in sorted(graph):
        visit(m)


def test_the_split_modules_keep_their_public_import_paths():
    figures, plots = importlib.import_module("orrc.viz.figures"), importlib.import_module("orrc.viz.plots")
    for name in figures.__all__:
        assert hasattr(figures, name), f"orrc.viz.figures.{name} is gone"
    for name in plots.__all__:
        assert hasattr(plots, name), f"orrc.viz.plots.{name} is gone"
    from orrc.viz.legibility import legible
    from orrc.viz.narrow import narrowed
    from orrc.viz.tables import Table

    assert figures.legible is legible and figures.narrowed is narrowed and plots.Table is Table
