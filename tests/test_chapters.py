"""Every chapter of the book executes top to bottom without an error (ORRC_QUICK=1 sizes).

The chapters are MyST Markdown notebooks. The session's one book build (the ``book``
fixture of conftest.py: forced execution of every chapter, in a fresh kernel each)
writes each executed notebook to ``_build/test/_build/jupyter_execute/<page>.ipynb``; this test
reads them back, one test per chapter of _toc.yml, so that a failing chapter is named.
"""
import nbformat
import pytest

from conftest import BOOK_OUT
from tools.toc import notebook_pages


@pytest.mark.slow
@pytest.mark.parametrize("chapter", notebook_pages())
def test_chapter_executes(book, chapter):
    path = BOOK_OUT / "_build" / "jupyter_execute" / f"{chapter}.ipynb"
    assert path.is_file(), f"{chapter}: the build wrote no executed notebook {path}"
    assert path.stat().st_mtime >= book["started"], f"{chapter}: {path} is older than this build"
    nb = nbformat.read(path, as_version=4)
    assert any(c.get("outputs") for c in nb.cells), f"{chapter}: the executed notebook has no outputs"
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            assert out.get("output_type") != "error", f"{chapter}: {out.get('ename')}: {out.get('evalue')}"
            if out.get("name") == "stderr":
                assert "Traceback" not in out.get("text", ""), f"{chapter} printed a traceback"
