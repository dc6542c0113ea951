"""orrc.certify.minmax_constants: the constants ᾱ_W, γ̄_W of Appendix D.

Certified pairs (linear-quadratic, box or ball W) bound the exact V_{W,M}(x) at every state
tried, sampled ones far from the origin included; the certified curve lies above the lower
curve of exact samples and shares its two ends (V_{W,M}(0)/max‖w‖² and λ_max(P_0)); the
constants depend on x and W only through x/max‖w‖ (scaling W leaves them unchanged); the
paper's γ̄_W = γ̄ M fails; estimates are labelled.
"""
import numpy as np
import pytest

import orrc
from orrc import certify
from conftest import random_lq_problem


@pytest.fixture(scope="module")
def scalar():
    ex = orrc.examples.scalar_unstable(A=1.2)
    return ex.system, ex.cost, orrc.Box(-0.3, 0.3)


def test_certified_pair_bounds_the_exact_value_everywhere_tried(scalar):
    sysm, cost, W = scalar
    M = 6
    c = certify.minmax_constants(sysm, cost, M, W)
    assert not c.estimate and c.admissible and c.M == M
    rhc = orrc.MinMaxRHC(sysm, cost, M, W, method="exact")
    for x in np.r_[0.0, np.geomspace(1e-3, 1e4, 30), -np.geomspace(1e-3, 1e4, 30)]:
        V = rhc.plan(np.array([x])).upper
        assert V <= c.bound(x * x) * (1 + 1e-9), x
    # every point of the certified Pareto curve is admissible too
    for gb, ah in c.pareto[::25]:
        for x in np.geomspace(1e-2, 1e4, 15):
            assert rhc.plan(np.array([x])).upper <= (ah * x * x + gb * W.max_norm_sq) * (1 + 1e-9)


def test_certified_curve_is_above_the_exact_samples_and_shares_their_ends(scalar):
    sysm, cost, W = scalar
    c = certify.minmax_constants(sysm, cost, 6, W, n_samples=30)
    gbs, ahs = c.pareto[:, 0], c.pareto[:, 1]
    low = c.info["lower_pareto"][:, 1]
    ok = np.isfinite(low)
    assert ok.sum() > 100 and np.all(ahs[ok] >= low[ok] * (1 - 1e-9))
    assert np.all(np.diff(ahs) <= 1e-12 * ahs[:-1])                        # decreasing in γ̄_W
    V0 = orrc.MinMaxRHC(sysm, cost, 6, W).plan(np.zeros(1)).upper
    assert c.info["gamma_bar_W_min"] == pytest.approx(V0 / W.max_norm_sq, rel=1e-12)
    assert gbs[0] > c.info["gamma_bar_W_min"]
    P0 = certify.alpha_hi_floor(sysm, cost, [6])[0]
    assert ahs[-1] == pytest.approx(P0, rel=1e-3) and np.all(ahs >= P0 * (1 - 1e-12))
    s = c.info["samples"]
    far = np.argmax(s["sigma"])                                            # V_(W,M)(x)/σ(x) → λ_max(P_0) as x grows
    assert s["V"][far] / s["sigma"][far] == pytest.approx(P0, rel=1e-2)


def test_constants_do_not_depend_on_the_size_of_W(scalar):
    sysm, cost, W = scalar
    a = certify.minmax_constants(sysm, cost, 6, W)
    b = certify.minmax_constants(sysm, cost, 6, orrc.Box(-3.0, 3.0))
    assert a.alpha_hi_W == pytest.approx(b.alpha_hi_W, rel=1e-6)
    assert a.gamma_bar_W == pytest.approx(b.gamma_bar_W, rel=1e-6)
    assert a.gamma_c_W == pytest.approx(b.gamma_c_W, rel=1e-6)


