"""The figures of the Theorem 1 chapter (orrc.viz.theory_plots): they draw the data they are
given (checked against independent computations of γ_c, R^p_t(γ) and the simulated costs),
and reject bad input with a ValueError that names the argument."""
import math

import numpy as np
import pytest

from conftest import legend_under_axes
from matplotlib.figure import Figure

import orrc
from orrc import certify, checks, theory
from orrc.viz import explore, theory_plots
import numerics
import paper


@pytest.fixture(scope="module")
def scalar():
    ex = orrc.examples.scalar_unstable(A=1.2)
    M = 7
    c = certify.lq_constants(ex.system, ex.cost, M, grid=60)
    assert c.admissible
    rhc = orrc.PreviewRHC(ex.system, ex.cost, M=M)
    T = 40
    w = orrc.disturbances.uniform_ball(T + M, 1, radius=0.5, seed=0)
    traj = orrc.simulate(ex.system, rhc, ex.x0, w, T)
    return ex, M, c, rhc, traj


def _lines(ax):
    return [ln for ln in ax.get_lines() if len(ln.get_xdata()) > 0]


# -- gamma_c_map -----------------------------------------------------------------------------------
def test_gamma_c_map_draws_theorem1_gamma_c(scalar):
    ex, M, c, _, _ = scalar
    a = np.linspace(c.a, 0.99, 50)
    g = [theory.gamma_c(M, ai, c.alpha_lo, c.alpha_hi, c.gamma_bar) for ai in a]
    fig = theory_plots.gamma_c_map({"M = 7": (a, g)}, {"M = 7": (c.a, c.gamma_c)}, [6, 7, 8],
                                   [2.0e3, c.gamma_c, 500.0], floor=[10.0, 2 * c.gamma_bar, 8.0])
    assert isinstance(fig, Figure)
    ax, ax2 = fig.axes[:2]
    curve, dot = _lines(ax)[:2]
    np.testing.assert_allclose(curve.get_ydata(), [paper.gamma_c(M, ai, c.alpha_lo, c.alpha_hi, c.gamma_bar)
                                                   for ai in a], rtol=1e-12)
    assert dot.get_xdata()[0] == c.a and dot.get_ydata()[0] == pytest.approx(
        paper.gamma_c(M, c.a, c.alpha_lo, c.alpha_hi, c.gamma_bar), rel=1e-9)
    best, floor = _lines(ax2)[:2]
    np.testing.assert_array_equal(best.get_xdata(), [6, 7, 8])
    assert best.get_ydata()[1] == c.gamma_c and floor.get_ydata()[1] == 2 * c.gamma_bar
    # the remark γ_c >= 2γ̄ is visible: the curve lies above the floor
    assert np.all(best.get_ydata() > floor.get_ydata())


@pytest.mark.parametrize("kwargs, match", [
    ({"curves": {}}, "curves"),
    ({"a_min": [(0.9, 1.0)]}, "a_min"),
    ({"gamma_c_best": [1.0, 2.0]}, "gamma_c_best"),
    ({"Ms": [1, 2, 3]}, "M"),
    ({"floor": [1.0]}, "floor"),
    ({"curves": {"x": ([0.9, 0.95], [1.0])}}, "gamma_c"),
])
def test_gamma_c_map_rejects_bad_input(kwargs, match):
    args = {"curves": {"x": ([0.9, 0.95], [1.0, 2.0])}, "a_min": {}, "Ms": [5, 6, 7],
            "gamma_c_best": [3.0, 2.0, 1.0]}
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        theory_plots.gamma_c_map(**args)


# -- attenuation_levels ----------------------------------------------------------------------------
def test_attenuation_levels_draws_the_exact_levels(scalar):
    ex, _, _, _, _ = scalar
    Ms = [2, 3, 5, 7]
    cert = [math.inf, math.inf] + [certify.lq_constants(ex.system, ex.cost, m, grid=40).gamma_c for m in (5, 7)]
    stat = [certify.worst_case_attenuation_limit(ex.system, orrc.PreviewRHC(ex.system, ex.cost, M=m)).gamma
            for m in Ms]
    lqr = certify.worst_case_attenuation_limit(ex.system, orrc.LQR(ex.system, ex.cost)).gamma
    fig = theory_plots.attenuation_levels(Ms, {"certified γ_c": cert, "exact, stationary γ∞": stat,
                                               "LQR without preview": lqr}, threshold_M=5)
    ax = fig.axes[0]
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    # inf (no certificate below the threshold) is left out, not drawn as a huge number
    np.testing.assert_array_equal(lines["certified γ_c"].get_xdata(), [5, 7])
    np.testing.assert_allclose(lines["exact, stationary γ∞"].get_ydata(), stat)
    assert list(lines["LQR without preview"].get_ydata()) == [lqr, lqr]          # a horizontal line
    assert lines["LQR without preview"].get_color() == "tab:orange"
    assert ax.get_yscale() == "log"
    # the certificate lies above what the controller achieves, and preview beats LQR here
    assert cert[-1] > stat[-1] and stat[-1] < lqr


