"""Every figure of the book has a text alternative written from what the figure knows:
its titles, what is plotted against what, its scales and series; an explorer's frame adds its
parameter values. No fixed ``alt="figure"``."""
from __future__ import annotations

import re

from matplotlib.figure import Figure

from orrc.viz import explore, figures, plots
from orrc.viz.describe import describe, frame_description, plain


def two_panels() -> Figure:
    fig = Figure(figsize=(6.0, 3.0))
    left, right = fig.subplots(1, 2)
    left.plot([1, 2], [3, 4], label=r"$\bar\gamma_c$ bound")
    left.plot([1, 2], [3, 5], label="preview RHC")
    left.legend()
    left.set(xlabel="horizon $M$", ylabel="cost", yscale="log", title="Cost")
    right.bar([1, 2], [3, 4])
    right.set_ylabel("regret")
    fig.suptitle("Cost and regret")
    return fig


def test_the_description_says_what_each_panel_plots():
    text = describe(two_panels())
    assert text.startswith("Cost and regret. 2 panels.")
    assert "Panel 1, Cost: cost against horizon M (y on a log scale); series: γ̄_c bound, preview RHC." in text
    assert "Panel 2, regret." in text
    assert "$" not in text and "\\" not in text


def test_mathtext_reads_as_plain_text():
    assert plain(r"$\alpha_{hi}\,\sigma(x)$ and $\Vert w \Vert^2$") == "α_hi σ(x) and ‖ w ‖^2"
    assert plain("two\nlines") == "two lines"
    # an accent stays on its letter (ᾱ is not α), a style command leaves its text, \varphi is φ
    assert plain(r"$\overline{\alpha}_{\mathcal W}$, $\bar\gamma$, $\underline{\alpha}$") == "\u03b1\u0304_W, \u03b3\u0304, \u03b1\u0332"
    assert plain(r"$\hat\theta - \theta$ and $c_s^{\rm known}$, $\varphi_t$") == "\u03b8\u0302 - \u03b8 and c_s^known, \u03c6_t"


def test_a_book_figure_is_described_from_its_own_labels():
    fig = plots.information_pattern(3, 2, 2, 8)
    text = describe(fig)
    assert plain(fig.axes[0].get_title())[1:] in text and "time step" in text
    html = figures.figure_html(plots.information_pattern(3, 2, 2, 8))
    alts = re.findall(r'alt="([^"]*)"', html)
    assert len(alts) == 2 and len(set(alts)) == 1 and alts[0] and alts[0] != "figure"


def test_each_frame_of_an_explorer_names_its_parameters():
    ex = explore(lambda M, gamma: plots.information_pattern(3, M, M, 8), M=[1, 2], gamma=[0.5, 2.0],
                 live=False, static=True)
    assert set(ex.alts) == set(ex.frames["images"])
    assert ex.alts["0_1"].startswith("Frame with M = 1, gamma = 2.") and "M_w=1" in ex.alts["0_1"]
    assert len(set(ex.alts.values())) == 4, "every frame has its own description"
    first = re.findall(r'<img[^>]*alt="([^"]*)"', ex.html)
    assert first and all(a == ex.alts["0_0"] for a in first), "the first frame's images carry its description"
    assert '"alts"' in ex.html and "wide.alt = frames.alts[k]" in ex.html, "a slider move updates the description"
    assert frame_description({"T": 10}, two_panels()).startswith("Frame with T = 10. Cost and regret.")
