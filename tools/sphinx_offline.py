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
4. offers each chapter as a plain ``.ipynb`` that any Jupyter front end shows as the page
   shows it (tools/download.py: the numbers the executed chapter glued, the references and
   citations as Sphinx resolved them, the statements as bold titles, only the code cells the
   page shows) in ``_build/html/_sources/<page>.ipynb``; sphinx-book-theme's download menu gets
   its ``.ipynb`` entry (the theme shows it when the page context has ``ipynb_source``) and two
   more: the pinned ``requirements-reader.txt`` and the ``orrc`` wheel, written beside the
   notebook. The notebook opens with a cell that says how to install what it needs
   (:data:`INSTALL`).
"""
from __future__ import annotations

import functools
import json
import re
import shutil
from importlib import metadata
from pathlib import Path

import nbformat
from sphinx.application import Sphinx
from sphinx.errors import ExtensionError
from sphinx.util import logging

# loaded by Sphinx as the top-level module ``sphinx_offline`` (local_extensions puts tools/ on the
# path), imported by the tests as ``tools.sphinx_offline``
if __package__:
    from .download import Resolved, UnresolvedError, portable_source, reader_notebook, role_texts
else:
    from download import Resolved, UnresolvedError, portable_source, reader_notebook, role_texts

logger = logging.getLogger(__name__)


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


def repository(app: Sphinx) -> Path:
    """The folder of the project's ``pyproject.toml``, ``orrc/`` and ``requirements-reader.txt``: the
    book's source folder, else the one of the ``orrc`` package the build imports (the solution-free
    edition builds from a copy of ``book/`` and ``tools/`` only)."""
    from importlib.util import find_spec

    spec = find_spec("orrc")
    candidates = [Path(app.srcdir), Path(__file__).resolve().parents[1]]
    if spec is not None and spec.origin:
        candidates.append(Path(spec.origin).resolve().parents[1])
    for folder in candidates:
        if all((folder / name).exists() for name in ("pyproject.toml", "orrc", READER_REQUIREMENTS)):
            return folder
    raise ExtensionError(f"no project folder with pyproject.toml, orrc/ and {READER_REQUIREMENTS} among {candidates}")


READER_REQUIREMENTS = "requirements-reader.txt"   # pinned, at the repository's root
INSTALL = f"pip install -r {READER_REQUIREMENTS}"   # tests/test_downloads.py installs exactly what this says
DOWNLOAD_NOTE = ("*{title}*, a chapter of the book *Online Learning Robust Control*, as a plain "
                 "Jupyter notebook.\n\nTo run it, save three files from the download menu of the "
                 "chapter's page into one folder: this notebook, `" + READER_REQUIREMENTS + "` and "
                 "`{wheel}` (the `orrc` package). In that folder, in a Python 3.11+ environment:\n\n"
                 f"    {INSTALL}\n    jupyter notebook {{name}}\n\n"
                 "The first line installs `orrc`, the packages the chapter uses, Jupyter Notebook and "
                 "nbconvert, at the versions the book was built with; the notebook also opens in "
                 "JupyterLab, VS Code or Colab once they are installed. The numbers, references and "
                 "citations in the text are those of the book's page; running the cells computes "
                 "the numbers again.")


def _plain(title: str) -> str:
    import html

    return html.unescape(re.sub(r"<[^>]+>", "", str(title))).strip()


# ---------------------------------------------------------------- what the build knows, for the downloads

_XREF = {"ref": ("std", "ref"), "numref": ("std", "numref"), "doc": ("std", "doc"), "term": ("std", "term"),
         "eq": ("math", "eq"), "prf:ref": ("prf", "ref")}


def _xref(app: Sphinx, pagename: str):
    """``xref(role, target, title)``: the text Sphinx's own resolution of the reference shows in the HTML."""
    from docutils import nodes
    from sphinx import addnodes

    def resolve(role, target, title):
        if role not in _XREF:
            return None
        domain_name, typ = _XREF[role]
        try:
            domain = app.env.get_domain(domain_name)
        except Exception:   # noqa: BLE001 - a domain the build does not load
            return None
        if domain_name == "std" and typ in ("ref", "numref"):
            target = target.lower()
        node = addnodes.pending_xref("", refdomain=domain_name, reftype=typ, reftarget=target,
                                     refexplicit=title is not None, refdoc=pagename, refwarn=False)
        contnode = nodes.inline(title or target, title or target)
        node += contnode
        try:
            found = domain.resolve_xref(app.env, pagename, app.builder, typ, target, node, contnode)
        except Exception:   # noqa: BLE001 - an unresolvable target reads as unresolved
            found = None
        text = found.astext().strip() if found is not None else ""
        return text or None

    return resolve


