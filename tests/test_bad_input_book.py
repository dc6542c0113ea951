"""Bad input to the book's tools (orrc.viz.figures, orrc.viz.glue, orrc.viz.explore, the constants and
margins tables, tools.build_book): a clear orrc.OrrcValueError naming the argument, never a
traceback from deep inside matplotlib."""
import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

import orrc  # noqa: E402
from orrc.viz import explore, figures, glue, theory_plots  # noqa: E402


def small_figure(width=5.0):
    fig = Figure(figsize=(width, 2.0))
    fig.subplots().plot([0, 1], [0, 1])
    return fig


def a_plot(M):
    return small_figure()


PNG = figures.figure_to_png(small_figure())

CASES = [
    # orrc.viz.figures
    (lambda: figures.render("not a figure"), orrc.OrrcValueError, ["fig", "matplotlib Figure", "str"], "render-type"),
    (lambda: figures.render(small_figure(), dpi=72), orrc.OrrcValueError, ["dpi", ">= 100", "72"], "render-dpi"),
    (lambda: figures.render(small_figure(), dpi=100.5), orrc.OrrcValueError, ["dpi", "integer"], "render-dpi-float"),
    (lambda: figures.figure_to_png(None), orrc.OrrcValueError, ["fig", "NoneType"], "to-png-type"),
    (lambda: figures.figure_to_png(small_figure(), dpi=50), orrc.OrrcValueError, ["dpi", "50"], "to-png-dpi"),
    (lambda: figures.figure_html([1, 2]), orrc.OrrcValueError, ["fig", "list"], "html-type"),
    (lambda: figures.legible(small_figure(), min_pt=float("nan")), orrc.OrrcValueError, ["min_pt"], "legible-nan"),
    (lambda: figures.legible(small_figure(), min_pt=0.0), orrc.OrrcValueError, ["min_pt", "0"], "legible-range"),
    (lambda: figures.legible(np.zeros(3)), orrc.OrrcValueError, ["fig", "ndarray"], "legible-type"),
    (lambda: figures.narrowed(small_figure(), width=20.0), orrc.OrrcValueError, ["width", "20"], "narrow-too-wide"),
    (lambda: figures.narrowed(small_figure(), width=float("inf")), orrc.OrrcValueError, ["width"], "narrow-inf"),
    (lambda: figures.narrowed("fig"), orrc.OrrcValueError, ["fig", "str"], "narrow-type"),
    (lambda: figures.narrowed(small_figure(), panel_height=0.0), orrc.OrrcValueError, ["panel_height"],
     "narrow-height"),
    (lambda: figures.picture_html(b"not a png", None), orrc.OrrcValueError, ["wide", "PNG"], "picture-bytes"),
    (lambda: figures.picture_html("text", None), orrc.OrrcValueError, ["wide", "str"], "picture-type"),
    (lambda: figures.picture_html(PNG, b"GIF89a"), orrc.OrrcValueError, ["small", "PNG"], "picture-small"),
    (lambda: figures.picture_html(PNG, None, uid="1 bad id"), orrc.OrrcValueError, ["uid", "1 bad id"],
     "picture-uid"),
    # orrc.viz.glue
    (lambda: glue("", 1.0), orrc.OrrcValueError, ["name", "non-empty string"], "glue-empty"),
    (lambda: glue(3, 1.0), orrc.OrrcValueError, ["name", "3"], "glue-type"),
    # orrc.viz.explore
    (lambda: explore(a_plot, M=[1, 2], dpi=70, live=False), orrc.OrrcValueError, ["dpi", ">= 100", "70"],
     "explore-dpi"),
    (lambda: explore(lambda M, a: small_figure(), M=list(range(30)), a=list(range(30)), live=False),
     orrc.OrrcValueError, ["explore over 900 frames", "too large", "limit"], "explore-too-many-frames"),
    # the tables of the theory chapters
    (lambda: theory_plots.constants_table({}), orrc.OrrcValueError, ["constants", "non-empty dict"],
     "constants-table-empty"),
    (lambda: theory_plots.constants_table({"a": 1.0}), orrc.OrrcValueError, ["constants['a']", "Constants", "float"],
     "constants-table-type"),
    (lambda: theory_plots.constants_table([1]), orrc.OrrcValueError, ["constants[0]", "Constants", "int"], "constants-table-list"),
    (lambda: theory_plots.constants_table([]), orrc.OrrcValueError, ["constants", "empty list"], "constants-table-empty-list"),
    (lambda: theory_plots.margins_table({"x": "margins"}), orrc.OrrcValueError, ["margins['x']", "Margins", "str"],
     "margins-table-type"),
    (lambda: theory_plots.margins_table(None), orrc.OrrcValueError, ["margins", "NoneType"], "margins-table-none"),
    (lambda: orrc.viz.plots.table(["a", "b"], [[1.0]]), orrc.OrrcValueError, ["row 0", "1 cells", "2 columns"],
     "table-row"),
    (lambda: orrc.viz.plots.table(["a"], [[1.0]], digits=0), orrc.OrrcValueError, ["digits", "0"], "table-digits"),
]


@pytest.mark.parametrize("call, exc, words", [c[:3] for c in CASES], ids=[c[3] for c in CASES])
def test_bad_input_is_refused_with_a_clear_message(call, exc, words):
    with pytest.raises(exc) as info:
        call()
    assert isinstance(info.value, ValueError)
    for w in words:
        assert w in str(info.value), f"{w!r} not in the message {str(info.value)!r}"


def test_a_test_size_build_is_refused_in_the_published_folder(monkeypatch):
    """tools.build_book never writes a shortened build where readers look (_build/html)."""
    from tools.build_book import ROOT, build

    monkeypatch.setenv("ORRC_QUICK", "1")
    with pytest.raises(ValueError, match="test-size build .* must not be written to .*_build/html"):
        build(ROOT)
