"""The map of the paper's results: which result rests on which, each box a link to its chapter.

Loaded by ``_config.yml`` (``sphinx: local_extensions: {sphinx_map: tools}``). The directive

    ```{results-map}
    :part: 2
    ```

draws the map with matplotlib when the book is built (static, offline, no script), as an inline
SVG whose boxes are links to the chapters that compute each result, in a numbered figure with its
caption, as every figure of the book. ``:part:`` (1, 2 or 3: the
column of Algorithm 1, 2 or 3) draws that part's boxes in the accent colour; without it every
column is drawn alike. The links are resolved for the page the map is on, after Sphinx has read
every page (``doctree-resolved``), so they work from any page and in the student edition.
"""
from __future__ import annotations

import io
import re
from dataclasses import dataclass

from docutils import nodes
from docutils.parsers.rst import Directive, directives


@dataclass(frozen=True)
class Result:
    key: str
    label: str          # the text in the box (two short lines at most)
    page: str           # the docname of the chapter that computes it
    column: int         # 0: the setting and the comparisons (centre); 1, 2, 3: Algorithm 1, 2, 3
    row: int


RESULTS = (
    Result("problem", "The problem\nEq. (2): $R^p_T(\\gamma)$", "book/problem", 0, 0),
    Result("alg1", "Algorithm 1\npreview RHC", "book/preview_rhc", 1, 1),
    Result("alg2", "Algorithm 2\nestimate, then control", "book/unknown_systems", 2, 1),
    Result("alg3", "Algorithm 3\nmin-max RHC", "book/minmax", 3, 1),
    Result("lemma1", "Lemma 1\n$V_M$ decreases", "book/lemma1", 1, 2),
    Result("lemma34", "Lemmas 3-4\nLipschitz in $\\theta$", "book/lemma3_4", 2, 2),
    Result("lemma6", "Lemma 6\nmin-max value", "book/minmax", 3, 2),
    Result("lemma2", "Lemma 2\neach stage cost", "book/lemma2", 1, 3),
    Result("lemma5", "Lemma 5\nwith model error", "book/theorem2", 2, 3),
    Result("theorem1", "Theorem 1\n$\\gamma_c = O(\\overline{\\gamma})$", "book/theorem1", 1, 4),
    Result("theorem2", "Theorem 2\nthe price of learning", "book/theorem2", 2, 4),
    Result("theorem3", "Theorem 3\nno preview", "book/minmax", 3, 4),
    Result("comparison", "Comparisons\nLQR, $H_\\infty$, GPC, regret", "book/comparison", 0, 5),
)

#: (from, to): the result ``to`` is proved from ``from`` (or runs on it)
RESTS_ON = (
    ("problem", "alg1"), ("problem", "alg2"), ("problem", "alg3"),
    ("alg1", "lemma1"), ("lemma1", "lemma2"), ("lemma2", "theorem1"),
    ("alg2", "lemma34"), ("lemma1", "lemma34"), ("lemma34", "lemma5"), ("lemma2", "lemma5"),
    ("lemma5", "theorem2"),
    ("alg3", "lemma6"), ("lemma6", "theorem3"),
    ("theorem1", "comparison"), ("theorem3", "comparison"),
)
ALT = ("A map of the paper's results. The problem, Eq. (2), leads to three algorithms. "
       "Algorithm 1 (preview RHC) leads to Lemma 1, Lemma 2 and Theorem 1. Algorithm 2 (estimate, "
       "then control) leads to Lemmas 3 and 4, which also use Lemma 1, then to Lemma 5, which also "
       "uses Lemma 2, and to Theorem 2. Algorithm 3 (min-max RHC) leads to Lemma 6 and Theorem 3. "
       "Theorems 1 and 3 lead to the comparisons. Each box links to the chapter that computes it.")


CAPTION = ("The paper's results and how they rest on each other: an arrow points from a result to one "
           "proved with it. Each box links to the chapter that computes it.")


