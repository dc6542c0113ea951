"""The estimation phase of Algorithm 2: excitation signals and the three estimators (orrc.estimation)."""
import casadi as ca
import numpy as np
import pytest

import orrc
from orrc import estimation as est


def rollout(system, x0, U, W):
    X = np.zeros((len(U) + 1, system.n))
    X[0] = x0
    for k in range(len(U)):
        X[k + 1] = system.step(X[k], U[k], W[k])
    return X


# -- excitation -----------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", est.excitation.KINDS)
def test_excitation_is_bounded_seeded_and_exciting(kind):
    u = est.excitation.make(kind, 200, 2, amplitude=0.7, seed=3)
    assert u.shape == (200, 2) and np.all(np.abs(u) <= 0.7 + 1e-15)
    np.testing.assert_array_equal(u, est.excitation.make(kind, 200, 2, amplitude=0.7, seed=3))
    assert not np.array_equal(u, est.excitation.make(kind, 200, 2, amplitude=0.7, seed=4))
    # persistently exciting of order 4 in each input: the Hankel matrix of lags 0..3 has full rank
    for i in range(2):
        Hk = np.column_stack([u[j:len(u) - 4 + j, i] for j in range(4)])
        assert np.linalg.matrix_rank(Hk) == 4


def test_prbs_is_binary_with_a_maximum_length_period():
    u = est.prbs(31, 1, amplitude=2.0, seed=0)[:, 0]     # one period of a 5-bit register: 2^5 - 1 = 31
    assert set(np.unique(u)) == {-2.0, 2.0}
    assert np.sum(u > 0) == 16                             # an m-sequence has 2^(b-1) ones per period
    # and its circular autocorrelation is two-valued: N at lag 0, -1 (in units of amplitude²) elsewhere
    corr = np.array([u @ np.roll(u, k) for k in range(31)]) / 4.0
    np.testing.assert_allclose(corr, [31.0] + [-1.0] * 30)
    held = est.prbs(40, 1, hold=4, seed=0)[:, 0]
    assert np.all(held.reshape(10, 4) == held.reshape(10, 4)[:, :1])


# -- least squares, linear ------------------------------------------------------------------------------
@pytest.mark.parametrize("seed", range(4))
def test_least_squares_recovers_A_B_exactly_from_the_first_exciting_steps(seed):
    rng = np.random.default_rng(seed)
    n, m = int(rng.integers(1, 4)), int(rng.integers(1, 3))
    A = rng.standard_normal((n, n))
    A *= 0.9 / max(abs(np.linalg.eigvals(A)))
    B = rng.standard_normal((n, m))
    system = orrc.LinearSystem(A, B)
    N = n + m                                         # the first persistently exciting steps
    U = est.gaussian(N, m, amplitude=1.0, seed=seed)
    W = orrc.disturbances.uniform_ball(N, n, 0.3, seed=seed)
    X = rollout(system, rng.standard_normal(n), U, W)
    e = est.least_squares_linear(X, U, W, true=system)
    assert e.rank == e.rank_needed == n + m and e.exciting
    # exact up to rounding: eps · cond([x_k; u_k]) · ‖[A B]‖, with a factor 100 of room
    tol = 100 * np.finfo(float).eps * e.condition * np.linalg.norm(np.hstack([A, B]))
    assert e.error <= max(tol, 1e-14) and tol < 1e-8
    np.testing.assert_allclose(e.A, A, atol=1e-8)
    np.testing.assert_allclose(e.B, B, atol=1e-8)
    assert e.residual < 1e-10


