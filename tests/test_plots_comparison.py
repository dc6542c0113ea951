"""The figures of the comparison chapter draw the numbers they are given (orrc.viz.comparison_plots)."""
import numpy as np
import pytest
from matplotlib.figure import Figure

import orrc
from orrc.comparison import compare, preview_value
from orrc.viz import comparison_plots as cp


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
    widths = [p.get_width() for p in fig.axes[0].patches]
    assert widths == pytest.approx([r.dynamic_regret for r in rows])
    # rows without a worst case (the clairvoyant) are left out
    assert len(cp.metric_bars(rows, "worst_regret").axes[0].patches) == 2


def test_preview_decay_draws_the_excess_and_the_fit(scalar):
    s, c, _, _ = scalar
    pv = preview_value(s, c, 10, range(5), orrc.disturbances.uniform_ball(60, 1, 1.0, seed=1), 50)
    fig = cp.preview_decay(pv)
    dots, fit, rho = fig.axes[0].get_lines()[:3]
    np.testing.assert_allclose(dots.get_ydata(), pv.excess[pv.excess > 0])
    assert fit.get_ydata()[1] / fit.get_ydata()[0] == pytest.approx(pv.rate)
    assert rho.get_ydata()[1] / rho.get_ydata()[0] == pytest.approx(pv.rho_sq)


def test_running_cost_is_the_cumulative_cost(scalar):
    s, c, w, _ = scalar
    tr = orrc.simulate(s, orrc.LQR(s, c), np.zeros(1), w, 12)
    line = cp.running_cost({"LQR": tr}).axes[0].get_lines()[0]
    np.testing.assert_allclose(line.get_ydata(), np.cumsum(tr.costs))


@pytest.mark.parametrize("call, match", [
    (lambda rows: cp.metric_bars(rows, "speed"), "metric must be one of"),
    (lambda rows: cp.metric_bars([], "cost"), "rows must be a non-empty list"),
    (lambda rows: cp.preview_decay(rows), "pv must be"),
    (lambda rows: cp.running_cost({}), "trajs"),
])
def test_comparison_plots_reject_bad_input(scalar, call, match):
    with pytest.raises(ValueError, match=match):
        call(scalar[3])
