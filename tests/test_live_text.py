"""The chapters' text where they run live: quoted numbers (``glued``) and claims (``claim``).

* ``{eval}`glued("key", "fmt")``` shows the glued value formatted exactly as the book's
  ``{glue:text}`key:fmt``` does, without quotes, in a kernel (what jupyterlab-myst evaluates)
  and in the HTML (tools/sphinx_live.py reads the same expression).
* ``claim(cond, statement)`` fails the book's build on a false claim and, in a live kernel,
  shows one line naming the statement and lets the notebook go on.
"""
import warnings

import numpy as np
import pytest

from orrc._validate import OrrcValueError
from orrc.viz import claim, glue, glued
from orrc.viz.claims import ClaimError, ClaimWarning
from tools.sphinx_live import parse_glued


@pytest.mark.parametrize("value, fmt, text", [(23.391, ".0f", "23"), (0.123456, ".4f", "0.1235"),
                                              (1234.5, ".3g", "1.23e+03"), (7, "", "7"),
                                              (3.0, "d", "3"), (12, ".1f", "12.0"), (0.25, ".0%", "25%")])
def test_a_quoted_number_reads_as_the_books_glue_text_renders_it(value, fmt, text):
    """The text/plain a kernel returns for ``glued(key, fmt)`` (its repr) is myst-nb's
    ``format_plain_text`` of the glued value's repr: the same number in the notebook and the HTML."""
    from myst_nb.core.variables import format_plain_text

    glue("test-live-q", value)
    quoted = glued("test-live-q", fmt)
    assert repr(quoted) == str(quoted) == text
    assert format_plain_text(repr(glued["test-live-q"]), fmt or "s") == text


def test_a_quoted_number_in_a_kernel_has_no_quotes():
    """A kernel formats an expression's value through IPython's display formatter: text/plain only,
    the bare number (a str would show as '23')."""
    from IPython.core.formatters import DisplayFormatter

    glue("test-live-k", 23.391)
    data, _ = DisplayFormatter().format(glued("test-live-k", ".0f"))
    assert data == {"text/plain": "23"}


def test_quoting_a_key_never_glued_or_a_bad_format_names_the_problem():
    glue("test-live-b", 1.5)
    with pytest.raises(OrrcValueError, match="key must be a key glued earlier.*'no-such-key'"):
        glued("no-such-key", ".1f")
    with pytest.raises(OrrcValueError, match="fmt '.1z' does not format"):
        glued("test-live-b", ".1z")
    with pytest.raises(OrrcValueError, match="fmt must be a format"):
        glued("test-live-b", 2)


@pytest.mark.parametrize("value", [3.25, np.float64(2.5), 7, "text", [1, 2]])
def test_in_a_build_kernel_without_myst_nb_glue_writes_what_myst_nb_writes(value):
    """The test build runs the chapters in the environment a download installs, which has no
    myst-nb: there ``glue`` writes the output myst-nb's ``glue`` writes (the book reads it)."""
    from IPython.core.interactiveshell import InteractiveShell
    from IPython.utils.capture import capture_output
    from myst_nb import glue as myst_glue

    from orrc.viz.notebook import _record

    InteractiveShell.instance()
    with capture_output() as theirs:
        myst_glue("test-live-r", value, display=False)
    with capture_output() as ours:
        _record("test-live-r", value)
    assert [(o.data, o.metadata) for o in ours.outputs] == [(o.data, o.metadata) for o in theirs.outputs]
    assert ours.outputs and all(k.startswith("application/papermill.record/") for k in ours.outputs[0].data)


@pytest.mark.parametrize("expression, parsed", [
    ('glued("l1-q19", ".0f")', ("l1-q19", ".0f")), ("glued('a-b')", ("a-b", "")),
    (' glued( "k" , ".2e" ) ', ("k", ".2e")), ("glued(k)", None), ("1 + 1", None),
    ('glued("k", ".2f") + 1', None)])
def test_the_html_book_reads_exactly_the_glued_form(expression, parsed):
    assert parse_glued(expression) == parsed


