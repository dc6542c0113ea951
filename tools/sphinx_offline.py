"""A small Sphinx extension that makes the rendered book work offline.

Loaded by ``_config.yml`` (``sphinx: local_extensions: {sphinx_offline: tools}``). It

1. ships MathJax 3 into the HTML: the files come from the installed registry
   package ``sphinx-mathjax-offline`` (pinned in ``requirements.txt``), are copied
   into ``_build/html/_static/mathjax/`` when the HTML builder starts, and
   ``mathjax_path`` points at the self-contained ``tex-svg.js`` there, so no page
   loads MathJax from a CDN;
2. leaves Thebe out: Jupyter Book always loads ``sphinx_thebe``, which emits its
   configuration script twice per page (console error "Identifier 'THEBE_JS_URL'
   has already been declared") and names a CDN URL; the book does not use Thebe,
   so its handlers are disconnected and its assets dropped from every page; the saved
   ipywidgets state is dropped too (``_config.yml`` already hides the live widget
   output, which shows its precomputed frames instead);
3. sets the theme's default colour mode (else a console error on a first visit);
4. offers each chapter as a plain ``.ipynb``: the chapter's MyST source is converted
   with jupytext (cells only, no outputs) into ``_build/html/_sources/<page>.ipynb``
   and sphinx-book-theme's download menu gets its ``.ipynb`` entry
   (the theme shows it when the page context has ``ipynb_source``). The notebook opens
   with a cell that says how to install what it needs (:data:`INSTALL`: ``orrc`` with its
   ``book`` extra), and a bare ``from myst_nb import glue`` becomes ``from orrc.viz import
   glue`` (myst-nb's glue when myst-nb is there, a plain store otherwise).
"""
from __future__ import annotations

import re
import shutil
from importlib import metadata
from pathlib import Path

import nbformat
from sphinx.application import Sphinx
from sphinx.errors import ExtensionError


MATHJAX_DIST = "sphinx-mathjax-offline"
MATHJAX_BUNDLE = "tex-svg.js"  # TeX input + SVG output with its fonts built in: needs no font files


def mathjax_source() -> Path:
    """The ``mathjax`` directory of the installed ``sphinx-mathjax-offline`` package (MathJax 3)."""
    try:
        dist = metadata.distribution(MATHJAX_DIST)
    except metadata.PackageNotFoundError as exc:
        raise ExtensionError(f"the package {MATHJAX_DIST!r} (offline MathJax 3) is not installed; "
                             "it is pinned in requirements.txt") from exc
    src = Path(dist.locate_file("sphinx-mathjax-offline/static/mathjax"))
    bundle = src / MATHJAX_BUNDLE
    if not bundle.is_file():
        raise ExtensionError(f"{bundle} not found in the installed {MATHJAX_DIST!r}")
    head = bundle.read_text(encoding="utf-8", errors="replace")[:400_000]
    m = re.search(r'VERSION="(\d+)\.(\d+)\.(\d+)"', head)
    if not m or m.group(1) != "3":
        raise ExtensionError(f"{bundle} is not MathJax 3 (found version {m.group(0) if m else 'none'})")
    return src


def _ignore(src_root: Path):
    """Skip the top-level combined bundles other than MATHJAX_BUNDLE and the CommonHTML output;
    keep the directories tex-svg.js may load lazily (TeX extensions, menu, accessibility, speech)."""
    def ignore(directory: str, names: list[str]) -> set[str]:
        rel = Path(directory).relative_to(src_root).as_posix()
        skip = set()
        for name in names:
            path = name if rel == "." else f"{rel}/{name}"
            if rel == "." and name.endswith(".js") and name != MATHJAX_BUNDLE:
                skip.add(name)
            elif path.startswith("output/chtml") or name == "__pycache__":
                skip.add(name)
        return skip
    return ignore


def copy_mathjax(app: Sphinx) -> None:
    """Copy MathJax 3 into ``<html>/_static/mathjax`` (before pages are written, so they get checksums)."""
    if app.builder.format != "html":
        return
    src = mathjax_source()
    dest = Path(app.outdir) / "_static" / "mathjax"
    shutil.copytree(src, dest, ignore=_ignore(src), dirs_exist_ok=True)


def configure(app: Sphinx, config) -> None:
    """Point ``mathjax_path`` (relative to ``_static``) at the shipped bundle; give the theme a colour mode.

    Without ``default_mode`` the pydata theme logs a console error on a reader's first visit
    ("Got invalid theme mode: . Resetting to auto."); the figures are drawn on white, so light.
    """
    config.mathjax_path = f"mathjax/{MATHJAX_BUNDLE}"
    context = dict(config.html_context or {})
    context.setdefault("default_mode", "light")  # the pydata theme reads it from html_context
    config.html_context = context


