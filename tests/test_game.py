"""orrc.solvers.game: the game Riccati recursion is the saddle point of the M-step quadratic game,
its stationary solution is the H∞ controller, and the optimal level is python-control's squared
H∞ norm of the optimal closed loop, below which no stabilising gain goes."""
import control
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import orrc
from orrc.solvers import game
from conftest import random_lq_problem
from numerics import frequency_response_error, level_bracket_holds


def problem(seed, n=None, m=None):
    s, c = random_lq_problem(np.random.default_rng(seed), n, m, rho_range=(0.3, 1.4))
    return s.A, s.B, c.Q, c.R


def condensed_game(A, B, Q, R, gamma, M, x0, Pf):
    """The M-step game in condensed form: J(U, W) = zᵀHz + 2zᵀh + k with z = (U, W); its saddle
    point solves H z = −h (J strictly convex in U and strictly concave in W here)."""
    n, m = B.shape
    Phi = np.zeros(((M + 1) * n, n))
    Gu = np.zeros(((M + 1) * n, M * m))
    Gw = np.zeros(((M + 1) * n, M * n))
    for j in range(M + 1):
        Phi[j * n:(j + 1) * n] = np.linalg.matrix_power(A, j)
        for i in range(j):
            Aji = np.linalg.matrix_power(A, j - 1 - i)
            Gu[j * n:(j + 1) * n, i * m:(i + 1) * m] = Aji @ B
            Gw[j * n:(j + 1) * n, i * n:(i + 1) * n] = Aji
    Qb = np.zeros(((M + 1) * n, (M + 1) * n))
    Qb[:M * n, :M * n] = np.kron(np.eye(M), Q)
    Qb[M * n:, M * n:] = Pf
    G = np.hstack([Gu, Gw])
    H = G.T @ Qb @ G
    H[:M * m, :M * m] += np.kron(np.eye(M), R)
    H[M * m:, M * m:] -= gamma * np.eye(M * n)
    h = G.T @ Qb @ Phi @ x0
    k = x0 @ Phi.T @ Qb @ Phi @ x0
    return H, h, k, M * m


@pytest.mark.parametrize("seed", range(6))
def test_recursion_value_is_the_brute_force_saddle_point_of_the_condensed_game(seed):
    A, B, Q, R = problem(seed)
    n, m = B.shape
    rng = np.random.default_rng(50 + seed)
    M = int(rng.integers(2, 6))
    Pf = np.eye(n) * rng.uniform(0, 2)
    x0 = rng.standard_normal(n)
    # γ large enough for the open-loop game to be concave in W (then both saddle points exist)
    H0, _, _, mu = condensed_game(A, B, Q, R, 0.0, M, x0, Pf)
    gamma = 1.5 * np.linalg.eigvalsh(H0[mu:, mu:])[-1] + 0.1
    H, h, k, mu = condensed_game(A, B, Q, R, gamma, M, x0, Pf)
    assert np.linalg.eigvalsh(H[:mu, :mu])[0] > 0 and np.linalg.eigvalsh(H[mu:, mu:])[-1] < 0
    z = np.linalg.solve(H, -h)
    value = k - h @ np.linalg.solve(H, h)
    sol = game.finite_horizon_game(A, B, Q, R, gamma, M, Pf=Pf)
    assert sol.value(x0) == pytest.approx(value, rel=1e-9, abs=1e-12)
    assert len(sol.P) == M + 1 and len(sol.K) == M == len(sol.Kw)
    # the feedback saddle point replays the open-loop saddle trajectory
    U, W = z[:mu].reshape(M, m), z[mu:].reshape(M, n)
    x = x0.copy()
    for j in range(M):
        u, w = -sol.K[j] @ x, sol.Kw[j] @ x
        np.testing.assert_allclose(u, U[j], rtol=1e-7, atol=1e-9 * (1 + np.abs(U).max()))
        np.testing.assert_allclose(w, W[j], rtol=1e-7, atol=1e-9 * (1 + np.abs(W).max()))
        x = A @ x + B @ u + w


