"""What a reader sees runs as shown: the visible code of every page of ``_toc.yml`` runs, in
page order, on what the reader can see.

A code cell is *hidden* when it is tagged ``remove-cell`` or ``remove-input`` (the reader sees
neither its code nor, for ``remove-cell``, its output); every other code cell is *visible*,
the code cells of a solution included (folded in the HTML, one click away). A hidden cell
tagged ``size-switch`` (with ``remove-cell``) rebinds a teaching value for the test size right
after the visible cell that sets it: ``T = orrc.config.size(T, 40)``.

* Static: no visible cell uses a name that only hidden cells bind (and no earlier visible cell
  binds), or a name that a hidden cell other than a size switch rebound after the visible code
  bound it; a ``size-switch`` cell rebinds only names that a visible cell bound before it. Names
  are found with :mod:`symtable` (assignments, imports, definitions, ``for`` and ``with``
  targets, walrus; names used inside functions, lambdas and comprehensions count).
* The run: every page is executed once per session, visible and hidden cells in page order at
  the test size, by the book's build in the environment its download installs
  (tests/downloads.py); with the static check, the visible cells alone (the download) run too.
  tests/test_downloads.py checks that the download holds exactly the visible cells.
* Code style: code lines of at most 88 characters; every ``assert`` states its claim.
"""
from __future__ import annotations

import builtins
import symtable
from pathlib import Path

import jupytext
import pytest

from tools.toc import ROOT, notebook_pages

PAGES = notebook_pages()
HIDDEN_TAGS = {"remove-cell", "remove-input"}
SIZE_SWITCH = "size-switch"
# names an IPython kernel defines besides Python's builtins
KERNEL_NAMES = set(dir(builtins)) | {"get_ipython", "display", "__file__"}


def code_cells(page: str, root: Path = ROOT) -> list[dict]:
    """The code cells of a page in order: index (among code cells, from 1), source, tags."""
    nb = jupytext.read(Path(root) / f"{page}.md")
    cells = [c for c in nb.cells if c.cell_type == "code"]
    return [{"n": i, "source": c.source, "tags": set(c.metadata.get("tags", []))}
            for i, c in enumerate(cells, 1)]


def is_hidden(cell: dict) -> bool:
    return bool(cell["tags"] & HIDDEN_TAGS)


def python_of(source: str) -> str:
    """The cell as the kernel runs it (IPython magics turned into plain Python)."""
    from IPython.core.inputtransformer2 import TransformerManager

    return TransformerManager().transform_cell(source)


def bound_and_used(source: str) -> tuple[set[str], set[str]]:
    """(names the cell binds at module level, names it reads that it does not bind itself).

    A name read inside a function, lambda, class or comprehension and bound in none of the
    enclosing local scopes is a global read; it counts as used."""
    top = symtable.symtable(python_of(source), "<cell>", "exec")
    bound = {s.get_name() for s in top.get_symbols()
             if s.is_assigned() or s.is_imported() or s.is_namespace()}
    used = {s.get_name() for s in top.get_symbols() if s.is_referenced()}

    def walk(table):
        for child in table.get_children():
            for s in child.get_symbols():
                if s.is_global() and s.is_referenced():
                    used.add(s.get_name())
                elif s.is_free() and s.is_referenced() and s.get_name() in top.get_identifiers():
                    used.add(s.get_name())
            walk(child)

    walk(top)
    return bound, used - bound - KERNEL_NAMES


def hidden_dependencies(page: str, root: Path = ROOT) -> list[str]:
    """Each problem of a page as a sentence naming the cell and the name."""
    problems: list[str] = []
    visible: set[str] = set()
    hidden: set[str] = set()
    rebound: dict[str, int] = {}     # visible names a later hidden cell rebound: name -> cell
    for cell in code_cells(page, root):
        bound, used = bound_and_used(cell["source"])
        first = cell["source"].strip().splitlines()[0][:60] if cell["source"].strip() else ""
        where = f"{page}, code cell {cell['n']} ({first!r})"
        if SIZE_SWITCH in cell["tags"]:
            if not is_hidden(cell):
                problems.append(f"{where}: a size-switch cell must be hidden (remove-cell)")
            new = sorted(bound - visible)
            if new:
                problems.append(f"{where}: the size-switch cell binds {new}, which no earlier "
                                "visible cell binds (it may only rebind a teaching value)")
        elif is_hidden(cell):
            hidden |= bound
            rebound.update({name: cell["n"] for name in bound & visible})
        else:
            only_hidden = sorted((used - visible) & hidden)
            if only_hidden:
                problems.append(f"{where}: uses {only_hidden}, bound only in hidden cells")
            changed = sorted(used & set(rebound))
            if changed:
                problems.append(f"{where}: uses {changed}, rebound out of sight by hidden code "
                                f"cell(s) {sorted({rebound[n] for n in changed})} (tag a size "
                                "switch `size-switch`)")
            visible |= bound
            for name in bound:
                rebound.pop(name, None)
    return problems


