"""Algorithm 2 (orrc.EstimateThenControl) in orrc.simulate: its two phases, what it reads, what it records."""
import casadi as ca
import numpy as np
import pytest

import orrc
from orrc import estimation as est
from test_estimation import pendulum_model


@pytest.fixture(scope="module")
def two_mass_run():
    ex = orrc.examples.two_mass_spring()
    M, N, T = 12, 10, 60
    model = orrc.ParametricSystem.linear(4, 1)
    w = orrc.disturbances.uniform_ball(T + M, 4, 0.05, seed=1)
    etc = orrc.EstimateThenControl(model, ex.cost, M, N, excitation=est.prbs(N, 1, seed=2),
                                   theta_true=model.pack(ex.system.A, ex.system.B))
    return ex, M, N, T, w, orrc.simulate(ex.system, etc, ex.x0, w, T)


def test_after_estimation_the_inputs_are_those_of_algorithm_1_on_the_true_system(two_mass_run):
    ex, M, N, T, w, traj = two_mass_run
    rhc = orrc.PreviewRHC(ex.system, ex.cost, M)
    assert traj.info["theta_error"] < 1e-12
    for t in range(N, T):
        u_true = rhc.plan(traj.x[t], traj.w_all[t:t + M]).inputs[0]
        np.testing.assert_allclose(traj.u[t], u_true, atol=1e-8, rtol=0)


def test_the_estimation_phase_applies_the_excitation_and_the_record_says_which_phase(two_mass_run):
    ex, M, N, T, w, traj = two_mass_run
    np.testing.assert_array_equal(traj.u[:N], est.prbs(N, 1, seed=2))
    assert list(traj.info["phase"]) == ["estimate"] * N + ["control"] * (T - N)
    assert np.all(np.isnan(traj.info["values"][:N])) and np.all(np.isfinite(traj.info["values"][N:]))
    assert traj.info["theta_hat"].shape == (20,) and traj.info["N"] == N


def test_theta_true_is_only_reported_the_inputs_do_not_depend_on_it(two_mass_run):
    ex, M, N, T, w, traj = two_mass_run
    model = orrc.ParametricSystem.linear(4, 1)
    for use_w in (True, False):
        kw = dict(excitation=est.prbs(N, 1, seed=2), use_w=use_w)
        with_t = orrc.simulate(ex.system, orrc.EstimateThenControl(model, ex.cost, M, N, **kw,
                                                                   theta_true=np.zeros(20)), ex.x0, w, T)
        without = orrc.simulate(ex.system, orrc.EstimateThenControl(model, ex.cost, M, N, **kw), ex.x0, w, T)
        np.testing.assert_array_equal(with_t.u, without.u)
        assert without.info["theta_error"] is None and with_t.info["theta_error"] > 0


def test_it_reads_only_its_observation_the_future_beyond_the_preview_does_not_matter(two_mass_run):
    ex, M, N, T, w, traj = two_mass_run
    model = orrc.ParametricSystem.linear(4, 1)
    t_cut = 30
    w2 = w.copy()
    w2[t_cut + M:] += 1.0                         # change the disturbances beyond the preview of t_cut
    traj2 = orrc.simulate(ex.system, orrc.EstimateThenControl(model, ex.cost, M, N, excitation=est.prbs(N, 1, seed=2)),
                          ex.x0, w2, T)
    np.testing.assert_array_equal(traj.u[:t_cut + 1], traj2.u[:t_cut + 1])


def test_the_estimator_gets_the_disturbances_the_controller_observed():
    seen = {}

    def spy(X, U, W):
        seen.update(X=X, U=U, W=W)
        return np.array([0.5, 1.0])

    system = orrc.LinearSystem([[0.5]], [[1.0]])
    model = orrc.ParametricSystem.linear(1, 1)
    w = orrc.disturbances.uniform_box(20, 1, -0.5, 0.5, seed=0)
    traj = orrc.simulate(system, orrc.EstimateThenControl(model, orrc.QuadraticCost([[1.0]], [[0.1]]), 3, 6,
                                                          estimator=spy), np.zeros(1), w, 15)
    np.testing.assert_array_equal(seen["X"], traj.x[:7])
    np.testing.assert_array_equal(seen["U"], traj.u[:6])
    np.testing.assert_array_equal(seen["W"], w[:6])


def pendulum_alg2():
    """Algorithm 2 on the pendulum with (d/m, 1/m) unknown: M = 10, N = 8, |u| <= 4 (the NLP path)."""
    model = pendulum_model()
    theta = np.array([0.4, 2.5])
    cost = orrc.QuadraticCost(np.diag([10.0, 1.0]), [[0.1]])
    etc = orrc.EstimateThenControl(model, cost, 10, 8, excitation=est.prbs(8, 1, seed=0), input_bounds=(-4, 4),
                                   theta_true=theta)
    return model, theta, cost, etc


