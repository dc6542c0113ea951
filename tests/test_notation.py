"""One meaning per symbol, held where a program can hold it (the appendix book/notation.md lists
every symbol):

* symbols in the prose and in tables are math: a table header or cell never writes ``R^p_T`` or
  ``gamma_c`` as plain text;
* ρ is the radius of the states of Lemmas 3-4 only: no other page prints "rho" or ρ (the spectral
  radius of a closed loop is λ_K);
* σ is σ(x) only: no page prints a forecast or noise parameter as "sigma =".
"""
from __future__ import annotations

import re

import jupytext
import nbformat
import pytest

from conftest import BOOK_OUT, ROOT
from tools.toc import notebook_pages, sub_pages, teaching_chapters

PAGES = [p for c in teaching_chapters() for p in [c, *sub_pages(c)]]
_MATH = re.compile(r"\$[^$]*\$")
_CODE = re.compile(r"`[^`]*`")
_ROLE = re.compile(r"\{[\w:.-]+\}`[^`]*`")
# a symbol written as plain text: a letter with a TeX superscript or subscript (R^p_T, gamma_c, a_min)
_PLAIN_SYMBOL = re.compile(r"(?<![\w\\])(?:[A-Za-z]\^[\w{]|(?:gamma|alpha|theta|lambda|sigma|rho)_\w)")


def table_cells(markdown: str) -> list[str]:
    """The cells of every Markdown table of a page, math, code and roles removed."""
    cells = []
    for line in markdown.splitlines():
        if line.lstrip().startswith("|") and not re.fullmatch(r"\s*\|[\s:|-]+\|\s*", line):
            text = _ROLE.sub(" ", _CODE.sub(" ", _MATH.sub(" ", line)))
            cells += [c.strip() for c in text.strip().strip("|").split("|")]
    return cells


@pytest.mark.parametrize("page", PAGES)
def test_symbols_in_tables_are_math(page):
    nb = jupytext.read(ROOT / f"{page}.md")
    md = "\n".join(c.source for c in nb.cells if c.cell_type == "markdown")
    plain = [c for c in table_cells(md) if _PLAIN_SYMBOL.search(c)]
    assert not plain, f"{page}: table cells write symbols as plain text (use $...$): {plain[:5]}"


def printed(page: str) -> str:
    path = BOOK_OUT / "_build" / "jupyter_execute" / f"{page}.ipynb"
    nb = nbformat.read(path, as_version=4)
    out = []
    for cell in nb.cells:
        for o in cell.get("outputs", []) if cell.cell_type == "code" else []:
            out.append(o.get("text", "") if o.get("output_type") == "stream"
                       else o.get("data", {}).get("text/plain", ""))
    return "\n".join(out)


@pytest.mark.slow
@pytest.mark.parametrize("page", [p for p in notebook_pages() if "lemma3_4" not in p])
def test_rho_and_sigma_keep_their_meaning_in_printed_output(book, page):
    text = printed(page)
    assert not re.search(r"\brho\b|ρ", text), f"{page} prints rho/ρ, which is Lemmas 3-4's radius (use lambda_K)"
    assert not re.search(r"\bsigma\s*=", text), f"{page} prints 'sigma =', but σ is σ(x)"


# every page of the book's text whose source is Markdown (the notation appendix and the errata too)
TEXT_PAGES = sorted({*PAGES, "book/paper", "book/notation", "book/errata"})


@pytest.mark.parametrize("page", TEXT_PAGES)
def test_one_glyph_per_symbol(page):
    """The margin ε̃ of Lemma 2 is written \\tilde\\epsilon everywhere, as in the notation appendix
    (a reader who meets ϵ̃ and ε̃ takes them for two symbols)."""
    text = (ROOT / f"{page}.md").read_text()
    assert r"\tilde\varepsilon" not in text, f"{page} writes \\tilde\\varepsilon; the book writes \\tilde\\epsilon"


def test_the_model_error_is_eta():
    """Lemmas 3-4 perturb the model as θ̂ = θ + η d; the notation appendix says the same."""
    notation = (ROOT / "book" / "notation.md").read_text()
    chapter = (ROOT / "book" / "lemma3_4.md").read_text()
    assert r"\hat\theta = \theta + \eta" in chapter, "the chapter no longer writes θ̂ = θ + η d"
    assert r"\theta + \varepsilon" not in notation and r"\theta + \eta" in notation, \
        "the notation appendix writes the model error of Lemmas 3-4 as θ̂ = θ + η d, as the chapter does"
