"""The pages of the book, read from ``_toc.yml``, and which of them are notebooks (used by the tests)."""
from __future__ import annotations

import re
from pathlib import Path

from sphinx_external_toc.parsing import parse_toc_yaml

ROOT = Path(__file__).resolve().parents[1]


def toc_pages(root: Path = ROOT) -> list[str]:
    """Every page of ``_toc.yml`` in reading order, as docnames such as ``book/lemma1``.

    The file is read by the parser Jupyter Book itself uses (``sphinx_external_toc``), so
    a malformed ``_toc.yml`` fails here as in the build; pages are listed depth first, each
    before its subtrees; a suffix ``.md`` or ``.ipynb`` is dropped.
    """
    site = parse_toc_yaml(Path(root) / "_toc.yml")
    pages: list[str] = []

    def walk(doc: str) -> None:
        pages.append(re.sub(r"\.(md|ipynb)$", "", doc))
        for tree in site[doc].subtrees:
            for child in tree.files():
                walk(child)

    walk(site.root.docname)
    return pages


def is_notebook(page: str, root: Path = ROOT) -> bool:
    """A page is a notebook (executed by the build) when its MyST source has a jupytext
    header with a kernelspec."""
    src = Path(root) / f"{page}.md"
    if not src.exists():
        return False
    text = src.read_text(encoding="utf-8")
    return text.startswith("---") and "kernelspec:" in text.split("\n---", 1)[0]


def notebook_pages(root: Path = ROOT) -> list[str]:
    """The pages of ``_toc.yml`` that are notebooks, in reading order."""
    return [p for p in toc_pages(root) if is_notebook(p, root)]