@pytest.mark.parametrize("levels, kw, match", [
    ({}, {}, "levels"),
    ({"a": [1.0, 2.0]}, {}, "levels\\['a'\\]"),
    ({"a": "abc"}, {}, "levels"),
    ({"a": [1.0, 2.0, 3.0]}, {"threshold_M": 0}, "threshold_M"),
])
def test_attenuation_levels_rejects_bad_input(levels, kw, match):
    with pytest.raises(ValueError, match=match):
        theory_plots.attenuation_levels([2, 3, 4], levels, **kw)


# -- regret_growth ---------------------------------------------------------------------------------
def test_regret_growth_draws_eq2_and_the_theorem1_ceiling(scalar):
    _, M, c, _, traj = scalar
    gamma = c.gamma_c
    margin = checks.theorem1_margin(traj, M, c.a, c.alpha_lo, c.alpha_hi, c.gamma_bar, gamma)
    R = {"γ_c": orrc.attenuation_regret(traj, gamma, cumulative=True), "γ = 1": orrc.attenuation_regret(
        traj, 1.0, cumulative=True)}
    fig = theory_plots.regret_growth(margin.t, R, ceiling=margin.bound, ylim=(-5, 5))
    ax = fig.axes[0]
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    numerics.assert_within(lines["γ = 1"].get_ydata(), paper.running_regret(traj.costs, traj.w, 1.0),
                           numerics.running_regret_error(traj.costs, traj.w, 1.0))
    numerics.assert_within(lines["γ_c"].get_ydata(), paper.running_regret(traj.costs, traj.w, gamma),
                           numerics.running_regret_error(traj.costs, traj.w, gamma))
    ceiling = lines["Theorem 1 ceiling $C_t$"].get_ydata()
    assert np.all(ceiling >= lines["γ_c"].get_ydata())          # Theorem 1 holds along the run
    assert ax.get_ylim() == (-5.0, 5.0)


def test_regret_growth_without_ylim_follows_the_data_at_every_gamma(scalar):
    """The chapter's explorer draws R^p_t(γ) from below the exact level up to γ_c without fixed
    limits: in every frame the vertical axis holds every curve (no frame leaves the plot)."""
    _, _, c, _, traj = scalar
    t = np.arange(1, traj.T + 1)
    for gamma in (0.8, 1.0, 10.0, c.gamma_c):
        R = {"run": orrc.attenuation_regret(traj, gamma, cumulative=True)}
        lo, hi = theory_plots.regret_growth(t, R).axes[0].get_ylim()
        assert lo <= R["run"].min() and R["run"].max() <= hi, (gamma, (lo, hi))
        assert hi - lo < 2 * (max(R["run"].max(), 0.0) - min(R["run"].min(), 0.0)), (gamma, (lo, hi))


def test_regret_growth_rejects_bad_input(scalar):
    _, _, _, _, traj = scalar
    t = np.arange(1, traj.T + 1)
    r = orrc.attenuation_regret(traj, 1.0, cumulative=True)
    with pytest.raises(ValueError, match="R"):
        theory_plots.regret_growth(t, {})
    with pytest.raises(ValueError, match="ceiling"):
        theory_plots.regret_growth(t, {"a": r}, ceiling=r[:-1])
    with pytest.raises(ValueError, match=r"R\['a'\]"):
        theory_plots.regret_growth(t, {"a": np.r_[r[:-1], np.nan]})


# -- adversary -------------------------------------------------------------------------------------
def test_adversary_draws_the_worst_disturbance_and_its_cost(scalar):
    ex, _, _, rhc, _ = scalar
    T = 20
    res = certify.worst_case_attenuation(ex.system, rhc, T)
    tr = orrc.simulate(ex.system, rhc, np.zeros(1), res.w, T)
    fig = theory_plots.adversary({"preview RHC": res.w}, {"preview RHC": tr.costs}, title="t")
    ax, ax2 = fig.axes[:2]
    np.testing.assert_allclose(ax.get_lines()[0].get_ydata(), res.w[:, 0])
    np.testing.assert_allclose(ax2.get_lines()[0].get_ydata(), tr.costs)
    # the drawn cost over the drawn energy is the exact worst case γ*_T
    assert np.sum(ax2.get_lines()[0].get_ydata()) / np.sum(ax.get_lines()[0].get_ydata() ** 2) == \
        pytest.approx(res.gamma, rel=1e-9)
    # a two-dimensional disturbance is drawn as its norm
    w2 = np.ones((5, 2))
    fig = theory_plots.adversary({"x": w2}, {"x": np.ones(5)})
    np.testing.assert_allclose(fig.axes[0].get_lines()[0].get_ydata(), np.sqrt(2.0))


