"""The chapters of the book, one test per chapter of _toc.yml (so that new chapters are held to the
same rules without a change here).

* Every chapter executes top to bottom without an error (ORRC_QUICK=1 sizes). The session's one book
  build (the ``book`` fixture of conftest.py: forced execution of every chapter, in a fresh kernel
  each) writes each executed notebook to ``_build/test/_build/jupyter_execute/<page>.ipynb``; the
  tests read them back. A hidden claim check (``claim(cond, "statement")`` in a ``remove-cell``
  cell) that fails raises in the book's build, so it fails here and fails the build.
* The chapters read as live notebooks: claims are ``claim(...)`` calls with a statement, never an
  ``assert`` (which would halt a reader's what-if run); every number the prose quotes,
  ``{eval}`glued("key", "fmt")```, is a key the chapter glues; ``glue`` comes from ``orrc.viz``
  (never ``myst_nb``); hidden cells are collapsed in JupyterLab too (``jupyter.source_hidden``).
* Visible cells hold teaching code only: the switch between the full and the test size
  (``orrc.config``) lives in cells tagged ``remove-cell``.
* A chapter saved unchanged by JupyterLab stays byte-identical: its header is the one jupytext writes.
* Numbers that two chapters both quote agree.
"""
import ast
import json
import re

import jupytext
import nbformat
import pytest

from conftest import BOOK_OUT, ROOT, run_coroutine
from tools.toc import notebook_pages

CHAPTERS = notebook_pages()


def executed(chapter):
    return BOOK_OUT / "_build" / "jupyter_execute" / f"{chapter}.ipynb"


def glued(chapter) -> dict:
    """The values a chapter glued, as text: myst-nb writes them beside the executed notebook,
    into ``<page>.glue.json`` (the notebook itself keeps no glue output)."""
    data = json.loads(executed(chapter).with_suffix(".glue.json").read_text(encoding="utf-8"))
    return {name: next(v for k, v in out["data"].items() if k.endswith("text/plain")) for name, out in data.items()}


@pytest.mark.slow
@pytest.mark.parametrize("chapter", CHAPTERS)
def test_chapter_executes(book, chapter):
    path = executed(chapter)
    assert path.is_file(), f"{chapter}: the build wrote no executed notebook {path}"
    assert path.stat().st_mtime >= book["started"], f"{chapter}: {path} is older than this build"
    nb = nbformat.read(path, as_version=4)
    assert any(c.get("outputs") for c in nb.cells), f"{chapter}: the executed notebook has no outputs"
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            assert out.get("output_type") != "error", f"{chapter}: {out.get('ename')}: {out.get('evalue')}"
            if out.get("name") == "stderr":
                assert "Traceback" not in out.get("text", ""), f"{chapter} printed a traceback"


SIZE_SWITCH = re.compile(r"\borrc\.config\.|\bORRC_QUICK\b|\bconfig\.(quick|size)\(")


@pytest.mark.parametrize("chapter", CHAPTERS)
def test_visible_cells_hold_teaching_code_only(chapter):
    """The full/test size switch is not where a reader sees it: only cells tagged remove-cell use
    ``orrc.config`` (``T = orrc.config.size(200, 80)`` there, ``T`` in the visible cell)."""
    nb = jupytext.read(ROOT / f"{chapter}.md")
    shown = [c.source for c in nb.cells if c.cell_type == "code"
             and "remove-cell" not in c.metadata.get("tags", [])]
    offending = [src.splitlines()[0] + " ..." for src in shown if SIZE_SWITCH.search(src)]
    assert not offending, (f"{chapter}: visible cells switch sizes for the tests; move the switch into a cell "
                           f"tagged remove-cell: {offending}")


