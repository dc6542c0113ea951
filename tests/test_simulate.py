"""The simulator enforces the paper's information pattern and records what happened."""
import numpy as np
import pytest

import orrc
from orrc.controllers import Controller, Decision


class Spy(Controller):
    """Records every observation it is given."""

    def __init__(self, m, preview_w, preview_c=0, cost=None):
        self.m, self.preview_w, self.preview_c, self.cost = m, preview_w, preview_c, cost
        self.seen = []

    def control(self, obs):
        self.seen.append(obs)
        return Decision(u=np.zeros(self.m))


def test_controller_sees_exactly_its_preview_and_zeros_past_the_data():
    ex = orrc.examples.double_integrator()
    T, M = 10, 3
    w = np.arange(2 * (T + 1), dtype=float).reshape(T + 1, 2)  # only one row of tail
    spy = Spy(1, M, cost=ex.cost)
    orrc.simulate(ex.system, spy, ex.x0, w, T)
    assert len(spy.seen) == T
    for t, obs in enumerate(spy.seen):
        assert obs.t == t and obs.w_preview.shape == (M, 2)
        for j in range(M):
            expect = w[t + j] if t + j < len(w) else np.zeros(2)
            np.testing.assert_array_equal(obs.w_preview[j], expect)
        assert obs.cost_params is None
        assert not obs.x.flags.writeable and not obs.w_preview.flags.writeable


def test_controller_without_preview_sees_no_disturbance():
    ex = orrc.examples.scalar_unstable()
    spy = Spy(1, 0, cost=ex.cost)
    orrc.simulate(ex.system, spy, ex.x0, np.ones((5, 1)), 5)
    assert all(o.w_preview.shape == (0, 1) for o in spy.seen)
    assert spy.seen[0].w_past is None and spy.seen[1].w_past[0] == 1.0


def test_cost_preview_is_the_window_of_the_sequence():
    ex = orrc.examples.scalar_unstable()
    seq = ex.cost.scaled(np.arange(1.0, 8.0))  # 7 costs, simulation needs more: last repeats
    spy = Spy(1, 2, preview_c=3, cost=ex.cost)
    orrc.simulate(ex.system, spy, ex.x0, np.zeros((8, 1)), 6, costs=seq)
    q = [o.cost_params[:, 0] for o in spy.seen]  # the Q entry of each previewed cost
    np.testing.assert_array_equal(q[0], [1, 2, 3])
    np.testing.assert_array_equal(q[5], [6, 7, 7])


def test_trajectory_obeys_the_dynamics_and_records_costs(rng):
    ex = orrc.examples.van_der_pol()
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 8, input_bounds=ex.input_bounds)
    w = 0.05 * rng.standard_normal((30, 2))
    traj = orrc.simulate(ex.system, rhc, ex.x0, w, 20)
    for t in range(20):
        np.testing.assert_allclose(traj.x[t + 1], ex.system.step(traj.x[t], traj.u[t], w[t]), atol=1e-12)
        assert traj.costs[t] == pytest.approx(ex.cost(traj.x[t], traj.u[t]))
    np.testing.assert_allclose(traj.sigma, np.sum(traj.x ** 2, axis=1))
    assert traj.values is not None and np.all(traj.values >= traj.costs - 1e-9)  # V_M >= c_t


def test_divergence_is_an_error_not_a_nan():
    sysm = orrc.LinearSystem([[1e200]], [[1.0]])
    with pytest.raises(FloatingPointError, match="diverged"):
        orrc.simulate(sysm, orrc.ZeroInput(1, orrc.QuadraticCost([[1]], [[1]])), [1.0], np.zeros((5, 1)), 5)


def test_rhc_beats_lqr_and_clairvoyant_beats_both(rng):
    ex = orrc.examples.two_mass_spring()
    T = 80
    w = orrc.disturbances.sinusoid(T + 20, 4, amplitude=0.2, period=15)
    clair = orrc.simulate(ex.system, orrc.Clairvoyant(ex.system, ex.cost, T), ex.x0, w, T)
    rhc = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 20), ex.x0, w, T)
    lqr = orrc.simulate(ex.system, orrc.LQR(ex.system, ex.cost), ex.x0, w, T)
    r_rhc, r_lqr = orrc.dynamic_regret(rhc, clair), orrc.dynamic_regret(lqr, clair)
    assert 0 <= r_rhc < r_lqr
    assert orrc.dynamic_regret(clair, clair) == 0.0


