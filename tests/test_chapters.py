"""Every chapter of the book executes top to bottom without an error (ORRC_QUICK=1 sizes).

The chapters are MyST Markdown notebooks; they are read with jupytext and run
with nbclient in a fresh kernel, one test per chapter listed in _toc.yml.
"""
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]


def toc_chapters():
    toc = yaml.safe_load((ROOT / "_toc.yml").read_text())
    files = [toc["root"]]

    def walk(entries):
        for e in entries or []:
            if "file" in e:
                files.append(e["file"])
            walk(e.get("sections"))
            for part in e.get("parts", []) if isinstance(e, dict) else []:
                walk(part.get("chapters"))

    walk(toc.get("chapters"))
    for part in toc.get("parts", []):
        walk(part.get("chapters"))
    return [f for f in files if (ROOT / f"{f}.md").exists()]


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
