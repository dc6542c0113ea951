"""Every chapter's ``.ipynb`` download runs in a fresh environment installed as its first cell says,
and shows its text in any Jupyter front end (no MyST role or directive left in its Markdown).

How the downloads are run (once per session, shared with tests/test_visible_code.py):
tests/downloads.py.
"""
from pathlib import Path

import nbformat
import pytest

from conftest import background
from downloads import CHAPTERS, download, install_command, requirements_of
from tools.download import raw_markup


@pytest.fixture(scope="session")
def downloads_run(book):
    """Every chapter's download executed in the fresh environment (in the background as soon as
    the book is built, ``conftest.after``; tests/downloads.py)."""
    return background("downloads_run")


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
    for build_only in ("myst_nb", "claim(", "glue(", "orrc.config.size("):
        assert build_only not in sources, f"{chapter}: the download keeps the build's {build_only!r}"


@pytest.mark.slow
@pytest.mark.parametrize("chapter", CHAPTERS)
def test_the_download_runs_in_a_fresh_environment_outside_the_repository(downloads_run, chapter):
    result = downloads_run["results"][chapter]
    assert result["error"] is None, f"{chapter}: `{result['command']}` failed:\n{result['error']}"
    env = Path(downloads_run["python"]).parent.parent
    assert Path(result["orrc"]).is_relative_to(env), (f"{chapter}: the kernel imported orrc from "
                                                       f"{result['orrc']!r}, not from the fresh environment {env}")


@pytest.mark.slow
@pytest.mark.parametrize("chapter", CHAPTERS)
def test_the_executed_download_shows_no_myst_markup(downloads_run, chapter):
    """The notebook as nbconvert executed it: no raw {eval}, {prf:...}, {cite...}, {numref}, {eq},
    {ref}, {py:...} role and no directive in its Markdown (what Jupyter Notebook 7, JupyterLab
    without extensions, VS Code and Colab would show raw)."""
    result = downloads_run["results"][chapter]
    assert result["executed"] is not None, f"{chapter}: the download did not run: {result['error']}"
    raw = raw_markup(nbformat.read(result["executed"], as_version=4))
    assert not raw, f"{chapter}: MyST markup left in the download's Markdown: {raw[:5]}"
