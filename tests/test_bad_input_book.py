"""Bad input to the book's tools (orrc.viz.figures, orrc.viz.glue, orrc.viz.explore, the constants and
margins tables, tools.build_book): a clear orrc.OrrcValueError naming the argument, never a
traceback from deep inside matplotlib."""
import os

import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

import orrc  # noqa: E402
from orrc.viz import explore, figures, glue, theory_plots  # noqa: E402

from bad_input import assert_bad_input, case, params  # noqa: E402


def small_figure(width=5.0):
    fig = Figure(figsize=(width, 2.0))
    fig.subplots().plot([0, 1], [0, 1])
    return fig


def a_plot(M):
    return small_figure()


PNG = figures.figure_to_png(small_figure())

CASES = [
    case("render-type", lambda: figures.render("not a figure"),
         "fig", "matplotlib Figure", "str"),
    case("render-dpi", lambda: figures.render(small_figure(), dpi=72),
         "dpi", ">= 100", "72"),
    case("render-dpi-float", lambda: figures.render(small_figure(), dpi=100.5),
         "dpi", "integer"),
    case("to-png-type", lambda: figures.figure_to_png(None),
         "fig", "NoneType"),
    case("to-png-dpi", lambda: figures.figure_to_png(small_figure(), dpi=50),
         "dpi", "50"),
    case("html-type", lambda: figures.figure_html([1, 2]),
         "fig", "list"),
    case("legible-nan", lambda: figures.legible(small_figure(), min_pt=float("nan")),
         "min_pt"),
    case("legible-range", lambda: figures.legible(small_figure(), min_pt=0.0),
         "min_pt", "0"),
    case("legible-type", lambda: figures.legible(np.zeros(3)),
         "fig", "ndarray"),
    case("narrow-too-wide", lambda: figures.narrowed(small_figure(), width=20.0),
         "width", "20"),
    case("narrow-inf", lambda: figures.narrowed(small_figure(), width=float("inf")),
         "width"),
    case("narrow-type", lambda: figures.narrowed("fig"),
         "fig", "str"),
    case("narrow-height", lambda: figures.narrowed(small_figure(), panel_height=0.0),
         "panel_height"),
    case("picture-bytes", lambda: figures.picture_html(b"not a png", None),
         "wide", "PNG"),
    case("picture-type", lambda: figures.picture_html("text", None),
         "wide", "str"),
    case("picture-small", lambda: figures.picture_html(PNG, b"GIF89a"),
         "small", "PNG"),
    case("picture-uid", lambda: figures.picture_html(PNG, None, alt="a line", uid="1 bad id"),
         "uid", "1 bad id"),
    case("picture-alt", lambda: figures.picture_html(PNG, None),
         "alt", "text alternative", "NoneType"),
    case("glue-empty", lambda: glue("", 1.0),
         "name", "non-empty string"),
    case("glue-type", lambda: glue(3, 1.0),
         "name", "3"),
    case("explore-dpi", lambda: explore(a_plot, M=[1, 2], dpi=70, live=False),
         "dpi", ">= 100", "70"),
    case("explore-too-many-frames", lambda: explore(lambda M, a: small_figure(), M=list(range(30)), a=list(range(30)), live=False),
         "explore over 900 frames", "too large", "limit"),
    case("explore-live-type", lambda: explore(a_plot, M=[1, 2], live="yes"),
         "live", "True, False or None", "'yes'"),
    case("explore-static-type", lambda: explore(a_plot, M=[1, 2], live=False, static=1),
         "static", "True, False or None", "1"),
    case("explore-shows-nothing", lambda: explore(a_plot, M=[1, 2], live=False, static=False),
         "live=False and static=False", "shows nothing"),
    case("explore-live-no-figure", lambda: explore(lambda M: None, M=[1, 2], live=True),
         "plot must return a matplotlib Figure", "NoneType"),
    case("render-live-type", lambda: figures.render_live("not a figure"),
         "fig", "matplotlib Figure", "str"),
    case("render-live-dpi", lambda: figures.render_live(small_figure(), dpi=99),
         "dpi", ">= 100", "99"),
    case("constants-table-empty", lambda: theory_plots.constants_table({}),
         "constants", "non-empty dict"),
    case("constants-table-type", lambda: theory_plots.constants_table({"a": 1.0}),
         "constants['a']", 'Constants', 'float'),
    case("constants-table-list", lambda: theory_plots.constants_table([1]),
         "constants[0]", "Constants", "int"),
    case("constants-table-empty-list", lambda: theory_plots.constants_table([]),
         "constants", "empty list"),
    case("margins-table-type", lambda: theory_plots.margins_table({"x": "margins"}),
         "margins['x']", 'Margins', 'str'),
    case("margins-table-none", lambda: theory_plots.margins_table(None),
         "margins", "NoneType"),
    case("table-row", lambda: orrc.viz.plots.table(["a", "b"], [[1.0]]),
         "row 0", "1 cells", "2 columns"),
    case("table-digits", lambda: orrc.viz.plots.table(["a"], [[1.0]], digits=0),
         "digits", "0"),
]


@pytest.mark.parametrize("call, exc, words", params(CASES))
def test_bad_input_is_refused_with_a_clear_message(call, exc, words):
    assert_bad_input(call, exc, words)


def test_every_build_sets_the_book_build_signal(tmp_path):
    """tools.build_book.build runs jupyter-book with ORRC_BOOK_BUILD=1 (what orrc.config.book_build
    reads), for the published book, the test build and the solution-free edition alike."""
    import tools.build_book as bb

    # the commands go to a runner of the test's own: the session's book build runs beside this test,
    # in another thread, with the real subprocess.call (patching the module would hand it the fake)
    seen, before = [], os.environ.get("ORRC_BOOK_BUILD")
    assert bb.build(tmp_path, extra_env={"ORRC_QUICK": "1"}, run=lambda cmd, **kw: seen.append(kw["env"]) or 1) == 1
    assert len(seen) == 2, "the chapters' execution and jupyter-book, each with the build's environment"
    assert all(env["ORRC_BOOK_BUILD"] == "1" and env["ORRC_QUICK"] == "1" for env in seen)
    assert os.environ.get("ORRC_BOOK_BUILD") == before     # set in the build's environment only


def test_a_test_size_build_is_refused_in_the_published_folder(monkeypatch):
    """tools.build_book never writes a shortened build where readers look (_build/html)."""
    from tools.build_book import ROOT, build

    monkeypatch.setenv("ORRC_QUICK", "1")
    with pytest.raises(ValueError, match="test-size build .* must not be written to .*_build/html"):
        build(ROOT)
