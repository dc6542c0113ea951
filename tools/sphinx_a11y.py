"""Pages that every reader can use: on a phone, with a keyboard, with a screen reader, without an emoji font.

Loaded by ``_config.yml`` (``sphinx: local_extensions: {sphinx_a11y: tools}``). It

1. adds ``book/_static/orrc-a11y.css`` and ``orrc-a11y.js`` to every page: a display equation,
   code block or table wider than its column scrolls sideways in its own box, and the script marks
   each box that does (class ``orrc-overflows``: a shadow at the edge where more content waits,
   a visible scroll bar) and makes it reachable from the keyboard (``tabindex="0"``, a ``region``
   with a label), as the accessibility audit asks of scrollable regions; colours where the theme's
   contrast falls short of WCAG AA; a name for each control that matches what it shows (label in
   name) and for the sidebar's section toggles; the list of citations without the list role whose
   entries are not list items (:func:`_roles`);
2. writes the status column of the execution-times table (``{nb-exec-table}``, which myst-nb
   fills with the emoji ✅ and ❌, placeholder boxes where the reader's browser lacks an emoji font)
   as a small inline SVG mark and the word "passed" or "failed".

The browser tests (tests/test_book.py) check both, and run the axe-core audit on every page.
"""
from __future__ import annotations

from pathlib import Path

from docutils import nodes
from sphinx.transforms.post_transforms import SphinxPostTransform

STATIC = Path(__file__).resolve().parents[1] / "book" / "_static"

#: the words that replace myst-nb's emoji status marks, and their inline SVG marks
STATUS = {
    "✅": ("passed", '<svg class="orrc-status-mark" aria-hidden="true" focusable="false" viewBox="0 0 16 16" '
                    'width="1em" height="1em"><path d="M2 8.5l4 4 8-9" fill="none" stroke="currentColor" '
                    'stroke-width="2.2" stroke-linecap="round" stroke-linejoin="round"/></svg>'),
    "❌": ("failed", '<svg class="orrc-status-mark" aria-hidden="true" focusable="false" viewBox="0 0 16 16" '
                    'width="1em" height="1em"><path d="M3 3l10 10M13 3L3 13" fill="none" stroke="currentColor" '
                    'stroke-width="2.2" stroke-linecap="round"/></svg>'),
}


class StatusMarks(SphinxPostTransform):
    """Replace the emoji status marks of tables (myst-nb's execution table) by an SVG and a word."""

    default_priority = 15   # after myst-nb's ExecutionStatsPostTransform (8) made the table

    def run(self, **kwargs) -> None:
        for table in self.document.findall(nodes.table):
            for text in list(table.findall(nodes.Text)):
                mark = STATUS.get(text.astext().strip())
                if mark is None:
                    continue
                word, svg = mark
                new = nodes.inline("", "", classes=["orrc-status", f"orrc-status-{word}"])
                if self.app.builder.format == "html":
                    new += nodes.raw("", svg, format="html")
                new += nodes.Text(word)
                text.parent.replace(text, new)


def _roles(app, pagename, templatename, context, doctree) -> None:
    """The list of citations without the ARIA roles docutils gives it (``role="list"`` around
    ``doc-biblioentry`` entries holding ``doc-backlink`` links: a list whose children are not list
    items, a critical finding of the audit); the entries stay a ``div`` each, as they look."""
    body = context.get("body")
    if body and 'class="citation-list"' in body:
        context["body"] = (body.replace('<div role="list" class="citation-list">', '<div class="citation-list">')
                           .replace(' role="doc-biblioentry"', ""))


def _static_path(app) -> None:
    if str(STATIC) not in app.config.html_static_path:
        app.config.html_static_path.append(str(STATIC))


def setup(app):
    app.connect("builder-inited", _static_path)
    app.add_css_file("orrc-a11y.css")
    app.add_js_file("orrc-a11y.js", loading_method="defer")
    app.add_post_transform(StatusMarks)
    app.connect("html-page-context", _roles)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
