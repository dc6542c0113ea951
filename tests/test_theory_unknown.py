"""Section 5.2 as formulas (orrc.theory.unknown) and Lemma 3's constants (orrc.certify.lipschitz)."""
import numpy as np
import pytest

import orrc
import paper_unknown as paper
from orrc import certify, theory
from orrc.solvers.lq import LQPreviewLaw


# -- the formulas against the paper ----------------------------------------------------------------------
@pytest.mark.parametrize("seed", range(5))
def test_lemma4_and_lemma5_constants_are_the_papers(seed):
    rng = np.random.default_rng(seed)
    alpha_lo = rng.uniform(0.5, 2.0)
    alpha_hi = alpha_lo * rng.uniform(1.0, 2.0)
    M = int(np.ceil(alpha_hi ** 2 / alpha_lo ** 2 + 1)) + int(rng.integers(1, 5))
    aV, ak, ac, Lf = rng.uniform(0.1, 3.0, 4)
    at = theory.alpha_f_tilde(Lf, M)
    assert at == pytest.approx(paper.alpha_f_tilde(Lf, 1.0, M))
    assert theory.Gamma_V_theta(M, alpha_lo, alpha_hi, aV, ak, ac, at) == pytest.approx(
        paper.Gamma_V_theta(M, alpha_lo, alpha_hi, aV, ak, ac, at))
    a = theory.min_decay_rate(M, alpha_lo, alpha_hi)
    a = a + rng.uniform(0, 1) * (1 - a) * 0.9
    eps = alpha_hi * (1 - a)
    c = theory.lemma5_c(M, a, alpha_lo, alpha_hi, aV, ak, ac, at)
    assert c == pytest.approx(paper.c(aV, ak, ac, at, M, alpha_lo, alpha_hi, eps))
    for H in (0, 1, M, 3 * M):
        assert theory.lemma5_M_theta(H, a, c, aV) == pytest.approx(paper.M_theta(H, a, c, aV))


def test_without_model_error_lemma4_and_lemma5_are_lemma1_and_lemma2():
    M, a, lo, hi, gb = 6, None, 1.0, 1.3, 0.4
    a = theory.min_decay_rate(M, lo, hi)
    w = np.random.default_rng(0).standard_normal((M + M - 1, 2)) * 0.1
    assert theory.lemma5_bound(0.7, w, 0.0, M, M, a, lo, hi, gb, 2.0, 3.0, 1.0, 1.5) == pytest.approx(
        theory.lemma2_bound(0.7, w, M, M, a, lo, hi, gb))
    e = float(np.sum(w[:M] ** 2))
    assert theory.lemma4_bound(0.7, e, 0.0, M, lo, hi, gb, 2.0, 3.0, 1.0, 1.5) == pytest.approx(
        theory.Gamma_V(M, lo, hi) * 0.7 + theory.Gamma_V_gamma(M, lo, hi, gb) * e)
    # the θ-term is linear in ‖θ̂ - θ‖ with slope Γ^θ_V (Lemma 4) and M_θ (Lemma 5)
    d4 = theory.lemma4_bound(0.7, e, 0.3, M, lo, hi, gb, 2.0, 3.0, 1.0, 1.5) - \
        theory.lemma4_bound(0.7, e, 0.0, M, lo, hi, gb, 2.0, 3.0, 1.0, 1.5)
    assert d4 == pytest.approx(0.3 * theory.Gamma_V_theta(M, lo, hi, 2.0, 3.0, 1.0, 1.5))


def test_M_theta_runs_from_alpha_V_to_c_over_one_minus_a():
    a, c, aV = 0.8, 2.0, 5.0
    assert theory.lemma5_M_theta(0, a, c, aV) == pytest.approx(aV)
    assert theory.lemma5_M_theta(400, a, c, aV) == pytest.approx(c / (1 - a))


def test_theorem2_bound_grows_like_T_times_the_error_and_is_theorem1_without_it():
    M, lo, hi, gb = 5, 1.0, 1.2, 0.3
    a = theory.min_decay_rate(M, lo, hi)
    gc = theory.gamma_c(M, a, lo, hi, gb)
    w = np.random.default_rng(1).uniform(-0.3, 0.3, (400 + M, 1))
    costs = np.full(20, 0.5)
    args = (M, a, lo, hi, gb, gc, 1.0, 2.0, 1.0, 1.1)
    b0 = theory.theorem2_constant(costs, w, 0.4, 0.0, 400, 20, *args)
    assert b0.model_error == 0.0
    assert b0.known == pytest.approx(theory.theorem1_constant(0.4, w[20:], 380, M, a, lo, hi, gb, gc))
    assert b0.estimation == pytest.approx(costs.sum() - gc * np.sum(w[:20] ** 2))
    b1 = theory.theorem2_constant(costs, w, 0.4, 0.1, 400, 20, *args)
    b2 = theory.theorem2_constant(costs, w[:200 + M], 0.4, 0.1, 200, 20, *args)
    c = theory.lemma5_c(M, a, lo, hi, 1.0, 2.0, 1.0, 1.1)
    slope = (b1.model_error - b2.model_error) / 200
    assert slope == pytest.approx(0.1 * c / (1 - a), rel=1e-6)     # O((T - N) g(N))


