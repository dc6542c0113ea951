"""Figures a reader can read (orrc.viz.figures): every figure is rendered at 100 dpi with fonts of at
least 9 pt, wide (at most 7.4 in, inside the book's 757 px column at 1366 px) and, for a phone, narrow
(3.4 in, inside the 358 px column at 390 px) with its panels stacked; the page shows the one that fits.
And the chapters' glue works without the book's tools (orrc.viz.glue)."""
import base64
import io
import re

import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from PIL import Image  # noqa: E402

from orrc.viz import figures, glue  # noqa: E402
from orrc.viz.notebook import glued  # noqa: E402


def three_panels(width=10.0, sharey=False):
    fig = Figure(figsize=(width, 3.0), layout="constrained")
    axes = fig.subplots(1, 3, sharey=sharey)
    for i, ax in enumerate(axes):
        for k in range(3):
            ax.plot(np.arange(10), np.arange(10) * (i + k + 1), label=f"curve {k}")
        ax.set_title(f"panel {i}: a rather long title that must wrap on a phone", fontsize=7)
        ax.tick_params(labelsize=6)
    axes[0].legend(fontsize=6, ncols=3, loc="upper center", bbox_to_anchor=(0.5, -0.2))
    fig.suptitle("a figure title with math $\\overline{\\alpha}(\\overline{\\gamma})$ that is long", fontsize=8)
    return fig, axes


def png_size(png: bytes):
    img = Image.open(io.BytesIO(png))
    return img.size, img.info.get("dpi")


def test_legible_raises_every_small_font_to_9_pt_and_keeps_larger_ones():
    fig, axes = three_panels()
    big = axes[1].text(0.5, 0.5, "big", fontsize=14)
    figures.legible(fig)
    texts = [t for t in fig.findobj(matplotlib.text.Text) if t.get_text()]
    assert min(t.get_fontsize() for t in texts) >= 9
    assert big.get_fontsize() == 14
    for ax in axes:
        assert all(t.get_fontsize() >= 9 for t in ax.get_xticklabels() + ax.get_yticklabels())


def test_tick_labels_avoid_half_steps_and_sci_notation_on_short_log_ranges():
    fig = Figure(figsize=(5, 3))
    ax_lin, ax_log = fig.subplots(1, 2)
    ax_lin.plot([0, 1], [40.0, 49.0])
    ax_lin.set_ylim(40.0, 49.0)
    ax_log.semilogy([0, 1], [2.0, 9.0])
    ax_log.set_ylim(2.0, 9.0)
    fig.canvas.draw()                      # without the tidy: 42.5-style and 3×10⁰-style labels
    before = [t.get_text() for t in ax_log.get_yticklabels(minor=True)]
    assert any("10^" in t or "\\times" in t for t in before if t)
    figures.legible(fig)
    fig.canvas.draw()
    lin = [float(t.get_text().replace("−", "-")) for t in ax_lin.get_yticklabels() if t.get_text()]
    assert lin and all(abs(v * 2 - round(v * 2)) < 1e-9 and round(v * 2) % 2 == 0 for v in lin), lin
    logs = [t.get_text() for t in ax_log.get_yticklabels(minor=True) + ax_log.get_yticklabels() if t.get_text()]
    assert logs and not any("10^" in t or "\\times" in t for t in logs), logs


def test_narrowed_stacks_the_panels_for_a_phone_and_restores_the_figure():
    fig, axes = three_panels(sharey=True)
    specs = [ax.get_subplotspec() for ax in axes]
    size, titles = tuple(fig.get_size_inches()), [ax.get_title() for ax in axes]
    with figures.narrowed(fig):
        w, h = fig.get_size_inches()
        assert w == pytest.approx(figures.NARROW_IN) and h > 3 * figures.PANEL_IN - 1e-9
        rows = [ax.get_subplotspec().rowspan.start for ax in axes]
        assert rows == [0, 1, 2] and all(ax.get_subplotspec().colspan.start == 0 for ax in axes)
        assert axes[0].get_legend()._ncols == 1
        assert all("\n" in ax.get_title() for ax in axes), "long titles wrap"
        assert "$\\overline{\\alpha}(\\overline{\\gamma})$" in fig._suptitle.get_text(), "never inside math"
        assert all(t.get_visible() for t in axes[2].get_yticklabels()), "shared y: every panel labelled"
    assert tuple(fig.get_size_inches()) == size and [ax.get_title() for ax in axes] == titles
    assert [ax.get_subplotspec() for ax in axes] == specs and axes[0].get_legend()._ncols == 3


