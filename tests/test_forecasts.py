"""Forecasts of the disturbance (orrc.forecasts) and the controllers that use them
(orrc.controllers.forecast): the information pattern of Eq. (2) with a forecast in place of the
preview, each forecast model's error, robust preview RHC between Algorithms 1 and 3, and the
λ-confident policy."""
from __future__ import annotations

import itertools
import warnings

import casadi as ca
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


# ---------------------------------------------------------------- robust preview RHC, any system

def _pendulum():
    return orrc.examples.inverted_pendulum()


def _as_general_system(system):
    """The linear system x⁺ = A x + B u + w written as a general orrc.System (CasADi operations)."""
    A, B = system.A, system.B
    return orrc.NonlinearSystem(lambda x, u, w: ca.mtimes(A, x) + ca.mtimes(B, u) + w, system.n, system.m)


@pytest.mark.parametrize("seed", range(3))
def test_robust_preview_is_preview_rhc_on_the_forecast_when_the_error_set_is_zero_on_the_pendulum(seed):
    """E = {0}: the exchange's problem is Algorithm 1's on the forecast (no error to search): the
    same value and first input as PreviewRHC's own NLP solver, to the solvers' tolerances (both
    stop at 1e-8 or below on the optimality conditions of the same smooth problem)."""
    pend, M = _pendulum(), 8
    rng = np.random.default_rng(seed)
    x, W_hat = rng.uniform(-0.5, 0.5, 2), rng.uniform(-0.1, 0.1, (M, 2))
    robust = RobustPreviewRHC(pend.system, pend.cost, M, E=orrc.Box(0.0, 0.0, n=2), input_bounds=pend.input_bounds)
    assert robust.method == "exchange" and not robust.exact
    a = robust.plan(x, W_hat)
    b = orrc.PreviewRHC(pend.system, pend.cost, M, input_bounds=pend.input_bounds).plan(x, W_hat)
    assert a.success and a.gap <= 1e-6 * a.upper
    assert abs(a.value - b.value) < 1e-8 * max(1.0, abs(b.value))
    assert np.abs(a.inputs[0] - b.inputs[0]).max() < 1e-6 * max(1.0, np.abs(b.inputs).max())


@pytest.mark.parametrize("W", [orrc.Box(-0.05, 0.05, n=2), orrc.Ball(0.05, n=2)], ids=["box", "ball"])
def test_robust_preview_is_minmax_rhcs_exchange_plan_with_a_zero_forecast_and_e_equal_to_w(W):
    """A zero forecast and E = W: the same scenario exchange, with the same starts, as Algorithm 3's
    open-loop MinMaxRHC(method="exchange"), on the nonlinear pendulum."""
    pend, M = _pendulum(), 8
    x = np.array([0.3, -0.2])
    a = RobustPreviewRHC(pend.system, pend.cost, M, E=W, input_bounds=pend.input_bounds).plan(x, np.zeros((M, 2)))
    b = orrc.MinMaxRHC(pend.system, pend.cost, M, W, input_bounds=pend.input_bounds, method="exchange").plan(x)
    assert a.success and b.success
    assert abs(a.value - b.value) < 1e-8 * max(1.0, abs(b.value))
    assert np.abs(a.inputs - b.inputs).max() < 1e-8 * max(1.0, np.abs(b.inputs).max())
    assert np.abs(a.worst_w - b.worst_w).max() <= 1e-8 * 0.05


@pytest.mark.parametrize("seed", range(4))
def test_the_exchange_agrees_with_the_exact_lq_method_within_its_gap(seed):
    """A linear system given as a general System goes to the exchange; the same problem as an
    orrc.LinearSystem goes to the exact vertex epigraph. The exchange's outer problem is convex
    here, so its ``lower`` bounds the exact min-max value V from below; its value lies within its
    reported gap of V; and its plan's worst case over every vertex sequence of E (enumerated: the
    cost is convex in the errors) is at least V and is the worst case the local search found."""
    rng = np.random.default_rng(30 + seed)
    system, cost = random_lq_problem(rng)
    n, M = system.n, 4
    x, W_hat = rng.standard_normal(n), 0.1 * rng.standard_normal((M, n))
    E = orrc.Box(-0.2, 0.2, n=n)
    general = RobustPreviewRHC(_as_general_system(system), cost, M, E=E)
    exact = RobustPreviewRHC(system, cost, M, E=E)
    assert (general.method, general.exact, exact.method, exact.exact) == ("exchange", False, "exact", True)
    a, V = general.plan(x, W_hat), exact.plan(x, W_hat).value
    tol = 1e-9 * max(1.0, V)            # the two formulations round differently
    assert a.success and a.lower <= V + tol
    assert abs(a.value - V) <= a.gap + tol

    def J(U, errors):
        xj, total = x, 0.0
        for j in range(M):
            total += xj @ cost.Q @ xj + U[j] @ cost.R @ U[j]
            xj = system.A @ xj + system.B @ U[j] + W_hat[j] + errors[j]
        return total

    corners = [np.array(v) for v in itertools.product((-0.2, 0.2), repeat=n)]
    worst = max(J(a.inputs, list(seq) + [np.zeros(n)]) for seq in itertools.product(corners, repeat=M - 1))
    assert worst >= V - tol
    assert abs(worst - a.upper) <= tol