# -- Lemma 3's constants ------------------------------------------------------------------------------
@pytest.mark.parametrize("seed", range(3))
def test_the_casadi_recursion_is_the_lq_value_matrix_and_law(seed):
    from conftest import random_lq_problem

    system, cost = random_lq_problem(np.random.default_rng(seed))
    M = 6
    H, G = certify.lq_value_matrices(system, cost, M)
    law = LQPreviewLaw(system.A, system.B, cost.Q, cost.R, M)
    scale = np.abs(law.H).max()
    np.testing.assert_allclose(H, law.H, atol=1e-10 * scale)
    np.testing.assert_allclose(G, np.hstack([law.K, law.L]), atol=1e-10 * max(1.0, np.abs(law.L).max()))


def test_lq_lipschitz_bounds_the_change_of_value_and_input_on_the_region():
    system = orrc.LinearSystem([[0.5, 0.2], [0.0, 0.7]], [[1.0], [0.5]])
    cost = orrc.QuadraticCost(np.eye(2), [[0.1]])
    M, radius, rho = 5, 0.05, 1.0
    L = certify.lq_lipschitz(system, cost, M, radius=radius, rho=rho, grid=3)
    assert not L.estimate and "grid" in L.method
    assert L.local_V <= L.alpha_V and L.local_kappa <= L.alpha_kappa
    rng = np.random.default_rng(0)
    H0, G0 = certify.lq_value_matrices(system, cost, M)
    worst_V = worst_k = 0.0
    for _ in range(300):
        th = L.theta + radius * rng.uniform(-1, 1, L.theta.size)
        H1, G1 = certify.lq_value_matrices(system, cost, M, th)
        z = rng.standard_normal(2 + 2 * M)
        z *= rho / np.linalg.norm(z)
        d = np.linalg.norm(th - L.theta)
        worst_V = max(worst_V, abs(z @ (H1 - H0) @ z) / d)
        worst_k = max(worst_k, np.linalg.norm((G1 - G0) @ z) / d)
    assert worst_V <= L.alpha_V and worst_k <= L.alpha_kappa
    # and a sampled estimate of the same constants stays below the grid maximum
    S = certify.sampled_lipschitz(orrc.ParametricSystem.linear(2, 1), cost, M, L.theta, radius, n_samples=30,
                                  x_radius=0.5 * rho, w_radius=0.5 * rho / np.sqrt(M), seed=1)
    assert S.estimate and S.alpha_V <= L.alpha_V and S.alpha_kappa <= L.alpha_kappa
    assert S.alpha_f_S == pytest.approx(np.linalg.norm(np.hstack([system.A, system.B]), 2), rel=0.05)


def test_lq_lipschitz_takes_each_grid_points_own_derivative():
    """α_V = ρ² max σ_max(∂vec H/∂θ) and α_κ = ρ max σ_max(∂vec G/∂θ), each Jacobian taken at one point of Θ:
    compared with central differences of lq_value_matrices point by point (the grid's Jacobians must not mix)."""
    system = orrc.LinearSystem([[0.5]], [[1.0]])
    cost = orrc.QuadraticCost([[1.0]], [[0.1]])
    M, radius, rho, h = 4, 0.2, 1.5, 1e-6
    L = certify.lq_lipschitz(system, cost, M, radius=radius, rho=rho, grid=5)
    sV, sK = [], []
    for th in L.info["points"]:
        cols = [[(a - b) / (2 * h) for a, b in zip(certify.lq_value_matrices(system, cost, M, th + h * e),
                                                     certify.lq_value_matrices(system, cost, M, th - h * e))]
                for e in np.eye(2)]
        sV.append(np.linalg.norm(np.c_[cols[0][0].ravel(), cols[1][0].ravel()], 2))
        sK.append(np.linalg.norm(np.c_[cols[0][1].ravel(), cols[1][1].ravel()], 2))
    np.testing.assert_allclose(L.info["sigma_H"], sV, rtol=1e-6)
    np.testing.assert_allclose(L.info["sigma_G"], sK, rtol=1e-6)
    assert L.alpha_V == pytest.approx(rho ** 2 * max(sV), rel=1e-6)
    assert L.alpha_kappa == pytest.approx(rho * max(sK), rel=1e-6)


def test_sampled_lipschitz_of_a_nonlinear_model_uses_one_nlp():
    from test_estimation import pendulum_model

    model = pendulum_model()
    cost = orrc.QuadraticCost(np.diag([10.0, 1.0]), [[0.1]])
    S = certify.sampled_lipschitz(model, cost, 8, [0.4, 2.5], 0.1, n_samples=8, x_radius=0.3, w_radius=0.01,
                                  input_bounds=(-5, 5), seed=0)
    assert S.estimate and S.alpha_V > 0 and S.alpha_kappa > 0 and S.info["failures"] == 0
    assert "estimate" in S.method and "not a certificate" in S.method


def test_theorem2_bound_for_many_horizons_at_once_is_the_bound_for_each():
    M, lo, hi, gb = 4, 1.0, 1.1, 0.2
    a = theory.min_decay_rate(M, lo, hi)
    gc = theory.gamma_c(M, a, lo, hi, gb)
    w = np.random.default_rng(2).uniform(-0.3, 0.3, (80 + M, 1))
    args = (np.full(10, 0.3), w, 0.2, 0.05)
    rest = (10, M, a, lo, hi, gb, gc, 1.0, 2.0, 1.0, 1.1)
    Ts = np.arange(11, 81)
    many = theory.theorem2_constant(*args, Ts, *rest)
    for i in (0, 17, len(Ts) - 1):
        one = theory.theorem2_constant(*args, int(Ts[i]), *rest)
        assert many.total[i] == pytest.approx(one.total, rel=1e-12)
        assert many.model_error[i] == pytest.approx(one.model_error, rel=1e-12)