def test_finite_horizon_game_refuses_a_level_below_the_smallest_admissible_one():
    A, B, Q, R = problem(3)
    level = game.finite_game_level(A, B, Q, R, 6)
    game.finite_horizon_game(A, B, Q, R, level * (1 + 1e-6), 6)          # just above: a saddle point
    with pytest.raises(orrc.OrrcValueError, match=r"gamma = .* below the smallest admissible level") as err:
        game.finite_horizon_game(A, B, Q, R, 0.99 * level, 6)
    assert f"{level:.6g}" in str(err.value)


@pytest.mark.parametrize("seed", range(4))
def test_stationary_game_is_the_limit_of_the_finite_recursion(seed):
    A, B, Q, R = problem(seed)
    gamma = 1.3 * game.optimal_game_level(A, B, Q, R)
    st = game.stationary_game(A, B, Q, R, gamma)
    fin = game.finite_horizon_game(A, B, Q, R, gamma, 400)
    P = st.P[0]
    np.testing.assert_allclose(fin.P[0], P, rtol=1e-8, atol=1e-10 * np.abs(P).max())
    np.testing.assert_allclose(fin.K[0], st.K[0], rtol=1e-7, atol=1e-9 * (1 + np.abs(st.K[0]).max()))
    assert st.stationary and st.value(np.ones(A.shape[0])) == pytest.approx(np.ones(A.shape[0]) @ P @ np.ones(A.shape[0]))


def closed_loop_norm_sq(A, B, Q, R, K):
    """python-control's squared H∞ norm of x⁺ = (A − BK)x + w, z = [Q^½x; −R^½Kx] (inf if unstable)."""
    Acl = A - B @ K
    if np.max(np.abs(np.linalg.eigvals(Acl))) >= 1:
        return np.inf
    Qh, Rh = np.linalg.cholesky(Q).T, np.linalg.cholesky(R).T
    n = A.shape[0]
    C = np.vstack([Qh, -Rh @ K])
    # python-control 0.10.2's norm routine needs a square system: zero input columns keep the norm
    Bw = np.hstack([np.eye(n), np.zeros((n, C.shape[0] - n))])
    sys = control.ss(Acl, Bw, C, np.zeros((C.shape[0], C.shape[0])), dt=True)
    return float(control.system_norm(sys, p="inf", tol=1e-12)) ** 2


def sweep_norm_sq(A, B, Q, R, K):
    """The peak of the frequency response of the closed loop (a grid refined by a scalar search): a
    lower bound on the squared H∞ norm that does not miss narrow peaks."""
    from orrc.certify.attenuation import _peak_gain_sq

    C = np.vstack([np.linalg.cholesky(Q).T, -np.linalg.cholesky(R).T @ K])
    n = A.shape[0]
    return _peak_gain_sq(A - B @ K, np.eye(n), C, np.zeros((C.shape[0], n)), grid=400)


def norm_sq_lower_bound(A, B, Q, R, K):
    """The larger of python-control's norm (a bisection estimate, which can fall short of a sharp
    peak) and the refined sweep: both are lower bounds on the squared H∞ norm."""
    pc = closed_loop_norm_sq(A, B, Q, R, K)
    return pc if not np.isfinite(pc) else max(pc, sweep_norm_sq(A, B, Q, R, K))


