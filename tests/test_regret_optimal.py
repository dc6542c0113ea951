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
