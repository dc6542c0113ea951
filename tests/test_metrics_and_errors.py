"""R^p_T(γ) and the error messages for bad input."""
import control
import numpy as np
import pytest

import orrc


@pytest.fixture
def traj():
    ex = orrc.examples.scalar_unstable()
    w = orrc.disturbances.uniform_ball(30, 1, 0.5, seed=0)
    return orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 4), ex.x0, w, 25)


def test_attenuation_regret_is_eq2(traj):
    gamma = 1.7
    manual = sum(traj.costs[t] - gamma * traj.w[t] @ traj.w[t] for t in range(traj.T))
    assert orrc.attenuation_regret(traj, gamma) == pytest.approx(manual)
    running = orrc.attenuation_regret(traj, gamma, cumulative=True)
    assert running.shape == (25,) and running[-1] == pytest.approx(manual)


def test_attenuation_ratio_is_the_break_even_gamma(traj):
    g = orrc.attenuation_ratio(traj)
    assert orrc.attenuation_regret(traj, g) == pytest.approx(0.0, abs=1e-9)
    assert orrc.attenuation_regret(traj, 1.01 * g) < 0 < orrc.attenuation_regret(traj, 0.99 * g)


def test_from_statespace():
    sysd = control.ss([[1.0, 0.1], [0, 1]], [[0], [0.1]], np.eye(2), np.zeros((2, 1)), 0.1)
    s = orrc.LinearSystem.from_statespace(sysd)
    assert s.n == 2 and s.m == 1
    with pytest.raises(ValueError, match="discrete-time"):
        orrc.LinearSystem.from_statespace(control.ss([[0.0]], [[1.0]], [[1.0]], [[0.0]]))


@pytest.mark.parametrize("call, match", [
    (lambda ex: orrc.PreviewRHC(ex.system, ex.cost, 0), r"M must be an integer >= 1; got 0"),
    (lambda ex: orrc.PreviewRHC(ex.system, ex.cost, 2.5), r"M must be an integer; got 2.5"),
    (lambda ex: orrc.PreviewRHC(ex.system, ex.cost, 3, solver="fast"), r"solver must be .*got 'fast'"),
    (lambda ex: orrc.PreviewRHC(ex.system, ex.cost, 3).plan([0, 0], np.zeros((2, 2))),
     r"w_preview must have shape \(M, n\) = \(3, 2\).*got shape \(2, 2\)"),
    (lambda ex: orrc.PreviewRHC(ex.system, ex.cost, 3).plan([0, np.nan], np.zeros((3, 2))), r"x must be finite"),
    (lambda ex: orrc.PreviewRHC(ex.system, ex.cost, 3).plan([0, 0, 0], np.zeros((3, 2))),
     r"x must have shape \(2\); got shape \(3,\)"),
    (lambda ex: orrc.PreviewRHC(ex.system, ex.cost, 3, input_bounds=(1, -1)), r"input_bounds needs lo <= hi"),
    (lambda ex: orrc.PreviewRHC(ex.system, orrc.QuadraticCost(np.eye(3), [[1]]), 3), r"n=3 states"),
    (lambda ex: orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 3), ex.x0, np.zeros((4, 2)), 5),
     r"w must have shape \(L, 2\) with L >= T = 5; got shape \(4, 2\)"),
    (lambda ex: orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 3), ex.x0, np.zeros((9, 2)), 0),
     r"T must be an integer >= 1; got 0"),
    (lambda ex: orrc.QuadraticCost(-np.eye(2), [[1]]), r"Q must be positive semidefinite"),
    (lambda ex: orrc.QuadraticCost(np.eye(2), [[0]]), r"R must be positive definite"),
    (lambda ex: orrc.LinearSystem(np.eye(2), np.ones((3, 1))), r"B must have shape \(2, m\)"),
    (lambda ex: orrc.NonlinearSystem(lambda x, u, w: x[0], 2, 1), r"vector of length n_states=2"),
    (lambda ex: orrc.disturbances.make("storm", 5, 2), r"unknown disturbance kind 'storm'; allowed"),
])
def test_bad_input_is_a_clear_value_error(call, match):
    ex = orrc.examples.double_integrator()
    with pytest.raises(ValueError, match=match):
        call(ex)


def test_negative_gamma_is_rejected(traj):
    with pytest.raises(ValueError, match=r"gamma must be >= 0.0; got -1.0"):
        orrc.attenuation_regret(traj, -1.0)


def test_attenuation_ratio_without_disturbance_is_an_error():
    ex = orrc.examples.scalar_unstable()
    traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 3), ex.x0, np.zeros((5, 1)), 5)
    with pytest.raises(ValueError, match="non-zero disturbance"):
        orrc.attenuation_ratio(traj)


def test_import_orrc_does_not_import_plotting():
    import subprocess
    import sys
    code = "import orrc, sys; print('matplotlib' in sys.modules, 'ipywidgets' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]
