"""Every chapter's ``.ipynb`` download runs in a fresh environment installed as its first cell says,
and shows its text in any Jupyter front end (no MyST role or directive left in its Markdown).

Each chapter runs once per session, in the session's book build, in the environment its download
installs (tests/downloads.py); these checks read that run and the built downloads.
"""
import json
import os
import subprocess
import tempfile
import zipfile
from pathlib import Path

import nbformat
import pytest
import yaml

from conftest import BOOK_OUT, ROOT
from downloads import CHAPTERS, download, install_command, requirements_of, visible_code
from fresh_env import orrc_wheel, reader_requirements
from tools.download import portable_source, raw_markup


@pytest.mark.slow
@pytest.mark.parametrize("chapter", CHAPTERS)
def test_the_download_says_how_to_install_it_and_needs_no_build_tool(book, chapter):
    nb = nbformat.read(download(chapter), as_version=4)
    first = nb.cells[0]
    assert first.cell_type == "markdown"
    assert install_command(first.source)[0] == "-r"
    registry, wheels = requirements_of(chapter)
    assert len(wheels) == 1 and wheels[0].name.startswith("orrc-"), f"{chapter}: the install names {wheels}"
    assert all("==" in line for line in registry), f"{chapter}: unpinned requirements {registry}"
    names = {line.split("==")[0].lower().replace("_", "-") for line in registry}
    assert {"notebook", "nbconvert", "ipykernel", "matplotlib"} <= names, (
        f"{chapter}: the install gives no Jupyter front end, nbconvert or kernel: {sorted(names)}")
    sources = "\n".join(c.source for c in nb.cells if c.cell_type == "code")
    for build_only in ("myst_nb", "claim(", "glue(", "glued(", "orrc.config.size("):
        assert build_only not in sources, f"{chapter}: the download keeps the build's {build_only!r}"


def _wheel_files(wheel: Path) -> dict[str, bytes]:
    """The package files of a wheel (its ``orrc/`` modules), by name."""
    with zipfile.ZipFile(wheel) as zf:
        return {n: zf.read(n) for n in zf.namelist() if n.startswith("orrc/")}


@pytest.mark.slow
@pytest.mark.parametrize("chapter", CHAPTERS)
def test_the_download_installs_the_environment_the_chapter_ran_in(book, chapter):
    """The session's one run of the chapter (the book's build) was in the environment that the
    download's install command gives: the same pinned registry lines, the same package (the
    session's wheel, tests/fresh_env.py, that the build's environment installs)."""
    registry, wheels = requirements_of(chapter)
    assert registry == reader_requirements(), f"{chapter}: the download installs other pins than the build ran with"
    assert _wheel_files(wheels[0]) == _wheel_files(orrc_wheel()), f"{chapter}: the download's wheel is another orrc"


@pytest.mark.slow
@pytest.mark.parametrize("chapter", CHAPTERS)
def test_the_download_holds_the_code_the_page_shows(book, chapter):
    """The page's visible code cells, in order, with the build's names (``claim``, ``glue``,
    ``glued``, which no visible cell calls) left out of their imports."""
    nb = nbformat.read(download(chapter), as_version=4)
    code = [c.source for c in nb.cells if c.cell_type == "code"]
    assert code == [portable_source(c) for c in visible_code(chapter)], (
        f"{chapter}: the download's code cells are not the page's visible ones")


@pytest.mark.slow
def test_the_chapters_ran_in_a_fresh_environment_outside_the_repository(book):
    """The build's kernel is the fresh environment's Python, with nothing of the checkout on its
    path; it imports orrc from that environment; each chapter runs in a temporary folder."""
    assert book["rc"] == 0, "the book's build failed"
    env = Path(book["python"]).parent.parent
    assert not env.is_relative_to(ROOT / ".venv") and (env / "pyvenv.cfg").is_file()
    spec = json.loads((BOOK_OUT / "_build" / "kernel" / "kernels" / "python3" / "kernel.json").read_text())
    assert spec["argv"][0] == str(book["python"]) and spec["env"]["PYTHONPATH"] == ""
    assert yaml.safe_load((ROOT / "_config.yml").read_text())["execute"]["run_in_temp"] is True
    with tempfile.TemporaryDirectory() as tmp:
        run = subprocess.run([str(book["python"]), "-c", "import orrc; print(orrc.__file__)"], cwd=tmp,
                             env={**os.environ, **spec["env"]}, capture_output=True, text=True, check=True)
    assert Path(run.stdout.strip()).is_relative_to(env), f"the kernel imports orrc from {run.stdout.strip()!r}"


@pytest.mark.slow
@pytest.mark.parametrize("chapter", CHAPTERS)
def test_the_chapter_ran_to_the_end_in_that_environment(book, chapter):
    nb = nbformat.read(BOOK_OUT / "_build" / "jupyter_execute" / f"{chapter}.ipynb", as_version=4)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert code and all(c.get("execution_count") for c in code), f"{chapter}: a code cell did not run"
    errors = [o for c in code for o in c.get("outputs", []) if o.get("output_type") == "error"]
    assert not errors, f"{chapter}: {errors[0].get('ename')}: {errors[0].get('evalue')}"


@pytest.mark.slow
@pytest.mark.parametrize("chapter", CHAPTERS)
def test_the_download_shows_no_myst_markup(book, chapter):
    """No raw {eval}, {prf:...}, {cite...}, {numref}, {eq}, {ref}, {py:...} role and no directive
    in the download's Markdown (what Jupyter Notebook 7, JupyterLab without extensions, VS Code and
    Colab would show raw)."""
    raw = raw_markup(nbformat.read(download(chapter), as_version=4))
    assert not raw, f"{chapter}: MyST markup left in the download's Markdown: {raw[:5]}"


@pytest.mark.slow
@pytest.mark.parametrize("chapter", CHAPTERS)
def test_the_build_writes_the_text_of_every_citation_and_reference_for_make_lab(book, chapter):
    """``make lab`` shows a chapter's citations, references and API names as the HTML does, from
    ``<page>.roles.json`` of the build (tools/lab_contents.py): every such role of the chapter has
    its text there, and no text is a bare key."""
    import jupytext

    from tools.download import CODE_BLOCK, LAB_ROLES, ROLE

    texts = json.loads((BOOK_OUT / "_build" / "jupyter_execute" / f"{chapter}.roles.json").read_text(encoding="utf-8"))
    nb = jupytext.read(ROOT / f"{chapter}.md")
    markdown = CODE_BLOCK.sub("", "\n".join(c.source for c in nb.cells if c.cell_type == "markdown"))
    roles = {m.group(0) for m in ROLE.finditer(markdown) if m.group("role") and LAB_ROLES.match(m.group("role"))}
    assert roles == set(texts), f"{chapter}: roles without a text: {sorted(roles - set(texts))[:5]}"
    # a citation or an untitled reference that reads as its own key or label was not resolved
    bare = [r for r, t in texts.items() if not t.strip() or (
        not r.startswith("{py:") and "<" not in r and t.strip("*` ") == r.split("`")[1])]
    assert not bare, f"{chapter}: roles shown as their keys: {bare[:5]}"
