"""The unknown-system figures (orrc.viz.unknown_plots): they draw what orrc computes, are legible on a
phone (narrow, 12 pt text) and reject bad input with a clear error."""
import numpy as np
import pytest
from matplotlib.figure import Figure

import orrc
from orrc import checks, estimation as est
from orrc.tradeoff import Tradeoff
from orrc.viz import unknown_plots as up

SYS = orrc.LinearSystem([[0.5]], [[1.0]])
COST = orrc.QuadraticCost([[1.0]], [[0.1]])


@pytest.fixture(scope="module")
def runs():
    model = orrc.ParametricSystem.linear(1, 1)
    w = orrc.disturbances.uniform_box(60, 1, -0.5, 0.5, seed=0)
    alg2 = orrc.simulate(SYS, orrc.EstimateThenControl(model, COST, 3, 6, use_w=False, theta_true=[0.5, 1.0]),
                         np.zeros(1), w, 50)
    alg1 = orrc.simulate(SYS, orrc.PreviewRHC(SYS, COST, 3), np.zeros(1), w, 50)
    return alg2, alg1


def text_sizes(fig):
    fig.canvas.draw()
    sizes = [t.get_fontsize() for ax in fig.axes for t in ax.get_xticklabels() + ax.get_yticklabels()
             if t.get_text()]
    sizes += [ax.xaxis.label.get_fontsize() for ax in fig.axes if ax.xaxis.label.get_text()]
    return sizes


def test_estimation_errors_draw_the_errors_and_their_fitted_slope():
    Ns = np.array([10, 20, 40, 80])
    fig = up.estimation_errors(Ns, {"noisy": 1 / np.sqrt(Ns), "exact": np.zeros(4)}, fit_from=20)
    ax = fig.axes[0]
    noisy, exact = ax.get_lines()[:2]
    np.testing.assert_allclose(noisy.get_ydata(), 1 / np.sqrt(Ns))
    assert "slope -0.50" in noisy.get_label()
    np.testing.assert_allclose(exact.get_ydata(), 1e-15)            # exact values drawn at the floor
    assert fig.get_size_inches()[0] <= 5.0 and min(text_sizes(fig)) >= 11


def test_phase_frame_shades_the_estimation_phase_and_accumulates_the_excess(runs):
    alg2, alg1 = runs
    fig = up.phase_frame(alg2, alg1, fast=True)
    top, bottom = fig.axes
    np.testing.assert_allclose(top.get_lines()[1].get_ydata(), alg2.x[:, 0])
    np.testing.assert_allclose(bottom.get_lines()[0].get_ydata(), np.cumsum(alg2.costs - alg1.costs))
    shaded = [p for p in top.patches]
    assert len(shaded) == 1 and shaded[0].get_x() == pytest.approx(-0.5)
    assert "estimation, N = 6" in [t.get_text() for t in bottom.get_legend().get_texts()]


