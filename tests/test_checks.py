"""Lemma 1, Lemma 2 and Theorem 1 along simulated trajectories of Algorithm 1.

With certified constants (orrc.certify.lq_constants) the paper's inequalities must hold
at every step, for every disturbance: zero violations beyond floating-point tolerance.
The margins are also recomputed here step by step from orrc.theory and orrc.metrics
(independent index arithmetic), and the checks are shown to detect a false constant.
"""
import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import orrc
from orrc import certify, checks, theory
from conftest import random_lq_problem


def random_instance(seed):
    rng = np.random.default_rng(seed)
    return (*random_lq_problem(rng), rng)


@settings(max_examples=50, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])
@given(seed=st.integers(0, 2 ** 31 - 1), kind=st.sampled_from(orrc.disturbances.KINDS),
       scale=st.floats(0.01, 10.0), extra_M=st.integers(0, 3), x_scale=st.floats(0.0, 5.0))
def test_no_violations_with_certified_constants(seed, kind, scale, extra_M, x_scale):
    sysm, cost, rng = random_instance(seed)
    M0 = certify.smallest_certified_M(sysm, cost, 40)
    assume(M0 is not None)                      # no admissible M <= 40: skip the instance
    M = M0 + extra_M
    c = certify.lq_constants(sysm, cost, M)
    assert c.admissible
    T = 3 * M + 5
    w = orrc.disturbances.make(kind, T + M, sysm.n, scale, seed=rng)
    x0 = rng.standard_normal(sysm.n) * x_scale
    traj = orrc.simulate(sysm, orrc.PreviewRHC(sysm, cost, M), x0, w, T)
    l1 = checks.lemma1_margins(traj, M, c.alpha_lo, c.alpha_hi, c.gamma_bar)
    assert l1.holds(), (l1.lower.violations(), l1.increment.violations())
    for H in sorted({M, M + 1, 2 * M, T - 1}):
        l2 = checks.lemma2_margins(traj, M, H, c.a, c.alpha_lo, c.alpha_hi, c.gamma_bar)
        assert l2.holds(), (H, l2.violations())
    # a larger a is admissible too (Lemma 2 and Theorem 1 hold for every a in [a_min, 1))
    a2 = 0.5 * (c.a + 1)
    assert checks.lemma2_margins(traj, M, M, a2, c.alpha_lo, c.alpha_hi, c.gamma_bar).holds()
    for gamma in (c.gamma_c, 3 * c.gamma_c):
        th = checks.theorem1_margin(traj, M, c.a, c.alpha_lo, c.alpha_hi, c.gamma_bar, gamma)
        assert th.holds(), th.violations()
    gc2 = theory.gamma_c(M, a2, c.alpha_lo, c.alpha_hi, c.gamma_bar)
    assert checks.theorem1_margin(traj, M, a2, c.alpha_lo, c.alpha_hi, c.gamma_bar, gc2).holds()


@pytest.fixture(scope="module")
def scalar_run():
    ex = orrc.examples.scalar_unstable()
    M = certify.smallest_certified_M(ex.system, ex.cost) + 3
    c = certify.lq_constants(ex.system, ex.cost, M)
    T = 60
    w = orrc.disturbances.make("uniform_ball", T + M, 1, 0.5, seed=3)
    traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, M), ex.x0, w, T)
    return ex, M, c, traj


def test_margins_equal_a_step_by_step_recomputation(scalar_run):
    """The same margins from orrc.theory and orrc.metrics, one step at a time (0-based indices:
    the increment at t uses w_t..w_{t+M-1}; Lemma 2 at t uses w_t..w_{t+H+M-2})."""
    ex, M, c, traj = scalar_run
    args = (c.alpha_lo, c.alpha_hi, c.gamma_bar)
    l1 = checks.lemma1_margins(traj, M, *args)
    GV, GVg = theory.Gamma_V(M, c.alpha_lo, c.alpha_hi), theory.Gamma_V_gamma(M, *args)
    for t in range(traj.T - 1):
        S = float(np.sum(traj.w_all[t:t + M] ** 2))
        expected = GV * traj.sigma[t] + GVg * S - (traj.values[t + 1] - traj.values[t])
        assert l1.increment.margin[t] == pytest.approx(expected, rel=1e-12, abs=1e-12)
        assert l1.lower.margin[t] == pytest.approx(traj.values[t] - c.alpha_lo * traj.sigma[t], rel=1e-12)
    H = M + 4
    l2 = checks.lemma2_margins(traj, M, H, c.a, *args)
    assert len(l2) == traj.T - H
    for t in range(traj.T - H):
        bound = theory.lemma2_bound(traj.sigma[t], traj.w_all[t:t + H + M - 1], M, H, c.a, *args)
        assert l2.margin[t] == pytest.approx(bound - traj.costs[t + H], rel=1e-12)
    th = checks.theorem1_margin(traj, M, c.a, *args, c.gamma_c)
    R = orrc.attenuation_regret(traj, c.gamma_c, cumulative=True)
    for Tp in (1, M, M + 1, traj.T):
        C = theory.theorem1_constant(traj.sigma[0], traj.w_all, Tp, M, c.a, *args, c.gamma_c)
        assert th.margin[Tp - 1] == pytest.approx(C - R[Tp - 1], rel=1e-10)
        assert th.actual[Tp - 1] == pytest.approx(R[Tp - 1], rel=1e-12)
    assert l1.holds() and l2.holds() and th.holds()


