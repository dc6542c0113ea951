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


#: the parts of the book whose chapters teach the paper (held to the chapter shape of
#: tools/teaching_shape.py); the other parts are the front matter, the course and the appendices
TEACHING_PARTS = ("The setting", "Known system, with preview: Algorithm 1", "Unknown system: Algorithm 2",
                  "No preview: Algorithm 3", "Comparisons")


def parts(root: Path = ROOT) -> list[tuple[str, list[str]]]:
    """The parts of ``_toc.yml`` in order: (caption, the docnames of its chapters, without the
    sub-pages of a chapter)."""
    site = parse_toc_yaml(Path(root) / "_toc.yml")
    return [(tree.caption or "", [re.sub(r"\.(md|ipynb)$", "", f) for f in tree.files()])
            for tree in site[site.root.docname].subtrees]


def sub_pages(page: str, root: Path = ROOT) -> list[str]:
    """The sub-pages of a chapter (its ``sections`` in ``_toc.yml``), depth first."""
    site = parse_toc_yaml(Path(root) / "_toc.yml")
    doc = next(d for d in site if re.sub(r"\.(md|ipynb)$", "", d) == page)
    found: list[str] = []
    for tree in site[doc].subtrees:
        for child in tree.files():
            name = re.sub(r"\.(md|ipynb)$", "", child)
            found += [name, *sub_pages(name, root)]
    return found


def teaching_chapters(root: Path = ROOT) -> list[str]:
    """The notebook chapters of the teaching parts (without their sub-pages), in reading order."""
    return [p for caption, pages in parts(root) if caption in TEACHING_PARTS for p in pages
            if is_notebook(p, root)]
