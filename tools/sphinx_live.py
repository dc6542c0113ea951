"""The chapters' inline expressions in the HTML book, from the executed notebooks' glued values.

Loaded by ``_config.yml`` (``sphinx: local_extensions: {sphinx_live: tools}``). The prose quotes
a computed number as ``{eval}`glued("key", "fmt")``` (see ``orrc.viz.notebook``): a MyST
inline expression, which jupyterlab-myst evaluates in the live kernel. MyST-NB evaluates
``{eval}`` only in its "inline" execution mode, where every chapter runs in a kernel that stays
open while the page is parsed; the book executes in "cache" mode instead (the solution-free
edition reuses the cached notebooks, and the tests read them). This extension therefore
replaces the ``eval`` role: an expression of exactly the form ``glued("key")`` or
``glued("key", "fmt")`` renders as ``{glue:text}`key:fmt``` does, from the value the executed
chapter glued (myst-nb's glue outputs), formatted with the same ``format(value, fmt)``. Any
other expression is an error (a Sphinx warning, which fails the build): the book's prose has no
other inline expressions.
"""
from __future__ import annotations

import re

from docutils import nodes
from myst_nb.ext.glue.roles import PasteTextRole
from sphinx.application import Sphinx

GLUED = re.compile(r"""^\s*glued\(\s*(["'])(?P<key>[^"']+)\1\s*(?:,\s*(["'])(?P<fmt>[^"']*)\3\s*)?\)\s*$""")


def parse_glued(expression: str) -> tuple[str, str] | None:
    """``(key, fmt)`` of an expression ``glued("key", "fmt")`` (``fmt`` "" when absent), else None."""
    m = GLUED.match(expression)
    return None if m is None else (m.group("key"), m.group("fmt") or "")


class GluedEvalRole(PasteTextRole):
    """``{eval}`glued("key", "fmt")``` as ``{glue:text}`key:fmt```."""

    def run(self) -> tuple[list[nodes.Node], list[nodes.system_message]]:
        parsed = parse_glued(self.text)
        if parsed is None:
            msg = (f"inline expression {self.text!r}: the book renders only glued(\"key\", \"fmt\") "
                   "(a value glued by the chapter, see orrc.viz.notebook)")
            return [], [self.document.reporter.warning(msg, line=self.line)]
        key, fmt = parsed
        # PasteTextRole formats with "s" when no format is given; format(value, "") is str(value)
        self.text = f"{key}:{fmt}" if fmt else key
        return super().run()


def register(app: Sphinx, config=None) -> None:
    """Replace myst-nb's ``eval`` role (registered in myst-nb's own setup) with :class:`GluedEvalRole`."""
    app.add_role("eval", GluedEvalRole(), override=True)


def setup(app: Sphinx) -> dict:
    app.setup_extension("myst_nb")   # its eval role first, then ours over it
    app.connect("config-inited", register, priority=900)
    return {"version": "0.1", "parallel_read_safe": True, "parallel_write_safe": True}