def test_adversary_legend_covers_no_curve(scalar):
    """One legend, under the axes of the costs, in the wide and the phone's rendering (inside the
    panels it sat on the humps of the worst disturbance and of its cost)."""

    from orrc.viz.figures import narrowed

    ex, _, _, rhc, _ = scalar
    res = certify.worst_case_attenuation(ex.system, rhc, 20)
    tr = orrc.simulate(ex.system, rhc, np.zeros(1), res.w, 20)
    fig = theory_plots.adversary({"preview RHC": res.w, "again": res.w}, {"preview RHC": tr.costs, "again": tr.costs})
    ax, ax2 = fig.axes[:2]
    assert ax.get_legend() is None

    assert legend_under_axes(fig, ax2)
    with narrowed(fig):
        assert legend_under_axes(fig, ax2)


def test_adversary_rejects_bad_input():
    w = np.ones((5, 1))
    with pytest.raises(ValueError, match="ws"):
        theory_plots.adversary({}, {"a": np.ones(5)})
    with pytest.raises(ValueError, match="costs has no entry for 'a'"):
        theory_plots.adversary({"a": w}, {"b": np.ones(5)})
    with pytest.raises(ValueError, match=r"costs\['a'\]"):
        theory_plots.adversary({"a": w}, {"a": np.ones(4)})
    with pytest.raises(ValueError, match=r"ws\['a'\]"):
        theory_plots.adversary({"a": np.ones(5)}, {"a": np.ones(5)})


# -- theorem1_frame --------------------------------------------------------------------------------
def test_theorem1_frame_draws_gamma_c_and_the_ceiling(scalar):
    _, M, c, _, traj = scalar
    a_grid = np.linspace(c.a, 0.99, 30)
    g_grid = [theory.gamma_c(M, a, c.alpha_lo, c.alpha_hi, c.gamma_bar) for a in a_grid]
    a = float(a_grid[10])
    gc = paper.gamma_c(M, a, c.alpha_lo, c.alpha_hi, c.gamma_bar)
    margin = checks.theorem1_margin(traj, M, a, c.alpha_lo, c.alpha_hi, c.gamma_bar, gc)
    fig = theory_plots.theorem1_frame(M, a, c.a, a_grid, g_grid, margin, ylim=(-100, 10))
    ax, ax2 = fig.axes[:2]
    marker = _lines(ax)[1]
    assert marker.get_xdata()[0] == a and marker.get_ydata()[0] == pytest.approx(gc, rel=1e-12)
    lines = {ln.get_label(): ln for ln in ax2.get_lines()}
    R = [ln for k, ln in lines.items() if k.startswith("$R^p_t")][0]
    numerics.assert_within(R.get_ydata(), paper.running_regret(traj.costs, traj.w, gc),
                           numerics.running_regret_error(traj.costs, traj.w, gc))
    np.testing.assert_allclose(lines["Theorem 1 ceiling $C_t$"].get_ydata(), margin.bound)
    assert ax2.get_ylim() == (-100.0, 10.0)
    assert "smallest margin" in fig._suptitle.get_text()


def test_theorem1_frame_shows_the_given_exact_gamma_c_between_grid_points(scalar):
    _, M, c, _, traj = scalar
    a_grid = np.linspace(c.a, 0.99, 6)
    g_grid = [theory.gamma_c(M, a, c.alpha_lo, c.alpha_hi, c.gamma_bar) for a in a_grid]
    a = float(0.5 * (a_grid[2] + a_grid[3]))                   # between two grid points
    gc = paper.gamma_c(M, a, c.alpha_lo, c.alpha_hi, c.gamma_bar)
    assert f"{np.interp(a, a_grid, g_grid):.4g}" != f"{gc:.4g}"  # the interpolation would be off
    margin = checks.theorem1_margin(traj, M, a, c.alpha_lo, c.alpha_hi, c.gamma_bar, gc)
    fig = theory_plots.theorem1_frame(M, a, c.a, a_grid, g_grid, margin, gamma_c=gc)
    ax, ax2 = fig.axes[:2]
    marker = _lines(ax)[1]
    assert marker.get_xdata()[0] == a and marker.get_ydata()[0] == gc
    labels = [ln.get_label() for ln in ax2.get_lines() if ln.get_label().startswith("$R^p_t")]
    assert labels == [rf"$R^p_t(\gamma_c)$, $\gamma_c = {gc:.4g}$"]