def test_phase_frame_legends_stay_inside_the_figure():
    """Each legend fits in the figure's width, in the wide and the phone's rendering (one long
    label, "excess cost (shaded: N = 10)", ran past the right edge of the phone's figure)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from orrc.viz.figures import narrowed

    model = orrc.ParametricSystem.linear(1, 1)
    w = orrc.disturbances.uniform_box(160, 1, -0.5, 0.5, seed=0)
    alg2 = orrc.simulate(SYS, orrc.EstimateThenControl(model, COST, 3, 120, use_w=False, theta_true=[0.5, 1.0]),
                         np.zeros(1), w, 150)                       # a three-digit N, the longest label
    alg1 = orrc.simulate(SYS, orrc.PreviewRHC(SYS, COST, 3), np.zeros(1), w, 150)
    fig = up.phase_frame(alg2, alg1, title="Van der Pol, EDMD (degree 3), N = 120", fast=True)

    def inside():
        canvas = FigureCanvasAgg(fig)
        canvas.draw()
        r = canvas.get_renderer()
        return all(fig.bbox.x0 - 1 <= ax.get_legend().get_window_extent(r).x0 and
                   ax.get_legend().get_window_extent(r).x1 <= fig.bbox.x1 + 1 for ax in fig.axes)

    assert inside()
    with narrowed(fig):
        assert inside()


def test_lemma4_terms_draw_the_margins(runs):
    alg2, _ = runs
    m = checks.lemma4_margins(alg2, 3, 1.0, 1.2, 0.2, 1.0, 1.0, 1.0, 1.0)
    fig = up.lemma4_terms(m, theta_part=0.5)
    bound, without, actual = fig.axes[0].get_lines()[:3]
    np.testing.assert_allclose(bound.get_ydata(), m.bound)
    np.testing.assert_allclose(without.get_ydata(), m.bound - 0.5)
    np.testing.assert_allclose(actual.get_ydata(), m.actual)


def test_loss_vs_error_reports_the_order_of_the_loss():
    e = np.geomspace(1e-3, 1e-1, 5)
    fig = up.loss_vs_error(e, {"first": 2 * e, "second": 3 * e ** 2})
    labels = [ln.get_label() for ln in fig.axes[0].get_lines()]
    assert labels == ["first: slope 1.00", "second: slope 2.00"]


def test_lipschitz_quotients_and_theorem2_parts():
    d = np.array([0.1, 0.2, 0.3])
    fig = up.lipschitz_quotients(d, d * 0.5, d * 0.2, 1.0, 0.5)
    assert len(fig.axes) == 2
    np.testing.assert_allclose(fig.axes[0].get_lines()[0].get_ydata(), d * 0.5)
    Ts = np.arange(5, 10)
    fig = up.theorem2_parts(Ts, {"a": np.ones(5), "b": Ts * 1.0}, actual=-np.ones(5))
    total = [ln for ln in fig.axes[0].get_lines() if ln.get_label() == "bound (sum)"][0]
    np.testing.assert_allclose(total.get_ydata(), 1 + Ts)


def make_tradeoff():
    Ns = np.array([10.0, 20.0, 40.0, 80.0])
    S = 2
    loss = np.tile(0.1 / np.sqrt(Ns), (S, 1))
    t = Tradeoff(Ns=Ns, explore_cost=np.tile(Ns, (S, 1)), known_cost=np.zeros((S, 4)), transient=np.zeros((S, 4)),
                 loss=loss, errors=np.tile(1 / np.sqrt(Ns), (S, 1)), c0=0.0, window=10, burn_in=2)
    from orrc.tradeoff import _fit

    t.fit = _fit(t)
    return t


def test_tradeoff_figures_draw_the_fitted_minimisers():
    t = make_tradeoff()
    assert t.fit["p"] == pytest.approx(0.5) and t.fit["slope_e"] == pytest.approx(1.0)
    Ts = np.array([1e3, 2e3])
    fig = up.tradeoff_curves(t, Ts)
    stars = [ln for ln in fig.axes[0].get_lines() if ln.get_marker() == "*"]
    np.testing.assert_allclose([s.get_xdata()[0] for s in stars], t.best_N(Ts))
    fig = up.best_N(t, Ts)
    assert f"slope {t.slope(Ts):.2f}" in fig.axes[0].get_lines()[0].get_label()
    # the exact minimiser of N + 0.1 (T - N)/sqrt(N) for T = 1000
    grid = np.geomspace(10, 80, 100000)
    exact = grid[np.argmin(grid + 0.1 * (1e3 - grid) / np.sqrt(grid))]
    assert t.best_N([1e3])[0] == pytest.approx(exact, rel=2e-3)


@pytest.mark.parametrize("call, words", [
    (lambda: up.estimation_errors([1, 2], {"a": [1.0]}), "errors['a']"),
    (lambda: up.estimation_errors([1, 2], {}), "errors must be a non-empty dict"),
    (lambda: up.estimation_errors([1, 2], {"a": [1.0, 0.5]}, fit_from=5), "fit_from"),
    (lambda: up.phase_frame("traj", "ref"), "traj must be an orrc Trajectory"),
    (lambda: up.lemma4_terms("margins", 1.0), "margins must be orrc.checks.Margins"),
    (lambda: up.lipschitz_quotients([0.1, 0.2], [0.1], [0.1, 0.2], 1.0, 1.0), "dV must have shape"),
    (lambda: up.theorem2_parts([1, 2], {"a": [1.0, 2.0]}, [1.0]), "actual must have shape"),
    (lambda: up.tradeoff_curves("study", [1e3]), "tradeoff must be"),
    (lambda: up.best_N(make_tradeoff(), [1e3, float("nan")]), "Ts must be finite"),
    (lambda: up.prediction_errors([1, 2], {"a": [1.0, 2.0]}, {"lin": float("inf")}), "references['lin']"),
])
def test_bad_input_is_a_clear_error(call, words):
    with pytest.raises(orrc.OrrcValueError) as info:
        call()
    assert words in str(info.value)


def test_lipschitz_quotients_legend_clears_the_line():
    """Each panel's legend (upper left) sits above its line α‖θ̂ − θ‖ in the wide and the phone's
    rendering: no point of the line falls inside the legend's box."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from orrc.viz.figures import narrowed

    rng = np.random.default_rng(0)
    d = np.geomspace(0.011, 0.27, 120) * rng.uniform(0.5, 1.0, 120)
    fig = up.lipschitz_quotients(d, d * rng.uniform(0.001, 0.3, 120), d * rng.uniform(0.005, 0.5, 120),
                                 alpha_V=1.38, alpha_kappa=2.3, title="Lemma 3")

    def legends_clear():
        canvas = FigureCanvasAgg(fig)
        canvas.draw()
        r = canvas.get_renderer()
        for ax in fig.axes:
            box = ax.get_legend().get_window_extent(r)
            line = ax.get_lines()[1]
            pts = line.get_transform().transform(line.get_xydata())
            if box.count_contains(pts):
                return False
        return True

    assert legends_clear()
    with narrowed(fig):
        assert legends_clear()