def _number(app: Sphinx):
    """``number(kind, label)``: the number the HTML shows for a numbered equation or directive."""
    from docutils.nodes import make_id

    env = app.env

    def number(kind, label):
        if kind == "displaymath":
            found = env.get_domain("math").equations.get(label)
            if not found:
                return ""
            docname, n = found
            numbers = env.toc_fignumbers.get(docname, {}).get("displaymath", {}).get(make_id(f"equation-{label}"))
            return ".".join(map(str, numbers)) if numbers else str(n)
        proof = getattr(env, "proof_list", {}).get(label)
        docs = [proof["docname"]] if proof else list(env.toc_fignumbers)
        kinds = [proof["countertype"]] if proof else [kind]
        for docname in docs:
            for k in kinds:
                numbers = env.toc_fignumbers.get(docname, {}).get(k, {}).get(label)
                if numbers:
                    return ".".join(map(str, numbers))
        return ""

    return number


def _bib(app: Sphinx) -> dict:
    """The book's bibliography (``bibtex_bibfiles``), parsed once per build."""
    if not hasattr(app, "_orrc_bib"):
        from pybtex.database import BibliographyData, parse_file

        data = BibliographyData()
        for name in app.config.bibtex_bibfiles or []:
            for key, entry in parse_file(str(Path(app.srcdir) / name)).entries.items():
                data.entries[key] = entry
        app._orrc_bib = data.entries
    return app._orrc_bib


@functools.lru_cache(maxsize=None)
def _text_backend():
    """pybtex's plain-text backend, looked up once (pybtex finds a backend by reading every installed
    package's entry points: about 20 ms a lookup, and a build renders hundreds of names and titles)."""
    from pybtex.plugin import find_plugin

    return find_plugin("pybtex.backends", "text")()


@functools.lru_cache(maxsize=None)
def _latex(text: str) -> str:
    """A BibTeX field's LaTeX (``Pel{\\'e}``) as plain text (``Pelé``)."""
    from pybtex.richtext import Text

    return Text.from_latex(text).render(_text_backend())


def _authors(entry) -> str:
    people = entry.persons.get("author") or entry.persons.get("editor") or []
    last = [_latex(" ".join(p.prelast_names + p.last_names)) for p in people]
    if len(last) >= 3:
        return f"{last[0]} et al."
    return " and ".join(last) or "Anonymous"


def _citations(app: Sphinx):
    entries = _bib(app)

    def cite(keys, textual):
        parts = []
        for key in keys:
            if key not in entries:
                raise ValueError(f"citation {key!r} is not in {app.config.bibtex_bibfiles}")
            e = entries[key]
            parts.append((_authors(e), e.fields.get("year", "n.d.")))
        if textual:
            return "; ".join(f"{a} ({y})" for a, y in parts)
        return "(" + "; ".join(f"{a}, {y}" for a, y in parts) + ")"

    def bibliography(keys):
        lines = ["**References**", ""]
        for key in sorted(keys, key=lambda k: (_authors(entries[k]), entries[k].fields.get("year", ""))):
            e = entries[key]
            people = e.persons.get("author") or e.persons.get("editor") or []
            names = ", ".join(_latex(str(p)) for p in people)
            venue = e.fields.get("journal") or e.fields.get("booktitle") or e.fields.get("publisher") or ""
            lines.append(f"* {names} ({e.fields.get('year', 'n.d.')}). {_latex(e.fields.get('title', ''))}."
                         + (f" *{_latex(venue)}*." if venue else ""))
        return "\n".join(lines)

    return cite, bibliography


def _glued(app: Sphinx, pagename: str) -> dict:
    """``key -> text/plain`` of every value the executed chapter glued (MyST-NB's ``<page>.glue.json``)."""
    import json

    path = Path(app.env.mystnb_config.output_folder).joinpath(*f"{pagename}.glue.json".split("/"))
    if not path.is_file():
        return {}
    data = json.loads(path.read_text(encoding="utf-8"))
    return {k: v.get("data", {}).get("text/plain", "") for k, v in data.items()}


def resolved(app: Sphinx, pagename: str):
    """What the build knows about ``pagename`` (:class:`tools.download.Resolved`)."""
    cite, bibliography = _citations(app)
    return Resolved(glued=_glued(app, pagename), xref=_xref(app, pagename), number=_number(app),
                    cite=cite, bibliography=bibliography)


# ---------------------------------------------------------------- the orrc wheel beside the downloads

