"""The contents manager of ``make lab``: a chapter opens in JupyterLab unmodified.

JupyterLab reads a chapter (``book/*.md``) through jupytext's contents manager. When the kernel
starts, JupyterLab writes the kernel's ``language_info`` into the notebook's metadata; the
Markdown file does not store it (jupytext leaves it out of the text), so the open chapter counted
as modified: closing it asked to save, and autosave rewrote it (byte-identical, but confusing).
JupyterLab skips a metadata write that changes nothing (``setMetadata`` compares the values), so
this contents manager hands out a text notebook with the ``language_info`` that the kernel will
report: the one of ipykernel's Python kernel in this environment (the server and the kernel run
the same Python in ``.venv``). Saving drops it again (jupytext's default metadata filter), so the
file on disk never holds it.

After Run All, jupyterlab-myst stores the values of the prose's inline expressions
(``{eval}`glued(...)```) in each Markdown cell's metadata (``user_expressions``); jupytext would
write them into the chapter on the next save. This contents manager leaves them out.

The numbers of the text before the chapter has run: jupyterlab-myst shows an inline expression's
stored result (``user_expressions``) until the cell runs again. When the published book has been
built from exactly these sources (``make book``: its stamp ``_build/orrc-build.json`` matches
:func:`tools.build_book.inputs_digest`), a chapter is handed out with the results of its
expressions taken from that build's glued values (``_build/jupyter_execute/<page>.glue.json``),
formatted as the HTML formats them; so a reader sees the book's numbers on opening a chapter, and
this run's numbers once it has run. Without such a build the expressions show as code until then.

Citations, references to other pages and API names: jupyterlab-myst sees one notebook and no
bibliography, so ``{cite:t}`key```, ``{ref}`label``` or ``{py:func}`orrc.simulate``` would show
their keys. From the same published build (``_build/jupyter_execute/<page>.roles.json``, written by
tools/sphinx_offline.py) the chapter is handed out with each such role replaced by the text the
HTML shows ("Muthirayan and Khargonekar (2021)", "Lemma 2", a section's title); each Markdown cell
keeps what it replaced in its metadata (``orrc_roles``), and saving puts the roles back (the
whole cell as written when the cell was not edited), so the file on disk keeps its roles.

Loaded by ``tools/jupyter_lab_config.py`` (``make lab``).
"""
from __future__ import annotations

import json
import re
from pathlib import Path

from jupyter_server.services.contents.largefilemanager import AsyncLargeFileManager
from jupytext.async_contentsmanager import build_async_jupytext_contents_manager_class
from traitlets import Unicode, default

from tools.build_book import ROOT, inputs_digest, read_stamp
from tools.download import CODE_BLOCK, ROLE
from tools.sphinx_live import parse_glued

EVAL = re.compile(r"\{eval\}`([^`]*)`")

TEXT_NOTEBOOKS = (".md", ".py")
# cell metadata that jupyterlab-myst (user_expressions) or this contents manager (orrc_roles) writes
# and the chapters never store
NOT_SAVED = ("user_expressions", "orrc_roles")


def kernel_language_info() -> dict:
    """The ``language_info`` that ipykernel's Python kernel of this Python reports on start."""
    from ipykernel.ipkernel import IPythonKernel

    return dict(IPythonKernel.language_info)


