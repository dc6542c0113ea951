"""Every chapter of the book executes top to bottom without an error (ORRC_QUICK=1 sizes).

The chapters are MyST Markdown notebooks; they are read with jupytext and run
with nbclient in a fresh kernel, one test per chapter listed in _toc.yml.
"""
from pathlib import Path

import pytest

from tools.toc import toc_pages

ROOT = Path(__file__).resolve().parents[1]


def toc_chapters():
    """The pages of _toc.yml that have a MyST source (every chapter is a notebook)."""
    return [p for p in toc_pages(ROOT) if (ROOT / f"{p}.md").exists()]


@pytest.mark.slow
@pytest.mark.parametrize("chapter", toc_chapters())
def test_chapter_executes(chapter, monkeypatch):
    import jupytext
    from nbclient import NotebookClient

    monkeypatch.setenv("ORRC_QUICK", "1")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    nb = jupytext.read(ROOT / f"{chapter}.md")
    client = NotebookClient(nb, timeout=300, kernel_name="python3", allow_errors=False,
                            resources={"metadata": {"path": str((ROOT / chapter).parent)}})
    client.execute()
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            assert out.get("output_type") != "error", f"{chapter}: {out.get('ename')}: {out.get('evalue')}"
            if out.get("name") == "stderr":
                assert "Traceback" not in out.get("text", ""), f"{chapter} printed a traceback"
