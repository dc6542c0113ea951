"""Every chapter teaches first, then checks (tools/teaching_shape.py has the measures):

* a main path of about 2,000 words at most and a page of about 4,500 (its sub-pages too);
* a computation from scratch printed equal to orrc's: the line "largest difference, from
  scratch vs orrc: ..." below 1e-8;
* a main figure drawn by visible matplotlib code, numbered and captioned;
* "Reading the paper critically" at the end of the main path, only exercises and references after;
* the map of the paper's results links every result to its chapter.

The chapters are those of the teaching parts of ``_toc.yml`` (tools.toc.TEACHING_PARTS); the
executed notebooks are the session's one book build (the ``book`` fixture).
"""
from __future__ import annotations


import nbformat
import pytest

from conftest import BOOK_HTML, BOOK_OUT
from tools import teaching_shape as shape
from tools.toc import sub_pages, teaching_chapters

CHAPTERS = teaching_chapters()
SUB_PAGES = [s for c in CHAPTERS for s in sub_pages(c)]


def executed(page: str):
    path = BOOK_OUT / "_build" / "jupyter_execute" / f"{page}.ipynb"
    assert path.is_file(), f"{page}: the build wrote no executed notebook {path}"
    return nbformat.read(path, as_version=4)


def test_the_teaching_parts_hold_every_chapter_of_the_paper():
    names = {c.split("/")[-1] for c in CHAPTERS}
    assert {"problem", "preview_rhc", "lemma1", "lemma2", "theorem1", "unknown_systems", "lemma3_4",
            "theorem2", "minmax", "comparison"} <= names, sorted(names)


@pytest.mark.slow
@pytest.mark.parametrize("chapter", CHAPTERS)
def test_a_chapter_has_a_short_main_path(book, chapter):
    n = shape.main_path_words(executed(chapter))
    assert n <= shape.MAIN_PATH_MAX, (f"{chapter}: the main path has {n} words (about 2,000 at most): move "
                                      "deeper material to a 'Going deeper' section or a sub-page")


@pytest.mark.slow
@pytest.mark.parametrize("page", CHAPTERS + SUB_PAGES)
def test_a_page_is_short(book, page):
    n = shape.page_words(executed(page))
    assert n <= shape.PAGE_MAX, f"{page}: the page shows {n} words with code and output (about 4,500 at most)"


@pytest.mark.slow
@pytest.mark.parametrize("chapter", CHAPTERS)
def test_the_computation_from_scratch_equals_orrc(book, chapter):
    diffs = shape.scratch_differences(executed(chapter))
    assert diffs, f"{chapter}: no line 'largest difference, from scratch vs orrc: ...' is printed"
    assert all(d < shape.SCRATCH_TOLERANCE for d in diffs), f"{chapter}: from scratch vs orrc differ: {diffs}"


@pytest.mark.slow
@pytest.mark.parametrize("chapter", CHAPTERS)
def test_the_main_figure_is_drawn_by_visible_code(book, chapter):
    assert shape.main_figure_cells(executed(chapter)), (
        f"{chapter}: no visible code cell draws a figure with matplotlib and gives it a number and a "
        "caption (mystnb: figure: name, caption)")


@pytest.mark.parametrize("chapter", CHAPTERS)
def test_reading_the_paper_critically_closes_the_main_path(chapter):
    import jupytext

    from tools.toc import ROOT

    problems = shape.critical_section_problems(jupytext.read(ROOT / f"{chapter}.md"))
    assert not problems, f"{chapter}: {problems}"


def test_the_map_links_every_result_to_its_chapter():
    """The map of the paper's results (tools/sphinx_map.py) is SVG whose boxes link to chapters of
    the book, with a text alternative."""
    import xml.etree.ElementTree as ET

    from tools.sphinx_map import RESULTS, RESTS_ON, draw_svg
    from tools.toc import toc_pages

    pages = set(toc_pages())
    assert {r.page for r in RESULTS} <= pages, "a box of the map points to a page not in _toc.yml"
    keys = {r.key for r in RESULTS}
    assert all(a in keys and b in keys for a, b in RESTS_ON)
    svg = draw_svg({r.page: f"{r.page}.html" for r in RESULTS})
    root = ET.fromstring(svg)
    ns = {"svg": "http://www.w3.org/2000/svg", "xlink": "http://www.w3.org/1999/xlink"}
    hrefs = {a.get(f"{{{ns['xlink']}}}href") for a in root.iter(f"{{{ns['svg']}}}a")}
    assert {f"{r.page}.html" for r in RESULTS} <= hrefs
    assert root.find("svg:title", ns) is not None and "Lemma 6" in root.find("svg:title", ns).text


@pytest.mark.slow
def test_the_map_is_on_the_paper_at_a_glance_and_its_links_resolve(book):
    from bs4 import BeautifulSoup

    assert book["rc"] == 0, "the book build failed"
    page = BOOK_HTML / "book" / "paper.html"
    soup = BeautifulSoup(page.read_text(encoding="utf-8"), "html.parser")
    svg = soup.find("svg", class_="orrc-results-map")
    assert svg is not None, "the paper-at-a-glance page has no map"
    links = [a.get("xlink:href") or a.get("href") for a in svg.find_all("a")]
    assert links and all((page.parent / link.split("#")[0]).resolve().is_file() for link in links), links
