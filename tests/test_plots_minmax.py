"""The min-max chapter's figures (orrc.viz.minmax_plots): they draw the plans, constants, margins and
trajectories they are given (checked against the data), and reject bad input with a clear error."""
import numpy as np
import pytest
from matplotlib.figure import Figure

import orrc
from orrc import certify, checks
from orrc.viz import explore, minmax_plots


@pytest.fixture(scope="module")
def scalar():
    ex = orrc.examples.scalar_unstable(A=1.2)
    W, M, T = orrc.Box(-0.3, 0.3), 6, 20
    c = certify.minmax_constants(ex.system, ex.cost, M, W, n_samples=8)
    rhc = orrc.MinMaxRHC(ex.system, ex.cost, M, W)
    traj = orrc.simulate(ex.system, rhc, np.array([1.0]), W.sample(T, 0), T)
    return ex, W, M, c, rhc, traj


def _lines(ax):
    return [ln for ln in ax.get_lines() if len(ln.get_xdata()) > 0]


def test_bounds_history_draws_each_iterations_bounds(scalar):
    ex, W, M, c, rhc, traj = scalar
    exch = orrc.MinMaxRHC(ex.system, ex.cost, M, W, method="exchange").plan(np.array([2.0]))
    fig = minmax_plots.bounds_history({"exchange": exch, "exact": rhc.plan(np.array([2.0]))})
    assert isinstance(fig, Figure)
    ax, ax2 = fig.axes[:2]
    lower = next(ln for ln in ax.get_lines() if ln.get_label() == "exchange: lower")
    np.testing.assert_allclose(lower.get_ydata(), exch.history[:, 0] / exch.value)
    gap = next(ln for ln in ax2.get_lines() if ln.get_label() == "exchange")
    rel_gap = (exch.history[:, 1] - exch.history[:, 0]) / exch.history[:, 1]
    np.testing.assert_allclose(gap.get_ydata(), np.maximum(rel_gap, 1e-16))


def test_minmax_pareto_draws_the_certified_and_the_lower_curve_and_the_papers_pair(scalar):
    ex, W, M, c, _, _ = scalar
    pre = certify.lq_constants(ex.system, ex.cost, M)
    fig = minmax_plots.minmax_pareto(c, preview=pre)
    ax = fig.axes[0]
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    cert = next(v for k, v in lines.items() if k.startswith("certified"))
    np.testing.assert_allclose(cert.get_xdata(), c.pareto[:, 0])
    np.testing.assert_allclose(cert.get_ydata(), c.pareto[:, 1])
    star = next(ln for ln in ax.get_lines() if ln.get_marker() == "*")
    assert (star.get_xdata()[0], star.get_ydata()[0]) == (c.gamma_bar_W, c.alpha_hi_W)
    cross = next(ln for ln in ax.get_lines() if ln.get_marker() == "X")
    assert cross.get_xdata()[0] == pytest.approx(pre.gamma_bar * M)
    assert cross.get_xdata()[0] < c.info["gamma_bar_W_min"]                 # left of the admissible region


def test_lemma6_check_and_theorem3_growth_draw_the_margins(scalar):
    ex, W, M, c, _, traj = scalar
    l6 = checks.lemma6_margins(traj, M, W, c.alpha_lo, c.alpha_hi_W, c.gamma_bar_W)
    vb = checks.minmax_value_bound_margins(traj, M, W, c.alpha_hi_W, c.gamma_bar_W)
    fig = minmax_plots.lemma6_check(l6, vb, title="t")
    ax, ax2 = fig.axes[:2]
    np.testing.assert_allclose(_lines(ax)[0].get_ydata(), vb.bound)
    np.testing.assert_allclose(_lines(ax2)[0].get_ydata(), l6.increment.bound)
    np.testing.assert_allclose(_lines(ax2)[1].get_ydata(), np.diff(traj.values))
    t3 = checks.theorem3_margin(traj, M, W, c.a, c.alpha_lo, c.alpha_hi_W, c.gamma_bar_W, c.gamma_c_W)
    fig = minmax_plots.theorem3_growth({"run": (traj, t3)}, c.gamma_c_W, W.max_norm_sq)
    cum, bound, real = _lines(fig.axes[0])[:3]
    np.testing.assert_allclose(cum.get_ydata(), np.cumsum(traj.costs))
    np.testing.assert_allclose(bound.get_ydata(), t3.bound + c.gamma_c_W * np.arange(1, traj.T + 1) * W.max_norm_sq)
    assert np.all(bound.get_ydata() >= cum.get_ydata())                    # the theorem's bound, above the cost


