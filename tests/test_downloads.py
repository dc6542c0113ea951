"""Every chapter's ``.ipynb`` download runs in a fresh environment installed as its first cell says.

The book offers each chapter as a plain notebook (``_sources/<page>.ipynb``, written by
tools/sphinx_offline.py); its first cell tells the reader what to install
(``pip install '.[book]'`` in the repository's folder). Here that is taken literally: the
command is read from the first cell of the session's built download; ``tests/fresh_env.py`` builds
a virtual environment with the machine's Python and what that command installs (no ``.venv``, no
requirements.txt pins): the dependencies ``pyproject.toml`` declares for the project and for the
extras the command names, then the project's wheel (what ``pip install .`` builds) without
dependencies. The environment is keyed by the dependencies (built once, about 100 s here); the
wheel is reinstalled every session (seconds).
Each download is then executed with nbclient in a kernel of that environment, from a working
directory outside the repository, at the test size (ORRC_QUICK=1), two chapters at a time.
"""
import json
import os
import re
import shlex
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import nbformat
import pytest

from conftest import BOOK_HTML, ROOT, after, background
from fresh_env import fresh_env, orrc_wheel, with_wheels
from tools.toc import notebook_pages

CHAPTERS = notebook_pages()
PIP = re.compile(r"pip install ('[^']+'|\"[^\"]+\"|\S+)")


def download(chapter: str) -> Path:
    return BOOK_HTML / "_sources" / f"{chapter}.ipynb"


def install_spec(first_cell: str) -> str:
    """The package spec of the ``pip install ...`` command that the download's first cell gives."""
    found = PIP.findall(first_cell)
    assert len(found) == 1, f"the first cell should give one `pip install` command; found {found}"
    return shlex.split(found[0])[0]


def requirement_lines(spec: str) -> list[str]:
    """What ``pip install <spec>`` installs for the project folder ``.`` with its extras: the
    dependencies ``pyproject.toml`` declares for them (the project itself comes as its wheel)."""
    import tomllib

    m = re.fullmatch(r"\.(?:\[([\w,-]+)\])?", spec)
    assert m, f"the first cell installs {spec!r}, not the project folder '.[extra]'"
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    lines = list(project["dependencies"])
    for extra in filter(None, (m.group(1) or "").split(",")):
        assert extra in project["optional-dependencies"], f"pyproject.toml has no extra {extra!r}"
        lines += project["optional-dependencies"][extra]
    return lines


def run_download(chapter: str, python: Path, timeout: float = 600) -> dict:
    """Execute the download of ``chapter`` in a kernel of ``python``, from a temporary folder."""
    from jupyter_client.kernelspec import KernelSpecManager
    from jupyter_client.manager import KernelManager
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError

    nb = nbformat.read(download(chapter), as_version=4)
    with tempfile.TemporaryDirectory(prefix="orrc-download-") as tmp:
        work = Path(tmp) / "work"
        spec_dir = Path(tmp) / "kernels" / "orrc-download"
        work.mkdir()
        spec_dir.mkdir(parents=True)
        env = {"ORRC_QUICK": "1", "MPLBACKEND": "module://matplotlib_inline.backend_inline"}
        (spec_dir / "kernel.json").write_text(json.dumps({
            "argv": [str(python), "-m", "ipykernel_launcher", "-f", "{connection_file}"],
            "display_name": "fresh environment", "language": "python", "env": env}))
        ksm = KernelSpecManager(kernel_dirs=[str(spec_dir.parent)])
        km = KernelManager(kernel_name="orrc-download", kernel_spec_manager=ksm)
        os_env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV",
                                                                  "ORRC_BOOK_BUILD")}
        nb.cells.append(nbformat.v4.new_code_cell("import sys, orrc\nprint(orrc.__file__)"))
        client = NotebookClient(nb, km=km, timeout=timeout, allow_errors=False,
                                resources={"metadata": {"path": str(work)}})
        t0 = time.perf_counter()
        error = None
        try:
            client.execute(env=os_env)   # the kernel's environment: nothing of the repository
        except CellExecutionError as exc:
            error = str(exc)[-1500:]
        imported = "".join(o.get("text", "") for o in nb.cells[-1].get("outputs", [])).strip()
        return {"error": error, "seconds": time.perf_counter() - t0, "orrc": imported}


@pytest.fixture(scope="session")
def downloads_run(book):
    """Every chapter's download executed in the fresh environment, two at a time: {chapter: result}
    (in the background as soon as the book is built, ``conftest.after``)."""
    return background("downloads_run")


@after("book", "downloads_run")
def run_the_downloads(book):
    assert book["rc"] == 0, "the book's build failed; its downloads are not there"
    first = nbformat.read(download(CHAPTERS[0]), as_version=4).cells[0].source
    t0 = time.perf_counter()
    # keyed by the dependencies only; the project's wheel goes on top (a package change reinstalls it)
    python = with_wheels(fresh_env("download", requirement_lines(install_spec(first))), [orrc_wheel()])
    env_seconds = time.perf_counter() - t0
    with ThreadPoolExecutor(max_workers=2) as pool:
        results = dict(zip(CHAPTERS, pool.map(lambda c: run_download(c, python), CHAPTERS)))
    print(f"\nfresh environment {env_seconds:.0f} s; chapters: " +
          ", ".join(f"{c.split('/')[-1]} {r['seconds']:.0f} s" for c, r in results.items()))
    return {"python": python, "results": results}


@pytest.mark.slow
@pytest.mark.parametrize("chapter", CHAPTERS)
def test_the_download_says_how_to_install_it(book, chapter):
    nb = nbformat.read(download(chapter), as_version=4)
    first = nb.cells[0]
    assert first.cell_type == "markdown"
    requirement_lines(install_spec(first.source))
    sources = "\n".join(c.source for c in nb.cells if c.cell_type == "code")
    assert "myst_nb" not in sources, f"{chapter}: the download imports myst_nb, which '.[book]' does not install"


@pytest.mark.slow
@pytest.mark.parametrize("chapter", CHAPTERS)
def test_the_download_runs_in_a_fresh_environment_outside_the_repository(downloads_run, chapter):
    result = downloads_run["results"][chapter]
    assert result["error"] is None, f"{chapter}: {result['error']}"
    env = Path(downloads_run["python"]).parent.parent
    assert Path(result["orrc"]).is_relative_to(env), (f"{chapter}: the kernel imported orrc from "
                                                       f"{result['orrc']!r}, not from the fresh environment {env}")
