"""The Lemma 1 figures (orrc.viz.theory_plots): they draw the constants and margins that
orrc.certify and orrc.checks compute, and reject bad input with a clear error."""
import numpy as np
import pytest
from matplotlib.figure import Figure

import orrc
from orrc import certify, checks
from orrc.viz import theory_plots

from conftest import assert_legible, legend_under_axes


@pytest.fixture(scope="module")
def lemma1_run():
    ex = orrc.examples.scalar_unstable()
    M, T = 25, 30
    c = certify.lq_constants(ex.system, ex.cost, M)
    w = orrc.disturbances.uniform_ball(T + M, 1, radius=0.5, seed=3)
    traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, M), ex.x0, w, T)
    l1 = checks.lemma1_margins(traj, M, c.alpha_lo, c.alpha_hi, c.gamma_bar)
    vb = checks.value_bound_margins(traj, M, c.alpha_hi, c.gamma_bar)
    return ex, M, c, l1, vb


def test_pareto_curves_draw_the_curve_and_mark_the_chosen_pair(lemma1_run):
    ex, M, c, _, _ = lemma1_run
    c10 = certify.lq_constants(ex.system, ex.cost, 10)   # below the threshold: no finite γ_c
    fig = theory_plots.pareto_curves({"M = 10": c10, f"M = {M}": c})
    assert isinstance(fig, Figure)
    ax, ax2 = fig.axes[:2]
    curve = next(ln for ln in ax.get_lines() if ln.get_label() == f"M = {M}")
    np.testing.assert_allclose(curve.get_xdata(), c.pareto[:, 0])
    # measured against the threshold: ᾱ(γ̄) / (α_lo √(M-1)), below 1 where Γ_V < 0
    np.testing.assert_allclose(curve.get_ydata(), c.pareto[:, 1] / (c.alpha_lo * np.sqrt(M - 1)))
    assert any(ln.get_ydata()[0] == 1.0 for ln in ax.get_lines() if len(ln.get_ydata()) == 2)
    assert_legible(fig)
    stars = [ln for ln in ax.get_lines() if ln.get_marker() == "*"]
    assert [(s.get_xdata()[0], s.get_ydata()[0]) for s in stars] == [
        (c10.gamma_bar, pytest.approx(c10.alpha_hi / 3.0)),                       # √(10 - 1) = 3
        (c.gamma_bar, pytest.approx(c.alpha_hi / (c.alpha_lo * np.sqrt(M - 1))))]
    # the knee at M = 10 lies above 1 (no admissible pair), the chosen pair at M = 25 below it
    assert stars[0].get_ydata()[0] > 1 > stars[1].get_ydata()[0]
    # right panel: γ_c only for the certified horizon, its minimum at the star
    gc_lines = [ln for ln in ax2.get_lines() if ln.get_label().startswith("M = ")]
    assert len(gc_lines) == 1
    assert np.min(gc_lines[0].get_ydata()) == pytest.approx(c.gamma_c, rel=0.02)


def test_pareto_curves_without_gamma_c_draw_one_panel_with_the_same_curve(lemma1_run):
    _, M, c, _, _ = lemma1_run
    fig = theory_plots.pareto_curves({f"M = {M}": c}, gamma_c=False)
    assert len(fig.axes) == 1
    curve = next(ln for ln in fig.axes[0].get_lines() if ln.get_label() == f"M = {M}")
    np.testing.assert_allclose(curve.get_ydata(), c.pareto[:, 1] / (c.alpha_lo * np.sqrt(M - 1)))
    assert_legible(fig)
    with pytest.raises(ValueError, match="gamma_c"):
        theory_plots.pareto_curves({f"M = {M}": c}, gamma_c="no")