def test_controller_costs_and_the_explorer_frame(scalar):
    ex, W, M, c, _, traj = scalar
    fig = minmax_plots.controller_costs({"a": {"LQR": 2.0, "min-max RHC": 3.0}, "b": {"LQR": 5.0}})
    heights = sorted(p.get_height() for p in fig.axes[0].patches if np.isfinite(p.get_height()))
    assert heights == [2.0, 3.0, 5.0]
    # each bar shows its value, and a missing bar ("b" has no min-max RHC) no label
    assert sorted(t.get_text() for t in fig.axes[0].texts if t.get_text()) == ["2", "3", "5"]
    # values of one order: a linear axis from zero, room above the tallest bar for its value
    assert fig.axes[0].get_yscale() == "linear" and fig.axes[0].get_ylim()[0] == 0.0
    assert fig.axes[0].get_ylim()[1] >= 1.1 * 5.0
    # values over decades: a log axis whose bottom is below the smallest bar (every bar shows)
    fig = minmax_plots.controller_costs({"a": {"LQR": 0.4, "min-max RHC": 3.0}, "b": {"LQR": 12.0}})
    lo, hi = fig.axes[0].get_ylim()
    assert fig.axes[0].get_yscale() == "log" and lo < 0.4 / 2 and hi >= 3 * 12.0 - 1e-9
    vb = checks.minmax_value_bound_margins(traj, M, W, c.alpha_hi_W, c.gamma_bar_W)
    lqr = orrc.simulate(ex.system, orrc.ZeroInput(1, ex.cost), np.array([1.0]), traj.w, traj.T)
    fig = minmax_plots.minmax_frame(M, 0.3, {"min-max RHC": traj, "zero input": lqr}, bound=vb.bound, w_max_sq=0.09)
    ax, ax2 = fig.axes[:2]
    np.testing.assert_allclose(_lines(ax)[0].get_ydata(), np.cumsum(traj.costs))
    np.testing.assert_allclose(_lines(ax2)[0].get_ydata(), traj.values)
    np.testing.assert_allclose(_lines(ax2)[1].get_ydata(), vb.bound)
    ex_ = explore(lambda r: minmax_plots.minmax_frame(M, r, {"min-max RHC": traj}), r=[0.1, 0.3], dpi=100)
    assert len(ex_.frames) == 2 and 'class="orrc-frames"' in ex_.html


@pytest.mark.parametrize("call, match", [
    (lambda s: minmax_plots.bounds_history({}), "plans"),
    (lambda s: minmax_plots.bounds_history({"x": 1}), "MinMaxPlan"),
    (lambda s: minmax_plots.minmax_pareto(s[3].pareto), "MinMaxConstants"),
    (lambda s: minmax_plots.minmax_pareto(s[3], preview=1.0), "preview"),
    (lambda s: minmax_plots.lemma6_check("x"), "lemma6"),
    (lambda s: minmax_plots.theorem3_growth({"r": (s[5], 1.0)}, 1.0, 0.09), "Trajectory, Margins"),
    (lambda s: minmax_plots.theorem3_growth({"r": 1}, -1.0, 0.09), "gamma"),
    (lambda s: minmax_plots.controller_costs({"a": {"LQR": -1.0}}), "costs"),
    (lambda s: minmax_plots.controller_costs({"a": {}}), r"costs\['a'\] must be a non-empty dict"),
    (lambda s: minmax_plots.minmax_frame(0, 0.3, {"m": s[5]}), "M must be"),
    (lambda s: minmax_plots.minmax_frame(6, 0.3, {"m": 1}), "Trajectory"),
    (lambda s: minmax_plots.minmax_frame(6, 0.3, {"min-max": s[5]}, bound=np.ones(3)), "bound"),
])
def test_bad_input_is_a_clear_error(scalar, call, match):
    with pytest.raises(orrc.OrrcValueError, match=match):
        call(scalar)
