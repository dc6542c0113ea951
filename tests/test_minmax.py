"""Algorithm 3 (min-max RHC, Appendix D): orrc.MinMaxRHC and its solvers against brute force.

* the exact method's V_{W,M}(x) equals the min-max value computed here from scratch: every one
  of the 2^{nM} vertex sequences rolled out by this file's own code, and (small instances) the
  epigraph solved by SciPy's SLSQP, or (all instances up to n = 2, M = 6) orrc's plan certified
  optimal by weak duality (multipliers from NNLS on the sequences active at the plan);
* scenario exchange reaches the exact value within its tolerance with a small fraction of the
  vertex sequences (n = 2, M = 8), and on the pendulum its bounds meet within a documented
  number of iterations;
* the information pattern: no disturbance preview (preview_w = 0), causality in closed loop.
"""
import itertools
import warnings

import numpy as np
import pytest
from scipy.optimize import minimize, nnls

import orrc
from orrc.solvers.minmax import MinMaxPlan, VertexEpigraph
from conftest import random_lq_problem

# the documented bound on the pendulum (README, chapter 10, benchmarks/minmax.py)
PENDULUM_MAX_ITERATIONS = 5


def _problem(seed, n, m=1, rho=(0.5, 1.3)):
    rng = np.random.default_rng(seed)
    sysm, cost = random_lq_problem(rng, n=n, m=m, rho_range=rho)
    lo = -rng.uniform(0.1, 0.6, n)
    hi = rng.uniform(0.1, 0.6, n)
    x = rng.standard_normal(n) * rng.uniform(0.2, 2.0)
    return sysm, cost, lo, hi, x


def _rollout_cost(A, B, Q, R, x, U, Wseq):
    """Σ_{j<M} x_jᵀQx_j + u_jᵀRu_j along x_{j+1} = Ax_j + Bu_j + w_j; Wseq (M, n) or a batch (N, M, n)."""
    Wseq = np.asarray(Wseq, float)
    batch = Wseq.reshape((-1,) + Wseq.shape[-2:])
    xx = np.tile(np.asarray(x, float), (len(batch), 1))
    total = np.zeros(len(batch))
    for j in range(len(U)):
        total += np.einsum("si,ij,sj->s", xx, Q, xx) + U[j] @ R @ U[j]
        xx = xx @ A.T + B @ U[j] + batch[:, j]
    return total if Wseq.ndim == 3 else float(total[0])


def _all_vertex_sequences(lo, hi, M):
    verts = np.array(list(itertools.product(*zip(lo, hi))))
    return verts[np.array(list(itertools.product(range(len(verts)), repeat=M)))]      # (2^(nM), M, n)


def _quadratics(A, B, Q, R, M, x, Ws):
    """J(U, W_v) = UᵀHU + gᵥᵀU + kᵥ for every sequence, from rollouts (exact for a quadratic)."""
    m = B.shape[1]
    d = M * m
    E = np.eye(d).reshape(d, M, m)
    J = lambda U, W: _rollout_cost(A, B, Q, R, x, U, W)  # noqa: E731
    z = np.zeros_like(Ws[0])
    H = np.array([[0.5 * (J(E[i] + E[j], z) - J(E[i], z) - J(E[j], z) + J(0 * E[i], z)) for j in range(d)]
                  for i in range(d)])
    g = np.column_stack([0.5 * (J(E[i], Ws) - J(-E[i], Ws)) for i in range(d)])
    k = J(0 * E[0], Ws)
    return 0.5 * (H + H.T), g, k


def _slsqp_minmax(H, g, k, n):
    # sequences that differ only in w_{M-1} give bitwise identical (g_v, k_v) (x_M is not costed):
    # SLSQP fails on the duplicated constraints, so each distinct function is kept once
    gk = np.unique(np.column_stack([g, k]), axis=0)
    assert len(gk) == len(k) // 2 ** n
    g, k = gk[:, :-1], gk[:, -1]
    d = H.shape[0]
    z0 = np.zeros(d + 1)
    z0[-1] = k.max()
    cons = {"type": "ineq", "fun": lambda z: z[-1] - (z[:-1] @ H @ z[:-1] + g @ z[:-1] + k),
            "jac": lambda z: np.hstack([-(2 * H @ z[:-1])[None, :] - g, np.ones((len(k), 1))])}
    res = minimize(lambda z: z[-1], z0, jac=lambda z: np.r_[np.zeros(d), 1.0], constraints=[cons],
                   method="SLSQP", options={"ftol": 1e-11, "maxiter": 1000})
    assert res.success, res.message
    return float(res.x[-1])