def test_in_the_book_build_a_false_claim_fails_with_its_statement(monkeypatch):
    monkeypatch.setenv("ORRC_BOOK_BUILD", "1")
    assert claim(2 < 3, "two is less than three") is None
    with pytest.raises(ClaimError, match="the warm start needs fewer iterations"):
        claim(5 < 3, "the warm start needs fewer iterations")
    assert issubclass(ClaimError, AssertionError)


def test_outside_a_kernel_and_the_build_a_false_claim_warns_and_goes_on(monkeypatch):
    monkeypatch.delenv("ORRC_BOOK_BUILD", raising=False)
    with pytest.warns(ClaimWarning, match="the text's statement no longer holds: .the plan starts at the bound"):
        claim(False, "the plan starts at the bound")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        claim(True, "the plan starts at the bound")


def test_a_claim_needs_a_statement_and_one_truth_value(monkeypatch):
    import numpy as np

    monkeypatch.setenv("ORRC_BOOK_BUILD", "1")
    with pytest.raises(OrrcValueError, match="statement must be the claim"):
        claim(True, "")
    with pytest.raises(OrrcValueError, match="condition must be one truth value"):
        claim(np.array([True, False]), "all hold")
    claim(np.bool_(True), "a numpy truth value")


def test_in_a_live_kernel_a_false_claim_shows_one_line_and_the_cell_goes_on():
    """A real kernel without the build signal: the cell with a false claim ends normally (its
    last print runs), shows one note naming the statement, and raises nothing; with
    ORRC_BOOK_BUILD=1 the same cell fails with the statement."""
    from benchmarks.widgets import ROOT, CheckFailed, Kernel, kernel_env

    code = ("from orrc.viz import claim, glue\nclaim(1 > 2, 'the bound holds at every step')\n"
            "glue('test-live-x', 2.5)\nprint('went on')")
    k = Kernel(ROOT / "book", kernel_env(quick=True))
    try:
        live = k.run(code)   # raises CheckFailed on an error
        with pytest.raises(CheckFailed, match="ClaimError: the bound holds at every step"):
            k.run("import os; os.environ['ORRC_BOOK_BUILD'] = '1'\n" + code)
    finally:
        k.close()
    notes = [m["content"]["data"]["text/plain"] for m in live
             if m["msg_type"] == "display_data" and "text/plain" in m["content"]["data"]]
    claims = [n for n in notes if "no longer holds" in n]
    assert len(claims) == 1 and "the bound holds at every step" in claims[0]
    assert "expected after changing a parameter" in claims[0]
    assert [m["content"]["text"] for m in live if m["msg_type"] == "stream"] == ["went on\n"]
    assert "Numbers quoted in the text: test-live-x = 2.5" in notes[-1]   # the fallback, under the cell


CHAPTER = """---
jupytext:
  text_representation:
    extension: .md
    format_name: myst
kernelspec:
  display_name: Python 3 (ipykernel)
  language: python
  name: python3
---

The gap is {eval}`glued("x-gap", ".0f")` times an increment, and {eval}`glued("x-missing")`.

```{code-cell} ipython3
from orrc.viz import glue, glued
glue("x-gap", 84.6)
```
"""