def test_parametric_pendulum_estimate_enters_the_nlp_as_a_parameter_without_rebuilding_it():
    model, theta, cost, etc = pendulum_alg2()
    solvers_before = dict(etc._rhc._nlp._nlpsol)  # the CasADi solvers (SQP, IPOPT), built once
    w = orrc.disturbances.uniform_box(60, 2, -0.01, 0.01, seed=3)
    traj = orrc.simulate(model.at(theta), etc, np.array([0.5, 0.0]), w, 40)
    assert all(etc._rhc._nlp._nlpsol[k] is v for k, v in solvers_before.items())
    assert traj.info["theta_error"] < 1e-9 and traj.n_failures == 0
    rhc = orrc.PreviewRHC(model.at(theta), cost, 10, input_bounds=(-4, 4))
    for t in (8, 20, 39):
        np.testing.assert_allclose(traj.u[t], rhc.plan(traj.x[t], traj.w_all[t:t + 10]).inputs[0], atol=1e-5)
    assert np.abs(traj.x[-5:, 0]).max() < 0.05


def test_preview_rhc_on_the_edmd_model_keeps_van_der_pol_bounded():
    vdp = orrc.examples.van_der_pol()
    N, T, M = 200, 300, 15
    model = est.EDMD(est.polynomial_dictionary(2, 3), ridge=1e-8)
    etc = orrc.EstimateThenControl(model, vdp.cost, M, N, excitation=est.gaussian(N, 1, amplitude=2.0, seed=0))
    w = orrc.disturbances.uniform_ball(T + M, 2, 0.01, seed=1)
    traj = orrc.simulate(vdp.system, etc, vdp.x0, w, T)
    assert isinstance(etc._ctrl, orrc.LiftedRHC) and etc._ctrl.solver == "lq"   # the exact LQ path on z
    open_loop = orrc.simulate(vdp.system, orrc.ZeroInput(1, vdp.cost), vdp.x0, w, T)
    ctrl = np.linalg.norm(traj.x[N + 50:], axis=1)
    assert ctrl.max() < 0.2 < 1.0 < np.linalg.norm(open_loop.x[N + 50:], axis=1).max()   # the limit cycle is gone


def test_the_control_phase_is_public_one_nlp_on_the_casadi_path_built_at_n_on_the_lq_path():
    model, theta, cost, etc = pendulum_alg2()
    planner = etc.control_phase                 # built before any estimate, with θ̂ = theta0 = 0
    solver = planner.nlp.solver
    assert isinstance(planner, orrc.PreviewRHC) and planner.solver == "nlp" and np.all(planner.theta == 0)
    w = orrc.disturbances.uniform_box(40, 2, -0.01, 0.01, seed=3)
    orrc.simulate(model.at(theta), etc, np.array([0.5, 0.0]), w, 20)
    assert etc.control_phase is planner and planner.nlp.solver is solver
    np.testing.assert_allclose(planner.theta, theta, atol=1e-9)   # the estimate, set as a parameter
    lin = orrc.ParametricSystem.linear(1, 1)
    etc_lq = orrc.EstimateThenControl(lin, orrc.QuadraticCost([[1.0]], [[0.1]]), 3, 2)
    assert etc_lq.control_phase is None         # the exact LQ path is built from the estimate
    orrc.simulate(orrc.LinearSystem([[0.5]], [[1.0]]), etc_lq, np.zeros(1), np.zeros((10, 1)), 6)
    assert etc_lq.control_phase.solver == "lq" and etc_lq.control_phase.nlp is None


def test_l1_cost_uses_the_exact_qp_which_agrees_with_an_independent_solve():
    system = orrc.LinearSystem([[0.5, 0.1], [0.0, 0.8]], [[1.0, 0.0], [0.2, 1.0]])
    cost = orrc.L1Cost([1.0, 2.0], 0.1 * np.eye(2))
    M = 4
    rhc = orrc.PreviewRHC(system, cost, M, input_bounds=(-0.4, 0.4))
    assert rhc.solver == "qp"
    rng = np.random.default_rng(0)
    for _ in range(3):
        x, W = rng.uniform(-1, 1, 2), rng.uniform(-0.5, 0.5, (M, 2))
        plan = rhc.plan(x, W)
        # independent: casadi.Opti with slack variables written from the definition
        opti = ca.Opti()
        U = opti.variable(2, M)
        S = opti.variable(2, M)
        xk, J = ca.DM(x), 0
        for j in range(M):
            if j > 0:
                opti.subject_to(S[:, j] >= xk)
                opti.subject_to(S[:, j] >= -xk)
                J += ca.dot(ca.DM([1.0, 2.0]), S[:, j])
            J += 0.1 * ca.sumsqr(U[:, j])
            xk = ca.mtimes(ca.DM(system.A), xk) + ca.mtimes(ca.DM(system.B), U[:, j]) + ca.DM(W[j])
        opti.subject_to(opti.bounded(-0.4, ca.vec(U), 0.4))
        opti.minimize(J)
        opti.solver("ipopt", {"print_time": False}, {"print_level": 0, "sb": "yes", "tol": 1e-12})
        sol = opti.solve()
        np.testing.assert_allclose(plan.inputs, np.asarray(sol.value(U)).T, atol=1e-6)
        assert plan.value == pytest.approx(float(sol.value(J)) + 1.0 * abs(x[0]) + 2.0 * abs(x[1]), rel=1e-7)


def test_it_must_be_run_from_the_start():
    model = orrc.ParametricSystem.linear(1, 1)
    etc = orrc.EstimateThenControl(model, orrc.QuadraticCost([[1.0]], [[0.1]]), 3, 4)
    with pytest.raises(RuntimeError, match="from t = 0"):
        etc.control(orrc.Observation(2, np.zeros(1), np.zeros(1), np.zeros((3, 1)), None))