def _certified_by_duality(H, g, k, U):
    """(upper, lower): upper = max_v J_v(U); lower = min_U' Σ λ_v J_v(U') for the NNLS multipliers of the
    sequences active at U (any λ in the simplex gives a lower bound on min_U max_v J_v)."""
    vals = np.einsum("i,ij,j->", U, H, U) + g @ U + k
    upper = float(vals.max())
    act = np.flatnonzero(vals >= upper - 1e-7 * max(1.0, abs(upper)))
    grads = 2 * H @ U + g[act]                                  # ∇J_v(U), rows
    Amat = np.vstack([grads.T, 1e3 * np.ones((1, len(act)))])
    lam, _ = nnls(Amat, np.r_[np.zeros(len(U)), 1e3])
    lam = lam / lam.sum()
    gb = lam @ g[act]
    lower = float(lam @ k[act] - 0.25 * gb @ np.linalg.solve(H, gb))
    return upper, lower


@pytest.mark.parametrize("seed, n, M", [(0, 1, 2), (1, 1, 4), (2, 1, 6), (3, 2, 2), (4, 2, 3), (5, 2, 4)])
def test_exact_value_equals_a_brute_force_slsqp_solve_over_all_vertex_sequences(seed, n, M):
    sysm, cost, lo, hi, x = _problem(seed, n)
    H, g, k = _quadratics(sysm.A, sysm.B, cost.Q, cost.R, M, x, _all_vertex_sequences(lo, hi, M))
    brute = _slsqp_minmax(H, g, k, n)
    value = orrc.MinMaxRHC(orrc.LinearSystem(sysm.A, sysm.B), orrc.QuadraticCost(cost.Q, cost.R), M,
                           orrc.Box(lo, hi)).plan(x).value
    assert value == pytest.approx(brute, rel=1e-5)


@pytest.mark.parametrize("seed, n, M", [(10, 1, 5), (11, 1, 6), (12, 2, 4), (13, 2, 5), (14, 2, 6), (15, 2, 6)])
def test_exact_plan_is_optimal_over_all_vertex_sequences_by_weak_duality(seed, n, M):
    sysm, cost, lo, hi, x = _problem(seed, n)
    Ws = _all_vertex_sequences(lo, hi, M)
    H, g, k = _quadratics(sysm.A, sysm.B, cost.Q, cost.R, M, x, Ws)
    plan = orrc.MinMaxRHC(orrc.LinearSystem(sysm.A, sysm.B), orrc.QuadraticCost(cost.Q, cost.R), M,
                          orrc.Box(lo, hi)).plan(x)
    upper, lower = _certified_by_duality(H, g, k, plan.inputs.reshape(-1))
    assert upper - lower <= 1e-8 * upper                  # the plan is the min-max optimum (to rounding)
    assert plan.value == pytest.approx(upper, rel=1e-5)
    assert plan.certified and plan.lower <= upper * (1 + 1e-9) and plan.upper >= lower * (1 - 1e-9)
    # the worst case it reports is a vertex sequence attaining the value
    assert _rollout_cost(sysm.A, sysm.B, cost.Q, cost.R, x, plan.inputs, plan.worst_w) == pytest.approx(upper, rel=1e-9)
    assert orrc.Box(lo, hi).contains(plan.worst_w) and plan.sequences == 2 ** (n * (M - 1))