def test_render_draws_wide_and_narrow_pngs_at_100_dpi():
    fig, _ = three_panels(width=10.0)
    wide, narrow = figures.render(fig, close=False)
    (ww, wh), wdpi = png_size(wide)
    (nw, nh), ndpi = png_size(narrow)
    assert ww == round(100 * figures.WIDE_IN) and nw == round(100 * figures.NARROW_IN)
    assert wdpi == pytest.approx((100, 100), abs=0.01) and ndpi == pytest.approx((100, 100), abs=0.01)
    assert nh > wh, "the narrow rendering stacks the panels"
    assert tuple(fig.get_size_inches()) == (10.0, 3.0), "the figure keeps its size"
    with pytest.raises(ValueError, match="dpi must be an integer >= 100; got 72"):
        figures.render(fig, dpi=72)


def test_a_small_figure_has_one_rendering():
    fig = Figure(figsize=(3.0, 2.0))
    fig.subplots().plot([0, 1], [0, 1])
    wide, narrow = figures.render(fig)
    assert narrow is None and png_size(wide)[0][0] <= 300
    html = figures.picture_html(wide, None, alt="a line from (0, 0) to (1, 1)")
    assert html.count("<img") == 1 and "@container" not in html


def test_the_page_shows_the_rendering_that_fits_its_column():
    fig, _ = three_panels()
    html = figures.figure_html(fig)
    wide = re.search(r'data-variant="wide"[^>]*src="data:image/png;base64,([^"]+)"', html)
    narrow = re.search(r'data-variant="narrow"[^>]*src="data:image/png;base64,([^"]+)"', html)
    assert wide and narrow
    px = png_size(base64.b64decode(wide.group(1)))[0][0]
    uid = re.search(r'<div class="orrc-figure" id="([^"]+)"', html).group(1)
    # the narrow image is hidden unless the figure's container is narrower than the wide image
    assert f"#{uid} img[data-variant=narrow]{{display:none}}" in html
    assert f"@container (max-width: {px - 1}px){{#{uid} img[data-variant=wide]{{display:none}}" in html


def test_install_makes_figures_display_as_both_renderings():
    from IPython.core.interactiveshell import InteractiveShell

    ip = InteractiveShell.instance()
    try:
        assert figures.install(ip)
        fig, _ = three_panels()
        data, _ = ip.display_formatter.format(fig)
        assert 'class="orrc-figure"' in data["text/html"] and "image/png" not in data
        # `%matplotlib inline` registers the PNG form again ...
        ip.display_formatter.formatters["image/png"].for_type(Figure, lambda f: b"\x89PNG")
        ip.events.trigger("pre_run_cell", None)              # ... which the next cell drops again
        data, _ = ip.display_formatter.format(three_panels()[0])
        assert "image/png" not in data and 'class="orrc-figure"' in data["text/html"]
    finally:
        InteractiveShell.clear_instance()
    assert figures.install() is False, "outside IPython there is nothing to install"


def test_glue_works_without_the_book_tools():
    assert glue("test-figures-key", np.float64(2.5)) is None      # as myst-nb's glue: no Out in a cell
    assert glued["test-figures-key"] == 2.5 and type(glued["test-figures-key"]) is float
    with pytest.raises(ValueError, match="name must be a non-empty string"):
        glue("", 1.0)