def reader_files(app: Sphinx) -> list[Path]:
    """The files a download needs beside it, made once per build into ``<outdir>/_reader``: the
    project's wheel (``pip wheel`` of a copy of the package's sources) and
    ``requirements-reader.txt`` (the pinned file of the repository, and the wheel)."""
    import subprocess
    import sys
    import tempfile

    if getattr(app, "_orrc_reader", None):
        return app._orrc_reader
    root = repository(app)
    out = Path(app.outdir).parent / "_reader"
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    with tempfile.TemporaryDirectory(prefix="orrc-wheel-") as tmp:
        for name in ("pyproject.toml", "README.md", "LICENSE"):
            if (root / name).is_file():
                shutil.copy2(root / name, Path(tmp) / name)
        shutil.copytree(root / "orrc", Path(tmp) / "orrc", ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        run = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation",
                              "--disable-pip-version-check", "--quiet", "-w", str(out), tmp],
                             capture_output=True, text=True)
    wheels = sorted(out.glob("orrc-*.whl"))
    if run.returncode != 0 or len(wheels) != 1:
        raise ExtensionError(f"building the orrc wheel for the downloads failed:\n{run.stderr[-2000:]}")
    pins = (root / READER_REQUIREMENTS).read_text(encoding="utf-8").rstrip("\n")
    req = out / READER_REQUIREMENTS
    req.write_text(pins + f"\n# the orrc package, downloaded beside this file\n./{wheels[0].name}\n", encoding="utf-8")
    app._orrc_reader = [req, wheels[0]]
    return app._orrc_reader


def notebook_download(app: Sphinx, pagename, templatename, context, doctree) -> None:
    """Write ``_sources/<page>.ipynb`` (:func:`tools.download.reader_notebook` of the chapter's MyST
    source, with the executed chapter's numbers and the build's references), with the pinned
    requirements and the orrc wheel beside it, and announce the three to the theme."""
    if doctree is None or app.builder.format != "html" or pagename not in app.env.all_docs:
        return
    source = Path(app.env.doc2path(pagename))
    if source.suffix != ".md":
        return
    import jupytext

    nb = jupytext.reads(source.read_text(encoding="utf-8"), fmt="md:myst")
    if not nb.metadata.get("kernelspec"):
        return  # a plain Markdown page (e.g. book/execution.md), not a notebook
    known = resolved(app, pagename)
    # the texts of the page's citations and references, for make lab (tools/lab_contents.py), beside
    # the glued values myst-nb writes (_build/jupyter_execute/<page>.glue.json)
    roles = Path(app.outdir).parent / "jupyter_execute" / f"{pagename}.roles.json"
    roles.parent.mkdir(parents=True, exist_ok=True)
    roles.write_text(json.dumps(role_texts(nb, known), indent=1, ensure_ascii=False), encoding="utf-8")
    try:
        nb = reader_notebook(nb, known)
    except (UnresolvedError, ValueError) as exc:
        logger.warning(f"{pagename}.ipynb: {exc}", location=pagename)
        return
    out = Path(app.outdir) / "_sources" / f"{pagename}.ipynb"
    out.parent.mkdir(parents=True, exist_ok=True)
    files = reader_files(app)
    for f in files:
        shutil.copy2(f, out.parent / f.name)
    title = context.get("title") or pagename
    nb.cells.insert(0, nbformat.v4.new_markdown_cell(DOWNLOAD_NOTE.format(
        title=_plain(title), wheel=files[1].name, name=out.name)))
    nbformat.write(nb, out)
    context["ipynb_source"] = f"{pagename}.ipynb"
    context["orrc_reader_files"] = [str(Path(pagename).parent / f.name) for f in files]


def announce_reader_files(app: Sphinx, pagename, templatename, context, doctree) -> None:
    """Add the requirements file and the wheel to the page's download menu, after the .ipynb."""
    files = context.get("orrc_reader_files")
    if not files:
        return
    pathto = context["pathto"]
    for group in context.get("header_buttons", []):
        buttons = group.get("buttons") or []
        if any(b.get("label") == "download-notebook-button" for b in buttons):
            at = next(i for i, b in enumerate(buttons) if b.get("label") == "download-notebook-button") + 1
            buttons[at:at] = [{"type": "link", "url": f"{pathto('_sources', 1)}/{f}", "text": Path(f).name,
                               "icon": "fas fa-box", "label": f"download-reader-{i}-button",
                               "tooltip": "Needed to run the notebook"} for i, f in enumerate(files)]


def setup(app: Sphinx) -> dict:
    app.connect("config-inited", configure, priority=900)
    app.connect("builder-inited", drop_thebe_handlers)
    app.connect("builder-inited", copy_mathjax)
    # before sphinx-book-theme builds its header buttons (priority 501)
    app.connect("html-page-context", notebook_download, priority=450)
    app.connect("html-page-context", announce_reader_files, priority=600)   # after the theme's buttons (501)
    app.connect("html-page-context", drop_dead_assets, priority=990)
    return {"version": "0.1", "parallel_read_safe": True, "parallel_write_safe": True}