class ChapterContentsManager(build_async_jupytext_contents_manager_class(AsyncLargeFileManager)):
    """jupytext's contents manager; a text notebook comes with the kernel's ``language_info``, and
    the results of the prose's inline expressions (``user_expressions``, which jupyterlab-myst
    stores in a Markdown cell's metadata when it runs) are not written into the chapter."""

    book_root = Unicode(str(ROOT), config=True,
                        help="the repository whose published build (_build) holds the glued values")

    @default("cell_metadata_filter")
    def _no_expression_results(self):
        return "-" + ",-".join(NOT_SAVED)

    def built(self, path: str, suffix: str) -> dict:
        """The JSON file ``<page><suffix>`` that the published build wrote for the chapter ``path``
        (relative to the server's root, e.g. ``book/lemma1.md``) into ``_build/jupyter_execute``;
        {} without a build of exactly these sources at full size."""
        root = Path(self.book_root)
        stamp = read_stamp(root)
        page = Path(path.strip("/")).with_suffix("")
        found = root / "_build" / "jupyter_execute" / page.with_suffix(suffix)
        if not stamp or stamp.get("quick") or not found.is_file() or stamp.get("digest") != inputs_digest(root):
            return {}
        return json.loads(found.read_text(encoding="utf-8"))

    def built_values(self, path: str) -> dict:
        """{key: text/plain} that the published build glued for the chapter ``path``; {} without a
        build of exactly these sources."""
        return {k: v.get("data", {}).get("text/plain") for k, v in self.built(path, ".glue.json").items()}

    async def get(self, path, content=True, type=None, format=None, **kwargs):
        model = await super().get(path, content=content, type=type, format=format, **kwargs)
        if content and model.get("type") == "notebook" and str(path).endswith(TEXT_NOTEBOOKS):
            nb = model["content"]
            if "language_info" not in nb["metadata"]:
                nb["metadata"]["language_info"] = kernel_language_info()
            if any("{eval}" in c["source"] for c in nb["cells"] if c["cell_type"] == "markdown"):
                add_expression_results(nb, self.built_values(str(path)))
            show_role_texts(nb, self.built(str(path), ".roles.json"))
        return model

    async def save(self, model, path=""):
        if model.get("type") == "notebook" and model.get("content") and str(path).endswith(TEXT_NOTEBOOKS):
            restore_roles(model["content"])
        return await super().save(model, path)


def show_role_texts(nb, texts: dict) -> None:
    """Replace, in each Markdown cell outside its code blocks, every role of ``texts`` ({role as
    written: text shown}) by its text; the cell's metadata ``orrc_roles`` keeps the cell as
    written, as shown, and each (shown, written) pair in order, for :func:`restore_roles`."""
    if not texts:
        return
    for cell in nb["cells"]:
        if cell["cell_type"] != "markdown":
            continue
        source, pairs, out, at = cell["source"], [], [], 0
        blocks = [(m.start(), m.end()) for m in CODE_BLOCK.finditer(source)]
        for m in ROLE.finditer(source):
            if m.group(0) not in texts or any(a <= m.start() < b for a, b in blocks):
                continue
            out += [source[at:m.start()], texts[m.group(0)]]
            pairs.append([texts[m.group(0)], m.group(0)])
            at = m.end()
        if pairs:
            shown = "".join(out) + source[at:]
            cell["metadata"]["orrc_roles"] = {"written": source, "shown": shown, "pairs": pairs}
            cell["source"] = shown


def restore_roles(nb) -> None:
    """Undo :func:`show_role_texts` before a save: a cell not edited since is saved exactly as
    written; in an edited one each shown text, found in order, becomes its role again."""
    for cell in nb["cells"]:
        meta = cell.get("metadata", {}).pop("orrc_roles", None)
        if cell["cell_type"] != "markdown" or not meta:
            continue
        source = "".join(cell["source"]) if isinstance(cell["source"], list) else cell["source"]
        if source == meta["shown"]:
            cell["source"] = meta["written"]
            continue
        at = 0
        for shown, written in meta["pairs"]:
            i = source.find(shown, at)
            if i < 0:
                continue
            source = source[:i] + written + source[i + len(shown):]
            at = i + len(written)
        cell["source"] = source


def add_expression_results(nb, values: dict) -> None:
    """Store in each Markdown cell the results of its ``{eval}`glued(...)``` expressions, as
    jupyterlab-myst stores them after running the cell, from ``values`` ({key: text/plain})."""
    from myst_nb.core.variables import format_plain_text

    for cell in nb["cells"]:
        if cell["cell_type"] != "markdown":
            continue
        results = []
        for expression in EVAL.findall(cell["source"]):
            parsed = parse_glued(expression)
            if parsed is None or values.get(parsed[0]) is None:
                continue
            key, fmt = parsed
            text = format_plain_text(values[key], fmt or "s")
            results.append({"expression": expression,
                            "result": {"status": "ok", "data": {"text/plain": text}, "metadata": {}}})
        if results:
            cell["metadata"]["user_expressions"] = results