@pytest.mark.parametrize("page", PAGES)
def test_visible_cells_use_no_name_that_only_hidden_cells_bind(page):
    problems = hidden_dependencies(page)
    assert not problems, "\n".join(problems)


def test_the_static_check_finds_names_in_every_binding_form():
    """The rule of the static check on small cells: what binds, what reads, in which scope."""
    bound, used = bound_and_used(
        "%matplotlib inline\nimport numpy as np\nfrom os import path as p\n"
        "for i in range(3):\n    pass\nwith open(f) as fh:\n    pass\n"
        "def g(y):\n    return y + T + np.pi\n"
        "s = [k * w for k in K]\nif (n := len(s)) > 0:\n    pass\n"
        "h = lambda z: z * c\nclass C:\n    attr = D\n")
    assert bound >= {"np", "p", "i", "fh", "g", "s", "n", "h", "C"}, "every binding form binds"
    assert used == {"f", "T", "w", "K", "c", "D"}, "reads in nested scopes count, locals do not"


def test_the_static_check_reports_a_name_set_out_of_sight(tmp_path):
    """A visible cell reading a name only a hidden cell set is reported, naming the cell and the
    name; so is one reading a name a hidden cell (not a size switch) rebound; a size-switch
    cell that binds a new name is reported; a proper switch is not."""
    page = tmp_path / "book" / "p.md"
    page.parent.mkdir()
    cell = "```{{code-cell}} ipython3\n{tags}\n{src}\n```\n\n"
    page.write_text(
        "---\njupytext:\n  text_representation:\n    extension: .md\n    format_name: myst\n"
        "kernelspec:\n  display_name: Python 3\n  language: python\n  name: python3\n---\n\n"
        + cell.format(tags="", src="T = 200")
        + cell.format(tags=":tags: [remove-cell, size-switch]\n", src="T = min(T, 40)")
        + cell.format(tags=":tags: [remove-cell]\n", src="N = 10")
        + cell.format(tags="", src="print(T * N)")
        + cell.format(tags=":tags: [remove-cell, size-switch]\n", src="S = 3")
        + cell.format(tags=":tags: [remove-cell]\n", src="T = 10")
        + cell.format(tags="", src="print(T)"),
        encoding="utf-8")
    problems = hidden_dependencies("book/p", tmp_path)
    assert len(problems) == 3, problems
    assert "code cell 4" in problems[0] and "['N']" in problems[0], problems[0]
    assert "code cell 5" in problems[1] and "['S']" in problems[1], problems[1]
    assert "code cell 7" in problems[2] and "['T']" in problems[2], problems[2]


# ----------------------------------------------------------------------------- code style


@pytest.mark.parametrize("page", PAGES)
def test_code_lines_fit_and_every_check_states_its_claim(page):
    """Every code line of a page is at most 88 characters (it fits the page's code column);
    every ``assert`` carries a message that states the claim it checks (a string, not a
    tuple of values), so a failure tells the reader which statement of the text failed."""
    import ast

    long_lines, silent = [], []
    for cell in code_cells(page):
        long_lines += [f"code cell {cell['n']}: {len(line)} characters: {line.strip()[:50]}"
                       for line in cell["source"].splitlines() if len(line) > 88]
        for node in ast.walk(ast.parse(python_of(cell["source"]))):
            if isinstance(node, ast.Assert) and not (
                    isinstance(node.msg, ast.JoinedStr)
                    or (isinstance(node.msg, ast.Constant) and isinstance(node.msg.value, str))):
                silent.append(f"code cell {cell['n']}: {ast.unparse(node)[:70]}")
    assert not long_lines, f"{page}: lines over 88 characters:\n" + "\n".join(long_lines)
    assert not silent, f"{page}: asserts without a message stating the claim:\n" + "\n".join(silent)