def test_without_w_the_error_decays_like_one_over_root_N():
    system = orrc.LinearSystem([[0.5, 0.2], [0.0, 0.7]], [[1.0], [0.5]])
    Ns = np.array([25, 50, 100, 200, 400, 800, 1600])
    errs = []
    for seed in range(20):
        U = est.prbs(Ns[-1], 1, seed=seed)
        W = orrc.disturbances.uniform_box(Ns[-1], 2, -0.5, 0.5, seed=100 + seed)
        X = rollout(system, np.zeros(2), U, W)
        errs.append([est.least_squares_linear(X[:N + 1], U[:N], None, true=system).error for N in Ns])
    slope = np.polyfit(np.log(Ns), np.log(np.mean(errs, axis=0)), 1)[0]
    assert -0.62 < slope < -0.38                         # g(N) = Θ(1/√N)
    e_with_w = est.least_squares_linear(X, U, W, true=system).error
    assert e_with_w < 1e-12                              # and with w the estimate is exact


def test_rank_deficient_data_raise_with_the_rank_found_and_needed_or_warn():
    system = orrc.LinearSystem(np.eye(2) * 0.5, [[1.0], [0.0]])
    U = np.ones((6, 1))                                   # constant input from rest: x stays on one line
    X = rollout(system, np.zeros(2), U, np.zeros((6, 2)))
    with pytest.raises(orrc.OrrcValueError, match=r"rank 2, and the rank needed is 3"):
        est.least_squares_linear(X, U, np.zeros((6, 2)))
    with pytest.warns(est.RankWarning, match="minimum-norm"):
        e = est.least_squares_linear(X, U, np.zeros((6, 2)), rank_deficient="warn")
    assert e.rank == 2 and not e.exciting


def test_several_experiments_are_pooled():
    system = orrc.LinearSystem([[0.9]], [[0.5]])
    parts = []
    for s in range(3):
        U = est.gaussian(2, 1, seed=s)      # each experiment alone is too short for nothing, together exact
        W = np.zeros((2, 1))
        parts.append((rollout(system, np.array([float(s)]), U, W), U, W))
    e = est.least_squares_linear([p[0] for p in parts], [p[1] for p in parts], [p[2] for p in parts], true=system)
    assert e.N == 6 and e.error < 1e-12


# -- least squares, linear in θ -----------------------------------------------------------------------
def pendulum_model(dt=0.05):
    """ω+ = ω + dt (-(g/l) sin φ - c ω + k u): the damping c and the inverse inertia k unknown."""
    def f(x, u, w, th):
        return ca.vertcat(x[0] + dt * x[1], x[1] + dt * (-9.81 * ca.sin(x[0]) - th[0] * x[1] + th[1] * u[0])) + w
    return orrc.ParametricSystem(f, 2, 1, 2, name="pendulum", param_names=["c", "k"])


def test_parametric_least_squares_is_exact_with_w_and_root_N_without():
    model = pendulum_model()
    theta = np.array([0.4, 2.5])
    true = model.at(theta)
    assert model.linear_in_theta
    U = est.prbs(300, 1, amplitude=1.0, seed=1)
    W = orrc.disturbances.uniform_box(300, 2, -0.02, 0.02, seed=2)
    X = rollout(true, np.array([0.3, 0.0]), U, W)
    e = est.least_squares_parametric(model, X[:4], U[:3], W[:3], true=theta)
    assert e.rank == 2 and e.error < 1e-9
    e_noisy = [est.least_squares_parametric(model, X[:N + 1], U[:N], None, true=theta).error for N in (30, 300)]
    assert e_noisy[1] < e_noisy[0] and e_noisy[1] > 1e-6


def test_parametric_least_squares_refuses_a_model_not_affine_in_theta():
    model = orrc.ParametricSystem(lambda x, u, w, th: x * th[0] ** 2 + u + w, 1, 1, 1)
    assert not model.linear_in_theta
    with pytest.raises(orrc.OrrcValueError, match="not affine in theta"):
        est.least_squares_parametric(model, np.zeros((3, 1)), np.zeros((2, 1)))