def test_certified_for_two_states_and_a_ball():
    sysm, cost = random_lq_problem(np.random.default_rng(4), n=2, m=1, rho_range=(0.5, 0.9))
    M = 4
    for W in (orrc.Box([-0.2, -0.1], [0.3, 0.1]), orrc.Ball(0.2, 2)):
        c = certify.minmax_constants(sysm, cost, M, W, n_samples=10)
        assert not c.estimate
        rhc = orrc.MinMaxRHC(sysm, cost, M, W)
        rng = np.random.default_rng(0)
        for _ in range(10):
            x = rng.standard_normal(2) * 10 ** rng.uniform(-2, 2)
            assert rhc.plan(x).upper <= c.bound(x @ x) * (1 + 1e-6)


def test_the_papers_gamma_bar_W_equal_to_gamma_bar_M_fails(scalar):
    sysm, cost, W = scalar
    M = 6
    pre = certify.lq_constants(sysm, cost, M)                          # V_M <= ᾱσ + γ̄ Σ‖w‖²
    V0 = orrc.MinMaxRHC(sysm, cost, M, W).plan(np.zeros(1)).upper
    assert V0 > pre.gamma_bar * M * W.max_norm_sq                      # at x = 0 the paper's pair is violated
    # what γ̄ M does bound: the max-min value max_W V_M(0, W) (the preview controller's)
    rhc = orrc.PreviewRHC(sysm, cost, M)
    verts = [np.array(v, float).reshape(M, 1) for v in np.array(np.meshgrid(*[[-0.3, 0.3]] * M)).reshape(M, -1).T]
    assert max(rhc.plan(np.zeros(1), v).value for v in verts) <= pre.gamma_bar * M * W.max_norm_sq


def test_nonlinear_constants_are_labelled_estimates():
    ex = orrc.examples.inverted_pendulum()
    c = certify.minmax_constants(ex.system, ex.cost, 5, orrc.Box(-0.02, 0.02, 2), input_bounds=ex.input_bounds,
                                 n_samples=6, x_radius=0.5)
    assert c.estimate and "estimate" in c.method and "ESTIMATE" not in repr(c) and "estimated" in repr(c)
    s = c.info["samples"]
    assert np.all(c.bound(s["sigma"][s["sigma"] > 0]) >= s["V"][s["sigma"] > 0] * (1 - 1e-9))


def test_feedback_constants_certify_the_feedback_value():
    """The certified pair for policy="feedback" bounds V^fb at sampled states, its smallest γ̄_W is
    V^fb(0)/w̄², and it is no larger than the open-loop one (V^fb <= V)."""
    ex = orrc.examples.scalar_unstable(A=1.2)
    W = orrc.Box(-0.3, 0.3)
    fb = certify.minmax_constants(ex.system, ex.cost, 5, W, n_samples=12, policy="feedback")
    ol = certify.minmax_constants(ex.system, ex.cost, 5, W, n_samples=1)
    ctl = orrc.MinMaxRHC(ex.system, ex.cost, 5, W, policy="feedback")
    assert not fb.estimate and fb.info["V0"] == pytest.approx(ctl.plan(np.zeros(1)).value, rel=1e-9)
    assert fb.info["gamma_bar_W_min"] < ol.info["gamma_bar_W_min"]
    xs = np.linspace(-50.0, 50.0, 41)
    V = np.array([ctl.plan(np.array([x])).value for x in xs])
    assert np.all(V <= fb.bound(xs ** 2) * (1 + 1e-9))
    # the curve at any γ̄_W > V(0)/w̄² is an admissible pair too
    for g in (1.1, 3.0, 30.0):
        gb = g * fb.info["gamma_bar_W_min"]
        assert np.all(V <= fb.alpha_hi_at(gb) * xs ** 2 + gb * W.max_norm_sq + 1e-9 * V)


def test_maxmin_value_equals_preview_enumeration():
    import itertools

    rng = np.random.default_rng(2)
    from conftest import random_lq_problem

    sysm, cost = random_lq_problem(rng, n=2, m=1, rho_range=(0.6, 1.3))
    W = orrc.Box([-0.2, -0.4], [0.3, 0.1])
    x = rng.standard_normal(2)
    pre = orrc.PreviewRHC(sysm, cost, 3)
    brute = max(pre.plan(x, np.array(s)).value for s in itertools.product(W.vertices(), repeat=3))
    assert certify.maxmin_value(sysm, cost, 3, W, x) == pytest.approx(brute, rel=1e-9)