def test_theorem1_frame_below_a_min_says_the_theorem_does_not_apply(scalar):
    _, M, c, _, _ = scalar
    fig = theory_plots.theorem1_frame(M, 0.5, c.a)
    texts = " ".join(t.get_text() for ax in fig.axes for t in ax.texts)
    assert "does not apply" in texts and "not admissible" in fig._suptitle.get_text()
    assert not any(_lines(ax) for ax in fig.axes)


@pytest.mark.parametrize("args, match", [
    ((7, 1.0, 0.8), "a must be"),
    ((7, 0.9, -0.1), "a_min"),
    ((1, 0.9, 0.8), "M"),
    ((7, 0.9, 0.8), "needs a_grid, gamma_c_grid and margin"),
    ((7, 0.9, 0.8, [0.8, 0.9], [1.0, 2.0], "not margins"), "margin"),
    ((7, 0.9, 0.8, [0.8, 0.9], [1.0], None), "needs a_grid"),
])
def test_theorem1_frame_rejects_bad_input(args, match):
    with pytest.raises(ValueError, match=match):
        theory_plots.theorem1_frame(*args)


def test_theorem1_frame_serves_the_explorer(scalar):
    _, M, c, _, traj = scalar

    def frame(a):
        if a < c.a:
            return theory_plots.theorem1_frame(M, a, c.a)
        grid = np.linspace(c.a, 0.99, 20)
        gs = [theory.gamma_c(M, x, c.alpha_lo, c.alpha_hi, c.gamma_bar) for x in grid]
        gc = theory.gamma_c(M, a, c.alpha_lo, c.alpha_hi, c.gamma_bar)
        return theory_plots.theorem1_frame(
            M, a, c.a, grid, gs, checks.theorem1_margin(traj, M, a, c.alpha_lo, c.alpha_hi, c.gamma_bar, gc))

    ex = explore(frame, a=[0.5, 0.95], live=False)
    frames = ex.frames["images"]
    assert len(frames) == 2 and frames["0"] != frames["1"] and ex.frames["narrow"] is not None
    assert 'class="orrc-frames"' in ex.html


# -- attenuation_vs_T ------------------------------------------------------------------------------
def test_attenuation_vs_T_draws_the_finite_levels_and_their_limits(scalar):
    ex, _, _, rhc, _ = scalar
    Ts = [2, 5, 10, 20]
    res = [certify.worst_case_attenuation(ex.system, rhc, T) for T in Ts]
    fin = [r.gamma for r in res]
    tol = 1e-9
    cold = certify.worst_case_attenuation_limit(ex.system, rhc, start="cold", tol=tol).gamma
    stat = certify.worst_case_attenuation_limit(ex.system, rhc).gamma
    fig = theory_plots.attenuation_vs_T(Ts, {"RHC": fin}, {"cold": cold, "stationary γ∞": stat}, title="x")
    ax = fig.axes[0]
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    np.testing.assert_array_equal(lines["RHC"].get_xdata(), Ts)
    np.testing.assert_allclose(lines["RHC"].get_ydata(), fin)
    assert list(lines["cold"].get_ydata()) == [cold, cold]
    assert lines["stationary γ∞"].get_linestyle() == "--"
    assert ax.get_xscale() == "log"
    # the finite-T level never exceeds its T → ∞ cold-start limit (it grows with T), up to
    # rounding: γ = σ_max(G)² from a backward-stable SVD is off by 2·max(G.shape)·eps relative,
    # and the limit is a root found to xtol = tol·(bracket end <= 2γ), so within 2·tol relative
    err = np.array([2 * max(r.G.shape) * np.finfo(float).eps * r.gamma for r in res])
    assert np.all(np.diff(fin) >= -(err[1:] + err[:-1])) and fin[-1] <= cold * (1 + 2 * tol) + err[-1]


@pytest.mark.parametrize("Ts, levels, limits, match", [
    ([0, 1], {"a": [1.0, 2.0]}, None, "T"),
    ([1, 2], {}, None, "levels"),
    ([1, 2], {"a": [1.0]}, None, r"levels\['a'\]"),
    ([1, 2], {"a": [1.0, 2.0]}, [1.0], "limits"),
    ([1, 2], {"a": [1.0, 2.0]}, {"x": -1.0}, r"limits\['x'\]"),
])
def test_attenuation_vs_T_rejects_bad_input(Ts, levels, limits, match):
    with pytest.raises(ValueError, match=match):
        theory_plots.attenuation_vs_T(Ts, levels, limits)
