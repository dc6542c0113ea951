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

Loaded by ``tools/jupyter_lab_config.py`` (``make lab``).
"""
from __future__ import annotations

from jupyter_server.services.contents.largefilemanager import AsyncLargeFileManager
from jupytext.async_contentsmanager import build_async_jupytext_contents_manager_class
from traitlets import default

TEXT_NOTEBOOKS = (".md", ".py")
NOT_SAVED = ("user_expressions",)   # cell metadata that jupyterlab-myst writes and the chapters never store


def kernel_language_info() -> dict:
    """The ``language_info`` that ipykernel's Python kernel of this Python reports on start."""
    from ipykernel.ipkernel import IPythonKernel

    return dict(IPythonKernel.language_info)


class ChapterContentsManager(build_async_jupytext_contents_manager_class(AsyncLargeFileManager)):
    """jupytext's contents manager; a text notebook comes with the kernel's ``language_info``, and
    the results of the prose's inline expressions (``user_expressions``, which jupyterlab-myst
    stores in a Markdown cell's metadata when it runs) are not written into the chapter."""

    @default("cell_metadata_filter")
    def _no_expression_results(self):
        return "-" + ",-".join(NOT_SAVED)

    async def get(self, path, content=True, type=None, format=None, **kwargs):
        model = await super().get(path, content=content, type=type, format=format, **kwargs)
        if (content and model.get("type") == "notebook" and str(path).endswith(TEXT_NOTEBOOKS)
                and "language_info" not in model["content"]["metadata"]):
            model["content"]["metadata"]["language_info"] = kernel_language_info()
        return model
