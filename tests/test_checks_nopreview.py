"""Lemma 6 and Theorem 3 along simulated trajectories of Algorithm 3 (orrc.MinMaxRHC).

With certified constants (orrc.certify.minmax_constants) the class condition, both parts of
Lemma 6 and Theorem 3's explicit bound hold at every step, for disturbances anywhere in W
(random, constant at a vertex, switching between vertices, the controller's own worst case);
the margins are recomputed here from the trajectory; the checks detect a false constant and
refuse disturbances outside W or a controller with a disturbance preview.
"""
import numpy as np
import pytest

import orrc
from orrc import certify, checks, theory


@pytest.fixture(scope="module")
def setting():
    ex = orrc.examples.scalar_unstable(A=1.2)
    W = orrc.Box(-0.3, 0.3)
    M = 6
    c = certify.minmax_constants(ex.system, ex.cost, M, W)
    assert c.admissible and not c.estimate
    return ex, W, M, c


def _disturbances(kind, T, W, seed):
    rng = np.random.default_rng(seed)
    if kind == "random":
        return W.sample(T, rng)
    if kind == "vertex":
        return np.full((T, 1), W.hi[0])
    if kind == "switching":
        return np.where((np.arange(T) // 3) % 2 == 0, W.hi[0], W.lo[0])[:, None]
    return rng.choice([W.lo[0], W.hi[0]], size=(T, 1))


@pytest.mark.parametrize("kind", ["random", "vertex", "switching", "bang"])
@pytest.mark.parametrize("x0", [0.0, 1.0, -20.0])
def test_lemma6_and_theorem3_hold_at_every_step_with_certified_constants(setting, kind, x0):
    ex, W, M, c = setting
    T = 40
    traj = orrc.simulate(ex.system, orrc.MinMaxRHC(ex.system, ex.cost, M, W), np.array([x0]),
                         _disturbances(kind, T, W, 1), T)
    vb = checks.minmax_value_bound_margins(traj, M, W, c.alpha_hi_W, c.gamma_bar_W)
    l6 = checks.lemma6_margins(traj, M, W, c.alpha_lo, c.alpha_hi_W, c.gamma_bar_W)
    t3 = checks.theorem3_margin(traj, M, W, c.a, c.alpha_lo, c.alpha_hi_W, c.gamma_bar_W, c.gamma_c_W)
    assert vb.holds() and l6.holds() and t3.holds(), (vb, l6, t3)
    # the margins recomputed from the trajectory
    w2 = W.max_norm_sq
    V, sig = traj.values, traj.sigma[:T]
    np.testing.assert_allclose(vb.margin, c.alpha_hi_W * sig + c.gamma_bar_W * w2 - V, rtol=1e-12, atol=1e-12)
    GV, GVg = theory.Gamma_WV(M, c.alpha_lo, c.alpha_hi_W), theory.Gamma_WV_gamma(M, c.alpha_lo, c.alpha_hi_W,
                                                                                    c.gamma_bar_W)
    np.testing.assert_allclose(l6.increment.margin, GV * sig[:-1] + GVg * w2 - np.diff(V), rtol=1e-12, atol=1e-9)
    assert l6.Gamma_V == GV < 0
    Ts = np.arange(1, T + 1)
    C = [theory.theorem3_constant(sig[0], t, M, c.a, c.alpha_lo, c.alpha_hi_W, c.gamma_bar_W, w2, c.gamma_c_W)
         for t in Ts]
    np.testing.assert_allclose(t3.bound, C, rtol=1e-12)
    np.testing.assert_allclose(t3.actual, np.cumsum(traj.costs) - c.gamma_c_W * Ts * w2, rtol=1e-12)


def test_lemma6_holds_against_the_controllers_own_worst_case(setting):
    """The adversary plays the first disturbance of the worst-case sequence the plan was made against."""
    ex, W, M, c = setting
    rhc = orrc.MinMaxRHC(ex.system, ex.cost, M, W)
    x, xs, ws = np.array([2.0]), [], []
    for _ in range(25):
        p = rhc.plan(x)
        xs.append(x)
        ws.append(p.worst_w[0])
        x = ex.system.step(x, p.inputs[0], p.worst_w[0])
    traj = orrc.simulate(ex.system, orrc.MinMaxRHC(ex.system, ex.cost, M, W), np.array([2.0]), np.array(ws), 25)
    np.testing.assert_allclose(traj.x[:-1], np.array(xs), rtol=1e-9, atol=1e-12)
    l6 = checks.lemma6_margins(traj, M, W, c.alpha_lo, c.alpha_hi_W, c.gamma_bar_W)
    assert l6.holds()


def test_the_checks_detect_false_constants(setting):
    ex, W, M, c = setting
    T = 30
    traj = orrc.simulate(ex.system, orrc.MinMaxRHC(ex.system, ex.cost, M, W), np.array([5.0]), W.sample(T, 0), T)
    assert not checks.minmax_value_bound_margins(traj, M, W, c.alpha_hi_W, 0.1 * c.gamma_bar_W).holds()
    assert not checks.lemma6_margins(traj, M, W, 10 * c.alpha_lo, 10 * c.alpha_hi_W, c.gamma_bar_W).lower.holds()
    # Theorem 3's bound at gamma_c_W is far from tight: the margin is positive and grows with T
    t3 = checks.theorem3_margin(traj, M, W, c.a, c.alpha_lo, c.alpha_hi_W, c.gamma_bar_W, c.gamma_c_W)
    assert t3.margin[-1] > t3.margin[0] > 0


def test_the_checks_refuse_disturbances_outside_W_and_a_preview_controller(setting):
    ex, W, M, c = setting
    T = 10
    w = W.sample(T, 0)
    w[4] = 0.31
    traj = orrc.simulate(ex.system, orrc.MinMaxRHC(ex.system, ex.cost, M, W), np.array([1.0]), w, T)
    with pytest.raises(orrc.OrrcValueError, match="leave W"):
        checks.lemma6_margins(traj, M, W, c.alpha_lo, c.alpha_hi_W, c.gamma_bar_W)
    pre = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, M), np.array([1.0]), W.sample(T + M, 0), T)
    with pytest.raises(orrc.OrrcValueError, match="Algorithm 3"):
        checks.lemma6_margins(pre, M, W, c.alpha_lo, c.alpha_hi_W, c.gamma_bar_W)
    lqr = orrc.simulate(ex.system, orrc.ZeroInput(1, ex.cost), np.array([1.0]), W.sample(T, 0), T)
    with pytest.raises(orrc.OrrcValueError, match="no V_"):
        checks.theorem3_margin(lqr, M, W, c.a, c.alpha_lo, c.alpha_hi_W, c.gamma_bar_W, c.gamma_c_W)
