"""The baselines of the comparison chapter: the clairvoyant optimum is never beaten, the
value of preview decays geometrically, GPC's regret is sub-linear, RegretOptimal minimises the
worst-case regret among causal controllers, and worst_case_regret is the exact worst case."""
import numpy as np
import pytest

import orrc
from orrc import certify, checks
from orrc.controllers.gpc import best_fixed_policy
from conftest import random_lq_problem


def problem(seed, n=None, m=None):
    return random_lq_problem(np.random.default_rng(seed), n, m, rho_range=(0.3, 1.3))


# -- PreviewRHC(preview_w=k) ---------------------------------------------------------------------------
@pytest.mark.parametrize("k", [0, 2, 5])
def test_preview_rhc_with_k_seen_disturbances_plans_with_the_unseen_ones_zero(k):
    s, c = problem(1, n=2, m=1)
    M, T = 5, 12
    rhc = orrc.PreviewRHC(s, c, M, preview_w=k)
    assert rhc.preview_w == k and rhc.preview_c == M
    w = orrc.disturbances.uniform_ball(T + M, 2, 1.0, seed=3)
    tr = orrc.simulate(s, rhc, np.ones(2), w, T)
    full = orrc.PreviewRHC(s, c, M)
    for t in (0, 4, 11):
        W = np.zeros((M, 2))
        W[:k] = w[t:t + k]
        np.testing.assert_allclose(tr.u[t], full.plan(tr.x[t], W).inputs[0], rtol=1e-10, atol=1e-12)
    # the exact law: the feed-forward columns of the unseen disturbances dropped
    L = full.law.L[:, :k * 2]
    np.testing.assert_allclose(tr.u[3], -full.law.K @ tr.x[3] - L @ w[3:3 + k].ravel(), rtol=1e-10, atol=1e-12)


def test_lemma_checks_refuse_a_trajectory_that_saw_fewer_than_M_disturbances():
    ex = orrc.examples.scalar_unstable()
    w = orrc.disturbances.uniform_ball(30, 1, 0.5, seed=0)
    tr = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 5, preview_w=2), ex.x0, w, 20)
    with pytest.raises(orrc.OrrcValueError, match=r"saw only M_w = 2 .*preview_w=2"):
        checks.lemma1_margins(tr, 5, 1.0, 10.0, 2.0)


# -- the clairvoyant optimum -------------------------------------------------------------------------
@pytest.mark.parametrize("seed", range(6))
def test_clairvoyant_cost_is_never_above_any_controllers_cost(seed):
    s, c = problem(seed)
    rng = np.random.default_rng(seed)
    T, M = 16, 4
    n = s.n
    kind = ["uniform_ball", "sinusoid", "bursts", "gaussian"][seed % 4]
    w = orrc.disturbances.make(kind, T + M, n, scale=float(rng.uniform(0.1, 2.0)), seed=seed)
    w[T:] = 0.0        # nothing previewed past the run (the clairvoyant's horizon is T)
    clair = orrc.simulate(s, orrc.Clairvoyant(s, c, T), np.zeros(n), w, T).costs.sum()
    controllers = [orrc.LQR(s, c), orrc.ZeroInput(s.m, c), orrc.HInfinity(s, c), orrc.HInfinity(s, c, preview=2),
                   orrc.PreviewRHC(s, c, M), orrc.PreviewRHC(s, c, M, preview_w=0), orrc.GPC(s, c, H=3),
                   orrc.RegretOptimal(s, c, T) if s.n + s.m <= 3 else orrc.LQR(s, c)]
    for ctrl in controllers:
        cost = orrc.simulate(s, ctrl, np.zeros(n), w, T).costs.sum()
        assert clair <= cost * (1 + 1e-9) + 1e-12, ctrl.name
        # and its dynamic regret is at most the worst case times the energy (linear loops)
        if not isinstance(ctrl, orrc.GPC):
            wc = certify.worst_case_regret(s, ctrl, T)
            assert cost - clair <= wc.regret * np.sum(w[:T] ** 2) * (1 + 1e-7) + 1e-9, ctrl.name


# -- the value of preview ----------------------------------------------------------------------------
def test_preview_rhc_dynamic_regret_decays_geometrically_in_k():
    ex = orrc.examples.two_mass_spring()
    s, c = ex.system, ex.cost
    M, T = 30, 150
    w = orrc.disturbances.uniform_ball(T + M, s.n, 1.0, seed=0)
    clair = orrc.simulate(s, orrc.Clairvoyant(s, c, T), np.zeros(s.n), w, T).costs.sum()
    ks = np.arange(0, 13)
    regret = np.array([orrc.simulate(s, orrc.PreviewRHC(s, c, M, preview_w=int(k)), np.zeros(s.n), w, T).costs.sum()
                       - clair for k in ks])
    assert np.all(regret > 0) and np.all(np.diff(regret) < 0)
    slope, icpt = np.polyfit(ks, np.log(regret), 1)
    resid = np.log(regret) - (slope * ks + icpt)
    r2 = 1 - resid @ resid / np.sum((np.log(regret) - np.log(regret).mean()) ** 2)
    assert r2 >= 0.95
    rho = max(abs(np.linalg.eigvals(s.A - s.B @ orrc.LQR(s, c).K)))
    assert np.exp(slope) == pytest.approx(rho ** 2, rel=0.05)   # the literature's rate ρ(A − BK)^{2k}


