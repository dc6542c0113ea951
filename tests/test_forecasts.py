"""Forecasts of the disturbance (orrc.forecasts) and the controllers that use them
(orrc.controllers.forecast): the information pattern of Eq. (2) with a forecast in place of the
preview, each forecast model's error, robust preview RHC between Algorithms 1 and 3, and the
λ-confident policy."""
from __future__ import annotations

import numpy as np
import pytest

import orrc
from conftest import random_lq_problem
from orrc.controllers.base import Controller, Decision
from orrc.controllers.forecast import LambdaConfident, RobustPreviewRHC
from orrc.forecasts import AR, AdversarialError, Bias, Delay, Exact, Forecast, Noisy, Zero, forecast_errors

MODELS = [Exact(), Zero(), Noisy(0.1, growth=0.5, seed=1), Bias(0.05), Delay(2), AR(2), AdversarialError(0.1),
          Noisy(0.05, seed=2) + Bias(-0.02)]


@pytest.fixture
def di():
    ex = orrc.examples.double_integrator()
    w = orrc.disturbances.uniform_ball(L=80, n=2, radius=0.2, seed=0)
    return ex, w


class Spy(Controller):
    """Records every array it is handed; applies u = 0."""

    def __init__(self, M, n, m):
        self.preview_w, self.n, self.m = M, n, m
        self.name = "spy"
        self.seen = []

    def control(self, obs):
        self.seen.append((obs.t, obs.w_past, obs.w_preview))
        return Decision(u=np.zeros(self.m))


# ---------------------------------------------------------------- the information pattern

def test_an_exact_forecast_is_algorithm_1s_preview(di):
    ex, w = di
    rhc = orrc.PreviewRHC(ex.system, ex.cost, M=6)
    a = orrc.simulate(ex.system, rhc, ex.x0, w, T=60)
    b = orrc.simulate(ex.system, rhc, ex.x0, w, T=60, forecast=Exact())
    scale = np.abs(a.x).max()
    assert np.allclose(a.x, b.x, rtol=0, atol=1e-12 * scale) and np.allclose(a.u, b.u, rtol=0, atol=1e-12 * scale)
    assert a.forecasts is None and b.forecasts.shape == (60, 6, 2)


@pytest.mark.parametrize("model", MODELS, ids=lambda m: m.name)
def test_the_controller_sees_the_forecast_and_never_the_future(di, model):
    """At step t the controller holds the model's window (a read-only copy) and the revealed
    w_{t-1}; no array it is handed at step t holds w_t, ..., w_{t+M-1} unless the model forecast
    them exactly."""
    ex, w = di
    M, T = 5, 40
    spy = Spy(M, 2, 1)
    traj = orrc.simulate(ex.system, spy, ex.x0, w, T=T, costs=ex.cost, forecast=model)
    for t, past, preview in spy.seen:
        assert np.array_equal(preview, traj.forecasts[t])
        assert not preview.flags.writeable and not np.shares_memory(preview, traj.w_all)
        if t > 0:
            assert np.array_equal(past, w[t - 1])
        else:
            assert past is None
    truth = np.stack([traj.w_all[t:t + M] for t in range(T)])
    exact = np.isclose(traj.forecasts, truth, rtol=0, atol=0).all(axis=2)
    if isinstance(model, Exact):
        assert exact.all()
    elif isinstance(model, (Noisy, AdversarialError, Bias, Zero)) or model.name.startswith("noisy"):
        assert not exact.any(), f"{model.name}: a forecast equals the truth it was not given"