def test_the_checks_detect_false_constants(scalar_run):
    ex, M, c, traj = scalar_run
    # V_M >= α_lo σ fails for an α_lo above V_M(x)/σ(x) somewhere
    ratio = np.max(traj.values / np.maximum(traj.sigma[:-1], 1e-300))
    l1 = checks.lemma1_margins(traj, M, 1.01 * ratio, max(c.alpha_hi, 1.01 * ratio), c.gamma_bar)
    assert not l1.lower.holds() and len(l1.lower.violations()) > 0
    # Theorem 1: without disturbances C = ᾱ σ(x_0)(1-a^T)/(1-a); claiming σ(x_0) = 0 for a run
    # from x_0 != 0 must show a violation
    quiet = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, M), ex.x0, np.zeros((40 + M, 1)), 40)
    th = checks.theorem1_margin(quiet, M, c.a, c.alpha_lo, c.alpha_hi, c.gamma_bar, c.gamma_c)
    assert th.holds()
    quiet.sigma[0] = 0.0
    th = checks.theorem1_margin(quiet, M, c.a, c.alpha_lo, c.alpha_hi, c.gamma_bar, c.gamma_c)
    assert not th.holds() and th.violations()[0] == 1


def test_the_preview_tail_past_T_counts(scalar_run):
    """V^t_M sees w_t..w_{t+M-1}, which runs past T at the end: a disturbance only in the preview
    tail raises the last values, and Lemma 1 holds only because the bound counts the tail
    (``traj.w_all``); the applied disturbances ``traj.w`` alone would give a violated bound."""
    ex, M, c, _ = scalar_run
    T = 30
    w = np.zeros((T + M, 1))
    w[T:] = 1.0                                   # nothing acts before T; the controller previews it
    traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, M), np.zeros(1), w, T)
    assert np.all(traj.w == 0) and traj.values[-1] > 0
    l1 = checks.lemma1_margins(traj, M, c.alpha_lo, c.alpha_hi, c.gamma_bar)
    assert l1.holds() and l1.increment.t[-1] == T - 2
    GV = theory.Gamma_V(M, c.alpha_lo, c.alpha_hi)
    applied_only = GV * traj.sigma[:T - 1] - np.diff(traj.values)   # the bound without the tail
    assert applied_only.min() < 0


def test_check_errors(scalar_run):
    ex, M, c, traj = scalar_run
    args = (c.alpha_lo, c.alpha_hi, c.gamma_bar)
    lqr_traj = orrc.simulate(ex.system, orrc.LQR(ex.system, ex.cost), ex.x0, np.zeros((20, 1)), 20)
    with pytest.raises(ValueError, match="no V_M values"):
        checks.lemma1_margins(lqr_traj, M, *args)
    with pytest.raises(ValueError, match="previewed"):
        checks.lemma1_margins(traj, M + 1, *args)
    with pytest.raises(ValueError, match="H must be < T"):
        checks.lemma2_margins(traj, M, traj.T, c.a, *args)
    with pytest.raises(ValueError, match="H >= M"):
        checks.lemma2_margins(traj, M, M - 1, c.a, *args)
    with pytest.raises(ValueError, match="a must lie"):
        checks.lemma2_margins(traj, M, M, 0.5 * c.a, *args)
    with pytest.raises(ValueError, match="gamma >= gamma_c"):
        checks.theorem1_margin(traj, M, c.a, *args, 0.5 * c.gamma_c)
    with pytest.raises(ValueError, match="Trajectory"):
        checks.lemma1_margins("traj", M, *args)


def test_value_bound_margins(scalar_run):
    """The class condition V_M <= ᾱσ + γ̄Σ‖w‖² along the run: recomputed step by step from the
    value matrix H, it holds for the certified pair, and fails once γ̄ is far too small."""
    ex, M, c, traj = scalar_run
    vb = checks.value_bound_margins(traj, M, c.alpha_hi, c.gamma_bar)
    assert vb.holds() and len(vb) == traj.T
    H = c.info["H"]
    for t in range(0, traj.T, 7):
        z = np.concatenate([traj.x[t], traj.w_all[t:t + M].ravel()])
        assert vb.actual[t] == pytest.approx(z @ H @ z, rel=1e-9)
        bound = c.alpha_hi * traj.x[t] @ traj.x[t] + c.gamma_bar * np.sum(traj.w_all[t:t + M] ** 2)
        assert vb.bound[t] == pytest.approx(bound, rel=1e-12)
    # a run that starts at rest and is driven only by disturbances needs γ̄ (σ(x_0) = 0)
    w = np.zeros((20 + M, 1))
    w[:M] = 1.0
    quiet = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, M), np.zeros(1), w, 20)
    assert checks.value_bound_margins(quiet, M, c.alpha_hi, c.gamma_bar).holds()
    bad = checks.value_bound_margins(quiet, M, c.alpha_hi, 1e-3 * quiet.values[0] / M)
    assert not bad.holds() and bad.violations()[0] == 0
    with pytest.raises(ValueError, match="gamma_bar"):
        checks.value_bound_margins(traj, M, c.alpha_hi, -1.0)