def test_minmax_value_lies_between_max_min_and_the_nominal_plans_worst_case():
    sysm, cost, lo, hi, x = _problem(21, 2)
    M = 5
    rhc = orrc.PreviewRHC(sysm, cost, M)
    V = orrc.MinMaxRHC(sysm, cost, M, orrc.Box(lo, hi)).plan(x).value
    Ws = _all_vertex_sequences(lo, hi, M)
    max_min = max(rhc.plan(x, W).value for W in Ws)                # preview: the plan knows W
    U0 = rhc.plan(x, np.zeros((M, 2))).inputs                        # the nominal plan, played open loop
    nominal_worst = _rollout_cost(sysm.A, sysm.B, cost.Q, cost.R, x, U0, Ws).max()
    assert max_min <= V * (1 + 1e-9) and V <= nominal_worst * (1 + 1e-9)
    assert max_min < V                                               # the value of preview: strictly less here
    # W = {0}: the min-max problem is the nominal one
    V0 = orrc.MinMaxRHC(sysm, cost, M, orrc.Box(0.0, 0.0, 2)).plan(x).value
    assert V0 == pytest.approx(rhc.plan(x, np.zeros((M, 2))).value, rel=1e-9)


def test_exact_lower_bound_is_certified_by_weak_duality_for_any_multipliers():
    rng = np.random.default_rng(3)
    sysm, cost, lo, hi, x = _problem(30, 2)
    M = 4
    ve = VertexEpigraph(sysm, cost, M, orrc.Box(lo, hi), input_bounds=(np.array([-0.4]), np.array([0.3])))
    V = ve.solve(x).value
    H, Qb, QGu, E, DQ, kd = ve._prepare(None)
    c0 = ve.Phi @ x
    g0 = QGu.T @ c0
    U_nom = -np.linalg.solve(H, g0)
    nominal = float(c0 @ Qb @ c0 + g0 @ U_nom)
    beta = kd + 2 * DQ @ c0 + 2 * E @ U_nom
    lb, ub = ve.lbx[:-1] - U_nom, ve.ubx[:-1] - U_nom
    for _ in range(50):
        rows = rng.choice(ve.N, size=5, replace=False)
        d = nominal + ve._dual_bound(H, 2 * E[rows], beta[rows], rng.random(5), rng.standard_normal(M), lb, ub)
        assert d <= V * (1 + 1e-12)


@pytest.fixture(scope="module")
def lq8():
    sysm, cost, lo, hi, _ = _problem(40, 2, rho=(0.8, 1.2))
    return sysm, cost, orrc.Box(lo, hi)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_exchange_reaches_the_exact_value_with_a_hundredth_of_the_vertex_sequences(lq8, seed):
    sysm, cost, W = lq8
    M = 8
    x = np.random.default_rng(seed).standard_normal(2)
    exact = orrc.MinMaxRHC(sysm, cost, M, W, method="exact").plan(x)
    ex = orrc.MinMaxRHC(sysm, cost, M, W, method="exchange").plan(x)
    assert exact.certified and exact.gap <= 1e-8 * exact.value
    assert ex.success and ex.gap <= 1e-6 * abs(ex.upper) + 1e-10
    assert abs(ex.value - exact.value) <= 1e-6 * exact.value + 1e-10
    assert ex.scenarios <= 2 ** (2 * M) // 100                     # the bound: 1/100 of 2^{nM}
    assert ex.evaluations <= 2 ** (2 * M) // 100                   # even counting every sequence it tried
    assert exact.sequences == 2 ** (2 * (M - 1))


def test_exchange_on_a_ball_lies_between_the_inscribed_and_the_circumscribed_boxes():
    sysm, cost, _, _, x = _problem(50, 2)
    M, r = 4, 0.3
    inner = orrc.MinMaxRHC(sysm, cost, M, orrc.Box(-r / np.sqrt(2), r / np.sqrt(2), 2)).plan(x).value
    outer = orrc.MinMaxRHC(sysm, cost, M, orrc.Box(-r, r, 2)).plan(x).value
    ball = orrc.MinMaxRHC(sysm, cost, M, orrc.Ball(r, 2)).plan(x)
    assert ball.method == "exchange" and ball.success and not ball.certified
    assert inner * (1 - 1e-9) <= ball.value <= outer * (1 + 1e-9)
    assert np.all(np.linalg.norm(ball.worst_w, axis=1) <= r * (1 + 1e-9))


