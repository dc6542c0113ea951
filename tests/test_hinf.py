"""orrc.HInfinity: its level is the squared H∞ norm of its own closed loop (python-control), it is
optimal (no stabilising gain, and no preview controller with the same preview, does better), and
its guarantee Σc <= γΣ‖w‖² + x_0ᵀPx_0 holds along simulated trajectories."""
import numpy as np
import pytest

import orrc
from orrc import certify
from orrc.solvers import game
from conftest import random_lq_problem


def problem(seed, n=None, m=None):
    return random_lq_problem(np.random.default_rng(seed), n, m, rho_range=(0.3, 1.4))


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("preview", [0, 1, 3])
def test_hinf_gamma_is_the_squared_hinf_norm_of_its_closed_loop(seed, preview):
    s, c = problem(seed)
    h = orrc.HInfinity(s, c, preview=preview)
    norm_sq = certify.worst_case_attenuation_limit(s, h).gamma      # python-control's system_norm
    assert norm_sq == pytest.approx(h.gamma, rel=1e-4)
    assert h.gamma == pytest.approx(h.gamma_opt * (1 + 1e-5), rel=1e-12)
    # below the optimal level: a clear error naming it
    with pytest.raises(orrc.OrrcValueError, match="gamma"):
        orrc.HInfinity(s, c, gamma=0.99 * h.gamma_opt, preview=preview)


@pytest.mark.parametrize("seed", range(4))
def test_preview_helps_and_hinf_preview_is_the_best_causal_level_with_that_preview(seed):
    s, c = problem(seed)
    levels = [orrc.HInfinity(s, c, preview=k).gamma_opt for k in range(5)]
    assert all(b <= a * (1 + 1e-7) for a, b in zip(levels, levels[1:]))
    # Algorithm 1 with M = k sees the same k disturbances: its exact stationary level is not below
    for k in (1, 2, 4):
        rhc = orrc.PreviewRHC(s, c, M=k)
        assert certify.worst_case_attenuation_limit(s, rhc).gamma >= levels[k] * (1 - 1e-6)
    lqr = orrc.LQR(s, c)
    assert certify.worst_case_attenuation_limit(s, lqr).gamma >= levels[0] * (1 - 1e-6)


def test_the_books_scalar_example_levels():
    """x⁺ = 2x + u + w, c = x² + u²: 5 without preview, 1 with one step (cancel w), 1/2 from two on."""
    ex = orrc.examples.scalar_unstable()
    got = [orrc.HInfinity(ex.system, ex.cost, preview=k).gamma_opt for k in (0, 1, 2, 6)]
    np.testing.assert_allclose(got, [5.0, 1.0, 0.5, 0.5], rtol=1e-7)


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
    assert h.linearized and h.gamma == pytest.approx(game.optimal_game_level(A, B, ex.cost.Q, ex.cost.R) * (1 + 1e-5))
    w = orrc.disturbances.uniform_ball(60, 2, radius=0.01, seed=0)
    tr = orrc.simulate(ex.system, h, ex.x0 * 0.1, w, 60)
    assert np.all(np.isfinite(tr.x)) and np.abs(tr.x[-1]).max() < 0.1