def test_lemma1_check_keeps_its_symlog_labels_apart():
    """At M = 19 the bound is about 1e3 and the increments about ±0.1: the labelled ticks of the
    increment panel stay at least a tenth of the axis apart."""
    ex = orrc.examples.scalar_unstable()
    M, T = 19, 60
    c = certify.lq_constants(ex.system, ex.cost, M)
    w = orrc.disturbances.uniform_ball(T + M, 1, radius=0.5, seed=3)
    traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, M), ex.x0, w, T)
    l1 = checks.lemma1_margins(traj, M, c.alpha_lo, c.alpha_hi, c.gamma_bar)
    ax2 = theory_plots.lemma1_check(l1).axes[1]
    lo, hi = ax2.get_ylim()
    to_axis = ax2.yaxis.get_transform().transform
    pos = np.sort([(to_axis(np.array([t]))[0] - to_axis(np.array([lo]))[0])
                   / (to_axis(np.array([hi]))[0] - to_axis(np.array([lo]))[0]) for t in ax2.get_yticks()])
    assert 0.0 in ax2.get_yticks() and len(pos) >= 3
    assert np.diff(pos).min() >= 0.1 - 1e-9


def test_pareto_curves_label_estimates():
    ex = orrc.examples.van_der_pol(dt=0.3)
    est = certify.sampled_constants(ex.system, ex.cost, 8, n_samples=4, x_radius=1.0, w_radius=0.1,
                                    input_bounds=ex.input_bounds, seed=0)
    fig = theory_plots.pareto_curves({"VdP": est})
    assert "ESTIMATED" in fig._suptitle.get_text()


def test_horizon_threshold_shades_where_M_exceeds_the_requirement():
    Ms = np.arange(2, 12)
    alpha_hi = np.full(len(Ms), 2.0)      # requirement 2²/1 + 1 = 5
    fig = theory_plots.horizon_threshold(Ms, alpha_hi, 1.0, M_star=6)
    ax = fig.axes[0]
    np.testing.assert_allclose(ax.get_lines()[0].get_ydata(), 5.0)
    with pytest.raises(ValueError, match="alpha_hi"):
        theory_plots.horizon_threshold(Ms, alpha_hi[:-1], 1.0)
    with pytest.raises(ValueError, match="alpha_lo"):
        theory_plots.horizon_threshold(Ms, alpha_hi, 0.0)
    with pytest.raises(ValueError, match="M"):
        theory_plots.horizon_threshold([1, 2], [1.0, 1.0], 1.0)


def test_horizon_threshold_keeps_its_legend_off_the_curves():
    """The legend sits under the axes in the wide and the phone's rendering: in the lower right
    corner it covered the required horizon's plateau, the curve the text reads."""

    from orrc.viz.figures import narrowed

    Ms = np.arange(2, 41)
    fig = theory_plots.horizon_threshold(Ms, np.sqrt(np.minimum(Ms, 18.0)), 1.0, M_star=19)
    ax = fig.axes[0]

    assert legend_under_axes(fig, ax)
    with narrowed(fig):
        assert legend_under_axes(fig, ax)


def test_lemma1_check_draws_the_margins(lemma1_run):
    _, _, _, l1, vb = lemma1_run
    fig = theory_plots.lemma1_check(l1, vb, title="scalar")
    ax, ax2 = fig.axes[:2]
    lines = {ln.get_label(): ln for ln in ax2.get_lines()}
    inc = next(v for k, v in lines.items() if "V^{t+1}_M" in k)
    np.testing.assert_allclose(inc.get_ydata(), l1.increment.actual)
    bound = next(v for k, v in lines.items() if k.startswith("bound"))
    np.testing.assert_allclose(bound.get_ydata(), l1.increment.bound)
    upper = next(ln for ln in ax.get_lines() if r"\overline{\gamma}" in ln.get_label())
    np.testing.assert_allclose(upper.get_ydata(), vb.bound)
    smallest = min(l1.increment.margin.min(), l1.lower.margin.min())
    assert f"{smallest:.3g}" in fig._suptitle.get_text()
    assert_legible(fig)


def test_theory_plot_errors(lemma1_run):
    _, _, c, l1, vb = lemma1_run
    with pytest.raises(ValueError, match="constants"):
        theory_plots.pareto_curves({})
    with pytest.raises(ValueError, match="constants"):
        theory_plots.pareto_curves({"x": 1.0})
    with pytest.raises(ValueError, match="lemma1"):
        theory_plots.lemma1_check(vb)
    with pytest.raises(ValueError, match="value_bound"):
        theory_plots.lemma1_check(l1, value_bound=c)