def jupyterlab_save(path):
    """The text JupyterLab writes when it saves the text notebook ``path`` after Run All, its text
    unchanged.

    ``make lab`` reads the file through its contents manager (``tools/lab_contents.py``: jupytext's,
    which hands out the chapter with the kernel's ``language_info``); JupyterLab records the running
    kernel's spec (the installed ``python3`` kernel: display name "Python 3 (ipykernel)") and its
    ``language_info``, jupyterlab-myst stores the results of the prose's inline expressions in each
    Markdown cell's metadata (``user_expressions``), and the notebook is saved back through the same
    contents manager, on a copy of the file. Without jupyter_server (no ``make lab``), the same steps
    with jupytext's reader and writer and the contents manager's metadata filter.
    """
    import shutil
    import tempfile
    from pathlib import Path

    from jupyter_client.kernelspec import KernelSpecManager

    text = Path(path).read_text(encoding="utf-8")
    name = jupytext.reads(text, fmt="md:myst").metadata.get("kernelspec", {}).get("name", "python3")
    spec = KernelSpecManager().get_kernel_spec(name)
    kernelspec = {"display_name": spec.display_name, "language": spec.language, "name": name}
    language_info = {"name": "python", "mimetype": "text/x-python", "file_extension": ".py",
                     "pygments_lexer": "ipython3", "nbconvert_exporter": "python",
                     "codemirror_mode": {"name": "ipython", "version": 3}}

    def as_after_run_all(nb):
        nb["metadata"].update(kernelspec=kernelspec, language_info=language_info)
        for cell in nb["cells"]:
            for expr in EVAL.findall(cell["source"]) if cell["cell_type"] == "markdown" else []:
                cell["metadata"].setdefault("user_expressions", []).append(
                    {"expression": expr, "result": {"status": "ok", "data": {"text/plain": "1.5"}, "metadata": {}}})

    try:
        from tools.lab_contents import NOT_SAVED, ChapterContentsManager
    except ImportError:
        from jupytext.config import JupytextConfiguration

        config = JupytextConfiguration(cell_metadata_filter="-user_expressions")
        fmt = {"extension": ".md", "format_name": "myst"}
        nb = jupytext.reads(text, fmt=fmt, config=config)
        as_after_run_all(nb)
        return jupytext.writes(nb, fmt=fmt, config=config)
    assert NOT_SAVED == ("user_expressions", "orrc_roles")
    with tempfile.TemporaryDirectory() as tmp:
        shutil.copy(path, Path(tmp) / Path(path).name)
        cm = ChapterContentsManager(root_dir=tmp)
        model = run_coroutine(cm.get(Path(path).name))
        assert model["content"]["metadata"].get("language_info", {}).get("name") == "python"
        as_after_run_all(model["content"])
        run_coroutine(cm.save(model, Path(path).name))
        return (Path(tmp) / Path(path).name).read_text(encoding="utf-8")


def jupytext_header() -> str:
    """The header jupytext writes for a MyST notebook of this repository's pinned jupytext."""
    from jupyter_client.kernelspec import KernelSpecManager

    spec = KernelSpecManager().get_kernel_spec("python3")
    return ("---\njupytext:\n  text_representation:\n    extension: .md\n    format_name: myst\n"
            f"    format_version: 0.13\n    jupytext_version: {jupytext.__version__}\nkernelspec:\n"
            f"  display_name: {spec.display_name}\n  language: {spec.language}\n  name: python3\n---\n")


@pytest.mark.parametrize("chapter", CHAPTERS)
def test_saving_a_chapter_in_jupyterlab_leaves_it_byte_identical(chapter):
    path = ROOT / f"{chapter}.md"
    original = path.read_text(encoding="utf-8")
    saved = jupyterlab_save(path)
    if saved != original:
        import difflib

        diff = "".join(list(difflib.unified_diff(original.splitlines(True), saved.splitlines(True),
                                                 "in git", "after a save in JupyterLab"))[:40])
        pytest.fail(f"{chapter}.md changes when JupyterLab saves it unchanged. Start the chapter with exactly "
                    f"the header jupytext writes:\n\n{jupytext_header()}\n(and keep the cells as jupytext writes "
                    f"them). The change:\n{diff}")


def code_cells(chapter):
    return [c for c in jupytext.read(ROOT / f"{chapter}.md").cells if c.cell_type == "code"]


