"""The Lemma 2 figures (orrc.viz.theory_plots): they draw the coefficients M_{w,j} and the
margins of orrc.checks.lemma2_margins, the data in the figure is that data, and bad input
raises a ValueError naming the argument."""
import matplotlib.colors as mcolors
import numpy as np
import pytest

from conftest import legend_under_axes
from matplotlib.figure import Figure

import orrc
from orrc import certify, checks, theory
from orrc.viz import theory_plots
import paper


@pytest.fixture(scope="module")
def run():
    """Algorithm 1 on x+ = 1.2x + u + w (certified from M = 5) with certified constants."""
    ex = orrc.examples.scalar_unstable(A=1.2)
    M, H, T = 6, 8, 30
    c = certify.lq_constants(ex.system, ex.cost, M)
    w = orrc.disturbances.uniform_ball(T + M, 1, radius=0.5, seed=1)
    traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, M=M), 3.0 * ex.x0, w, T)
    mg = checks.lemma2_margins(traj, M, H, c.a, c.alpha_lo, c.alpha_hi, c.gamma_bar)
    b = theory.decay_b(c.alpha_lo, c.alpha_hi, c.gamma_bar)
    coef = theory.lemma2_coefficients(M, H, c.a, c.alpha_hi, c.gamma_bar, b)
    return M, H, c, b, coef, mg


def test_coefficients_plot_draws_the_papers_coefficients_and_the_three_bands():
    M, H, gb, b = 4, 9, 2.0, 3.0
    a_s = (0.6, 0.9)
    coefs = {f"a = {a}": theory.lemma2_coefficients(M, H, a, 1.5, gb, b) for a in a_s}
    fig = theory_plots.lemma2_coefficients(coefs, M, H)
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    assert ax.get_yscale() == "log"
    lines = ax.get_lines()
    assert [ln.get_label() for ln in lines] == list(coefs)
    for ln, a in zip(lines, a_s):
        np.testing.assert_array_equal(ln.get_xdata(), np.arange(H + M - 1))
        np.testing.assert_allclose(ln.get_ydata(), paper.lemma2_coefficients(M, H, a, gb, b), rtol=1e-12)
    # the shaded bands: window at t (0..M-1), decaying (M..H-1), window at t+H (H..H+M-2)
    spans = sorted((p.get_x(), p.get_x() + p.get_width()) for p in ax.patches)
    np.testing.assert_allclose(spans, [(-0.5, M - 0.5), (M - 0.5, H - 0.5), (H - 0.5, H + M - 1.5)])
    # H = M: no decaying middle band
    fig = theory_plots.lemma2_coefficients({"a": theory.lemma2_coefficients(M, M, 0.5, 1.0, gb, b)}, M, M)
    assert len(fig.axes[0].patches) == 2


def test_coefficients_plot_keeps_its_legend_off_the_curves():
    """A figure of its own puts the legend under the axes, in the wide and the phone's rendering
    (inside, it covered the flat tail that the text reads from right to left)."""

    from orrc.viz.figures import narrowed

    M, H = 8, 20
    coefs = {f"a = {a}": theory.lemma2_coefficients(M, H, a, 2.0, 4.0, 6.0) for a in (0.86, 0.9, 0.95)}
    fig = theory_plots.lemma2_coefficients(coefs, M, H)
    ax = fig.axes[0]

    assert legend_under_axes(fig, ax)
    with narrowed(fig):
        assert legend_under_axes(fig, ax)


def test_coefficients_plot_rejects_bad_input():
    good = np.ones(4 + 9 - 1)
    with pytest.raises(ValueError, match=r"coefs\['x'\]"):
        theory_plots.lemma2_coefficients({"x": good[:-1]}, 4, 9)      # wrong length
    with pytest.raises(ValueError, match="H"):
        theory_plots.lemma2_coefficients({"x": good}, 4, 3)           # H < M
    with pytest.raises(ValueError, match="coefs"):
        theory_plots.lemma2_coefficients({}, 4, 9)
    with pytest.raises(ValueError, match=r"coefs\['x'\]"):
        theory_plots.lemma2_coefficients({"x": np.full(12, np.nan)}, 4, 9)


def test_bounds_vs_actual_draws_the_data_with_distinct_colours():
    x = np.arange(6.0)
    actual = np.array([1.0, 0.0, 2.0, 3.0, 0.5, 4.0])
    bounds = {"bound": actual + 10, "part": actual + 1, "value": actual + 2}
    fig = theory_plots.bounds_vs_actual(x, actual, bounds, actual_label="c")
    ax = fig.axes[0]
    assert ax.get_yscale() == "log"
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    for k, v in bounds.items():
        np.testing.assert_array_equal(lines[k].get_ydata(), v)
    pos = actual > 0                                   # a zero cost cannot be drawn on a log scale
    np.testing.assert_array_equal(lines["c"].get_xdata(), x[pos])
    np.testing.assert_array_equal(lines["c"].get_ydata(), actual[pos])
    colours = [mcolors.to_hex(ln.get_color()) for ln in ax.get_lines()]
    assert len(set(colours)) == len(colours), colours  # every curve has its own colour
    # linear scale keeps every point; the legend can go below the axes
    fig = theory_plots.bounds_vs_actual(x, actual, bounds, log=False, actual_label="c", legend="below")
    ax = fig.axes[0]
    assert ax.get_yscale() == "linear"
    assert len([ln for ln in ax.get_lines() if ln.get_label() == "c"][0].get_ydata()) == len(x)
    fig.canvas.draw()
    leg = ax.get_legend().get_window_extent()
    assert leg.y1 <= ax.get_window_extent().y0 + 1      # entirely under the axes


