"""V_M for a whole run after the loop (Controller.values_batch): the same outputs as step by step.

The exact LQ path of PreviewRHC defers V_M(x_t, W_t) = z_tᵀ H z_t to one matrix product after the
run; every output of the Trajectory must be what the per-step computation gives, to 1e-12.
"""
import numpy as np
import pytest

import orrc
from orrc.controllers import Decision


class PerStep(orrc.PreviewRHC):
    """The LQ path as it was before the batch: control() at every step, u_t and V_M from one product
    per step (a subclass that overrides control() keeps it: no fast path)."""

    def control(self, obs):
        return super().control(obs)


def test_the_fast_path_is_the_controllers_own_step_and_a_subclass_keeps_its_control(two_masses):
    """PreviewRHC's exact LQ path offers fast_input (no Observation/Decision per step): the same
    trajectory as its control(); a subclass that overrides control() is called at every step."""
    ex, w = two_masses
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 10)
    assert rhc.fast_input is not None and rhc.fast_decision.value_deferred
    obs = orrc.Observation(0, ex.x0, None, w[:10], None)
    step = rhc.control(obs)  # a direct call (e.g. by a controller that wraps this one) reports V_M itself
    np.testing.assert_allclose(rhc.fast_input(ex.x0, w[:10]), step.u, rtol=1e-14, atol=1e-15)
    assert step.value == pytest.approx(rhc.values_batch(ex.x0[None], w[None, :10])[0], rel=1e-13)
    assert not step.value_deferred

    class Counting(orrc.PreviewRHC):
        calls = 0

        def control(self, obs):
            Counting.calls += 1
            return super().control(obs)

    sub = Counting(ex.system, ex.cost, 10)
    assert sub.fast_input is None
    _same(orrc.simulate(ex.system, sub, ex.x0, w, 30), orrc.simulate(ex.system, rhc, ex.x0, w, 30))
    assert Counting.calls == 30
    nlp = orrc.PreviewRHC(ex.system, ex.cost, 10, solver="nlp")
    assert nlp.fast_input is None  # its steps report solves


@pytest.fixture(scope="module")
def two_masses():
    ex = orrc.examples.two_mass_spring()
    w = orrc.disturbances.uniform_ball(260, 4, radius=0.05, seed=3)
    return ex, w


def _same(a, b):
    """Every output of two trajectories equal to 1e-12 (relative to each array's scale)."""
    for name in ("x", "u", "w", "w_all", "costs", "sigma", "values"):
        va, vb = getattr(a, name), getattr(b, name)
        np.testing.assert_allclose(va, vb, rtol=0, atol=1e-12 * max(1.0, np.abs(vb).max()), err_msg=name)
    for name in ("success", "value_valid", "iterations"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.status == b.status and a.fallback == b.fallback and a.solver == b.solver
    assert a.alpha_lo == b.alpha_lo and a.T == b.T


@pytest.mark.parametrize("M, preview_w", [(20, None), (20, 7), (1, None)])
def test_lq_path_values_after_the_loop_equal_the_per_step_values(two_masses, M, preview_w):
    ex, w = two_masses
    T = 200
    batch = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, M, preview_w=preview_w), ex.x0, w, T)
    step = orrc.simulate(ex.system, PerStep(ex.system, ex.cost, M, preview_w=preview_w), ex.x0, w, T)
    _same(batch, step)
    assert batch.solver_counts == {"lq": T} and batch.value_valid.all()
    # and each value is the quadratic form of its own (x_t, W_t), computed independently
    rhc = orrc.PreviewRHC(ex.system, ex.cost, M, preview_w=preview_w)
    k = rhc.preview_w
    for t in (0, 77, T - 1):
        W = np.zeros((M, 4))
        W[:k] = w[t:t + k]
        z = np.concatenate([batch.x[t], W.ravel()])
        assert batch.values[t] == pytest.approx(z @ rhc.law.H @ z, rel=1e-12)


def test_values_in_chunks_equal_one_product(two_masses):
    ex, w = two_masses
    law = orrc.PreviewRHC(ex.system, ex.cost, 10).law
    X = w[:100]
    windows = np.stack([w[t:t + 10] for t in range(100)])
    whole = law.values(X, windows)
    np.testing.assert_allclose(law.values(X, windows, chunk=7), whole, rtol=1e-14)
    np.testing.assert_allclose(whole, [law.value(X[t], windows[t]) for t in range(100)], rtol=1e-12)


def test_time_varying_costs_keep_their_per_step_values(two_masses):
    """With a cost sequence the LQ path solves each step's problem (Riccati with the previewed Q_t):
    nothing is deferred, and the values are those of the steps' own problems."""
    ex, w = two_masses
    seq = ex.cost.scaled(np.linspace(0.5, 2.0, 80))
    traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 10), ex.x0, w, 60, costs=seq)
    A, B, Q, R = ex.system.A, ex.system.B, ex.cost.Q, ex.cost.R
    for t in (0, 31):
        Qs = np.linspace(0.5, 2.0, 80)[t:t + 10, None, None] * Q
        V = orrc.solvers.lq.solve(A, B, Qs, [R] * 10, traj.x[t], w[t:t + 10])[2]
        assert traj.values[t] == pytest.approx(V, rel=1e-12)


