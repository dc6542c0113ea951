"""The package's house rules, read from its source: imports run one way, and no module is long.

Every file of ``orrc/`` is parsed with ``ast``; every ``import`` and ``from ... import`` in it counts,
also those inside functions (a function-level import is a dependency all the same, deferred only).
An import names a file of the package: ``from ..costs import QuadraticCost`` is an edge to
``orrc/costs.py``, ``from . import _validate`` one to ``orrc/_validate.py``, ``from .estimation import
prbs`` one to ``orrc/estimation/__init__.py``. The graph of these edges has no cycle.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "orrc"
MAX_LINES = 400


def _modules() -> dict[str, Path]:
    """Dotted module name -> file, for every file of the package (a package is its __init__.py)."""
    out = {}
    for path in sorted(ROOT.rglob("*.py")):
        parts = path.relative_to(ROOT.parent).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def _imports(name: str, path: Path, modules: dict) -> set[str]:
    """The package's modules that the file imports (anywhere in it)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name in modules}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - (node.level - 1)]
                base = ".".join(base + ([node.module] if node.module else []))
            else:
                base = node.module or ""
            for alias in node.names:
                target = f"{base}.{alias.name}"
                if target in modules:          # a module imported from its package
                    found.add(target)
                elif base in modules:          # a name imported from a module
                    found.add(base)
    found.discard(name)
    return found


def import_graph() -> dict[str, set[str]]:
    modules = _modules()
    return {name: _imports(name, path, modules) for name, path in modules.items()}


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan), each sorted."""
    index, low, stack, on_stack, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_the_graph_reads_imports_inside_functions_and_relative_ones():
    graph = import_graph()
    assert "orrc._validate" in graph["orrc.costs"], "costs imports the validation layer"
    # a function-level import counts (EstimateThenControl imports the estimators when it is built)
    assert "orrc.estimation" in graph["orrc.controllers.estimate"]
    # the validation layer (orrc._validate and the modules it re-exports) imports nothing else of the package
    layer = {"orrc._validate", "orrc._errors", "orrc._arguments", "orrc._size_limits"}
    assert graph["orrc._validate"] == layer - {"orrc._validate"}, f"orrc._validate imports {graph['orrc._validate']}"
    for name in layer:
        assert graph[name] <= layer, f"the validation layer's {name} imports {graph[name] - layer}"
    # the detector finds a circle when there is one
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []


def test_imports_run_one_way():
    found = cycles(import_graph())
    detail = "; ".join(" <-> ".join(c) for c in found)
    assert not found, f"import circles among the package's files: {detail}"


def code_lines(source: str) -> int:
    """The lines of a module that are not docstrings: a module's length is its code, and a numpydoc
    docstring with its examples (the API reference's text) makes a module no longer in concepts."""
    tree = ast.parse(source)
    doc = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) and isinstance(first.value.value, str):
                doc.update(range(first.lineno, first.end_lineno + 1))
    return sum(1 for i, _ in enumerate(source.splitlines(), 1) if i not in doc)


def test_code_lines_leave_out_docstrings_only():
    source = 'def f(x):\n    """Twice x.\n\n    Examples\n    --------\n    >>> f(1)\n    2\n    """\n    return 2 * x\n'
    assert code_lines(source) == 2
    assert code_lines('x = 1\ny = """not a docstring\nbut a value"""\n') == 3


@pytest.mark.parametrize("path", sorted(ROOT.rglob("*.py")), ids=lambda p: str(p.relative_to(ROOT.parent)))
def test_no_module_is_over_400_lines(path):
    lines = code_lines(path.read_text(encoding="utf-8"))
    where = path.relative_to(ROOT.parent)
    assert lines <= MAX_LINES, f"{where} has {lines} lines of code (over {MAX_LINES}): split it by concept"