def test_linear_structure_and_parametric_least_squares_agree():
    system = orrc.examples.double_integrator().system
    model = orrc.ParametricSystem.linear(2, 1)
    U = est.prbs(10, 1, seed=0)
    W = orrc.disturbances.uniform_ball(10, 2, 0.1, seed=1)
    X = rollout(system, np.array([1.0, 0.0]), U, W)
    a = est.least_squares_linear(X, U, None)
    b = est.least_squares_parametric(model, X, U, None)
    np.testing.assert_allclose(a.theta, b.theta, atol=1e-10)
    np.testing.assert_allclose(model.unpack(a.theta)[0], a.A)


# -- EDMD -----------------------------------------------------------------------------------------------
def vdp_data(n_traj, length, seed):
    vdp = orrc.examples.van_der_pol().system
    rng = np.random.default_rng(seed)
    Xs, Us = [], []
    for i in range(n_traj):
        U = est.gaussian(length, 1, amplitude=2.0, seed=rng)
        Xs.append(rollout(vdp, rng.uniform(-2, 2, 2), U, np.zeros((length, 2))))
        Us.append(U)
    return vdp, Xs, Us


def test_edmd_predicts_van_der_pol_20_steps_ahead_better_than_the_linearisation():
    vdp, Xs, Us = vdp_data(10, 100, seed=0)
    model = est.edmd(Xs, Us, est.polynomial_dictionary(2, 3), ridge=1e-9)
    _, Xf, Uf = vdp_data(5, 60, seed=1)                   # fresh data
    lin = orrc.LinearSystem(*vdp.linearize())
    e_edmd = est.prediction_error(model, Xf, Uf, horizon=20)
    e_lin = est.prediction_error(lin, Xf, Uf, horizon=20)
    assert e_edmd < 0.5 * e_lin
    assert est.prediction_error(vdp, Xf, Uf, horizon=20) == pytest.approx(0.0, abs=1e-12)


def test_edmd_one_step_is_exact_when_the_dictionary_spans_the_dynamics():
    # x+ = x + dt(x2, mu x2 - mu x1² x2 - x1 + u): the state part is linear in (x, x1²x2, u)
    vdp, Xs, Us = vdp_data(4, 30, seed=2)
    model = est.edmd(Xs, Us, est.polynomial_dictionary(2, 3), ridge=0.0)
    x, u = np.array([0.7, -0.4]), np.array([0.3])
    np.testing.assert_allclose(model.predict(x, u[None])[1], vdp.step(x, u, np.zeros(2)), atol=1e-9)


def test_dictionaries_contain_the_state_and_refuse_one_without_it():
    d = est.polynomial_dictionary(2, 3)
    assert d.K == 9 and d.labels[:2] == ["x1", "x2"] and "x1^2 x2" in d.labels
    np.testing.assert_array_equal(d.C, np.eye(2, 9))
    r = est.rbf_dictionary(np.array([[0.0, 0.0], [1.0, 1.0]]), width=0.5)
    assert r.K == 4
    np.testing.assert_allclose(r(np.array([1.0, 1.0]))[3], 1.0)
    mixed = est.Dictionary(lambda x: ca.vertcat(x[0] + x[1], x[0] - x[1], x[0] ** 2), 2)
    np.testing.assert_allclose(mixed.C @ mixed(np.array([0.3, -0.8])), [0.3, -0.8], atol=1e-12)
    with pytest.raises(orrc.OrrcValueError, match="must contain the state"):
        est.Dictionary(lambda x: ca.vertcat(x[0] ** 2, x[1] ** 2), 2)


def test_edmd_disturbance_channel_is_learned_when_w_is_given():
    system = orrc.LinearSystem([[0.8]], [[1.0]])
    U = est.prbs(50, 1, seed=0)
    W = orrc.disturbances.uniform_box(50, 1, -0.3, 0.3, seed=1)
    X = rollout(system, np.zeros(1), U, W)
    model = est.edmd(X, U, est.polynomial_dictionary(1, 1), W=W, ridge=0.0)
    np.testing.assert_allclose([model.A[0, 0], model.B[0, 0], model.E[0, 0]], [0.8, 1.0, 1.0], atol=1e-10)
    np.testing.assert_allclose(model.predict(X[0], U, W), X, atol=1e-9)
