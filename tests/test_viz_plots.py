"""The book's figure functions (orrc.viz.plots): they draw what orrc computes, and
reject bad input with a clear error."""
import numpy as np
import pytest
from matplotlib.figure import Figure

import orrc
from orrc.viz import plots
import numerics
import paper


@pytest.fixture(scope="module")
def scalar_runs():
    ex = orrc.examples.scalar_unstable()
    T, M = 40, 3
    w = orrc.disturbances.sinusoid(T + M, 1, amplitude=0.3, period=10)
    ctrls = {"zero input": orrc.ZeroInput(1, ex.cost), "LQR": orrc.LQR(ex.system, ex.cost),
             "preview RHC": orrc.PreviewRHC(ex.system, ex.cost, M=M),
             "clairvoyant": orrc.Clairvoyant(ex.system, ex.cost, T)}
    return ex, {k: orrc.simulate(ex.system, c, ex.x0, w, T) for k, c in ctrls.items()}


def test_running_regret_draws_eq2_computed_independently(scalar_runs):
    _, trajs = scalar_runs
    runs = {k: v for k, v in trajs.items() if k != "zero input"}
    gammas = [0.5, 2.0]
    fig = plots.running_regret(runs, gammas)
    assert isinstance(fig, Figure)
    for ax, tr in zip(fig.axes, runs.values()):
        for line, g in zip(ax.get_lines(), gammas):
            numerics.assert_within(line.get_ydata(), paper.running_regret(tr.costs, tr.w, g),
                                   numerics.running_regret_error(tr.costs, tr.w, g))


def test_cost_overview_off_scale_keeps_the_stable_loops_in_view(scalar_runs):
    _, trajs = scalar_runs
    fig = plots.cost_overview(trajs, off_scale=["zero input"])
    ax_x, ax_c = fig.axes[:2]
    stable_max = max(np.abs(tr.x).max() for k, tr in trajs.items() if k != "zero input")
    assert ax_x.get_ylim()[1] < 2 * stable_max < np.abs(trajs["zero input"].x).max()
    assert ax_c.get_ylim()[1] < trajs["zero input"].costs.sum()
    with pytest.raises(ValueError, match="off_scale"):
        plots.cost_overview(trajs, off_scale=["no such controller"])


def test_preview_gains_plots_the_norms_of_the_lq_feedforward():
    ex = orrc.examples.scalar_unstable()
    rhc = orrc.PreviewRHC(ex.system, ex.cost, M=6)
    fig = plots.preview_gains({"M=6": rhc}, K_ref=orrc.LQR(ex.system, ex.cost).K)
    line = fig.axes[0].get_lines()[0]
    L = np.abs(rhc.law.L.ravel())            # scalar system: ‖L_j‖ = |L_j|
    keep = L > 0
    np.testing.assert_allclose(line.get_ydata(), L[keep])
    assert not keep[-1]                      # L_{M-1} = 0: no terminal cost
    pend = orrc.examples.inverted_pendulum()
    with pytest.raises(ValueError, match="exact LQ path"):
        plots.preview_gains({"nlp": orrc.PreviewRHC(pend.system, pend.cost, M=3)})


def test_cost_vs_horizon_uses_log_unless_an_excess_is_not_positive():
    fig = plots.cost_vs_horizon([1, 2, 4], {"a": [10.0, 5.0, 4.1]}, optimum={"a": 4.0})
    assert fig.axes[1].get_yscale() == "log"
    fig = plots.cost_vs_horizon([1, 2, 4], {"a": [10.0, 5.0, 3.9]}, optimum={"a": 4.0})
    assert fig.axes[1].get_yscale() == "symlog"
    with pytest.raises(ValueError, match="shape"):
        plots.cost_vs_horizon([1, 2, 4], {"a": [10.0, 5.0]})