def test_a_learned_forecaster_does_not_read_the_truth(di):
    """AR's forecast at step t is the same whatever the future holds."""
    ex, w = di
    other = w.copy()
    other[30:] = -other[30:] + 0.05
    spy_a, spy_b = Spy(4, 2, 1), Spy(4, 2, 1)
    a = orrc.simulate(ex.system, spy_a, ex.x0, w, T=40, costs=ex.cost, forecast=AR(2))
    b = orrc.simulate(ex.system, spy_b, ex.x0, other, T=40, costs=ex.cost, forecast=AR(2))
    assert np.array_equal(a.forecasts[:31], b.forecasts[:31])   # up to t = 30 the past is the same
    assert not np.array_equal(a.forecasts[31:], b.forecasts[31:])


# ---------------------------------------------------------------- the forecast models

def test_noisy_errors_grow_with_the_lead_as_specified():
    scale, g, M, T = 0.2, 1.0, 4, 4000
    model = Noisy(scale, growth=g, seed=5)
    e = np.stack([model.window(t, np.zeros((t, 1)), np.zeros((M, 1))) for t in range(T)])[..., 0]
    target = scale * (1 + g * np.arange(M))
    # the sample standard deviation of T normal draws is within 5/sqrt(2T) of s_j, relatively
    assert np.all(np.abs(e.std(axis=0) / target - 1) < 5 / np.sqrt(2 * T))


def test_noisy_errors_do_not_depend_on_the_horizon():
    model = Noisy(0.3, growth=0.2, seed=1)
    short = model.window(7, np.zeros((7, 2)), np.zeros((3, 2)))
    long = model.window(7, np.zeros((7, 2)), np.zeros((9, 2)))
    assert np.array_equal(short, long[:3])


def test_bias_delay_and_adversarial_errors(di):
    ex, w = di
    rhc = orrc.PreviewRHC(ex.system, ex.cost, M=4)
    e = forecast_errors(orrc.simulate(ex.system, rhc, ex.x0, w, T=30, forecast=Bias([0.1, -0.05])))
    assert np.allclose(e, [0.1, -0.05], rtol=0, atol=1e-15)
    traj = orrc.simulate(ex.system, rhc, ex.x0, w, T=30, forecast=Delay(3))
    for t in range(30):
        for j in range(4):
            k = t + j - 3
            assert np.array_equal(traj.forecasts[t, j], w[k] if k >= 0 else np.zeros(2))
    traj = orrc.simulate(ex.system, rhc, ex.x0, w, T=30, forecast=AdversarialError(0.1))
    err = forecast_errors(traj)
    truth = traj.forecasts - err
    assert np.allclose(np.abs(err), 0.1, rtol=0, atol=1e-15) and np.all(err * truth <= 0)
    traj = orrc.simulate(ex.system, rhc, ex.x0, w, T=30, forecast=AdversarialError(0.1, norm="2"))
    assert np.allclose(np.linalg.norm(forecast_errors(traj), axis=2), 0.1, rtol=1e-12)


def test_errors_of_composed_models_add():
    truth, past = np.full((3, 2), 0.4), np.zeros((5, 2))
    both = (Noisy(0.1, seed=4) + Bias(0.2)).window(5, past, truth)
    alone = Noisy(0.1, seed=4).window(5, past, truth)
    assert np.allclose(both - alone, 0.2, rtol=0, atol=1e-15)


def test_ar_learns_an_autoregressive_disturbance():
    """A noiseless AR(2) process is forecast exactly once enough of it is revealed."""
    Phi = np.array([[0.5, 0.1, -0.2, 0.0], [0.0, 0.3, 0.1, 0.2]])
    w = np.zeros((60, 2))
    w[0], w[1] = [1.0, -0.5], [0.3, 0.8]
    for k in range(2, 60):
        w[k] = Phi @ np.concatenate([w[k - 1], w[k - 2]])
    f = AR(order=2, ridge=0.0).window(40, w[:40], w[40:45])
    assert np.allclose(f, w[40:45], rtol=0, atol=1e-9 * np.abs(w[:40]).max())
    assert np.array_equal(AR(order=2).window(2, w[:2], w[2:5]), np.zeros((3, 2)))   # too few samples: no preview