@pytest.mark.parametrize("stamp, shown", [("fresh", "85"), ("stale", None), ("test-size", None)])
def test_make_lab_shows_the_published_numbers_before_the_chapter_runs(tmp_path, stamp, shown):
    """make lab's contents manager hands out a chapter with its expressions' results from the
    published build (formatted as the HTML formats them), only when that build is of exactly these
    sources and at full size; a key the build did not glue stays an expression."""
    from conftest import run_coroutine
    import json

    pytest.importorskip("jupyter_server")
    from tools.build_book import inputs_digest
    from tools.lab_contents import ChapterContentsManager

    (tmp_path / "book").mkdir()
    (tmp_path / "book" / "x.md").write_text(CHAPTER, encoding="utf-8")
    glue_file = tmp_path / "_build" / "jupyter_execute" / "book" / "x.glue.json"
    glue_file.parent.mkdir(parents=True)
    glue_file.write_text(json.dumps({"x-gap": {"output_type": "display_data", "data": {"text/plain": "84.6"}}}))
    digest = inputs_digest(tmp_path) if stamp != "stale" else "0" * 64
    (tmp_path / "_build" / "orrc-build.json").write_text(json.dumps({"digest": digest, "quick": stamp == "test-size"}))
    cm = ChapterContentsManager(root_dir=str(tmp_path), book_root=str(tmp_path))
    model = run_coroutine(cm.get("book/x.md"))
    results = [r for c in model["content"]["cells"] for r in c["metadata"].get("user_expressions", [])]
    if shown is None:
        assert results == []
    else:
        assert results == [{"expression": 'glued("x-gap", ".0f")',
                            "result": {"status": "ok", "data": {"text/plain": shown}, "metadata": {}}}]


ROLES_CHAPTER = CHAPTER.replace(
    "The gap is", "As {cite:t}`paper2021` prove in {prf:ref}`lemma-two`, the gap is").replace(
    "```{code-cell}", "See {ref}`other-page` and `{cite:t}` in code.\n\n```{code-cell}")
ROLE_TEXTS = {"{cite:t}`paper2021`": "Author and Other (2021)", "{prf:ref}`lemma-two`": "Lemma 2",
              "{ref}`other-page`": "*The other page*"}


@pytest.mark.parametrize("stamp", ["fresh", "stale"])
def test_make_lab_shows_citations_and_references_as_the_book_does_and_saves_the_roles(tmp_path, stamp):
    """With a published build of exactly these sources, make lab hands out a chapter whose
    citations and references to other pages read as the HTML reads them (jupyterlab-myst alone
    would show their keys); saving writes the chapter's roles back: byte-identical when untouched,
    the roles kept around an edit."""
    from conftest import run_coroutine
    import json

    pytest.importorskip("jupyter_server")
    from tools.build_book import inputs_digest
    from tools.lab_contents import ChapterContentsManager

    import jupytext

    written = jupytext.writes(jupytext.reads(ROLES_CHAPTER, fmt="md:myst"), fmt="md:myst")  # as jupytext writes it
    chapter = tmp_path / "book" / "x.md"
    chapter.parent.mkdir()
    chapter.write_text(written, encoding="utf-8")
    built = tmp_path / "_build" / "jupyter_execute" / "book"
    built.mkdir(parents=True)
    (built / "x.roles.json").write_text(json.dumps(ROLE_TEXTS))
    digest = inputs_digest(tmp_path) if stamp == "fresh" else "0" * 64
    (tmp_path / "_build" / "orrc-build.json").write_text(json.dumps({"digest": digest, "quick": False}))
    cm = ChapterContentsManager(root_dir=str(tmp_path), book_root=str(tmp_path))
    model = run_coroutine(cm.get("book/x.md"))
    prose = "\n".join(c["source"] for c in model["content"]["cells"] if c["cell_type"] == "markdown")
    if stamp == "stale":
        assert "{cite:t}`paper2021`" in prose and "orrc_roles" not in json.dumps(model["content"])
        return
    assert "As Author and Other (2021) prove in Lemma 2, the gap is" in prose
    assert "See *The other page* and `{cite:t}` in code." in prose, "a role in inline code stays code"
    run_coroutine(cm.save({"type": "notebook", "format": "json", "content": model["content"]}, "book/x.md"))
    assert chapter.read_text(encoding="utf-8") == written
    model = run_coroutine(cm.get("book/x.md"))
    cell = next(c for c in model["content"]["cells"] if "Lemma 2" in c["source"])
    cell["source"] = cell["source"].replace("the gap is", "the gap, it turns out, is")
    run_coroutine(cm.save({"type": "notebook", "format": "json", "content": model["content"]}, "book/x.md"))
    assert chapter.read_text(encoding="utf-8") == written.replace("the gap is", "the gap, it turns out, is")