# -- GPC ------------------------------------------------------------------------------------------------
def test_gpc_regret_against_the_best_fixed_policy_in_hindsight_is_sublinear():
    ex = orrc.examples.scalar_unstable()
    s, c = ex.system, ex.cost
    H, Ts = 5, [100, 200, 400, 800]
    w = (orrc.disturbances.sinusoid(max(Ts) + 1, 1, amplitude=1.0, period=13)
         + orrc.disturbances.uniform_ball(max(Ts) + 1, 1, 0.3, seed=1))
    regret = []
    for T in Ts:
        g = orrc.GPC(s, c, H=H, lr=0.05)
        tr = orrc.simulate(s, g, np.zeros(1), w, T)
        assert tr.info["M"].shape == (T, H, 1, 1) and np.allclose(tr.info["w"][1:], w[:T - 1])
        _, best = best_fixed_policy(s, c, w, T, H, K=g.K, bounds=g.bounds)
        regret.append(tr.costs.sum() - best)
    regret = np.array(regret)
    assert np.all(regret > 0)
    assert np.polyfit(np.log(Ts), np.log(regret), 1)[0] < 0.8
    # the comparator is the cost of running the best policy: DisturbanceAction reproduces it
    M, best = best_fixed_policy(s, c, w, 200, H, K=g.K, bounds=g.bounds)
    run = orrc.simulate(s, orrc.DisturbanceAction(s, c, M, g.K), np.zeros(1), w, 200)
    assert run.costs.sum() == pytest.approx(best, rel=1e-10)


def test_gpc_surrogate_gradient_is_exact():
    s, c = problem(4, n=2, m=1)
    g = orrc.GPC(s, c, H=3)
    orrc.simulate(s, g, np.zeros(2), orrc.disturbances.uniform_ball(30, 2, 1.0, seed=0), 30)
    M = np.random.default_rng(0).standard_normal(g.M.shape)
    f, grad = g.surrogate(M)
    E = np.zeros_like(M)
    E[1, 0, 1] = 1e-6
    assert (g.surrogate(M + E)[0] - g.surrogate(M - E)[0]) / 2e-6 == pytest.approx(grad[1, 0, 1], rel=1e-6)


# -- the regret-optimal controller ---------------------------------------------------------------------
def arveson_distance_sq(cond):
    """min over strictly causal Φ of ‖S^½(Φ − Φ*)‖² by Arveson's distance formula: with a lower-triangular
    Δ, ΔᵀΔ = S, it is max_k ‖(ΔΦ*)[rows of steps <= k, columns of steps >= k]‖² (independent of the SDP)."""
    S = cond.S
    J = np.eye(len(S))[::-1]
    Delta = (J @ np.linalg.cholesky(J @ S @ J) @ J).T            # lower triangular, ΔᵀΔ = S
    Y = Delta @ cond.Phi_star
    T = cond.T
    m, n = Y.shape[0] // T, Y.shape[1] // T
    return max(np.linalg.norm(Y[:(k + 1) * m, k * n:], 2) ** 2 for k in range(T))


@pytest.mark.parametrize("seed", range(3))
def test_regret_optimal_has_the_smallest_worst_case_regret_of_the_causal_controllers(seed):
    s, c = problem(seed, m=1)
    T = 10
    ro = orrc.RegretOptimal(s, c, T)
    assert ro.regret == pytest.approx(ro.sdp_value, rel=1e-5)
    assert ro.regret == pytest.approx(arveson_distance_sq(ro.condensed), rel=1e-5)
    wc = certify.worst_case_regret(s, ro, T)
    assert wc.regret == pytest.approx(ro.regret, rel=1e-8)
    w = orrc.disturbances.uniform_ball(T + 5, s.n, 1.0, seed=seed)
    gpc = orrc.GPC(s, c, H=4)
    orrc.simulate(s, gpc, np.zeros(s.n), w, T)
    others = [orrc.LQR(s, c), orrc.HInfinity(s, c), gpc.frozen(), orrc.PreviewRHC(s, c, 5, preview_w=0),
              orrc.ZeroInput(s.m, c)]
    for ctrl in others:
        assert certify.worst_case_regret(s, ctrl, T).regret >= ro.regret * (1 - 1e-6), ctrl.name


def test_worst_case_regret_is_attained_and_never_exceeded():
    ex = orrc.examples.scalar_unstable()
    s, c = ex.system, ex.cost
    T = 15
    clair = orrc.Clairvoyant(s, c, T)
    rng = np.random.default_rng(0)
    for ctrl in (orrc.LQR(s, c), orrc.PreviewRHC(s, c, 4), orrc.HInfinity(s, c, preview=1)):
        r = certify.worst_case_regret(s, ctrl, T)
        assert np.sum(r.w ** 2) == pytest.approx(1.0)
        regret = lambda w: (orrc.simulate(s, ctrl, np.zeros(1), w, T).costs.sum()  # noqa: E731
                            - orrc.simulate(s, clair, np.zeros(1), w, T).costs.sum())
        assert regret(r.w) == pytest.approx(r.regret, rel=1e-9)
        for _ in range(10):
            w = rng.standard_normal((T, 1))
            assert regret(w / np.linalg.norm(w)) <= r.regret * (1 + 1e-9)


def test_frozen_gpc_attenuation_limit_matches_the_finite_horizon_level():
    ex = orrc.examples.double_integrator()
    s, c = ex.system, ex.cost
    M = 0.1 * np.random.default_rng(0).standard_normal((3, 1, 2))
    da = orrc.DisturbanceAction(s, c, M)
    lim = certify.worst_case_attenuation_limit(s, da).gamma
    fin = [certify.worst_case_attenuation(s, da, T).gamma for T in (50, 200)]
    assert fin[0] <= fin[1] <= lim * (1 + 1e-6) and fin[1] == pytest.approx(lim, rel=2e-2)
