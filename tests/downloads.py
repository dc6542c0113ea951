"""Every chapter's ``.ipynb`` download, run once per session as a student runs it.

The book offers each chapter as a plain notebook (``_sources/<page>.ipynb``, written by
tools/sphinx_offline.py and tools/download.py) with ``requirements-reader.txt`` and the ``orrc``
wheel beside it; its first cell says what to install (``pip install -r requirements-reader.txt``
in the folder of the three files). Here that is taken literally: the command is read from the
first cell of the session's built download, and ``tests/fresh_env.py`` builds a virtual
environment with the machine's Python and what that command installs (no ``.venv``): the
file's pinned registry lines (the environment is keyed by them and reused while they do not
change), then the wheel it names on top (reinstalled when the package changes; ``pip check``
confirms the result is what one ``pip install -r`` gives).

Each download is then executed with that environment's ``jupyter nbconvert --execute``, from a
temporary folder outside the repository holding only the three downloaded files, two chapters at
a time. The download holds the code cells the page shows; to run at the test size
(``ORRC_QUICK=1``) the chapter's ``size-switch`` cells (``T = orrc.config.size(T, 40)``, a no-op
at the full size) go back after the cells they follow, and a last cell prints where ``orrc``
was imported from. That run is the session's only execution of the reader's code, shared by two
checks: the download runs in a fresh environment (tests/test_downloads.py), and the visible code
of every page runs as a reader sees it (tests/test_visible_code.py).
"""
from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import jupytext
import nbformat

from conftest import BOOK_HTML, ROOT, after
from fresh_env import _local_files, fresh_env, with_wheels
from tools.toc import notebook_pages

CHAPTERS = notebook_pages()
PIP = re.compile(r"pip install ((?:-r\s+)?(?:'[^']+'|\"[^\"]+\"|\S+))")
SIZE_SWITCH = "size-switch"
HIDDEN = "remove-cell"
RUN_TIMEOUT = 900   # s, one chapter at the test size on a busy 2-core machine


def download(chapter: str) -> Path:
    return BOOK_HTML / "_sources" / f"{chapter}.ipynb"


def install_command(first_cell: str) -> list[str]:
    """The arguments of the one ``pip install ...`` command that the download's first cell gives."""
    found = PIP.findall(first_cell)
    assert len(found) == 1, f"the first cell should give one `pip install` command; found {found}"
    return shlex.split(found[0])


def requirements_of(chapter: str) -> tuple[list[str], list[Path]]:
    """(registry requirement lines, local wheels) that the download's install command installs,
    read from the requirements file it names, beside the download."""
    nb = nbformat.read(download(chapter), as_version=4)
    args = install_command(nb.cells[0].source)
    assert args[0] == "-r" and len(args) == 2, f"the first cell installs {args}, not one requirements file"
    folder = download(chapter).parent
    req = folder / args[1]
    assert req.is_file(), f"{req.name} is not beside {download(chapter).name} in the build"
    lines = [line.strip() for line in req.read_text(encoding="utf-8").splitlines()
             if line.strip() and not line.lstrip().startswith("#")]
    # pip reads a relative path in a requirements file from the folder it runs in: the download's
    wheels = [w for w in _local_files(lines, folder) if w.suffix == ".whl"]
    registry = [line for line in lines if not _local_files([line], folder)]
    assert len(registry) + len(wheels) == len(lines), f"unexpected lines in {req}: {lines}"
    return registry, wheels


def size_switched(chapter: str, nb: nbformat.NotebookNode) -> nbformat.NotebookNode:
    """The download with its chapter's size-switch cells put back after the code cells they follow
    (the download's code cells are the chapter's code cells not tagged ``remove-cell``)."""
    source = jupytext.read(ROOT / f"{chapter}.md")
    shown, switches = 0, {}
    for cell in source.cells:
        if cell.cell_type != "code":
            continue
        tags = set(cell.metadata.get("tags", []))
        if SIZE_SWITCH in tags:
            switches.setdefault(shown, []).append(cell.source)
        elif HIDDEN not in tags:
            shown += 1
    code = [i for i, c in enumerate(nb.cells) if c.cell_type == "code"]
    assert len(code) == shown, f"{chapter}: the download has {len(code)} code cells, the page shows {shown}"
    out = nbformat.v4.new_notebook(metadata=nb.metadata)
    out.cells = [nbformat.v4.new_code_cell(s) for s in switches.get(0, [])]
    for k, cell in enumerate(nb.cells):
        out.cells.append(cell)
        if cell.cell_type == "code":
            n = code.index(k) + 1
            out.cells += [nbformat.v4.new_code_cell(s) for s in switches.get(n, [])]
    out.cells.append(nbformat.v4.new_code_cell("import orrc\nprint(orrc.__file__)"))
    return out


