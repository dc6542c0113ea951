"""orrc.HInfinity: its level is the squared H∞ norm of its own closed loop (python-control), it is
optimal (no stabilising gain, and no preview controller with the same preview, does better), and
its guarantee Σc <= γΣ‖w‖² + x_0ᵀPx_0 holds along simulated trajectories."""
import numpy as np
import pytest

import orrc
from orrc import certify
from orrc.solvers import game
from conftest import random_lq_problem
from numerics import frequency_response_error, level_bracket_holds


def problem(seed, n=None, m=None):
    return random_lq_problem(np.random.default_rng(seed), n, m, rho_range=(0.3, 1.4))


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("preview", [0, 1, 3])
def test_hinf_gamma_is_the_squared_hinf_norm_of_its_closed_loop(seed, preview):
    s, c = problem(seed)
    h = orrc.HInfinity(s, c, preview=preview)
    lim = certify.worst_case_attenuation_limit(s, h)              # python-control's system_norm
    # γ* ∈ [gamma_opt − gamma_opt_error, gamma_opt] and γ* <= N <= h.gamma (tests/numerics.py)
    assert level_bracket_holds(h.gamma_opt, h.gamma_opt_error, lim.gamma, h.gamma, lim.closed_loop.A)
    assert 0 <= h.gamma_opt_error <= 1e-7 * h.gamma_opt              # the bisection's tol (1e-9) + a narrow band
    assert h.gamma == pytest.approx(h.gamma_opt * (1 + 1e-5), rel=1e-12)
    # below the bracket no level is accepted (the certificate cannot accept a level below γ*), with
    # a clear error naming the optimal level
    for g in (0.99 * h.gamma_opt, (h.gamma_opt - h.gamma_opt_error) * (1 - 1e-9)):
        with pytest.raises(orrc.OrrcValueError, match="is not above the optimal level"):
            orrc.HInfinity(s, c, gamma=g, preview=preview)


@pytest.mark.parametrize("seed", range(4))
def test_preview_helps_and_hinf_preview_is_the_best_causal_level_with_that_preview(seed):
    s, c = problem(seed)
    hs = [orrc.HInfinity(s, c, preview=k) for k in range(5)]
    # more preview never hurts, γ*_{k+1} <= γ*_k; with γ*_k ∈ [level_k − error_k, level_k]:
    # level_{k+1} − error_{k+1} <= γ*_{k+1} <= γ*_k <= level_k (from two steps on the levels can be
    # equal: the non-causal level, reached with finite preview, and then computed within error_k)
    assert all(b.gamma_opt - b.gamma_opt_error <= a.gamma_opt for a, b in zip(hs, hs[1:]))
    # Algorithm 1 with M = k sees the same k disturbances: its exact stationary level N is not below
    # γ*_k >= level_k − error_k, up to the rounding δ of the computed norm
    for k, ctrl in [(1, orrc.PreviewRHC(s, c, M=1)), (2, orrc.PreviewRHC(s, c, M=2)),
                    (4, orrc.PreviewRHC(s, c, M=4)), (0, orrc.LQR(s, c))]:
        lim = certify.worst_case_attenuation_limit(s, ctrl)
        delta = frequency_response_error(lim.closed_loop.A) if np.isfinite(lim.gamma) else 0.0
        assert lim.gamma * (1 + delta) >= hs[k].gamma_opt - hs[k].gamma_opt_error


def test_the_books_scalar_example_levels():
    """x⁺ = 2x + u + w, c = x² + u²: 5 without preview, 1 with one step (cancel w), 1/2 from two on."""
    ex = orrc.examples.scalar_unstable()
    for k, exact in [(0, 5.0), (1, 1.0), (2, 0.5), (6, 0.5)]:
        h = orrc.HInfinity(ex.system, ex.cost, preview=k)
        assert h.gamma_opt - h.gamma_opt_error <= exact <= h.gamma_opt     # the bracket holds the exact level
        assert h.gamma_opt_error <= 1e-8 * exact                           # and is narrow


@pytest.mark.parametrize("seed", range(3))
def test_hinf_guarantee_holds_along_trajectories(seed):
    s, c = problem(seed, n=2)
    k = 2
    h = orrc.HInfinity(s, c, gamma=None, preview=k)
    g = 1.2 * h.gamma_opt
    h2 = orrc.HInfinity(s, c, gamma=g, preview=k)
    rng = np.random.default_rng(seed)
    T = 80
    for w in (rng.standard_normal((T + k, 2)), orrc.disturbances.sinusoid(T + k, 2, period=9.0)):
        x0 = rng.standard_normal(2)
        tr = orrc.simulate(s, h2, x0, w, T)
        xi0 = np.concatenate([x0, w[:k].ravel()])        # the initial state of the augmented game
        bound = g * np.sum(w[k:T + k] ** 2) + xi0 @ h2.P @ xi0
        assert tr.costs.sum() <= bound * (1 + 1e-9)


def test_hinf_runs_on_the_linearised_pendulum_like_lqr():
    ex = orrc.examples.inverted_pendulum()
    h = orrc.HInfinity(ex.system, ex.cost)
    A, B = ex.system.linearize()
    # the same certified bisection (deterministic): the same level, and the controller 1e-5 above it
    assert h.linearized and h.gamma == game.optimal_game_level(A, B, ex.cost.Q, ex.cost.R) * (1 + 1e-5)
    w = orrc.disturbances.uniform_ball(60, 2, radius=0.01, seed=0)
    tr = orrc.simulate(ex.system, h, ex.x0 * 0.1, w, 60)
    assert np.all(np.isfinite(tr.x)) and np.abs(tr.x[-1]).max() < 0.1