def drop_thebe_handlers(app: Sphinx) -> None:
    """Disconnect sphinx_thebe's handlers that add its scripts and its per-page config node."""
    for event, listeners in list(app.events.listeners.items()):
        for listener in list(listeners):
            handler = listener.handler
            if getattr(handler, "__module__", "") == "sphinx_thebe" and handler.__name__ in (
                    "init_thebe_core", "update_thebe_context"):
                app.disconnect(listener.id)


WIDGET_STATE = "application/vnd.jupyter.widget-state+json"


def _is_dead(asset) -> bool:
    """A Thebe file (its stylesheet, added by sphinx_thebe's setup; its scripts and inline
    config are never added, see drop_thebe_handlers), or the saved ipywidgets state (the HTML
    shows static frames, not live widgets)."""
    name = str(getattr(asset, "filename", asset) or "")
    attrs = getattr(asset, "attributes", {}) or {}
    return "thebe" in name.lower() or attrs.get("type") == WIDGET_STATE


def drop_dead_assets(app: Sphinx, pagename, templatename, context, doctree) -> None:
    """Remove Thebe's scripts/stylesheet and the unused widget state (100-200 kB a page) from a page."""
    for key in ("script_files", "css_files"):
        files = context.get(key)
        if files:
            files[:] = [f for f in files if not _is_dead(f)]


INSTALL = "pip install '.[book]'"   # tests/test_downloads.py installs exactly what this says
DOWNLOAD_NOTE = ("*{title}*, a chapter of the book *Online Learning Robust Control*, as a plain "
                 "Jupyter notebook. To run it, install the `orrc` package with the book's extra "
                 "in a Python 3.11+ environment, in the folder of the book's repository:\n\n"
                 f"    {INSTALL}\n\n"
                 "and open this notebook with Jupyter from anywhere (`make lab` in the repository "
                 "installs JupyterLab too and opens the chapters as notebooks). The numbers the "
                 "text quotes, `glued(\"key\", \"format\")`, appear in the text in JupyterLab "
                 "with jupyterlab-myst, and in any notebook under the cell that computes them; "
                 "the rendered book has the outputs and the references to the other chapters.")

_BARE_GLUE = re.compile(r"^from myst_nb import glue\b", re.M)


def portable_source(code: str) -> str:
    """A code cell's source with ``from myst_nb import glue`` replaced by ``from orrc.viz import glue``."""
    return _BARE_GLUE.sub("from orrc.viz import glue", code)


def _plain(title: str) -> str:
    import html

    return html.unescape(re.sub(r"<[^>]+>", "", str(title))).strip()


def notebook_download(app: Sphinx, pagename, templatename, context, doctree) -> None:
    """Write ``_sources/<page>.ipynb`` from a chapter's MyST source and announce it to the theme."""
    if doctree is None or app.builder.format != "html" or pagename not in app.env.all_docs:
        return
    source = Path(app.env.doc2path(pagename))
    if source.suffix != ".md":
        return
    import jupytext

    nb = jupytext.reads(source.read_text(encoding="utf-8"), fmt="md:myst")
    if not nb.metadata.get("kernelspec"):
        return  # a plain Markdown page (e.g. book/execution.md), not a notebook
    nb.metadata.pop("jupytext", None)
    for cell in nb.cells:
        if cell.cell_type == "code":
            cell.source = portable_source(cell.source)
    title = context.get("title") or pagename
    nb.cells.insert(0, nbformat.v4.new_markdown_cell(DOWNLOAD_NOTE.format(title=_plain(title))))
    out = Path(app.outdir) / "_sources" / f"{pagename}.ipynb"
    out.parent.mkdir(parents=True, exist_ok=True)
    jupytext.write(nb, out, fmt="ipynb")
    context["ipynb_source"] = f"{pagename}.ipynb"


def setup(app: Sphinx) -> dict:
    app.connect("config-inited", configure, priority=900)
    app.connect("builder-inited", drop_thebe_handlers)
    app.connect("builder-inited", copy_mathjax)
    # before sphinx-book-theme builds its header buttons (priority 501)
    app.connect("html-page-context", notebook_download, priority=450)
    app.connect("html-page-context", drop_dead_assets, priority=990)
    return {"version": "0.1", "parallel_read_safe": True, "parallel_write_safe": True}