@pytest.mark.parametrize("seed", range(3))
def test_optimal_level_is_the_squared_hinf_norm_and_no_stabilising_gain_goes_below(seed):
    from scipy import optimize

    A, B, Q, R = problem(seed)
    level, error = game.optimal_game_level(A, B, Q, R, with_error=True)
    gamma = level * (1 + 1e-5)
    K = game.stationary_game(A, B, Q, R, gamma).K[0]
    # γ* ∈ [level − error, level], γ* <= N <= γ for the H∞ controller at γ (tests/numerics.py)
    assert level_bracket_holds(level, error, norm_sq_lower_bound(A, B, Q, R, K), gamma, A - B @ K)
    # below the level's bracket the game ARE has no admissible solution
    for g in (level * (1 - 1e-3), (level - error) * (1 - 1e-9)):
        with pytest.raises(orrc.OrrcValueError, match="not above the optimal level"):
            game.stationary_game(A, B, Q, R, g)
    # no stabilising gain does better than γ* >= level − error: random gains around the optimum and
    # LQR's, and a local search; each norm is a computed lower bound, off by at most its rounding δ
    rng = np.random.default_rng(seed)
    K_lqr = control.dlqr(A, B, Q, R)[0]

    def not_below(Kr):
        N = norm_sq_lower_bound(A, B, Q, R, Kr)
        return not np.isfinite(N) or N * (1 + frequency_response_error(A - B @ Kr)) >= level - error

    for base in (K, K_lqr):
        for scale in (1e-3, 1e-2, 1e-1, 0.5):
            for _ in range(3):
                assert not_below(base + scale * (1 + np.abs(base).max()) * rng.standard_normal(base.shape))
    best = optimize.minimize(lambda k: min(closed_loop_norm_sq(A, B, Q, R, k.reshape(K.shape)), 1e12),
                             K_lqr.ravel(), method="Nelder-Mead", options={"maxiter": 60})
    assert not_below(best.x.reshape(K.shape))


def test_game_with_a_disturbance_matrix_matches_the_identity_case():
    A, B, Q, R = problem(1, n=2, m=1)
    # each level comes with its bracket [level − error, level] ∋ γ*: brackets of the same γ* intersect
    a, ea = game.optimal_game_level(A, B, Q, R, E=np.eye(2), with_error=True)
    b, eb = game.optimal_game_level(A, B, Q, R, with_error=True)
    assert a - ea <= b and b - eb <= a
    # a disturbance entering with gain 2 costs 4 times as much (γ is the squared gain)
    c, ec = game.optimal_game_level(A, B, Q, R, E=2 * np.eye(2), with_error=True)
    assert c - ec <= 4 * b and 4 * (b - eb) <= c


@settings(max_examples=12, deadline=None, derandomize=True)
@given(seed=st.integers(0, 2 ** 31 - 1), preview=st.integers(0, 3))
def test_level_bracket_is_certified_and_tight_against_the_closed_loop_norm(seed, preview):
    """The bracket [level − error, level] holds γ*, and is narrow: just above the level (by 1e-7, or twice
    the error) the game is certified, and the H∞ controller's closed-loop norm N, computed independently
    (a refined frequency sweep), lies in [level − error, γ]: a level too low by more than 1e-7 relative,
    or too high by more than N − γ* (a fraction of 1e-7 here), fails."""
    from orrc.certify.attenuation import _peak_gain_sq
    from orrc.controllers.hinf import preview_buffer_system

    A, B, Q, R = problem(seed)
    E = None
    if preview:
        A, B, Q, E = preview_buffer_system(A, B, Q, preview)
    level, error = game.optimal_game_level(A, B, Q, R, E=E, with_error=True)
    assert 0 <= error <= 1e-7 * level
    gamma = level * (1 + max(1e-7, 2 * error / level))
    sol = game.stationary_game(A, B, Q, R, gamma, E=E)
    assert sol.info["error"] < np.inf and sol.info["margin"] > 0
    K = sol.K[0]
    Acl = A - B @ K
    C = np.vstack([_sqrt_psd(Q), -np.linalg.cholesky(R).T @ K])            # z = [Q^½x; R^½u]
    Bw = np.eye(A.shape[0]) if E is None else E
    N = _peak_gain_sq(Acl, Bw, C, np.zeros((C.shape[0], Bw.shape[1])), grid=400)
    assert level_bracket_holds(level, error, N, gamma, Acl)


def _sqrt_psd(S):
    lam, V = np.linalg.eigh(0.5 * (S + S.T))
    return np.sqrt(np.clip(lam, 0.0, None))[:, None] * V.T