def test_clairvoyant_optimum_is_below_every_causal_controller_on_the_pendulum():
    """Regression: a cold start that rolled the unstable pendulum out with zero input left IPOPT
    in a poor local optimum over long horizons (hindsight 'optimum' ~20x the RHC's cost)."""
    ex = orrc.examples.inverted_pendulum(u_max=8.0)
    T = 150
    w = orrc.disturbances.bursts(T + 20, 2, magnitude=0.3, seed=0)
    clair = orrc.simulate(ex.system, orrc.Clairvoyant(ex.system, ex.cost, T, input_bounds=ex.input_bounds),
                          ex.x0, w, T)
    rhc = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 20, input_bounds=ex.input_bounds),
                        ex.x0, w, T)
    assert clair.n_failures == 0
    assert 0 <= orrc.dynamic_regret(rhc, clair) < 0.1 * clair.costs.sum()


def test_linearize_is_the_jacobian_of_f_and_lqr_uses_it():
    """NonlinearSystem.linearize: the Jacobians of f at (x, u, 0); LQR on a nonlinear system
    is the LQR of that local model."""
    dt, mu = 0.3, 1.0
    ex = orrc.examples.van_der_pol(dt=dt, mu=mu)
    A0, B0 = ex.system.linearize()
    np.testing.assert_allclose(A0, [[1, dt], [-dt, 1 + dt * mu]], rtol=0, atol=1e-15)
    np.testing.assert_allclose(B0, [[0], [dt]], rtol=0, atol=1e-15)
    x1, x2 = 0.5, 0.2
    A, _ = ex.system.linearize([x1, x2], [0.7])
    np.testing.assert_allclose(A, [[1, dt], [dt * (-2 * mu * x1 * x2 - 1), 1 + dt * mu * (1 - x1 ** 2)]],
                               rtol=0, atol=1e-15)
    K_nl = orrc.LQR(ex.system, ex.cost).K
    K_lin = orrc.LQR(orrc.LinearSystem(A0, B0), ex.cost).K
    np.testing.assert_allclose(K_nl, K_lin, rtol=1e-12)


def test_trajectory_info_holds_what_the_controller_recorded():
    class Counting(orrc.Controller):
        name = "counting"

        def __init__(self):
            self.cost = orrc.QuadraticCost([[1.0]], [[1.0]])
            self.steps = []

        def reset(self):
            self.steps = []

        def control(self, obs):
            self.steps.append(obs.t)
            return orrc.Decision(u=np.zeros(1))

        def record(self):
            return {"steps": np.array(self.steps)}

    sys1 = orrc.LinearSystem([[0.5]], [[1.0]])
    c = Counting()
    traj = orrc.simulate(sys1, c, [1.0], np.zeros((5, 1)), T=5)
    assert np.array_equal(traj.info["steps"], np.arange(5))
    traj2 = orrc.simulate(sys1, orrc.ZeroInput(1, c.cost), [1.0], np.zeros((5, 1)), T=5)
    assert traj2.info == {}


class _ReportsNaN(Controller):
    """Reports V_M = NaN at t = 2; at the other steps ``value`` (None: no value reported)."""

    name = "reports NaN"

    def __init__(self, value):
        self.cost, self.value = orrc.QuadraticCost([[1.0]], [[1.0]]), value

    def control(self, obs):
        return Decision(u=np.zeros(1), value=float("nan") if obs.t == 2 else self.value)


@pytest.mark.parametrize("other", [1.0, None], ids=["values-at-every-step", "values-at-some-steps"])
def test_a_controller_reporting_a_nan_value_is_marked_and_warned_about(other):
    sys1 = orrc.LinearSystem([[0.5]], [[1.0]])
    with pytest.warns(orrc.NonFiniteWarning, match=r"reported a non-finite V_M .* at 1 successful step \(t = 2\)"):
        traj = orrc.simulate(sys1, _ReportsNaN(other), [1.0], np.zeros((5, 1)), T=5)
    if other is None:
        assert traj.values is None  # no V_M at every step: nothing to mark, the warning says so
    else:
        assert np.isnan(traj.values[2]) and traj.value_valid.tolist() == [True, True, False, True, True]