def test_exact_and_exchange_agree_with_input_bounds_and_respect_them():
    sysm, cost, lo, hi, x = _problem(60, 2)
    M, ub = 5, (np.array([-0.2]), np.array([0.25]))
    a = orrc.MinMaxRHC(sysm, cost, M, orrc.Box(lo, hi), input_bounds=ub, method="exact").plan(3 * x)
    b = orrc.MinMaxRHC(sysm, cost, M, orrc.Box(lo, hi), input_bounds=ub, method="exchange").plan(3 * x)
    assert a.value == pytest.approx(b.value, rel=2e-6)
    for p in (a, b):
        assert np.all(p.inputs >= -0.2 - 1e-9) and np.all(p.inputs <= 0.25 + 1e-9)
    free = orrc.MinMaxRHC(sysm, cost, M, orrc.Box(lo, hi)).plan(3 * x)
    assert free.value <= a.value * (1 + 1e-9)                        # bounds can only cost more


@pytest.fixture(scope="module")
def pendulum():
    return orrc.examples.inverted_pendulum()


@pytest.mark.parametrize("r, x0", [(0.02, (0.0, 0.0)), (0.02, (0.5, 0.0)), (0.1, (0.2, -0.3)), (0.2, (1.0, 0.0))])
def test_pendulum_exchange_bounds_meet_within_the_documented_iterations(pendulum, r, x0):
    rhc = orrc.MinMaxRHC(pendulum.system, pendulum.cost, 10, orrc.Box(-r, r, 2), input_bounds=pendulum.input_bounds)
    assert rhc.method == "exchange"
    p = rhc.plan(np.array(x0))
    assert p.success and p.status == "converged"
    assert p.gap <= 1e-6 * p.upper + 1e-10
    assert 1 <= p.iterations <= PENDULUM_MAX_ITERATIONS
    assert len(p.history) >= 1 and np.all(np.diff(p.history[:, 0]) >= -1e-12)      # lower bounds never fall
    # the worst case found is feasible and its cost is the value (an independent rollout)
    X, J = pendulum.x0 * 0 + np.array(x0), 0.0
    for u, w in zip(p.inputs, p.worst_w):
        J += pendulum.cost.value(X, u)
        X = pendulum.system.step(X, u, w)
    assert J == pytest.approx(p.value, rel=1e-9)
    assert orrc.Box(-r, r, 2).contains(p.worst_w) and np.all(np.abs(p.inputs) <= 20 + 1e-9)


def test_preview_w_is_zero_and_the_closed_loop_is_causal(pendulum):
    sysm, cost = pendulum.system, pendulum.cost
    W = orrc.Box(-0.05, 0.05, 2)
    seen = []

    class Spy(orrc.MinMaxRHC):
        def control(self, obs):
            seen.append(obs.w_preview.shape)
            return super().control(obs)

    rhc = Spy(sysm, cost, 6, W, input_bounds=pendulum.input_bounds)
    assert rhc.preview_w == 0 and rhc.preview_c == 6
    w1 = W.sample(12, 0)
    w2 = w1.copy()
    w2[6:] = W.sample(6, 1)                                          # a different future from t = 6 on
    t1 = orrc.simulate(sysm, rhc, pendulum.x0, w1, 10)
    assert all(s[0] == 0 for s in seen)
    t2 = orrc.simulate(sysm, rhc, pendulum.x0, w2, 10)
    np.testing.assert_array_equal(t1.u[:7], t2.u[:7])              # u_t depends on w_0..w_{t-1} only
    assert not np.array_equal(t1.u[7:], t2.u[7:])
    with pytest.raises(orrc.OrrcValueError, match="no disturbance preview"):
        rhc.control(orrc.Observation(0, pendulum.x0, None, np.zeros((6, 2)), None))


def test_closed_loop_records_bounds_and_worst_cases_per_step():
    ex = orrc.examples.scalar_unstable(A=1.2)
    W = orrc.Box(-0.3, 0.3)
    T, M = 15, 6
    rhc = orrc.MinMaxRHC(ex.system, ex.cost, M, W)
    traj = orrc.simulate(ex.system, rhc, ex.x0, W.sample(T, 2), T)
    info = traj.info
    assert info["method"] == "exact"
    for key in ("lower", "upper", "gap", "iterations", "scenarios", "evaluations", "certified"):
        assert info[key].shape == (T,), key
    assert info["worst_w"].shape == (T, M, 1) and W.contains(info["worst_w"].reshape(-1, 1))
    np.testing.assert_allclose(traj.values, info["upper"])
    assert np.all(info["gap"] <= 1e-9 * info["upper"]) and info["certified"].all()
    # the same run with scenario exchange: the same values within its tolerance
    ex_traj = orrc.simulate(ex.system, orrc.MinMaxRHC(ex.system, ex.cost, M, W, method="exchange"), ex.x0,
                            traj.w, T)
    np.testing.assert_allclose(ex_traj.values, traj.values, rtol=2e-6)
    np.testing.assert_allclose(ex_traj.u, traj.u, atol=1e-4 * np.abs(traj.u).max())


