"""Every chapter's ``.ipynb`` download, and the one run of each chapter that the checks share.

The book offers each chapter as a plain notebook (``_sources/<page>.ipynb``, written by
tools/sphinx_offline.py and tools/download.py) with ``requirements-reader.txt`` and the ``orrc``
wheel beside it; its first cell says what to install (``pip install -r requirements-reader.txt``
in the folder of the three files). The download holds the code cells the page shows (those not
tagged ``remove-cell``).

Each chapter is executed once per session: by the session's book build (the ``book`` fixture of
conftest.py), in a kernel of the environment that this install command gives (tests/fresh_env.py:
the machine's Python, the file's pinned registry lines and the wheel; nothing of ``.venv`` or of the
repository on its path), in a temporary folder. That run executes the page's hidden cells too;
since no visible cell reads a name that only a hidden cell binds or rebinds out of sight (the
static check of tests/test_visible_code.py), the visible cells alone, the download, run the same
way. tests/test_downloads.py checks that the download installs that environment and holds the
page's visible code.
"""
from __future__ import annotations

import re
import shlex
from pathlib import Path

import jupytext
import nbformat

from conftest import BOOK_HTML, ROOT
from fresh_env import _local_files
from tools.toc import notebook_pages

CHAPTERS = notebook_pages()
PIP = re.compile(r"pip install ((?:-r\s+)?(?:'[^']+'|\"[^\"]+\"|\S+))")
HIDDEN = "remove-cell"


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


def visible_code(chapter: str) -> list[str]:
    """The sources of the code cells the page shows, in order (its code cells not tagged
    ``remove-cell``): what its download holds."""
    source = jupytext.read(ROOT / f"{chapter}.md")
    return [c.source for c in source.cells
            if c.cell_type == "code" and HIDDEN not in c.metadata.get("tags", [])]