def test_other_figures_and_explorer_frame(scalar_runs):
    _, trajs = scalar_runs
    assert isinstance(plots.information_pattern(5, 3, 2, 10), Figure)
    assert isinstance(plots.cost_vs_energy([1.0, 10.0], {"LQR": [2.0, 20.0]}, gammas=[1.0]), Figure)
    assert isinstance(plots.disturbance_panel({"w": np.ones((10, 2))}, scales=np.ones(10)), Figure)
    assert isinstance(plots.solver_effort({"warm": [3, 2, 2]}, {"warm": [0.1, 0.1, 0.1]}), Figure)
    fig = plots.rhc_frame(trajs["preview RHC"], trajs["clairvoyant"], 1.0, input_bounds=(-1, 1), ylim_R=(-5, 5))
    assert fig.axes[2].get_ylim() == (-5.0, 5.0)
    from orrc.viz import explore

    ex = explore(lambda gamma: plots.rhc_frame(trajs["LQR"], trajs["clairvoyant"], gamma), gamma=[1.0, 2.0],
                 live=False)
    frames = ex.frames["images"]
    assert len(frames) == 2 and frames["0"] != frames["1"] and ex.frames["narrow"] is not None


def test_table_formats_and_checks_rows():
    t = plots.table(["a", "b"], [["x", 1.234567], ["y", 2]], digits=3)
    html = t._repr_html_()
    assert html.count("<tr>") == 3 and "1.23" in html and "1.2346" not in html
    assert t._repr_markdown_().splitlines()[0] == "| a | b |"
    with pytest.raises(ValueError, match="row 0 has 1 cells"):
        plots.table(["a", "b"], [["x"]])


@pytest.mark.parametrize("call, match", [
    (lambda: plots.running_regret({}, [1.0]), "non-empty dict"),
    (lambda: plots.running_regret({"a": 1}, [1.0]), "Trajectory"),
    (lambda: plots.information_pattern(11, 1, 1, 10), "between 1 and T"),
    (lambda: plots.cost_vs_energy([0.0, 1.0], {"a": [1.0, 2.0]}), "positive"),
])
def test_bad_input_is_a_clear_value_error(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_negative_gamma_is_rejected(scalar_runs):
    _, trajs = scalar_runs
    with pytest.raises(ValueError, match="gamma"):
        plots.running_regret({"LQR": trajs["LQR"]}, [-1.0])


def test_solver_effort_shows_the_distributions_on_integer_and_median_marked_axes():
    """The warm-start figure: the share of steps per iteration count (bars that sum to one per
    label, at integer positions, integer ticks) and the distribution of the times with each
    median marked, so that one slow step cannot make a run look slower than it is."""
    iters = {"warm": [2, 2, 3, 2], "cold": [3, 3, 3, 4]}
    times = {"warm": [1e-4, 1e-4, 1e-4, 2e-4, 0.04], "cold": [2e-4, 2e-4, 2e-4, 3e-4]}
    fig = plots.solver_effort(iters, times)
    ax_it, ax_t = fig.axes[:2]
    heights = {}
    for bar in ax_it.patches:
        heights.setdefault(bar.get_facecolor(), []).append(bar.get_height())
    assert sorted(round(sum(h), 12) for h in heights.values()) == [1.0, 1.0], "shares sum to one"
    ticks = [t for t in ax_it.get_xticks() if ax_it.get_xlim()[0] <= t <= ax_it.get_xlim()[1]]
    assert ticks and all(float(t).is_integer() for t in ticks), f"integer ticks: {ticks}"
    medians = sorted(line.get_xdata()[0] for line in ax_t.lines if line.get_linestyle() == "--")
    assert np.allclose(medians, [0.1, 0.2]), "the medians in ms: 0.1 warm (the outlier ignored), 0.2 cold"
    assert ax_t.get_xscale() == "log", "times on a log axis"


def test_the_two_min_max_controllers_have_colours_of_their_own():
    """The min-max chapter draws open-loop and feedback min-max RHC side by side: one colour each."""
    from orrc.viz.style import controller_color

    names = ["open-loop min-max", "feedback min-max", "preview RHC", "LQR", "H∞", "clairvoyant optimum"]
    colours = [controller_color(n, i) for i, n in enumerate(names)]
    assert len(set(colours)) == len(names), dict(zip(names, colours))
