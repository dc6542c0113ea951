"""The figures of the comparison chapter draw the numbers they are given (orrc.viz.comparison_plots)."""
import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import orrc
from orrc.comparison import compare, preview_value
from orrc.viz import comparison_plots as cp
from orrc.viz.figures import narrowed


@pytest.fixture(scope="module")
def scalar():
    ex = orrc.examples.scalar_unstable()
    s, c = ex.system, ex.cost
    w = orrc.disturbances.uniform_ball(20, 1, 1.0, seed=0)
    rows = compare(s, c, {"LQR": orrc.LQR(s, c), "preview RHC": orrc.PreviewRHC(s, c, 5)}, w, 12, 1.0)
    return s, c, w, rows


def test_metric_bars_draw_each_controllers_value(scalar):
    _, _, _, rows = scalar
    fig = cp.metric_bars(rows, "dynamic_regret")
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    vals = [r.dynamic_regret for r in rows]
    # every value is printed beside its bar, bars and labels in the rows' order
    assert [t.get_text() for t in ax.texts] == [f"{v:.3g}" for v in vals]
    if ax.get_xscale() == "linear":
        assert [p.get_width() for p in ax.patches] == pytest.approx(vals)
    # a linear axis when asked: the bars are the values
    lin = cp.metric_bars(rows, "cost", log=False).axes[0]
    assert [p.get_width() for p in lin.patches] == pytest.approx([r.cost for r in rows])
    # rows without a worst case (the clairvoyant) are left out
    assert len(cp.metric_bars(rows, "worst_regret").axes[0].patches) == 2


def test_metric_bars_use_a_log_axis_when_values_span_decades_and_every_bar_is_visible():
    ex = orrc.examples.scalar_unstable()
    s, c = ex.system, ex.cost
    w = orrc.disturbances.uniform_ball(40, 1, 1.0, seed=0)
    ctrl = {"LQR": orrc.LQR(s, c), "preview RHC": orrc.PreviewRHC(s, c, 10)}
    rows = compare(s, c, ctrl, w, 30, 1.0)[:2]            # the clairvoyant's zero regret left out
    vals = np.array([r.dynamic_regret for r in rows])
    assert vals.max() > 100 * vals.min() > 0                # the case of the chapter's chart
    ax = cp.metric_bars(rows, "dynamic_regret").axes[0]
    assert ax.get_xscale() == "log"
    lo, hi = ax.get_xlim()
    for p, v in zip(ax.patches, vals):                      # each bar starts inside the axis, ends at v
        assert lo <= p.get_x() < v and p.get_x() + p.get_width() == pytest.approx(v)
    assert hi > vals.max()
    # the clairvoyant's 0 has no bar on the log axis, but its value is printed
    ax0 = cp.metric_bars(compare(s, c, ctrl, w, 30, 1.0), "dynamic_regret").axes[0]
    assert ax0.get_xscale() == "log" and ax0.texts[-1].get_text() == "0"
    assert ax0.patches[-1].get_width() == 0.0 and ax0.patches[0].get_width() > 0
    # values within two decades keep a linear axis
    costs = [r.cost for r in rows]
    assert max(costs) < 100 * min(costs)
    assert cp.metric_bars(rows, "cost").axes[0].get_xscale() == "linear"


def test_preview_decay_draws_the_excess_and_the_fit(scalar):
    s, c, _, _ = scalar
    pv = preview_value(s, c, 10, range(5), orrc.disturbances.uniform_ball(60, 1, 1.0, seed=1), 50)
    fig = cp.preview_decay(pv)
    dots, fit, rho = fig.axes[0].get_lines()[:3]
    np.testing.assert_allclose(dots.get_ydata(), pv.excess[pv.excess > 0])
    assert fit.get_ydata()[1] / fit.get_ydata()[0] == pytest.approx(pv.rate)
    assert rho.get_ydata()[1] / rho.get_ydata()[0] == pytest.approx(pv.lambda_K_sq)


def test_running_cost_is_the_cumulative_cost(scalar):
    s, c, w, _ = scalar
    tr = orrc.simulate(s, orrc.LQR(s, c), np.zeros(1), w, 12)
    line = cp.running_cost({"LQR": tr}).axes[0].get_lines()[0]
    np.testing.assert_allclose(line.get_ydata(), np.cumsum(tr.costs))


def _renderer(fig):
    """The renderer of ``fig`` after its layout is drawn (an Agg canvas, as the book renders)."""
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return canvas.get_renderer()


def _boxes(fig, ax, artist):
    """The display boxes of ``ax`` and of ``artist`` after the figure's layout is drawn."""
    renderer = _renderer(fig)
    return ax.get_window_extent(renderer), artist.get_window_extent(renderer)


def test_running_cost_keeps_its_legend_off_the_curves(scalar):
    s, c, w, _ = scalar
    runs = {name: orrc.simulate(s, ctrl, np.zeros(1), w, 12)
            for name, ctrl in {"LQR": orrc.LQR(s, c), "preview RHC, M = 5": orrc.PreviewRHC(s, c, M=5),
                               "clairvoyant optimum": orrc.Clairvoyant(s, c, 12)}.items()}
    fig = cp.running_cost(runs)
    ax = fig.axes[0]
    box, legend = _boxes(fig, ax, ax.get_legend())
    assert legend.y1 < box.y0, "the legend overlaps the axes, where it can cover a curve"
    assert legend.y0 >= fig.bbox.y0 - 1, "the legend runs past the figure's bottom edge"
    with narrowed(fig):   # and in the phone's rendering too
        box, legend = _boxes(fig, ax, ax.get_legend())
        assert legend.y1 < box.y0 and legend.y0 >= fig.bbox.y0 - 1 and legend.x1 <= fig.bbox.x1 + 1


def test_metric_bars_label_stays_inside_a_phones_figure(scalar):
    """The bar names take most of a narrow figure's width: the axis label is flush right, never cut."""
    s, c, w, _ = scalar
    rows = compare(s, c, {"LQR": orrc.LQR(s, c), "regret-optimal, full information":
                          orrc.RegretOptimal(s, c, 12, causality="full-information")}, w, 12, 1.0)
    fig = cp.metric_bars(rows, "worst_regret")
    with narrowed(fig):
        label = fig.axes[0].xaxis.label.get_window_extent(_renderer(fig))
        assert fig.bbox.x0 - 1 <= label.x0 and label.x1 <= fig.bbox.x1 + 1


@pytest.mark.parametrize("call, match", [
    (lambda rows: cp.metric_bars(rows, "speed"), "metric must be one of"),
    (lambda rows: cp.metric_bars([], "cost"), "rows must be a non-empty list"),
    (lambda rows: cp.preview_decay(rows), "pv must be"),
    (lambda rows: cp.running_cost({}), "trajs"),
])
def test_comparison_plots_reject_bad_input(scalar, call, match):
    with pytest.raises(ValueError, match=match):
        call(scalar[3])