# ---------------------------------------------------------------- robust preview RHC

@pytest.mark.parametrize("seed", range(4))
def test_robust_preview_is_algorithm_1_when_the_error_set_is_zero(seed):
    rng = np.random.default_rng(seed)
    system, cost = random_lq_problem(rng)
    M = 4
    robust = RobustPreviewRHC(system, cost, M, E=orrc.Box(0.0, 0.0, n=system.n))
    rhc = orrc.PreviewRHC(system, cost, M)
    x, W = rng.standard_normal(system.n), 0.3 * rng.standard_normal((M, system.n))
    a, b = robust.plan(x, W), rhc.plan(x, W)
    scale = max(1.0, abs(b.value))
    assert abs(a.value - b.value) < 1e-8 * scale
    assert np.abs(a.inputs - b.inputs).max() < 1e-8 * max(1.0, np.abs(b.inputs).max())


@pytest.mark.parametrize("seed", range(4))
def test_robust_preview_is_algorithm_3_when_the_forecast_is_zero_and_the_error_set_is_w(seed):
    rng = np.random.default_rng(10 + seed)
    system, cost = random_lq_problem(rng, n=2, m=1)
    M, W = 4, orrc.Box(-0.2, 0.3, n=2)
    robust = RobustPreviewRHC(system, cost, M, E=W)
    minmax = orrc.MinMaxRHC(system, cost, M, W=W)
    x = rng.standard_normal(2)
    a, b = robust.plan(x, np.zeros((M, 2))), minmax.plan(x)
    assert abs(a.value - b.value) < 1e-8 * max(1.0, abs(b.value))
    assert np.abs(a.inputs - b.inputs).max() < 1e-8 * max(1.0, np.abs(b.inputs).max())


@pytest.mark.parametrize("seed", range(3))
def test_robust_preview_over_a_polytope_is_the_worst_case_over_its_vertex_sequences(seed):
    """E a triangle: the plan's value is min_U max over the sequences of E's vertices of the cost,
    solved independently (cvxpy, every sequence an epigraph constraint, the condensed prediction);
    the box given as a polytope of its corners plans as the box."""
    import itertools

    import cvxpy as cp

    rng = np.random.default_rng(20 + seed)
    system, cost = random_lq_problem(rng, n=2, m=1)
    A, B, Q, R = system.A, system.B, cost.Q, cost.R
    M, n = 3, 2
    E = orrc.Polytope([[-0.2, -0.1], [0.3, 0.0], [0.0, 0.25]])
    x, W_hat = rng.standard_normal(n), 0.2 * rng.standard_normal((M, n))
    plan = RobustPreviewRHC(system, cost, M, E=E).plan(x, W_hat)

    U, s = cp.Variable(M), cp.Variable()
    worst = []
    for seq in itertools.product(E.vertices(), repeat=M - 1):   # e_{M-1} reaches only the uncosted x_M
        xj, J = x, 0
        for j in range(M):
            J = J + cp.quad_form(xj, Q) + R[0, 0] * cp.square(U[j])
            e = seq[j] if j < M - 1 else np.zeros(n)
            xj = A @ xj + B[:, 0] * U[j] + W_hat[j] + e
        worst.append(J <= s)
    ref = cp.Problem(cp.Minimize(s), worst)
    ref.solve(solver=cp.CLARABEL)
    assert abs(plan.value - ref.value) < 1e-6 * max(1.0, abs(ref.value))
    assert np.abs(plan.inputs[:, 0] - U.value).max() < 1e-4 * max(1.0, np.abs(U.value).max())

    box = orrc.Box([-0.2, -0.1], [0.3, 0.25])
    corners = orrc.Polytope([[a, b] for a in (-0.2, 0.3) for b in (-0.1, 0.25)])
    a, b = (RobustPreviewRHC(system, cost, M, E=S).plan(x, W_hat) for S in (box, corners))
    assert abs(a.value - b.value) < 1e-9 * max(1.0, abs(a.value))
    assert np.abs(a.inputs - b.inputs).max() < 1e-8 * max(1.0, np.abs(a.inputs).max())


