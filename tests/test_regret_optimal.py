"""The regret-optimal controller by its structure (``orrc.solvers.regret``) is the SDP's: the same
worst-case regret to 1e-6 relative, a strictly causal operator, and Arveson's distance as its value.
"""
import numpy as np
import pytest

import orrc
from orrc.solvers.condensed import condensed
from orrc.solvers.regret import arveson_distance, causal_factor, parrott_completion

from conftest import random_lq_problem


def problem(seed, n, m):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n)) * 1.2 / np.sqrt(n)   # often open-loop unstable
    B = rng.normal(size=(n, m))
    Q = np.diag(rng.uniform(0.5, 2.0, n))
    return orrc.LinearSystem(A, B), orrc.QuadraticCost(Q, np.eye(m) * rng.uniform(0.2, 2.0))


@pytest.mark.parametrize("seed, n, m, T", [(0, 1, 1, 10), (1, 2, 1, 10), (2, 3, 2, 6), (3, 2, 2, 8)])
def test_the_structured_method_reaches_the_sdp_optimum(seed, n, m, T):
    s, c = problem(seed, n, m)
    structured, sdp = orrc.RegretOptimal(s, c, T), orrc.RegretOptimal(s, c, T, method="sdp")
    assert structured.method == "structured" and sdp.method == "sdp"
    # the same optimal worst-case regret (the SDP's own tolerance is about 1e-8 relative)
    assert structured.regret == pytest.approx(sdp.regret, rel=1e-6)
    # and never above it: the structured optimum is exact up to its level slack (1e-10)
    assert structured.regret <= sdp.regret * (1 + 1e-7)
    assert structured.regret == pytest.approx(structured.value, rel=1e-8)


@pytest.mark.parametrize("seed", range(2))
def test_the_structured_operator_is_strictly_causal_and_plays_in_closed_loop(seed):
    s, c = problem(seed, 2, 1)
    T = 9
    ro = orrc.RegretOptimal(s, c, T)
    m, n = s.m, s.n
    for t in range(T):  # block (t, s) of Φ is zero for s >= t: u_t does not use w_t
        assert not ro.Phi[t * m:(t + 1) * m, t * n:].any()
    w = orrc.disturbances.uniform_ball(T, n, radius=1.0, seed=seed)
    traj = orrc.simulate(s, ro, np.zeros(n), w, T)
    clair = orrc.simulate(s, orrc.Clairvoyant(s, c, T), np.zeros(n), w, T)
    regret = traj.costs.sum() - clair.costs.sum()
    assert -1e-9 <= regret <= ro.regret * np.sum(w ** 2) * (1 + 1e-7) + 1e-9


def test_arveson_distance_is_the_largest_fixed_staircase_block_and_parrott_attains_it():
    s, c = problem(5, 2, 1)
    T = 7
    cond = condensed(s.A, s.B, c.Q, c.R, T, K=orrc.LQR(s, c).K)
    Delta = causal_factor(cond.S)
    assert np.allclose(np.tril(Delta), Delta) and np.allclose(Delta.T @ Delta, cond.S, rtol=1e-12, atol=1e-12)
    Z = Delta @ cond.Phi_star
    g = arveson_distance(Z, T, 1, 2)
    E = parrott_completion(Z, T, 1, 2, g * (1 + 1e-10))
    assert np.linalg.norm(E, 2) <= g * (1 + 1e-8)                 # the completion attains the distance
    for t in range(T):                                             # and leaves the fixed blocks alone
        assert np.array_equal(E[t:t + 1, 2 * t:], Z[t:t + 1, 2 * t:])
    with pytest.raises(orrc.OrrcValueError, match="below (the norm of the fixed block|Arveson's distance)"):
        parrott_completion(Z, T, 1, 2, 0.5 * g)


def test_random_problems_agree_with_the_sdp():
    s, c = random_lq_problem(np.random.default_rng(11), n=2, m=1)
    a, b = orrc.RegretOptimal(s, c, 10), orrc.RegretOptimal(s, c, 10, method="sdp")
    assert a.regret == pytest.approx(b.regret, rel=1e-6)


# --- the full-information pattern (u_t may use w_t), against an independent convex program ---------

