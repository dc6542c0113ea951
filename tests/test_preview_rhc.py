"""Algorithm 1 (PreviewRHC) against independent computations."""
import casadi as ca
import control
import numpy as np
import pytest

import orrc
from conftest import FORCED_FAILURE, batch_optimum, random_lq
import numerics


@pytest.mark.parametrize("seed", range(6))
def test_lq_plan_is_the_exact_M_step_optimum(seed):
    rng = np.random.default_rng(seed)
    n, m, M = rng.integers(1, 4), rng.integers(1, 3), rng.integers(1, 8)
    A, B, Q, R = random_lq(rng, n, m)
    rhc = orrc.PreviewRHC(orrc.LinearSystem(A, B), orrc.QuadraticCost(Q, R), M)
    x, W = rng.standard_normal(n), rng.standard_normal((M, n))
    plan = rhc.plan(x, W)
    U_ref, V_ref, kappa = batch_optimum(A, B, Q, R, M, x, W, cond=True)
    assert rhc.solver == "lq"
    # two stable solutions of one problem agree to its conditioning: each input sequence is off by
    # about eps·κ(K)·‖U‖ (K the condensed Hessian; measured up to 36·eps·κ over 3000 draws), the
    # values by less (V is stationary in U). 16·(M·m)·eps·κ covers it for M·m >= 1 with room.
    tol = 16 * M * m * numerics.EPS * kappa
    np.testing.assert_allclose(plan.inputs, U_ref, rtol=0, atol=tol * np.abs(U_ref).max())
    assert plan.value == pytest.approx(V_ref, rel=tol)


def test_lq_value_is_the_quadratic_form_used_in_closed_loop(rng):
    A, B, Q, R = random_lq(rng, 3, 1)
    sysm, cost = orrc.LinearSystem(A, B), orrc.QuadraticCost(Q, R)
    rhc = orrc.PreviewRHC(sysm, cost, 6)
    w = rng.standard_normal((40, 3)) * 0.1
    traj = orrc.simulate(sysm, rhc, np.ones(3), w, 30)
    for t in (0, 7, 29):
        plan = rhc.plan(traj.x[t], w[t:t + 6])
        assert traj.values[t] == pytest.approx(plan.value, rel=1e-9)
        np.testing.assert_allclose(traj.u[t], plan.inputs[0], rtol=1e-9, atol=1e-12)


def test_preview_law_tends_to_the_lqr_gain_as_M_grows():
    ex = orrc.examples.double_integrator()
    K_lqr, _, _ = control.dlqr(ex.system.A, ex.system.B, ex.cost.Q, ex.cost.R)
    errors = []
    for M in (2, 5, 20, 80):
        law = orrc.PreviewRHC(ex.system, ex.cost, M).law
        errors.append(np.abs(law.K - K_lqr).max())
    assert errors[-1] < 1e-8
    assert all(a >= b - 1e-12 for a, b in zip(errors, errors[1:]))  # monotone approach


def test_pendulum_plan_matches_a_separately_built_casadi_optimum():
    ex = orrc.examples.inverted_pendulum()
    M = 15
    rhc = orrc.PreviewRHC(ex.system, ex.cost, M, input_bounds=ex.input_bounds)
    W = 0.05 * np.random.default_rng(3).standard_normal((M, 2))
    x0 = np.array([0.4, -0.3])
    plan = rhc.plan(x0, W)
    # independent: single shooting with casadi.Opti, written from the example's equations
    opti = ca.Opti()
    U = opti.variable(M)
    x = ca.DM(x0)
    J = 0
    dt = 0.05
    for j in range(M):
        J += 10 * x[0] ** 2 + x[1] ** 2 + 0.1 * U[j] ** 2
        x = ca.vertcat(x[0] + dt * x[1], x[1] + dt * (9.81 * ca.sin(x[0]) - 0.1 * x[1] + U[j])) + W[j]
    opti.minimize(J)
    opti.subject_to(opti.bounded(-20, U, 20))
    opti.solver("ipopt", {"print_time": False, "ipopt.print_level": 0, "ipopt.sb": "yes", "ipopt.tol": 1e-10})
    sol = opti.solve()
    assert plan.success and rhc.solver == "nlp"
    assert plan.value == pytest.approx(float(sol.value(J)), rel=1e-6)
    np.testing.assert_allclose(plan.inputs[:, 0], sol.value(U), atol=1e-4)


def test_input_bounds_are_respected_in_closed_loop():
    ex = orrc.examples.inverted_pendulum(u_max=3.0)
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds)
    traj = orrc.simulate(ex.system, rhc, np.array([0.3, 0.0]), np.zeros((40, 2)), 30)
    assert np.all(np.abs(traj.u) <= 3.0 + 1e-7)
    assert np.any(np.abs(traj.u) > 2.9)  # the bound is active at the start
    assert traj.n_failures == 0


def test_nlp_path_agrees_with_lq_path_on_a_linear_problem(rng):
    A, B, Q, R = random_lq(rng, 2, 1)
    sysm, cost = orrc.LinearSystem(A, B), orrc.QuadraticCost(Q, R)
    x, W = rng.standard_normal(2), rng.standard_normal((6, 2))
    p_lq = orrc.PreviewRHC(sysm, cost, 6).plan(x, W)
    p_nlp = orrc.PreviewRHC(sysm, cost, 6, solver="nlp").plan(x, W)
    assert p_nlp.value == pytest.approx(p_lq.value, rel=1e-7)