def test_a_ball_of_errors_is_planned_for_through_the_box_around_it(di):
    """A ball has no vertices: the plan is the box's around it, an upper bound on the ball's min-max
    value, which lies above the value over the square inscribed in the ball (a polytope inside it)."""
    ex, _ = di
    r, M = 0.2, 4
    W_hat = 0.1 * np.ones((M, 2))
    ball = RobustPreviewRHC(ex.system, ex.cost, M, E=orrc.Ball(r, n=2))
    box = RobustPreviewRHC(ex.system, ex.cost, M, E=orrc.Box(-r, r, n=2))
    inner = RobustPreviewRHC(ex.system, ex.cost, M, E=orrc.Polytope(
        r / np.sqrt(2) * np.array([[1.0, 1.0], [1.0, -1.0], [-1.0, 1.0], [-1.0, -1.0]])))
    a, b, c = (ctl.plan(ex.x0, W_hat) for ctl in (ball, box, inner))
    assert not ball.exact and box.exact and inner.exact
    assert a.value == b.value and np.array_equal(a.inputs, b.inputs)
    assert c.value < a.value


def test_a_larger_error_set_plans_for_more_cost(di):
    ex, w = di
    values = [RobustPreviewRHC(ex.system, ex.cost, 4, E=orrc.Box(-r, r, n=2)).plan(ex.x0, 0.1 * np.ones((4, 2))).value
              for r in (0.0, 0.1, 0.3)]
    assert values[0] < values[1] < values[2]


def test_robust_preview_runs_in_closed_loop_on_a_forecast(di):
    ex, w = di
    ctl = RobustPreviewRHC(ex.system, ex.cost, 4, E=orrc.Box(-0.1, 0.1, n=2))
    traj = orrc.simulate(ex.system, ctl, ex.x0, w, T=25, forecast=Noisy(0.05, seed=3))
    assert traj.success.all() and np.isfinite(traj.costs).all() and traj.info["value"].shape == (25,)


# ---------------------------------------------------------------- the λ-confident policy

def test_lambda_one_is_algorithm_1_on_the_forecast_and_zero_ignores_it(di):
    ex, w = di
    rhc = orrc.PreviewRHC(ex.system, ex.cost, M=5)
    model = Noisy(0.1, seed=7)
    trust = orrc.simulate(ex.system, LambdaConfident(ex.system, ex.cost, 5, lam=1.0), ex.x0, w, T=50, forecast=model)
    ce = orrc.simulate(ex.system, rhc, ex.x0, w, T=50, forecast=model)
    assert np.abs(trust.u - ce.u).max() < 1e-12 * max(1.0, np.abs(ce.u).max())
    ignore = orrc.simulate(ex.system, LambdaConfident(ex.system, ex.cost, 5, lam=0.0), ex.x0, w, T=50, forecast=model)
    blind = orrc.simulate(ex.system, rhc, ex.x0, w, T=50, forecast=Zero())
    assert np.abs(ignore.u - blind.u).max() < 1e-12 * max(1.0, np.abs(blind.u).max())


def test_self_tuning_trusts_an_exact_forecast_and_distrusts_noise(di):
    ex, w = di
    exact = orrc.simulate(ex.system, LambdaConfident(ex.system, ex.cost, 5), ex.x0, w, T=60, forecast=Exact())
    assert np.allclose(exact.info["lam"][6:], 1.0, rtol=0, atol=1e-12) and exact.info["lam"][0] == 0.5
    noisy = orrc.simulate(ex.system, LambdaConfident(ex.system, ex.cost, 5), ex.x0, w, T=60, forecast=Noisy(1.0, seed=2))
    assert noisy.info["lam"][-1] < 0.5