def _x(result: Result) -> float:
    return 2.0 if result.column == 0 else float(result.column)


def draw_svg(urls: dict[str, str], highlight: int | None = None, png=None) -> str:
    """The map as SVG text, each box a link to ``urls[result.page]`` (also as a PNG file ``png``
    when given, to look at)."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import pyplot as plt
    from matplotlib.patches import FancyBboxPatch

    by_key = {r.key: r for r in RESULTS}
    fig, ax = plt.subplots(figsize=(7.2, 6.0))
    ax.set_xlim(0.35, 3.65)
    ax.set_ylim(5.55, -0.5)
    ax.axis("off")
    w, h = 0.88, 0.62
    for src, dst in RESTS_ON:
        a, b = by_key[src], by_key[dst]
        if a.row == b.row:   # side by side: from the right edge to the left edge
            start, end = (_x(a) + w / 2, a.row), (_x(b) - w / 2, b.row)
        else:
            start, end = (_x(a), a.row + h / 2), (_x(b), b.row - h / 2)
        ax.annotate("", xy=end, xytext=start,
                    arrowprops={"arrowstyle": "-|>", "color": "#555555", "lw": 1.1,
                                "shrinkA": 2, "shrinkB": 2})
    for r in RESULTS:
        accent = highlight is not None and r.column == highlight
        box = FancyBboxPatch((_x(r) - w / 2, r.row - h / 2), w, h, boxstyle="round,pad=0.02",
                             facecolor="#dbe9f6" if accent else "#f4f4f4",
                             edgecolor="#1f5f99" if accent else "#444444", lw=1.6 if accent else 1.0)
        box.set_url(urls.get(r.page))
        ax.add_patch(box)
        text = ax.text(_x(r), r.row, r.label, ha="center", va="center", fontsize=9.5,
                       color="#0b3d6b", linespacing=1.35)
        text.set_url(urls.get(r.page))
    buf = io.StringIO()
    with matplotlib.rc_context({"svg.fonttype": "none"}):   # text stays text: small, selectable, read aloud
        fig.savefig(buf, format="svg", bbox_inches="tight")
    if png:
        fig.savefig(png, dpi=100, bbox_inches="tight")
    plt.close(fig)
    svg = buf.getvalue()
    svg = svg[svg.index("<svg"):]
    # scale with the column: keep the viewBox, drop the fixed size
    svg = re.sub(r'<svg([^>]*?) width="[^"]*" height="[^"]*"',
                 r'<svg\1 class="orrc-results-map" role="img" aria-labelledby="orrc-map-title"', svg, count=1)
    return svg.replace(">", f'><title id="orrc-map-title">{ALT}</title>', 1)


class results_map(nodes.General, nodes.Element):
    """Placeholder for the map until the links can be resolved."""


class ResultsMap(Directive):
    has_content = False
    option_spec = {"part": directives.positive_int}

    def run(self):
        """A numbered figure (Sphinx's numfig): the map's placeholder and the caption."""
        node = results_map()
        node["part"] = self.options.get("part")
        figure = nodes.figure("", node, nodes.caption(CAPTION, CAPTION), classes=["orrc-map"])
        self.state.document.set_id(figure)
        return [figure]


def _resolve(app, doctree, docname):
    for node in list(doctree.findall(results_map)):
        if app.builder.format != "html":
            node.replace_self(nodes.paragraph(text=ALT))
            continue
        urls = {r.page: app.builder.get_relative_uri(docname, r.page) for r in RESULTS}
        # the map keeps a legible size on a phone and scrolls sideways in its own box (orrc-a11y.js)
        html = f'<div class="orrc-map-wrap">{draw_svg(urls, node["part"])}</div>'
        node.replace_self(nodes.raw("", html, format="html"))


def setup(app):
    app.add_node(results_map)
    app.add_directive("results-map", ResultsMap)
    app.connect("doctree-resolved", _resolve)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