def test_a_closed_loop_with_a_zero_forecast_and_e_equal_to_w_is_algorithm_3s_on_time_varying_costs():
    """Step by step (warm starts shifted the same way, the previewed costs c_t..c_{t+M-1} passed as
    the exchange's parameters beside the forecast), the robust controller on the zero forecast with
    E = W applies Algorithm 3's inputs on the pendulum."""
    pend, M, T = _pendulum(), 6, 8
    W = orrc.Box(-0.05, 0.05, n=2)
    costs = pend.cost.scaled(1.0 + 0.5 * np.sin(np.arange(T + M)))
    w = W.sample(T, 3)
    robust = RobustPreviewRHC(pend.system, pend.cost, M, E=W, input_bounds=pend.input_bounds)
    a = orrc.simulate(pend.system, robust, pend.x0, w, T, costs=costs, forecast=Zero())
    b = orrc.simulate(pend.system, orrc.MinMaxRHC(pend.system, pend.cost, M, W, input_bounds=pend.input_bounds,
                                                  method="exchange"), pend.x0, w, T, costs=costs)
    assert a.success.all() and b.success.all()
    assert np.abs(a.u - b.u).max() <= 1e-8 * max(1.0, np.abs(b.u).max())
    plain = orrc.simulate(pend.system, robust, pend.x0, w, T, forecast=Zero())
    assert np.abs(plain.u - a.u).max() > 1e-3              # the previewed costs were used


def test_robust_preview_on_the_pendulum_never_reads_the_truth():
    """simulate's information pattern holds for the nonlinear path: the controller is handed the
    forecast (here a bias added to the truth), never the true window; its plans are those of a
    direct plan() call on the forecast windows the run recorded."""
    pend, M, T = _pendulum(), 6, 12
    w = orrc.disturbances.sinusoid(L=T + M, n=2, amplitude=0.05, period=40) * [0.0, 1.0]
    E = orrc.Box([0.0, -0.1], [0.0, 0.1])
    seen = []

    class Watching(RobustPreviewRHC):
        def control(self, obs):
            seen.append(np.array(obs.w_preview))
            return super().control(obs)

    ctl = Watching(pend.system, pend.cost, M, E=E, input_bounds=pend.input_bounds)
    traj = orrc.simulate(pend.system, ctl, pend.x0, w, T=T, forecast=Bias([0.0, 0.1]))
    assert traj.success.all() and traj.info["method"] == "exchange"
    for t, window in enumerate(seen):
        assert np.array_equal(window, traj.forecasts[t])
        assert np.allclose(window - w[t:t + M], [0.0, 0.1], rtol=0, atol=1e-15)  # never the truth itself
    cold = RobustPreviewRHC(pend.system, pend.cost, M, E=E, input_bounds=pend.input_bounds)
    first = cold.plan(pend.x0, traj.forecasts[0])
    assert np.array_equal(first.inputs[0], traj.u[0])
    assert np.all(traj.info["gap"] <= 1e-6 * traj.info["upper"] + 1e-10)


def test_a_nonlinear_robust_plan_hedges_for_more_cost_as_the_box_grows():
    pend, M = _pendulum(), 6
    W_hat = np.zeros((M, 2))
    values = [RobustPreviewRHC(pend.system, pend.cost, M, E=orrc.Box([0.0, -r], [0.0, r]),
                               input_bounds=pend.input_bounds).plan(pend.x0, W_hat).value for r in (0.0, 0.05, 0.2)]
    assert values[0] < values[1] < values[2]


def test_a_failed_exchange_is_reported_and_contained():
    """An exchange allowed one iteration does not close its gap: plan() warns once and returns the
    best plan found, marked. In closed loop a failed step (both rungs) applies the last good plan
    shifted by one, is marked, simulate warns once; failures in a row stop the run (SolverError)."""
    pend = _pendulum()
    short = RobustPreviewRHC(pend.system, pend.cost, 10, E=orrc.Ball(0.1, 2), input_bounds=pend.input_bounds,
                             exchange_options={"max_iter": 1})
    with pytest.warns(orrc.SolverWarning, match="min-max solve did not succeed") as record:
        p = short.plan(np.zeros(2), np.zeros((10, 2)))
    assert len(record) == 1
    assert not p.success and "no convergence" in p.status and p.fallback
    assert np.all(np.isfinite(p.inputs)) and p.lower <= p.upper

    M, T, E = 6, 6, orrc.Box([0.0, -0.1], [0.0, 0.1])
    w = orrc.disturbances.sinusoid(L=T + M, n=2, amplitude=0.05, period=40) * [0.0, 1.0]
    flaky = RobustPreviewRHC(pend.system, pend.cost, M, E=E, input_bounds=pend.input_bounds, max_failures=None)
    real = flaky._solver.solve

    def fail_at_step_2(*args):
        plan = real(*args)
        if len(flaky._log) == 2:
            plan.success, plan.status = False, "forced failure"
        return plan

    flaky._solver.solve = fail_at_step_2
    with pytest.warns(orrc.SolverWarning) as record:
        traj = orrc.simulate(pend.system, flaky, pend.x0, w, T, forecast=Bias([0.0, 0.1]))
    assert len([r for r in record if issubclass(r.category, orrc.SolverWarning)]) == 1
    assert list(traj.success) == [True, True, False, True, True, True]
    assert "forced failure" in traj.status[2] and np.isnan(traj.info["value"][2])
    np.testing.assert_array_equal(traj.u[2], flaky._log[1].inputs[1])      # the step-1 plan, shifted by one

    def forced(*args):
        plan = real(*args)
        plan.success, plan.status = False, "forced failure"
        return plan

    stubborn = RobustPreviewRHC(pend.system, pend.cost, M, E=E, input_bounds=pend.input_bounds)
    stubborn._solver.solve = forced
    with pytest.raises(orrc.SolverError, match="robust preview RHC.*3 consecutive"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        orrc.simulate(pend.system, stubborn, pend.x0, w, T, forecast=Bias([0.0, 0.1]))


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