def test_time_varying_costs_reach_both_methods_alike():
    ex = orrc.examples.scalar_unstable(A=1.2)
    W = orrc.Box(-0.3, 0.3)
    T, M = 10, 5
    costs = ex.cost.scaled(1.0 + 0.5 * np.sin(np.arange(T + M)))
    trajs = [orrc.simulate(ex.system, orrc.MinMaxRHC(ex.system, ex.cost, M, W, method=m), ex.x0, W.sample(T, 3), T,
                           costs=costs) for m in ("exact", "exchange")]
    np.testing.assert_allclose(trajs[0].values, trajs[1].values, rtol=2e-6)
    plain = orrc.simulate(ex.system, orrc.MinMaxRHC(ex.system, ex.cost, M, W), ex.x0, W.sample(T, 3), T)
    assert not np.allclose(plain.values, trajs[0].values)          # the previewed costs were used


def test_a_solve_that_does_not_converge_is_reported_and_contained(pendulum):
    rhc = orrc.MinMaxRHC(pendulum.system, pendulum.cost, 10, orrc.Ball(0.1, 2), input_bounds=pendulum.input_bounds,
                         exchange_options={"max_iter": 1})
    with pytest.warns(orrc.SolverWarning, match="min-max solve did not succeed") as record:
        p = rhc.plan(np.zeros(2))
    assert len(record) == 1
    assert not p.success and "no convergence" in p.status and p.fallback
    assert np.all(np.isfinite(p.inputs)) and p.lower <= p.upper
    assert isinstance(p, MinMaxPlan)


def test_failed_steps_climb_the_failure_ladder_in_closed_loop(pendulum):
    """A step that fails from the warm start is retried cold; failed steps are marked, the shifted
    successful plan is applied, simulate warns once, and three failures in a row stop the run."""
    W = orrc.Ball(0.1, 2)
    good = orrc.MinMaxRHC(pendulum.system, pendulum.cost, 6, W, input_bounds=pendulum.input_bounds)
    w = W.sample(8, 0)
    ref = orrc.simulate(pendulum.system, good, pendulum.x0, w, 6)
    assert ref.success.all()
    flaky = orrc.MinMaxRHC(pendulum.system, pendulum.cost, 6, W, input_bounds=pendulum.input_bounds,
                           max_failures=None)
    real = flaky._solver.solve
    calls = {"n": 0}

    def fail_at_step_2(x, P, guess_U=None, scenarios=None):
        calls["n"] += 1
        p = real(x, P, guess_U, scenarios)
        if len(flaky._log) == 2:                                     # both rungs of step t = 2 fail
            p.success, p.status = False, "forced failure"
        return p

    flaky._solver.solve = fail_at_step_2
    with pytest.warns(orrc.SolverWarning) as record:
        traj = orrc.simulate(pendulum.system, flaky, pendulum.x0, w, 6)
    assert len([r for r in record if issubclass(r.category, orrc.SolverWarning)]) == 1
    assert list(traj.success) == [True, True, False, True, True, True]
    assert "forced failure" in traj.status[2]
    np.testing.assert_allclose(traj.u[2], flaky._log[1].inputs[1])     # the step-1 plan, shifted by one
    stubborn = orrc.MinMaxRHC(pendulum.system, pendulum.cost, 6, W, input_bounds=pendulum.input_bounds)
    stubborn._solver.solve = lambda *a, **k: _failed(real(*a, **k))
    with pytest.raises(orrc.SolverError, match="3 consecutive"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        orrc.simulate(pendulum.system, stubborn, pendulum.x0, w, 6)


def _failed(p):
    p.success, p.status = False, "forced failure"
    return p