def test_bounds_vs_actual_rejects_bad_input():
    x = np.arange(5.0)
    with pytest.raises(ValueError, match="actual"):
        theory_plots.bounds_vs_actual(x, np.ones(4), {"b": np.ones(5)})
    with pytest.raises(ValueError, match=r"bounds\['b'\]"):
        theory_plots.bounds_vs_actual(x, np.ones(5), {"b": np.ones(4)})
    with pytest.raises(ValueError, match="bounds"):
        theory_plots.bounds_vs_actual(x, np.ones(5), {})
    with pytest.raises(ValueError, match="legend"):
        theory_plots.bounds_vs_actual(x, np.ones(5), {"b": np.ones(5)}, legend="outside")


def test_lemma2_frame_shows_coefficients_and_margins(run):
    M, H, c, b, coef, mg = run
    assert mg.holds()
    fig = theory_plots.lemma2_frame(M, c.a, c.a, coef=coef, margins=mg, H=H, ylim=(1e-4, 1e5),
                                    coef_ylim=(1.0, 1e4))
    ax, ax2 = fig.axes
    np.testing.assert_allclose(ax.get_lines()[0].get_ydata(), paper.lemma2_coefficients(M, H, c.a, c.gamma_bar, b),
                               rtol=1e-12)
    lines = {ln.get_label(): ln for ln in ax2.get_lines()}
    np.testing.assert_array_equal(lines["Lemma 2 bound"].get_xdata(), mg.t + H)
    np.testing.assert_array_equal(lines["Lemma 2 bound"].get_ydata(), mg.bound)
    pos = mg.actual > 0
    np.testing.assert_array_equal(lines["$c_{t+H}$"].get_ydata(), mg.actual[pos])
    assert ax2.get_ylim() == pytest.approx((1e-4, 1e5))
    assert ax.get_ylim() == pytest.approx((1.0, 1e4))
    assert pos.all()                                   # c = x² + u² > 0 along this run
    ratio = np.median(mg.bound / mg.actual)
    assert f"median bound / cost = {ratio:.3g}" in fig._suptitle.get_text()


def test_lemma2_frame_below_a_min_says_so_and_draws_nothing(run):
    M, H, c, b, coef, mg = run
    a = 0.5 * c.a
    fig = theory_plots.lemma2_frame(M, a, c.a)
    assert all(not ax.get_lines() for ax in fig.axes)
    text = " ".join(t.get_text() for ax in fig.axes for t in ax.texts)
    assert f"a_min = {c.a:.4f}" in text and "does not apply" in text
    assert "not admissible" in fig._suptitle.get_text()


def test_lemma2_frame_rejects_bad_input(run):
    M, H, c, b, coef, mg = run
    with pytest.raises(ValueError, match="a must be"):
        theory_plots.lemma2_frame(M, 1.0, c.a, coef=coef, margins=mg, H=H)
    with pytest.raises(ValueError, match="a must be"):
        theory_plots.lemma2_frame(M, 0.0, c.a)
    with pytest.raises(ValueError, match="a_min"):
        theory_plots.lemma2_frame(M, 0.9, float("nan"))
    with pytest.raises(ValueError, match="coef, margins and H"):
        theory_plots.lemma2_frame(M, c.a, c.a, coef=coef, H=H)
    with pytest.raises(ValueError, match="margins"):
        theory_plots.lemma2_frame(M, c.a, c.a, coef=coef, margins=mg.bound, H=H)
    with pytest.raises(ValueError, match="H"):
        theory_plots.lemma2_frame(M, c.a, c.a, coef=coef, margins=mg, H=M - 1)
    with pytest.raises(ValueError, match=r"coefs\["):
        theory_plots.lemma2_frame(M, c.a, c.a, coef=coef[:-1], margins=mg, H=H)
    with pytest.raises(ValueError, match="ylim"):
        theory_plots.lemma2_frame(M, c.a, c.a, coef=coef, margins=mg, H=H, ylim=(0.0, 1.0))
    with pytest.raises(ValueError, match="coef_ylim"):
        theory_plots.lemma2_frame(M, c.a, c.a, coef=coef, margins=mg, H=H, coef_ylim=(5.0, 1.0))


def test_lemma2_frame_serves_the_explorer(run):
    M, H, c, b, coef, mg = run
    from orrc.viz import explore

    def frame(a):
        if a < c.a:
            return theory_plots.lemma2_frame(M, a, c.a)
        co = theory.lemma2_coefficients(M, H, a, c.alpha_hi, c.gamma_bar, b)
        return theory_plots.lemma2_frame(M, a, c.a, coef=co, margins=mg, H=H)

    ex = explore(frame, a=[0.5 * c.a, c.a], live=False)
    frames = ex.frames["images"]
    assert len(frames) == 2 and frames["0"] != frames["1"] and ex.frames["narrow"] is not None
    assert 'class="orrc-frames"' in ex.html and "orrc-slider" in ex.html
