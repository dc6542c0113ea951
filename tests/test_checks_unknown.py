"""Lemma 4, Lemma 5 and Theorem 2 along trajectories of Algorithm 2 (orrc.checks.unknown), and the
exploration trade-off of Theorem 2 (orrc.tradeoff): the best N grows like T^{2/3} when g(N) = Θ(1/√N)."""
import numpy as np
import pytest

import orrc
from orrc import certify, checks, estimation as est, theory
from orrc.tradeoff import exploration_tradeoff

SCALAR = orrc.LinearSystem([[0.5]], [[1.0]])


@pytest.fixture(scope="module")
def wrong_model_run():
    """Algorithm 2 with an estimator that treats w as noise (‖θ̂ - θ‖ > 0), certified constants."""
    cost = orrc.QuadraticCost([[1.0]], [[0.1]])
    M, N, T = 4, 30, 200
    model = orrc.ParametricSystem.linear(1, 1)
    w = orrc.disturbances.uniform_box(T + M, 1, -0.5, 0.5, seed=0)
    etc = orrc.EstimateThenControl(model, cost, M, N, use_w=False, excitation=est.prbs(N, 1, 0.5, seed=0),
                                   theta_true=[0.5, 1.0])
    traj = orrc.simulate(SCALAR, etc, np.zeros(1), w, T)
    c = certify.lq_constants(SCALAR, cost, M)
    err = traj.info["theta_error"]
    rho = max(np.linalg.norm(np.r_[traj.x[t], traj.w_all[t:t + M].ravel()]) for t in range(T))
    lip = certify.lq_lipschitz(SCALAR, cost, M, radius=1.5 * err, rho=1.2 * rho, grid=5)
    return traj, M, N, c, lip, theory.alpha_f_tilde(lip.alpha_f_S, M), err


def test_lemma4_holds_along_the_control_phase_with_the_theta_term(wrong_model_run):
    traj, M, N, c, lip, at, err = wrong_model_run
    assert err > 0.01
    l4 = checks.lemma4_margins(traj, M, c.alpha_lo, c.alpha_hi, c.gamma_bar, lip.alpha_V, lip.alpha_kappa,
                               lip.alpha_c, at)
    assert l4.holds() and l4.t[0] == N and len(l4) == traj.T - 1 - N
    np.testing.assert_allclose(l4.actual, np.diff(traj.info["values"][N:]))
    GVt = theory.Gamma_V_theta(M, c.alpha_lo, c.alpha_hi, lip.alpha_V, lip.alpha_kappa, lip.alpha_c, at)
    l1_part = l4.bound - GVt * err
    assert np.all(GVt * err > l1_part.max())          # the θ-term dominates this bound


def test_lemma5_and_theorem2_hold_along_the_control_phase(wrong_model_run):
    traj, M, N, c, lip, at, err = wrong_model_run
    l5 = checks.lemma5_margins(traj, M, 2 * M, c.a, c.alpha_lo, c.alpha_hi, c.gamma_bar, lip.alpha_V,
                               lip.alpha_kappa, lip.alpha_c, at)
    assert l5.holds() and l5.t[0] == N
    t2 = checks.theorem2_margin(traj, M, c.a, c.alpha_lo, c.alpha_hi, c.gamma_bar, c.gamma_c, lip.alpha_V,
                                lip.alpha_kappa, lip.alpha_c, at)
    assert t2.holds() and t2.t[0] == N + 1 and t2.t[-1] == traj.T
    b = theory.theorem2_constant(traj.costs[:N], traj.w_all, traj.sigma[N], err, traj.T, N, M, c.a, c.alpha_lo,
                                 c.alpha_hi, c.gamma_bar, c.gamma_c, lip.alpha_V, lip.alpha_kappa, lip.alpha_c, at)
    assert t2.bound[-1] == pytest.approx(b.total, rel=1e-12)
    assert t2.actual[-1] == pytest.approx(orrc.attenuation_regret(traj, c.gamma_c))


def test_the_checks_fail_when_the_constants_are_too_small(wrong_model_run):
    traj, M, N, c, lip, at, err = wrong_model_run
    l4 = checks.lemma4_margins(traj, M, 1.0, 1.0, 1e-6, 0.0, 0.0, 0.0, 0.0)
    assert not l4.holds() and len(l4.violations()) > 0


def test_checks_need_a_trajectory_of_algorithm_2():
    ex = orrc.examples.scalar_unstable()
    traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 4), ex.x0, np.zeros((10, 1)), 8)
    with pytest.raises(orrc.OrrcValueError, match="not one of Algorithm 2"):
        checks.lemma4_margins(traj, 4, 1.0, 1.5, 1.0, 1.0, 1.0, 1.0, 1.0)


def test_best_exploration_length_grows_like_T_to_the_two_thirds():
    """g(N) = Θ(1/√N) (least squares not given w) and a Lipschitz cost: the loss per control step is
    first order in ‖θ̂ - θ‖, so the measured trade-off's minimiser grows like T^{2/3}.

    Measured on 8 seeds of closed loops of Algorithm 2 (orrc.simulate); the best N minimises the fitted
    trade-off curve, whose loss exponent p is fitted from the data (see orrc.tradeoff)."""
    cost = orrc.L1Cost([1.0], [[0.1]])
    model = orrc.ParametricSystem.linear(1, 1)
    Ns = np.unique(np.geomspace(10, 600, 8).astype(int))
    Ts = np.geomspace(1e3, 3e4, 6)
    tt = exploration_tradeoff(SCALAR, model, cost, 3, Ns, seeds=8, window=150, excitation_amplitude=0.5,
                              w_radius=0.5, theta_true=[0.5, 1.0])
    assert 0.35 < tt.fit["g_p"] < 0.65            # g(N) = Θ(1/√N), measured
    assert 0.3 < tt.fit["p"] < 0.7                 # the loss per step is first order in the error
    assert tt.interior(Ts).all()                   # every best N inside the measured range
    assert abs(tt.slope(Ts) - 2 / 3) < 0.15