class Deferring(orrc.Controller):
    """Defers V_M at odd steps (and reports it at even ones); records what values_batch was given."""

    name = "deferring"
    preview_w = 3
    cost = orrc.QuadraticCost([[1.0]], [[1.0]])

    def __init__(self):
        self.calls = []

    def control(self, obs):
        u = -0.5 * obs.x
        if obs.t % 2:
            return Decision(u=u, value_deferred=True)
        return Decision(u=u, value=float(obs.x @ obs.x + obs.w_preview.sum()))

    def values_batch(self, X, W_windows):
        self.calls.append((X.copy(), np.array(W_windows)))
        return (X ** 2).sum(axis=1) + W_windows.sum(axis=(1, 2))


def test_simulate_calls_values_batch_once_with_the_deferred_steps_states_and_windows():
    ctrl = Deferring()
    w = np.arange(12.0)[:, None]
    traj = orrc.simulate(orrc.LinearSystem([[0.9]], [[1.0]]), ctrl, [1.0], w, 9)
    assert len(ctrl.calls) == 1
    X, windows = ctrl.calls[0]
    np.testing.assert_array_equal(X[:, 0], traj.x[1:9:2, 0])
    np.testing.assert_array_equal(windows[:, :, 0], [w[t:t + 3, 0] for t in (1, 3, 5, 7)])
    np.testing.assert_allclose(traj.values, traj.x[:-1, 0] ** 2 + [w[t:t + 3, 0].sum() for t in range(9)])
    assert traj.value_valid.all()


class Affine(orrc.Controller):
    """A hand-written affine law u_t = −K x_t − L vec W_t offering the simulator's fast_affine path."""

    def __init__(self, K, L, preview_w, cost=None):
        self.K, self.L, self.preview_w, self.m, self.cost = K, L, preview_w, K.shape[0], cost
        self.fast_input = lambda x, W: -K @ x - L @ W.reshape(-1)
        self.fast_decision = Decision(u=None)
        self.fast_affine = (K, lambda windows: -windows.reshape(len(windows), -1) @ L.T)

    def control(self, obs):
        return Decision(u=-self.K @ obs.x - self.L @ obs.w_preview.reshape(-1))


def test_an_affine_law_gives_the_per_step_trajectory_on_linear_and_nonlinear_dynamics(two_masses):
    """fast_affine (the feed-forward of all steps in one product, then the closed loop) gives the
    per-step loop's x and u to 1e-12 of their scale, on a LinearSystem and on the same dynamics
    written as a NonlinearSystem (where each step calls f)."""
    ex, w = two_masses
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 6)
    K, L = rhc.law.K, rhc.law.L
    A, B = ex.system.A, ex.system.B
    nonlinear = orrc.NonlinearSystem(lambda x, u, w_: A @ x + B @ u + w_, 4, 1)
    for system in (ex.system, nonlinear):
        fast = orrc.simulate(system, Affine(K, L, 6, ex.cost), ex.x0, w, 80)
        per_step = orrc.simulate(system, PerStep(ex.system, ex.cost, 6), ex.x0, w, 80)
        for name in ("x", "u"):
            a, b = getattr(fast, name), getattr(per_step, name)
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * np.abs(b).max(), err_msg=f"{system.name}: {name}")


def test_the_batched_feedforward_reads_only_each_steps_own_window(two_masses):
    """The information pattern on the affine path: changing w_s changes no input before
    t = s − M_w + 1, the first step whose preview window holds w_s (as its last row, which moves only
    the plan's unweighted terminal state: the next step is the first to react)."""
    ex, w = two_masses
    M, s, T = 8, 50, 70
    rhc = orrc.PreviewRHC(ex.system, ex.cost, M)
    w2 = w.copy()
    w2[s] += 0.3
    a = orrc.simulate(ex.system, rhc, ex.x0, w, T)
    b = orrc.simulate(ex.system, rhc, ex.x0, w2, T)
    first = s - M + 1
    np.testing.assert_array_equal(a.u[:first], b.u[:first])
    assert np.abs(a.u[first + 1] - b.u[first + 1]).max() > 1e-6   # and a step that sees it reacts


@pytest.mark.parametrize("K, ff, words", [
    (np.zeros((2, 4)), lambda W: np.zeros((len(W), 1)), "(1, 4)"),
    (np.zeros((1, 4)), lambda W: np.zeros((len(W) - 1, 1)), "feed-forward of shape (30, 1)"),
])
def test_a_fast_affine_of_the_wrong_shape_is_refused_by_name(two_masses, K, ff, words):
    ex, w = two_masses
    ctrl = Affine(np.zeros((1, 4)), np.zeros((1, 12)), 3, ex.cost)
    ctrl.fast_affine = (K, ff)
    with pytest.raises(orrc.OrrcValueError, match="fast_affine") as err:
        orrc.simulate(ex.system, ctrl, ex.x0, w, 30)
    assert words in str(err.value)
