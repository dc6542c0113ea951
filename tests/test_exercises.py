"""Every chapter ends with 2 to 4 exercises, each with a solution whose code ran in the build (issue 15).

A chapter is every notebook chapter of the teaching parts of ``_toc.yml`` (``tools.toc.teaching_chapters``:
not the preface, the course materials, the appendices or a chapter's "Going deeper" sub-pages). Its exercises and solutions are read from its MyST source in the
book's fixed format (``tools/solutions.py``: ``{exercise}`` with a ``:label:``; a gated
``solution-start``/``solution-end`` pair whose ``code-cell``\\ s execute, or a plain
``{solution}`` for a solution without code; both ``:class: dropdown``). The code cells of each
solution are then found in the executed notebook of the session's book build (the ``book``
fixture, as in tests/test_chapters.py) and must have run, without an error.

A plain ``{solution}`` that shows code (a ```` ```python ```` block) fails: its code is never run,
so its stated result is not checked by anything.
"""
from __future__ import annotations

from pathlib import Path

import nbformat
import pytest

from conftest import BOOK_OUT
from tools.solutions import fences, parse
from tools.toc import teaching_chapters

ROOT = Path(__file__).resolve().parents[1]
NOT_CHAPTERS = ("preface", "execution", "instructors")
CHAPTERS = teaching_chapters(ROOT)


def solution_cells(nb) -> dict[str, list]:
    """The code cells of an executed notebook that sit inside each gated solution, by exercise label."""
    cells: dict[str, list] = {}
    current = None
    for cell in nb.cells:
        if cell.cell_type == "markdown":
            for f in fences(cell.source.split("\n")):
                if f.directive == "solution-start":
                    current = f.argument
                    cells.setdefault(current, [])
                elif f.directive == "solution-end":
                    current = None
        elif cell.cell_type == "code" and current is not None:
            cells[current].append(cell)
    return cells


def test_the_chapters_are_the_notebook_pages_but_the_preface_and_the_guides():
    assert CHAPTERS, "no chapter found in _toc.yml"
    assert not any(Path(p).name in NOT_CHAPTERS for p in CHAPTERS)


@pytest.mark.slow
@pytest.mark.parametrize("chapter", CHAPTERS, ids=lambda p: Path(p).name)
def test_every_chapter_has_2_to_4_exercises_whose_solutions_execute(book, chapter):
    src = parse(ROOT / f"{chapter}.md")
    labels = [e.label for e in src.exercises]
    assert 2 <= len(labels) <= 4, f"{chapter} has {len(labels)} exercises ({labels}); a chapter has 2 to 4"
    path = BOOK_OUT / "_build" / "jupyter_execute" / f"{chapter}.ipynb"
    assert path.is_file() and path.stat().st_mtime >= book["started"], f"{chapter}: no executed notebook from this build"
    executed = solution_cells(nbformat.read(path, as_version=4))
    for label in labels:
        sol = src.solution_for(label)
        assert sol is not None, f"{chapter}: exercise {label!r} has no solution"
        assert not sol.code_in_prose, (
            f"{chapter}: the solution of {label!r} shows code that never runs ({sol.code_in_prose[0][:60]!r}...); "
            "put it in code-cells of a gated solution (solution-start/solution-end) so the build executes it")
        cells = executed.get(label, [])
        assert [c.source.strip("\n") for c in cells] == sol.code, (
            f"{chapter}: the executed notebook holds {len(cells)} code cells for {label!r}, the source {len(sol.code)}")
        for i, cell in enumerate(cells):
            assert cell.get("execution_count") is not None, f"{chapter}: cell {i} of the solution of {label!r} did not run"
            errors = [o for o in cell.get("outputs", []) if o.get("output_type") == "error"]
            assert not errors, f"{chapter}: the solution of {label!r} raised {errors[0].get('ename')}: {errors[0].get('evalue')}"