def run_download(chapter: str, python: Path, out: Path) -> dict:
    """Execute the download of ``chapter`` (size-switched) with ``jupyter nbconvert --execute`` of
    the fresh environment ``python``, in a temporary folder holding the downloaded files only;
    keep the executed notebook as ``out``."""
    with tempfile.TemporaryDirectory(prefix="orrc-download-") as tmp:
        work = Path(tmp) / "work"
        work.mkdir()
        src = download(chapter)
        for f in src.parent.iterdir():   # the notebook, requirements-reader.txt, the wheel
            if f.suffix in (".txt", ".whl") or f == src:
                shutil.copy2(f, work / f.name)
        nb = size_switched(chapter, nbformat.read(src, as_version=4))
        nbformat.write(nb, work / src.name)
        # nothing of the repository or of the user's Jupyter: the environment's own kernel
        env = {k: v for k, v in os.environ.items()
               if k not in ("PYTHONPATH", "VIRTUAL_ENV", "ORRC_BOOK_BUILD", "JUPYTER_PATH", "JUPYTER_CONFIG_DIR")}
        env.update(ORRC_QUICK="1", JUPYTER_DATA_DIR=str(Path(tmp) / "data"), JUPYTER_CONFIG_DIR=str(Path(tmp) / "config"),
                   JUPYTER_RUNTIME_DIR=str(Path(tmp) / "runtime"), MPLBACKEND="module://matplotlib_inline.backend_inline")
        cmd = [str(python), "-m", "jupyter", "nbconvert", "--to", "notebook", "--execute", src.name,
               "--output", "executed.ipynb", f"--ExecutePreprocessor.timeout={RUN_TIMEOUT}",
               "--ExecutePreprocessor.kernel_name=python3"]
        t0 = time.perf_counter()
        run = subprocess.run(cmd, cwd=work, env=env, capture_output=True, text=True, timeout=3 * RUN_TIMEOUT)
        seconds = time.perf_counter() - t0
        executed = work / "executed.ipynb"
        error, imported = None, ""
        if run.returncode != 0 or not executed.is_file():
            error = (run.stderr or run.stdout)[-2500:]
        else:
            out.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(executed, out)
            last = nbformat.read(executed, as_version=4).cells[-1]
            imported = "".join(o.get("text", "") for o in last.get("outputs", [])).strip()
        return {"error": error, "seconds": seconds, "orrc": imported, "executed": out if error is None else None,
                "command": " ".join(cmd[1:5] + ["--execute", src.name])}


@after("book", "downloads_run", order=-1)   # the longest job after the book
def run_the_downloads(book):
    """Every chapter's download executed once in the fresh environment its first cell installs,
    two at a time: {"python", "env_seconds", "results": {chapter: run_download(...)}}."""
    assert book["rc"] == 0, "the book's build failed; its downloads are not there"
    t0 = time.perf_counter()
    registry, wheels = requirements_of(CHAPTERS[0])
    # keyed by the registry pins only; the wheel goes on top (a package change reinstalls it in seconds)
    python = with_wheels(fresh_env("reader", registry), wheels)
    env_seconds = time.perf_counter() - t0
    executed = BOOK_HTML.parents[1] / "downloads-executed"
    shutil.rmtree(executed, ignore_errors=True)
    with ThreadPoolExecutor(max_workers=2) as pool:
        results = dict(zip(CHAPTERS, pool.map(
            lambda c: run_download(c, python, executed / f"{c}.ipynb"), CHAPTERS)))
    print(f"\nreader environment {env_seconds:.0f} s; chapters: " +
          ", ".join(f"{c.split('/')[-1]} {r['seconds']:.0f} s" for c, r in results.items()))
    return {"python": python, "env_seconds": env_seconds, "results": results}