def test_time_varying_costs_reach_the_controller_through_its_preview_only(rng):
    A, B, Q, R = random_lq(rng, 2, 1)
    sysm, cost = orrc.LinearSystem(A, B), orrc.QuadraticCost(Q, R)
    T, M = 25, 4
    scales = 1 + rng.random(T + M)
    seq = cost.scaled(scales)
    w = 0.1 * rng.standard_normal((T + M, 2))
    rhc = orrc.PreviewRHC(sysm, cost, M)
    traj = orrc.simulate(sysm, rhc, np.ones(2), w, T, costs=seq)
    # the realised stage cost is c_t with the t-th scale
    for t in (0, 10, 24):
        x, u = traj.x[t], traj.u[t]
        assert traj.costs[t] == pytest.approx(scales[t] * x @ Q @ x + u @ R @ u)
        # and u_t is the optimum of the problem with c_t..c_{t+M-1}
        Qs = scales[t:t + M, None, None] * Q
        U, _, V = orrc.solvers.lq.solve(A, B, Qs, [R] * M, x, w[t:t + M])
        np.testing.assert_allclose(u, U[0], rtol=1e-9)
        assert traj.values[t] == pytest.approx(V)


def test_terminal_cost_extension_matches_infinite_horizon_lqr():
    ex = orrc.examples.double_integrator()
    _, S, _ = control.dlqr(ex.system.A, ex.system.B, ex.cost.Q, ex.cost.R)
    K, _, _ = control.dlqr(ex.system.A, ex.system.B, ex.cost.Q, ex.cost.R)
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 3, terminal_cost=S)
    np.testing.assert_allclose(rhc.law.K, K, atol=1e-9)  # the cost-to-go makes M = 3 exact


def test_state_bounds_extension_keeps_the_plan_inside():
    ex = orrc.examples.double_integrator()
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 15, state_bounds=([-np.inf, -0.3], [np.inf, 0.3]))
    plan = rhc.plan(np.array([1.0, 0.0]), np.zeros((15, 2)))
    assert plan.success and np.all(np.abs(plan.states[1:, 1]) <= 0.3 + 1e-7)
    free = orrc.PreviewRHC(ex.system, ex.cost, 15).plan(np.array([1.0, 0.0]), np.zeros((15, 2)))
    assert np.abs(free.states[:, 1]).max() > 0.3  # the constraint matters
    assert plan.value > free.value


def test_solver_failure_is_reported_warned_and_falls_back():
    """A failed direct plan() reports success=False with the status and warns once, naming what the
    plan holds. (The closed loop's failure policy: tests/test_solver_failures.py.)"""
    ex = orrc.examples.inverted_pendulum()
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 10, input_bounds=ex.input_bounds, solver_options=FORCED_FAILURE)
    with pytest.warns(orrc.SolverWarning, match="did not succeed.*the solver's last iterate"):
        plan = rhc.plan(np.array([0.5, 0.0]), np.zeros((10, 2)))
    assert not plan.success and "Maximum_Iterations" in plan.status
    assert plan.fallback == "the solver's last iterate"


def test_unknown_solver_option_is_a_clear_error():
    ex = orrc.examples.inverted_pendulum()
    with pytest.raises(ValueError, match=r"CasADi rejected .*'ipopt.no_such_option'"):
        orrc.PreviewRHC(ex.system, ex.cost, 5, input_bounds=ex.input_bounds,
                        solver_options={"ipopt.no_such_option": 1})


def test_nonconvex_time_varying_cost_in_casadi():
    """A non-convex, parametrised stage cost c_t(x, u) = p_t (1 - cos x1) + x2² + 0.1 u² (a pendulum
    energy-like cost) is optimised by the CasADi path; the plan is a local optimum that beats
    simple perturbations of itself."""
    ex = orrc.examples.inverted_pendulum()
    cost = orrc.Cost(lambda x, u, p: p[0] * (1 - ca.cos(x[0])) + x[1] ** 2 + 0.1 * u[0] ** 2,
                     n=2, m=1, n_params=1, default_params=[5.0], name="1 - cos")
    M = 10
    rhc = orrc.PreviewRHC(ex.system, cost, M, input_bounds=ex.input_bounds)
    params = np.linspace(2.0, 8.0, M)[:, None]
    x0, W = np.array([0.6, 0.0]), np.zeros((M, 2))
    plan = rhc.plan(x0, W, cost_params=params)

    def total(U):
        x, J = x0, 0.0
        for j in range(M):
            J += cost(x, U[j], params[j])
            x = ex.system.step(x, U[j], W[j])
        return J

    assert plan.success and total(plan.inputs) == pytest.approx(plan.value, rel=1e-8)
    rng = np.random.default_rng(0)
    for _ in range(20):
        U = np.clip(plan.inputs + 1e-3 * rng.standard_normal(plan.inputs.shape), -20, 20)
        assert total(U) >= plan.value - 1e-9
    # closed loop with a long enough horizon: the pendulum is brought upright (θ = 0 mod 2π,
    # both minima of the non-convex cost) and kept there
    rhc20 = orrc.PreviewRHC(ex.system, cost, 20, input_bounds=ex.input_bounds)
    seq = orrc.CostSequence(cost, 20 * np.linspace(1.0, 2.0, 80)[:, None])
    traj = orrc.simulate(ex.system, rhc20, x0, np.zeros((80, 2)), 60, costs=seq)
    assert traj.n_failures == 0
    assert 1 - np.cos(traj.x[-1, 0]) < 1e-6 and abs(traj.x[-1, 1]) < 1e-3