def independent_regret_optimum(s, c, T, diagonal):
    """The finite-horizon regret-optimal value from scratch: u = Φ_u w with Φ_u block lower triangular
    (its diagonal free when ``diagonal``), x = G_u u + G_w w from x_0 = 0 (x_0..x_{T-1} and u_0..u_{T-1}
    costed), the clairvoyant u* = Φ* w, and min ‖H^½(Φ_u − Φ*)‖₂² solved by cvxpy with Clarabel."""
    import cvxpy as cp

    n, m = s.n, s.m
    Gu, Gw = np.zeros((T * n, T * m)), np.zeros((T * n, T * n))
    for j in range(1, T):
        for i in range(j):
            Ap = np.linalg.matrix_power(s.A, j - 1 - i)
            Gu[j * n:(j + 1) * n, i * m:(i + 1) * m] = Ap @ s.B
            Gw[j * n:(j + 1) * n, i * n:(i + 1) * n] = Ap
    Qb, Rb = np.kron(np.eye(T), c.Q), np.kron(np.eye(T), c.R)
    H = Gu.T @ Qb @ Gu + Rb
    Phi_star = -np.linalg.solve(H, Gu.T @ Qb @ Gw)
    H_half = np.linalg.cholesky(H).T                       # H_halfᵀ H_half = H
    mask = np.kron(np.tril(np.ones((T, T)), k=0 if diagonal else -1), np.ones((m, n)))
    V = cp.Variable((T * m, T * n))
    prob = cp.Problem(cp.Minimize(cp.sigma_max(H_half @ cp.multiply(mask, V) - H_half @ Phi_star)))
    prob.solve(solver="CLARABEL")
    assert prob.status == "optimal"
    return prob.value ** 2


@pytest.mark.parametrize("seed, n, m, T", [(0, 1, 1, 8), (1, 2, 1, 6), (3, 2, 2, 5)])
def test_both_patterns_reach_the_optimum_of_an_independent_program(seed, n, m, T):
    s, c = problem(seed, n, m)
    for causality, diagonal in (("strict", False), ("full-information", True)):
        ro = orrc.RegretOptimal(s, c, T, causality=causality)
        # Clarabel's tolerance (about 1e-8 relative on the norm) sets the comparison's
        assert ro.regret == pytest.approx(independent_regret_optimum(s, c, T, diagonal), rel=1e-5)
        assert ro.regret == pytest.approx(ro.value, rel=1e-8)


@pytest.mark.parametrize("seed", range(2))
def test_the_full_information_operator_uses_w_t_and_plays_its_regret_in_closed_loop(seed):
    s, c = problem(seed, 2, 1)
    T, m, n = 8, 1, 2
    full = orrc.RegretOptimal(s, c, T, causality="full-information")
    strict = orrc.RegretOptimal(s, c, T)
    assert full.preview_w == 1 and strict.preview_w == 0
    for t in range(T):   # block (t, s) is zero for s > t; the diagonal blocks are used
        assert not full.Phi[t * m:(t + 1) * m, (t + 1) * n:].any()
    assert np.abs(np.diagonal(full.Phi.reshape(T, m, T, n), axis1=0, axis2=2)).max() > 1e-6
    # more information cannot raise the optimal worst-case regret, and here it lowers it
    assert full.regret < strict.regret
    # the certificate of the closed loop (orrc.certify) sees the same worst case
    assert orrc.certify.worst_case_regret(s, full, T).regret == pytest.approx(full.regret, rel=1e-7)
    w = orrc.disturbances.uniform_ball(T, n, radius=1.0, seed=seed)
    traj = orrc.simulate(s, full, np.zeros(n), w, T)
    clair = orrc.simulate(s, orrc.Clairvoyant(s, c, T), np.zeros(n), w, T)
    regret = traj.costs.sum() - clair.costs.sum()
    assert -1e-9 <= regret <= full.regret * np.sum(w ** 2) * (1 + 1e-7) + 1e-9


def test_the_full_information_sdp_agrees_with_the_structured_method():
    s, c = problem(2, 2, 1)
    a = orrc.RegretOptimal(s, c, 8, causality="full-information")
    b = orrc.RegretOptimal(s, c, 8, method="sdp", causality="full-information")
    assert a.regret == pytest.approx(b.regret, rel=1e-6)


def test_an_unknown_causality_is_refused_with_the_allowed_values():
    s, c = problem(0, 1, 1)
    with pytest.raises(orrc.OrrcValueError, match="causality must be one of 'strict', 'full-information'"):
        orrc.RegretOptimal(s, c, 4, causality="noncausal")