@pytest.mark.parametrize("chapter", CHAPTERS)
def test_claims_are_claim_calls_that_inform_in_a_live_notebook(chapter):
    """No ``assert`` in a chapter's cells: in a live kernel an assert halts Run All at the first
    claim a reader's change of a parameter contradicts; ``claim(cond, "statement")`` fails only the
    book's build and shows a note in a live notebook. Every claim states what it checks."""
    from IPython.core.inputtransformer2 import TransformerManager

    found = []
    for cell in code_cells(chapter):
        python = TransformerManager().transform_cell(cell.source)   # IPython magics as Python
        for node in ast.walk(ast.parse(python)):
            if isinstance(node, ast.Assert):
                found.append(f"assert at line {node.lineno} of {cell.source.splitlines()[0][:50]!r}")
            elif (isinstance(node, ast.Call) and getattr(node.func, "id", None) == "claim"
                  and not (len(node.args) >= 2 and (isinstance(node.args[1], ast.JoinedStr)
                                                    or isinstance(node.args[1], ast.Constant)
                                                    and str(node.args[1].value).strip()))):
                found.append(f"claim without a statement at line {node.lineno}")
    assert not found, (f"{chapter}: write each claim as claim(condition, \"the statement of the text\") "
                       f"(from orrc.viz import claim): {found}")


@pytest.mark.parametrize("chapter", CHAPTERS)
def test_glue_comes_from_orrc_viz(chapter):
    """``orrc.viz.glue`` works wherever ``orrc`` is installed; ``myst_nb`` is not in '.[book]'."""
    offending = [c.source.splitlines()[0] for c in code_cells(chapter) if re.search(r"\bmyst_nb\b", c.source)]
    assert not offending, f"{chapter}: import glue from orrc.viz, not myst_nb: {offending}"


@pytest.mark.parametrize("chapter", CHAPTERS)
def test_hidden_cells_are_collapsed_in_jupyterlab(chapter):
    """A cell the book hides (remove-cell, remove-input) shows collapsed in JupyterLab too, so
    size switches and claim checks are out of the reader's way there as well."""
    open_ = [c.source.splitlines()[0][:60] for c in code_cells(chapter)
             if {"remove-cell", "remove-input"} & set(c.metadata.get("tags", []))
             and not c.metadata.get("jupyter", {}).get("source_hidden")]
    assert not open_, f"{chapter}: hidden cells without jupyter: {{source_hidden: true}}: {open_}"


EVAL = re.compile(r"\{eval\}`([^`]*)`")


@pytest.mark.parametrize("chapter", CHAPTERS)
def test_the_prose_quotes_numbers_as_glued_expressions(chapter):
    """Numbers in the prose are ``{eval}`glued("key", "fmt")``` (rendered in JupyterLab and in the
    HTML), no longer ``{glue:text}`` (a bare key in JupyterLab), and the chapter imports ``glued``."""
    from tools.sphinx_live import parse_glued

    text = (ROOT / f"{chapter}.md").read_text(encoding="utf-8")
    assert "{glue:text}" not in text, f"{chapter}: quote numbers as {{eval}}`glued(\"key\", \"fmt\")`"
    bad = [e for e in EVAL.findall(text) if parse_glued(e) is None]
    assert not bad, f"{chapter}: inline expressions other than glued(\"key\", \"fmt\"): {bad}"
    if EVAL.search(text):
        assert re.search(r"^from orrc\.viz import .*\bglued\b", text, re.M), \
            f"{chapter}: the prose evaluates glued(...); import it (from orrc.viz import glue, glued)"


@pytest.mark.slow
@pytest.mark.parametrize("chapter", CHAPTERS)
def test_every_quoted_key_is_glued_by_the_chapter(book, chapter):
    """Every key the prose quotes is one the executed chapter glued (else a live notebook shows an
    error where the number should be)."""
    from tools.sphinx_live import parse_glued

    keys = {parse_glued(e)[0] for e in EVAL.findall((ROOT / f"{chapter}.md").read_text(encoding="utf-8"))
            if parse_glued(e)}
    if not keys:
        return
    missing = sorted(keys - set(glued(chapter)))
    assert not missing, f"{chapter}: the prose quotes keys the chapter never glues: {missing}"


def _number(text: str) -> float:
    return float(json.loads(text) if text.strip().startswith('"') else text)


@pytest.mark.slow
def test_the_van_der_pol_gamma_c_is_the_same_on_the_lemma1_deeper_and_theorem1_pages(book):
    """Both pages estimate the Van der Pol constants at M = 40 by the same sampling (30 samples,
    seed 0), at both sizes, so they quote the same estimated γ_c."""
    l1, t1 = glued("book/lemma1_deeper"), glued("book/theorem1")
    assert _number(l1["l1-vdp-gc"]) == pytest.approx(_number(t1["t1-vdp-gc40"]), rel=1e-12)
