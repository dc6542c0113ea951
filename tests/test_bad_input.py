"""Bad input gets a clear error, across the whole public API.

One table of cases (the format of ``tests/bad_input.py``): every public function and class of
``orrc``, ``orrc.theory``, ``orrc.certify``, ``orrc.checks``, ``orrc.disturbances``,
``orrc.examples``, ``orrc.metrics``, ``orrc.config`` and the public plotting functions of
``orrc.viz``, given wrong shapes, wrong types, non-finite, complex or empty values, values out
of range, and computations too large to run. Each case asserts the exception type
(``orrc.OrrcValueError`` throughout) and that the message names the argument.
"""
import functools
import math
import warnings

import casadi as ca
import numpy as np
import pytest

import orrc
import orrc.viz  # the plotting functions (not loaded by `import orrc`)
from bad_input import assert_bad_input, case, params
from conftest import FORCED_FAILURE
from orrc import certify, checks, disturbances as dist, examples as exs, theory as th

E = orrc.OrrcValueError


@functools.cache
def di():
    return exs.double_integrator()


@functools.cache
def pend():
    return exs.inverted_pendulum()


@functools.cache
def di_rhc(M=5):
    return orrc.PreviewRHC(di().system, di().cost, M)


@functools.cache
def pend_rhc(M=5):
    return orrc.PreviewRHC(pend().system, pend().cost, M, input_bounds=pend().input_bounds)


@functools.cache
def traj():
    """Algorithm 1 on the double integrator, T = 12, M = 5 (V_M at every step)."""
    return orrc.simulate(di().system, di_rhc(), di().x0, dist.sinusoid(20, 2, 0.1), 12)


@functools.cache
def lqr_traj():
    return orrc.simulate(di().system, orrc.LQR(di().system, di().cost), di().x0, dist.sinusoid(20, 2, 0.1), 12)


@functools.cache
def consts():
    return certify.lq_constants(di().system, di().cost, 5, grid=30)


@functools.cache
def margins():
    return checks.value_bound_margins(traj(), 5, consts().alpha_hi, consts().gamma_bar)


def overflowed_traj():
    """A run whose costs overflow (x stays finite): simulate warns; the metrics must refuse it."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", orrc.NonFiniteWarning)
        return orrc.simulate(orrc.LinearSystem([[0.5]], [[1.0]]), orrc.ZeroInput(1, orrc.QuadraticCost([[1e300]], [[1]])),
                             [1e10], np.zeros((3, 1)), 3)


def failed_traj():
    """A run whose solves all fail (max_failures=None): the checks must refuse it."""
    ex = pend()
    rhc = orrc.PreviewRHC(ex.system, ex.cost, 5, input_bounds=ex.input_bounds, solver_options=FORCED_FAILURE,
                          max_failures=None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", orrc.SolverWarning)
        return orrc.simulate(ex.system, rhc, ex.x0, np.zeros((10, 2)), 6)


class WrongU(orrc.Controller):
    name = "wrong u"
    cost = orrc.QuadraticCost(np.eye(2), [[1.0]])

    def control(self, obs):
        return orrc.Decision(u=np.zeros(3))


def fig():
    from matplotlib.figure import Figure
    return Figure()


def plots():
    from orrc.viz import plots
    return plots


def tplots():
    from orrc.viz import theory_plots
    return theory_plots


CASES = [
    # -- orrc.systems --------------------------------------------------------------------------------
    case("LinearSystem-complex-A", lambda: orrc.LinearSystem([[1 + 1j]], [[1.0]]), "A", "complex"),
    case("LinearSystem-empty-A", lambda: orrc.LinearSystem(np.zeros((0, 0)), np.zeros((0, 1))), "A", "non-empty"),
    case("LinearSystem-no-input", lambda: orrc.LinearSystem(np.eye(2), np.zeros((2, 0))), "B", "m >= 1"),
    case("LinearSystem-nonsquare-A", lambda: orrc.LinearSystem(np.ones((2, 3)), np.ones((2, 1))), "A", "square"),
    case("LinearSystem-nan-A", lambda: orrc.LinearSystem([[np.nan]], [[1.0]]), "A", "finite"),
    case("LinearSystem-text-A", lambda: orrc.LinearSystem("abc", [[1.0]]), "A", "numeric"),
    case("LinearSystem-B-rows", lambda: orrc.LinearSystem(np.eye(2), np.ones((3, 1))), "B", "(2, m)"),
    case("LinearSystem-name", lambda: orrc.LinearSystem([[1.0]], [[1.0]], name=3), "name"),
    case("LinearSystem-from_statespace-not-ss", lambda: orrc.LinearSystem.from_statespace(np.eye(2)), "sys"),
    case("LinearSystem-step-x-shape", lambda: di().system.step([1.0], [0.0], [0.0, 0.0]), "x", "(2)"),
    case("LinearSystem-step-u-nan", lambda: di().system.step([1.0, 0.0], [np.nan], [0.0, 0.0]), "u", "finite"),
    case("NonlinearSystem-math-sin", lambda: orrc.NonlinearSystem(
        lambda x, u, w: ca.vertcat(math.sin(x[0]), x[1] + u[0]) + w, 2, 1), "f", "CasADi operations"),
    case("NonlinearSystem-zero-states", lambda: orrc.NonlinearSystem(lambda x, u, w: x, 0, 1), "n_states"),
    case("NonlinearSystem-not-callable", lambda: orrc.NonlinearSystem("f", 2, 1), "f", "callable"),
    case("NonlinearSystem-wrong-length", lambda: orrc.NonlinearSystem(lambda x, u, w: x[0], 2, 1), "n_states=2"),
    case("NonlinearSystem-untraceable", lambda: orrc.NonlinearSystem(lambda x, u, w: x.no_such_thing, 2, 1),
         "f(x, u, w)", "tracing"),
    case("NonlinearSystem-linearize-x", lambda: pend().system.linearize([0.0]), "x", "(2)"),
    case("NonlinearSystem-step-w-inf", lambda: pend().system.step([0.0, 0.0], [0.0], [np.inf, 0.0]), "w", "finite"),

    # -- orrc.costs ----------------------------------------------------------------------------------
    case("QuadraticCost-Q-indefinite", lambda: orrc.QuadraticCost([[1.0, 0], [0, -1]], [[1.0]]), "Q",
         "positive semidefinite"),
    case("QuadraticCost-R-zero", lambda: orrc.QuadraticCost(np.eye(2), [[0.0]]), "R", "positive definite"),
    case("QuadraticCost-Q-empty", lambda: orrc.QuadraticCost(np.zeros((0, 0)), [[1.0]]), "Q", "non-empty"),
    case("QuadraticCost-Q-complex", lambda: orrc.QuadraticCost([[1j]], [[1.0]]), "Q", "complex"),
    case("QuadraticCost-Q-asymmetric", lambda: orrc.QuadraticCost([[1.0, 1.0], [0, 1.0]], [[1.0]]), "Q", "symmetric"),
    case("QuadraticCost-alpha_lo-nan", lambda: orrc.QuadraticCost(np.eye(2), [[1.0]], alpha_lo=np.nan), "alpha_lo",
         "finite"),
    case("QuadraticCost-alpha_lo-too-big", lambda: orrc.QuadraticCost(np.eye(2), [[1.0]], alpha_lo=2.0), "alpha_lo",
         "lambda_min(Q)"),
    case("QuadraticCost-alpha_lo-negative", lambda: orrc.QuadraticCost(np.eye(2), [[1.0]], alpha_lo=-1.0), "alpha_lo"),
    case("QuadraticCost-value-x-nan", lambda: di().cost.value([np.nan, 0.0], [0.0]), "x", "finite"),
    case("QuadraticCost-value-u-shape", lambda: di().cost.value([0.0, 0.0], [0.0, 1.0]), "u", "(1)"),
    case("QuadraticCost-value-p-indefinite", lambda: di().cost.value([1.0, 0.0], [0.0], [-1, 0, 0, 1, 1]), "p",
         "Q_t"),
    case("QuadraticCost-value-overflow", lambda: di().cost.value([1e200, 0.0], [0.0]), "stage cost", "x, u"),
    case("QuadraticCost-sigma-nan", lambda: di().cost.sigma([np.nan, 1.0]), "x", "finite"),
    case("QuadraticCost-sequence-Qs-shape", lambda: di().cost.sequence(np.ones((3, 3, 3))), "Qs"),
    case("QuadraticCost-sequence-Q-indefinite", lambda: di().cost.sequence(
        np.array([np.eye(2), -np.eye(2)])), "Qs", "Q_t", "row 1"),
    case("QuadraticCost-sequence-R-zero", lambda: di().cost.sequence(np.array([np.eye(2)]), np.zeros((1, 1, 1))),
         "Rs", "R_t"),
    case("QuadraticCost-scaled-negative", lambda: di().cost.scaled([1.0, -2.0]), "scales", "positive"),
    case("QuadraticCost-scaled-empty", lambda: di().cost.scaled([]), "scales", "empty"),
    case("QuadraticCost-unpack-length", lambda: di().cost.unpack([1.0, 2.0]), "p", "(5)"),
    case("QuadraticCost-check_params-width", lambda: di().cost.check_params(np.ones((3, 4))), "cost_params", "(L, 5)"),
    case("CostSequence-R-zero-row", lambda: orrc.CostSequence(di().cost, [[1, 0, 0, 1, 0.0]]), "params", "R_t"),
    case("CostSequence-Q-indefinite-row", lambda: orrc.CostSequence(di().cost, [[1, 0, 0, 1, 1.0], [1, 0, 0, -1, 1]]),
         "params", "Q_t", "row 1"),
    case("CostSequence-alpha_lo-nan", lambda: orrc.CostSequence(di().cost, [di().cost.default_params], alpha_lo=np.nan),
         "alpha_lo", "finite"),
    case("CostSequence-alpha_lo-above-rows", lambda: orrc.CostSequence(
        di().cost, [[0.5, 0, 0, 1, 1.0]], alpha_lo=0.9), "alpha_lo", "min_t lambda_min(Q_t)"),
    case("CostSequence-stage", lambda: orrc.CostSequence("quadratic", [[1.0]]), "stage"),
    case("CostSequence-empty", lambda: orrc.CostSequence(di().cost, np.zeros((0, 5))), "params", "at least one"),
    case("CostSequence-value-t", lambda: di().cost.scaled([1.0, 2.0]).value(-1, [0.0, 0.0], [0.0]), "t", ">= 0"),
    case("CostSequence-window-length", lambda: di().cost.scaled([1.0, 2.0]).window(0, 2.5), "length"),
    case("Cost-math-sin", lambda: orrc.Cost(lambda x, u: math.sin(x[0]) + u[0] ** 2, 1, 1), "fun", "CasADi"),
    case("Cost-sigma-negative", lambda: orrc.Cost(lambda x, u: x[0] ** 2 + u[0] ** 2, 1, 1, sigma=lambda x: -1.0),
         "sigma", ">= 0"),
    case("Cost-sigma-vector", lambda: orrc.Cost(lambda x, u: x[0] ** 2 + u[0] ** 2, 2, 1, sigma=lambda x: x),
         "sigma", "one real number"),
    case("Cost-sigma-not-callable", lambda: orrc.Cost(lambda x, u: x[0] ** 2, 1, 1, sigma=2.0), "sigma", "callable"),
    case("Cost-vector-valued", lambda: orrc.Cost(lambda x, u: x, 2, 1), "scalar"),
    case("Cost-n-zero", lambda: orrc.Cost(lambda x, u: u[0] ** 2, 0, 1), "n"),
    case("Cost-default_params-length", lambda: orrc.Cost(lambda x, u, p: p[0] * x[0] ** 2, 1, 1, n_params=1,
                                                         default_params=[1.0, 2.0]), "default_params"),
    case("Cost-alpha_lo-nan", lambda: orrc.Cost(lambda x, u: x[0] ** 2, 1, 1, alpha_lo=np.nan), "alpha_lo"),
    case("Cost-value-x-nan", lambda: orrc.Cost(lambda x, u: x[0] ** 2, 1, 1).value([np.nan], [0.0]), "x"),

    # -- orrc.disturbances ---------------------------------------------------------------------------
    case("zero-L", lambda: dist.zero(0, 2), "L", ">= 1"),
    case("zero-n-float", lambda: dist.zero(5, 1.5), "n", "integer"),
    case("zero-too-large", lambda: dist.zero(10 ** 12, 2), "L=1000000000000", "limit"),
    case("constant-value-length", lambda: dist.constant(5, 2, [1.0, 2.0, 3.0]), "value", "(2)"),
    case("sinusoid-phase-nan", lambda: dist.sinusoid(5, 2, phase=np.nan), "phase", "finite"),
    case("sinusoid-period-zero", lambda: dist.sinusoid(5, 2, period=0.0), "period"),
    case("sinusoid-amplitude-negative", lambda: dist.sinusoid(5, 2, amplitude=-1.0), "amplitude"),
    case("uniform_ball-seed-text", lambda: dist.uniform_ball(5, 2, seed="abc"), "seed"),
    case("uniform_ball-seed-negative", lambda: dist.uniform_ball(5, 2, seed=-1), "seed", "non-negative"),
    case("uniform_ball-radius-nan", lambda: dist.uniform_ball(5, 2, radius=np.nan), "radius"),
    case("uniform_box-lo-above-hi", lambda: dist.uniform_box(5, 2, lo=1.0, hi=0.0), "lo <= hi"),
    case("gaussian-std-negative", lambda: dist.gaussian(5, 2, std=-1.0), "std"),
    case("gaussian-seed-float", lambda: dist.gaussian(5, 2, seed=0.5), "seed"),
    case("bursts-every-zero", lambda: dist.bursts(5, 2, every=0), "every"),
    case("bursts-duration-float", lambda: dist.bursts(5, 2, duration=1.5), "duration"),
    case("make-kind", lambda: dist.make("storm", 5, 2), "kind", "storm"),
    case("make-scale-nan", lambda: dist.make("sinusoid", 5, 2, scale=np.nan), "scale"),
    case("energy-1d", lambda: dist.energy([1.0, 2.0]), "w", "2-dimensional"),
    case("energy-overflow", lambda: dist.energy(np.full((2, 2), 1e200)), "energy", "w"),
    case("Ball-radius-negative", lambda: orrc.Ball(-1.0, 2), "radius"),
    case("Ball-radius-huge", lambda: orrc.Ball(1e200, 2), "radius", "<= 1e+150"),
    case("Ball-n-zero", lambda: orrc.Ball(1.0, 0), "n"),
    case("Ball-contains-shape", lambda: orrc.Ball(1.0, 2).contains(np.zeros(3)), "w", "(2,)"),
    case("Ball-contains-tol", lambda: orrc.Ball(1.0, 2).contains(np.zeros(2), tol=np.nan), "tol"),
    case("Ball-sample-L", lambda: orrc.Ball(1.0, 2).sample(0), "L"),
    case("Ball-sample-seed", lambda: orrc.Ball(1.0, 2).sample(3, seed=1.5), "seed"),
    case("Box-lo-length", lambda: orrc.Box([0.0, 0.0, 0.0], [1.0, 1.0], n=2), "lo and hi", "length-2"),
    case("Box-lo-nan", lambda: orrc.Box(np.nan, 1.0, n=2), "lo", "finite"),
    case("Box-lo-above-hi", lambda: orrc.Box(1.0, 0.0, n=2), "lo <= hi"),
    case("Box-vertices-n40", lambda: orrc.Box(-1.0, 1.0, n=40).vertices(), "n=40", "TiB", "limit"),
    case("Box-contains-shape", lambda: orrc.Box(-1.0, 1.0, n=2).contains(np.zeros(5)), "w", "(2,)"),
    case("Box-sample-seed", lambda: orrc.Box(-1.0, 1.0, n=2).sample(3, seed=object()), "seed"),

    # -- orrc.examples -------------------------------------------------------------------------------
    case("scalar_unstable-b-zero", lambda: exs.scalar_unstable(B=0.0), "B", "non-zero"),
    case("scalar_unstable-r-negative", lambda: exs.scalar_unstable(r=-1.0), "r"),
    case("scalar_unstable-a-nan", lambda: exs.scalar_unstable(A=np.nan), "A", "finite"),
    case("double_integrator-dt-negative", lambda: exs.double_integrator(dt=-0.1), "dt"),
    case("double_integrator-r-zero", lambda: exs.double_integrator(r=0.0), "r"),
    case("double_integrator-q_vel-negative", lambda: exs.double_integrator(q_vel=-1.0), "q_vel"),
    case("two_mass_spring-dt-zero", lambda: exs.two_mass_spring(dt=0.0), "dt"),
    case("two_mass_spring-k-negative", lambda: exs.two_mass_spring(k=-1.0), "k"),
    case("inverted_pendulum-dt-negative", lambda: exs.inverted_pendulum(dt=-0.05), "dt"),
    case("inverted_pendulum-u_max-negative", lambda: exs.inverted_pendulum(u_max=-5.0), "u_max"),
    case("inverted_pendulum-friction-nan", lambda: exs.inverted_pendulum(friction=np.nan), "friction"),
    case("mass_chain-k-zero", lambda: exs.mass_chain(k=0), "k"),
    case("mass_chain-k-huge", lambda: exs.mass_chain(k=10**9), "k"),
    case("mass_chain-stiffness-negative", lambda: exs.mass_chain(stiffness=-1.0), "stiffness"),
    case("mass_chain-cubic-nan", lambda: exs.mass_chain(cubic=np.nan), "cubic"),
    case("mass_chain-u_max-zero", lambda: exs.mass_chain(u_max=0.0), "u_max"),
    case("quadrotor-dt-zero", lambda: exs.quadrotor(dt=0.0), "dt"),
    case("quadrotor-mass-nan", lambda: exs.quadrotor(mass=np.nan), "mass"),
    case("quadrotor-inertia-negative", lambda: exs.quadrotor(inertia=(0.02, -0.02, 0.04)), "inertia"),
    case("quadrotor-thrust_max-past-weight", lambda: exs.quadrotor(thrust_max=100.0), "thrust_max"),
    case("quadrotor-torque_max-zero", lambda: exs.quadrotor(torque_max=0.0), "torque_max"),
    case("van_der_pol-u_max-zero", lambda: exs.van_der_pol(u_max=0.0), "u_max"),
    case("van_der_pol-mu-negative", lambda: exs.van_der_pol(mu=-1.0), "mu"),
    case("van_der_pol-input_weight-nan", lambda: exs.van_der_pol(input_weight=np.nan), "input_weight"),

    # -- orrc.controllers ----------------------------------------------------------------------------
    case("PreviewRHC-system", lambda: orrc.PreviewRHC("sys", di().cost, 5), "system"),
    case("PreviewRHC-cost", lambda: orrc.PreviewRHC(di().system, np.eye(2), 5), "cost"),
    case("PreviewRHC-M-zero", lambda: orrc.PreviewRHC(di().system, di().cost, 0), "M", ">= 1"),
    case("PreviewRHC-M-float", lambda: orrc.PreviewRHC(di().system, di().cost, 2.5), "M", "integer"),
    case("PreviewRHC-lq-law-M-1e6", lambda: orrc.PreviewRHC(di().system, di().cost, 10 ** 6).law, "M=1000000",
         "TiB", "limit"),
    case("PreviewRHC-lq-law-M-2000", lambda: orrc.PreviewRHC(di().system, di().cost, 2000).law, "M=2000",
         "operations", "limit"),
    case("PreviewRHC-nlp-M-1e6", lambda: orrc.PreviewRHC(pend().system, pend().cost, 10 ** 6,
                                                         input_bounds=pend().input_bounds), "M=1000000", "limit"),
    case("PreviewRHC-input_bounds-length", lambda: orrc.PreviewRHC(di().system, di().cost, 5,
                                                                   input_bounds=([-1, -1], [1, 1])), "input_bounds[0]",
         "length-1"),
    case("PreviewRHC-input_bounds-not-pair", lambda: orrc.PreviewRHC(di().system, di().cost, 5, input_bounds=1.0),
         "input_bounds", "pair"),
    case("PreviewRHC-input_bounds-nan", lambda: orrc.PreviewRHC(di().system, di().cost, 5, input_bounds=(np.nan, 1)),
         "input_bounds", "no NaN"),
    case("PreviewRHC-state_bounds-order", lambda: orrc.PreviewRHC(di().system, di().cost, 5,
                                                                  state_bounds=([1, 1], [0, 0])), "state_bounds"),
    case("PreviewRHC-terminal-vector", lambda: orrc.PreviewRHC(di().system, di().cost, 5, terminal_cost=lambda x: x),
         "terminal_cost", "scalar"),
    case("PreviewRHC-terminal-shape", lambda: orrc.PreviewRHC(di().system, di().cost, 5, terminal_cost=np.eye(3)),
         "terminal_cost", "(2, 2)"),
    case("PreviewRHC-terminal-indefinite", lambda: orrc.PreviewRHC(di().system, di().cost, 5,
                                                                   terminal_cost=-np.eye(2)), "terminal_cost"),
    case("PreviewRHC-terminal-math", lambda: orrc.PreviewRHC(di().system, di().cost, 5,
                                                             terminal_cost=lambda x: math.exp(x[0])), "terminal_cost"),
    case("PreviewRHC-solver", lambda: orrc.PreviewRHC(di().system, di().cost, 5, solver="fast"), "solver", "'fast'"),
    case("PreviewRHC-solver_options-type", lambda: orrc.PreviewRHC(pend().system, pend().cost, 5,
                                                                   solver_options=[1]), "solver_options", "dict"),
    case("PreviewRHC-solver_options-unknown", lambda: orrc.PreviewRHC(
        pend().system, pend().cost, 5, solver_options={"ipopt.no_such_option": 1}), "ipopt.no_such_option"),
    case("PreviewRHC-max_failures-zero", lambda: orrc.PreviewRHC(di().system, di().cost, 5, max_failures=0),
         "max_failures", ">= 1"),
    case("PreviewRHC-max_failures-float", lambda: orrc.PreviewRHC(di().system, di().cost, 5, max_failures=1.5),
         "max_failures", "integer"),
    case("plan-warm_start-type", lambda: pend_rhc().plan(pend().x0, np.zeros((5, 2)), warm_start=np.zeros(5)),
         "warm_start", "Plan"),
    case("plan-warm_start-horizon", lambda: pend_rhc().plan(
        pend().x0, np.zeros((5, 2)), warm_start=orrc.PreviewRHC(pend().system, pend().cost, 3).plan(
            pend().x0, np.zeros((3, 2)))), "warm_start.inputs", "(5, 1)"),
    case("plan-x-nan", lambda: di_rhc().plan([np.nan, 0.0], np.zeros((5, 2))), "x", "finite"),
    case("plan-w_preview-short", lambda: di_rhc().plan([0.0, 0.0], np.zeros((2, 2))), "w_preview", "(5, 2)"),
    case("plan-w_preview-complex", lambda: di_rhc().plan([0.0, 0.0], np.zeros((5, 2), complex)), "w_preview",
         "complex"),
    case("plan-cost_params-R-zero", lambda: di_rhc().plan([1.0, 0.0], np.zeros((5, 2)),
                                                          np.tile([1, 0, 0, 1, 0.0], (5, 1))), "cost_params", "R_t"),
    case("plan-cost_params-Q-indefinite", lambda: di_rhc().plan([1.0, 0.0], np.zeros((5, 2)),
                                                                np.tile([1, 0, 0, -1, 1.0], (5, 1))), "cost_params",
         "Q_t"),
    case("plan-cost_params-rows", lambda: di_rhc().plan([1.0, 0.0], np.zeros((5, 2)), np.tile(di().cost.default_params,
                                                                                             (2, 1))), "cost_params",
         "M=5"),
    case("plan-overflow", lambda: di_rhc().plan([1e200, 0.0], np.zeros((5, 2))), "x", "overflows"),
    case("LQR-system", lambda: orrc.LQR("not a system", di().cost), "system"),
    case("LQR-cost", lambda: orrc.LQR(di().system, "cost"), "QuadraticCost"),
    case("LQR-dimensions", lambda: orrc.LQR(di().system, orrc.QuadraticCost(np.eye(3), [[1.0]])), "n=3"),
    case("LQR-unstabilisable", lambda: orrc.LQR(orrc.LinearSystem([[2.0]], [[0.0]]), orrc.QuadraticCost([[1]], [[1]])),
         "stabilising"),
    case("ZeroInput-m-zero", lambda: orrc.ZeroInput(0), "m"),
    case("ZeroInput-cost", lambda: orrc.ZeroInput(1, cost=np.eye(1)), "cost"),
    case("Clairvoyant-T-zero", lambda: orrc.Clairvoyant(di().system, di().cost, 0), "T"),
    case("Clairvoyant-T-mismatch", lambda: orrc.simulate(di().system, orrc.Clairvoyant(di().system, di().cost, 10),
                                                         di().x0, np.zeros((30, 2)), 20), "T=10", "T=20"),

    # -- orrc.simulate -------------------------------------------------------------------------------
    case("simulate-system", lambda: orrc.simulate("sys", di_rhc(), di().x0, np.zeros((9, 2)), 5), "system"),
    case("simulate-controller", lambda: orrc.simulate(di().system, "rhc", di().x0, np.zeros((9, 2)), 5), "controller"),
    case("simulate-x0-shape", lambda: orrc.simulate(di().system, di_rhc(), [1.0], np.zeros((9, 2)), 5), "x0", "(2)"),
    case("simulate-x0-nan", lambda: orrc.simulate(di().system, di_rhc(), [np.nan, 0.0], np.zeros((9, 2)), 5), "x0",
         "finite"),
    case("simulate-w-short", lambda: orrc.simulate(di().system, di_rhc(), di().x0, np.zeros((4, 2)), 5), "w",
         "L >= T = 5"),
    case("simulate-w-complex", lambda: orrc.simulate(di().system, di_rhc(), di().x0, np.zeros((9, 2), complex), 5),
         "w", "complex"),
    case("simulate-T-zero", lambda: orrc.simulate(di().system, di_rhc(), di().x0, np.zeros((9, 2)), 0), "T", ">= 1"),
    case("simulate-T-too-large", lambda: orrc.simulate(di().system, orrc.ZeroInput(1, di().cost), di().x0,
                                                       np.zeros((1, 2)), 10 ** 10), "T=10000000000", "limit"),
    case("simulate-controller-dimension", lambda: orrc.simulate(exs.scalar_unstable().system, di_rhc(), [1.0],
                                                                np.zeros((9, 1)), 5), "n=2", "n=1"),
    case("simulate-ZeroInput-dimension", lambda: orrc.simulate(di().system, orrc.ZeroInput(2, di().cost), di().x0,
                                                               np.zeros((9, 2)), 5), "m=2", "m=1"),
    case("simulate-costs-type", lambda: orrc.simulate(di().system, di_rhc(), di().x0, np.zeros((9, 2)), 5,
                                                      costs=np.eye(2)), "costs"),
    case("simulate-decision-u-shape", lambda: orrc.simulate(di().system, WrongU(), di().x0, np.zeros((9, 2)), 5),
         "wrong u", "m=1"),
    case("simulate-cost-family", lambda: orrc.simulate(
        di().system, di_rhc(), di().x0, np.zeros((9, 2)), 5,
        costs=orrc.CostSequence(orrc.Cost(lambda x, u, p: p[0] * x[0] ** 2 + u[0] ** 2, 2, 1, n_params=1),
                                [[1.0]])), "cost sequence's family"),

    # -- orrc.metrics --------------------------------------------------------------------------------
    case("attenuation_regret-traj", lambda: orrc.attenuation_regret("traj", 1.0), "traj", "Trajectory"),
    case("attenuation_regret-gamma-negative", lambda: orrc.attenuation_regret(traj(), -1.0), "gamma", ">= 0"),
    case("attenuation_regret-gamma-nan", lambda: orrc.attenuation_regret(traj(), np.nan), "gamma", "finite"),
    case("attenuation_regret-cumulative", lambda: orrc.attenuation_regret(traj(), 1.0, cumulative="yes"),
         "cumulative"),
    case("attenuation_regret-overflowed-run", lambda: orrc.attenuation_regret(overflowed_traj(), 1.0), "traj.costs",
         "not finite"),
    case("attenuation_regret-overflow", lambda: orrc.attenuation_regret(orrc.simulate(
        di().system, di_rhc(), di().x0, np.full((9, 2), 10.0), 5), 1e307), "R^p_T", "gamma="),
    case("attenuation_ratio-no-disturbance", lambda: orrc.attenuation_ratio(orrc.simulate(
        di().system, di_rhc(), di().x0, np.zeros((9, 2)), 5)), "disturbance"),
    case("dynamic_regret-reference-nan", lambda: orrc.dynamic_regret(traj(), np.nan), "reference", "finite"),
    case("dynamic_regret-reference-type", lambda: orrc.dynamic_regret(traj(), "best"), "reference"),
    case("dynamic_regret-reference-problem", lambda: orrc.dynamic_regret(traj(), lqr_traj().__class__(
        **{**vars(lqr_traj()), "x": lqr_traj().x + 1.0})), "reference", "same problem"),

    # -- orrc.theory ---------------------------------------------------------------------------------
    case("horizon_threshold-overflow", lambda: th.horizon_threshold(1e-200, 1.0), "alpha_lo=1e-200",
         "not representable"),
    case("gamma_tilde-underflow", lambda: th.gamma_tilde(5e-324, 1.0), "alpha_lo=5e-324"),
    case("Gamma_V-overflow", lambda: th.Gamma_V(2, 1e-300, 1e200), "alpha_hi=1e+200", "overflows"),
    case("Gamma_V-M-one", lambda: th.Gamma_V(1, 1.0, 2.0), "M", ">= 2"),
    case("Gamma_V_gamma-gamma_bar-zero", lambda: th.Gamma_V_gamma(5, 1.0, 2.0, 0.0), "gamma_bar"),
    case("min_decay_rate-below-threshold", lambda: th.min_decay_rate(3, 1.0, 2.0), "M=3", "threshold"),
    case("decay_b-alpha-order", lambda: th.decay_b(2.0, 1.0, 1.0), "alpha_lo", "alpha_hi"),
    case("lemma2_coefficients-H-1e10", lambda: th.lemma2_coefficients(10, 10 ** 10, 0.9, 2.0, 1.0, 1.0),
         "H=10000000000", "GiB", "limit"),
    case("lemma2_coefficients-H-below-M", lambda: th.lemma2_coefficients(10, 5, 0.9, 2.0, 1.0, 1.0), "H >= M"),
    case("lemma2_coefficients-a-one", lambda: th.lemma2_coefficients(10, 12, 1.0, 2.0, 1.0, 1.0), "a", "< 1.0"),
    case("lemma2_coefficients-overflow", lambda: th.lemma2_coefficients(10, 12, 1 - 1e-16, 2.0, 1.0, 1e300), "b=1e+300",
         "not finite"),
    case("lemma2_bound-w_window-rows", lambda: th.lemma2_bound(1.0, np.zeros((3, 2)), 10, 12, 0.99, 1.0, 2.0, 1.0),
         "w_window", "21"),
    case("lemma2_bound-sigma_t-negative", lambda: th.lemma2_bound(-1.0, np.zeros((21, 2)), 10, 12, 0.99, 1.0, 2.0, 1.0),
         "sigma_t"),
    case("gamma_c-a-outside", lambda: th.gamma_c(10, 0.1, 1.0, 2.0, 1.0), "a", "min_decay_rate"),
    case("gamma_c-overflow", lambda: th.gamma_c(10 ** 9, 0.999999999, 1e-3, 1.0, 1e300), "gamma_bar=1e+300",
         "not finite"),
    case("theorem1_constant-gamma-low", lambda: th.theorem1_constant(1.0, np.zeros((30, 1)), 20, 10, 0.99, 1.0, 2.0,
                                                                     1.0, 1.0), "gamma", "gamma_c"),
    case("theorem1_constant-w-short", lambda: th.theorem1_constant(1.0, np.zeros((3, 1)), 20, 10, 0.99, 1.0, 2.0, 1.0,
                                                                   1e9), "w", "rows"),
    case("gamma_c_remark-alpha_hi-nan", lambda: th.gamma_c_remark(1.0, np.nan, 1.0), "alpha_hi", "finite"),
    case("above_threshold-M-text", lambda: th.above_threshold("5", 1.0, 2.0), "M", "integer"),

    # -- orrc.certify --------------------------------------------------------------------------------
    case("lq_constants-nonlinear", lambda: certify.lq_constants(pend().system, pend().cost, 5), "system",
         "LinearSystem"),
    case("lq_constants-M-one", lambda: certify.lq_constants(di().system, di().cost, 1), "M", ">= 2"),
    case("lq_constants-grid-small", lambda: certify.lq_constants(di().system, di().cost, 5, grid=5), "grid", ">= 20"),
    case("lq_constants-grid-huge", lambda: certify.lq_constants(di().system, di().cost, 5, grid=10 ** 9),
         "grid=1000000000", "limit"),
    case("lq_constants-M-huge", lambda: certify.lq_constants(di().system, di().cost, 10 ** 5), "M=100000", "limit"),
    case("lq_constants-overflow", lambda: certify.lq_constants(exs.scalar_unstable(A=1e200).system,
                                                               exs.scalar_unstable().cost, 5), "overflows"),
    case("alpha_hi_floor-1e7", lambda: certify.alpha_hi_floor(di().system, di().cost, [10 ** 7]), "max(Ms)=10000000",
         "limit"),
    case("alpha_hi_floor-empty", lambda: certify.alpha_hi_floor(di().system, di().cost, []), "Ms", "at least one"),
    case("alpha_hi_floor-text", lambda: certify.alpha_hi_floor(di().system, di().cost, "abc"), "Ms", "iterable"),
    case("alpha_hi_floor-zero", lambda: certify.alpha_hi_floor(di().system, di().cost, [3, 0]), "Ms[1]", ">= 1"),
    case("smallest_certified_M-1e7", lambda: certify.smallest_certified_M(di().system, di().cost, M_max=10 ** 7),
         "M_max=10000000", "limit"),
    case("smallest_certified_M-one", lambda: certify.smallest_certified_M(di().system, di().cost, M_max=1), "M_max"),
    case("worst_case_attenuation-T-1e5", lambda: certify.worst_case_attenuation(di().system, di_rhc(), 10 ** 5),
         "T=100000", "limit"),
    case("worst_case_attenuation-T-5000-n4", lambda: certify.worst_case_attenuation(
        exs.two_mass_spring().system, orrc.LQR(exs.two_mass_spring().system, exs.two_mass_spring().cost), 5000),
         "T=5000", "GiB", "limit"),
    case("worst_case_attenuation-T-zero", lambda: certify.worst_case_attenuation(di().system, di_rhc(), 0), "T"),
    case("worst_case_attenuation-nlp", lambda: certify.worst_case_attenuation(
        di().system, orrc.PreviewRHC(di().system, di().cost, 5, solver="nlp"), 10), "solver='nlp'"),
    case("worst_case_attenuation-system", lambda: certify.worst_case_attenuation(pend().system, di_rhc(), 10),
         "system"),
    case("worst_case_attenuation_limit-start", lambda: certify.worst_case_attenuation_limit(
        di().system, di_rhc(), start="warm"), "start", "'warm'"),
    case("worst_case_attenuation_limit-tol", lambda: certify.worst_case_attenuation_limit(di().system, di_rhc(),
                                                                                          tol=0.0), "tol"),
    case("sampled_constants-n_samples-zero", lambda: certify.sampled_constants(pend().system, pend().cost, 5,
                                                                               n_samples=0), "n_samples"),
    case("sampled_constants-x_radius", lambda: certify.sampled_constants(pend().system, pend().cost, 5,
                                                                         x_radius=-1.0), "x_radius"),
    case("sampled_constants-cost-dims", lambda: certify.sampled_constants(
        pend().system, orrc.QuadraticCost(np.eye(3), [[1.0]]), 5), "n=3", "n=2"),
    case("sampled_constants-cost-type", lambda: certify.sampled_constants(pend().system, "Q", 5), "cost",
         "stage cost", "str"),
    case("sampled_constants-seed", lambda: certify.sampled_constants(pend().system, pend().cost, 5, seed="a"), "seed"),
    case("sampled_constants-huge", lambda: certify.sampled_constants(pend().system, pend().cost, 5, n_samples=10 ** 9),
         "n_samples=1000000000", "limit"),
    case("Constants-bound-sigma-nan", lambda: consts().bound(np.nan, 1.0), "sigma", "finite"),
    case("Constants-bound-w_energy-negative", lambda: consts().bound(1.0, -1.0), "w_energy", ">= 0"),
    case("Constants-bound-overflow", lambda: consts().bound(1e308, 1e308), "Constants.bound", "sigma="),
    case("Constants-alpha_hi_at-nan", lambda: consts().alpha_hi_at(np.nan), "gamma_bar"),
    case("Constants-alpha_hi_at-below", lambda: consts().alpha_hi_at(1e-12), "gamma_bar", "must exceed"),

    # -- orrc.checks ---------------------------------------------------------------------------------
    case("lemma1_margins-failed-solves", lambda: checks.lemma1_margins(failed_traj(), 5, 1.0, 50.0, 5.0), "traj",
         "the solve failed"),
    case("lemma1_margins-no-values", lambda: checks.lemma1_margins(lqr_traj(), 5, 1.0, 50.0, 5.0), "V_M", "LQR"),
    case("lemma1_margins-M-mismatch", lambda: checks.lemma1_margins(traj(), 6, 0.1, 50.0, 5.0), "M=6", "M_w=5"),
    case("lemma1_margins-traj", lambda: checks.lemma1_margins("traj", 5, 0.1, 50.0, 5.0), "traj", "Trajectory"),
    case("value_bound_margins-alpha_hi", lambda: checks.value_bound_margins(traj(), 5, 0.0, 5.0), "alpha_hi"),
    case("lemma2_margins-H-too-long", lambda: checks.lemma2_margins(traj(), 5, 12, 0.9, 0.1, 0.2, 1.0), "H", "< T = 12"),
    case("theorem1_margin-gamma-low", lambda: checks.theorem1_margin(
        traj(), 5, th.min_decay_rate(5, 1.0, 1.5), 1.0, 1.5, 1.0, 0.0), "gamma", "gamma_c"),
    case("lemma1_margins-overflowed-run", lambda: checks.lemma1_margins(overflowed_traj(), 5, 1.0, 2.0, 1.0),
         "V_M"),
    case("Margins-holds-rtol", lambda: margins().holds(rtol=np.nan), "rtol", "finite"),
    case("Margins-violations-atol", lambda: margins().violations(atol=-1.0), "atol"),

    # -- orrc.config ---------------------------------------------------------------------------------
    case("set_limits-negative", lambda: orrc.config.set_limits(max_bytes=-1), "max_bytes", "> 0"),
    case("set_limits-unknown", lambda: orrc.config.set_limits(max_seconds=10), "limit", "max_seconds"),
    case("limits-text", lambda: orrc.config.limits(max_ops="many").__enter__(), "max_ops", "real number"),

    # -- orrc.viz (public plotting functions) ----------------------------------------------------------
    case("explore-plot", lambda: orrc.viz.explore("plot", M=[1]), "plot", "function"),
    case("explore-no-params", lambda: orrc.viz.explore(lambda: fig()), "parameter"),
    case("explore-scalar-param", lambda: orrc.viz.explore(lambda M: fig(), M=5), "parameter 'M'", "list"),
    case("explore-initial", lambda: orrc.viz.explore(lambda M: fig(), M=[1, 2], initial={"M": 3}), "initial",
         "'M'"),
    case("explore-too-many-frames", lambda: orrc.viz.explore(lambda a, b, c: fig(), a=range(10), b=range(10),
                                                             c=range(10)), "1000 frames", "limit"),
    case("explore-returns-no-figure", lambda: orrc.viz.explore(lambda M: None, M=[1]), "plot", "Figure"),
    case("figure_to_png-not-figure", lambda: orrc.viz.figure_to_png("png"), "fig", "Figure"),
    case("figure_to_png-dpi", lambda: orrc.viz.figure_to_png(fig(), dpi=0), "dpi", ">= 1"),
    case("information_pattern-t", lambda: plots().information_pattern(9, 2, 2, 5), "t", "T=5"),
    case("cost_overview-empty", lambda: plots().cost_overview({}), "trajs", "empty"),
    case("cost_overview-state", lambda: plots().cost_overview({"rhc": traj()}, state=5), "state", "0..1"),
    case("running_regret-gammas", lambda: plots().running_regret({"rhc": traj()}, []), "gammas"),
    case("cost_vs_energy-energies", lambda: plots().cost_vs_energy([0.0, 1.0], {"a": [1, 2]}), "energies",
         "positive"),
    case("preview_gains-nlp", lambda: plots().preview_gains({"p": pend_rhc()}), "laws['p']", "LQ path"),
    case("cost_vs_horizon-M", lambda: plots().cost_vs_horizon([0, 5], {"a": [1, 2]}), "M", ">= 1"),
    case("disturbance_panel-ws", lambda: plots().disturbance_panel([np.zeros((3, 2))]), "ws", "dict"),
    case("rhc_frame-traj", lambda: plots().rhc_frame("traj", traj(), 1.0), "traj", "Trajectory"),
    case("solver_effort-empty", lambda: plots().solver_effort({}), "iterations"),
    case("table-row", lambda: plots().table(["a", "b"], [[1]]), "row 0", "2 columns"),
    case("table-digits", lambda: plots().table(["a"], [[1.0]], digits=0), "digits"),
    case("pareto_curves-type", lambda: tplots().pareto_curves({"M=5": "c"}), "constants['M=5']", "Constants"),
    case("horizon_threshold-plot-alpha_lo", lambda: tplots().horizon_threshold([2, 3], [1.0, 1.0], 0.0), "alpha_lo"),
    case("lemma1_check-type", lambda: tplots().lemma1_check(margins()), "lemma1", "lemma1_margins"),
    case("lemma2_coefficients-plot-H", lambda: tplots().lemma2_coefficients({"a": np.ones(5)}, 5, 3), "H", ">= 5"),
    case("bounds_vs_actual-legend", lambda: tplots().bounds_vs_actual([1, 2], [1, 2], {"b": [2, 3]}, legend="top"),
         "legend", "'top'"),
    case("lemma2_frame-missing", lambda: tplots().lemma2_frame(5, 0.9, 0.5), "coef", "margins"),
    case("gamma_c_map-a_min", lambda: tplots().gamma_c_map({"a": ([0.5], [1.0])}, [0.5], [5], [1.0]), "a_min",
         "dict"),
    case("attenuation_levels-shape", lambda: tplots().attenuation_levels([2, 3], {"x": [1.0, 2.0, 3.0]}), "levels['x']",
         "2 values"),
    case("regret_growth-length", lambda: tplots().regret_growth([1, 2, 3], {"r": [1.0]}), "R['r']", "(3)"),
    case("adversary-costs", lambda: tplots().adversary({"rhc": np.zeros((3, 1))}, {"lqr": np.zeros(3)}), "costs",
         "'rhc'"),
    case("theorem1_frame-missing", lambda: tplots().theorem1_frame(5, 0.9, 0.5), "a_grid", "margin"),
    case("attenuation_vs_T-limits", lambda: tplots().attenuation_vs_T([1, 2], {"x": [1.0, 2.0]}, limits=[1.0]),
         "limits", "dict"),
]


@pytest.mark.parametrize("call, exc, words", params(CASES))
def test_bad_input_gets_a_clear_error_naming_the_argument(call, exc, words):
    assert_bad_input(call, exc, words)


def _all_cases():
    """This table and those of the other bad-input modules (tests/test_bad_input_<topic>.py)."""
    import importlib
    from pathlib import Path

    cases = list(CASES)
    for path in sorted(Path(__file__).parent.glob("test_bad_input_*.py")):
        cases += list(getattr(importlib.import_module(path.stem), "CASES", []))
    return cases


def test_the_table_covers_the_public_api():
    import orrc.comparison
    import orrc.controllers.gpc
    import orrc.solvers.game
    import orrc.tradeoff
    from test_bad_input_unknown import CASES as CASES_UNKNOWN   # the unknown-system half

    assert len(CASES) >= 100
    ids = " ".join(c.id for c in _all_cases() + CASES_UNKNOWN)
    public = (orrc.__all__ + orrc.theory.__all__ + orrc.certify.__all__ + orrc.checks.__all__
              + orrc.estimation.__all__
              + ["zero", "constant", "sinusoid", "uniform_ball", "uniform_box", "gaussian", "bursts", "make", "energy"]
              + list(exs.ALL) + orrc.controllers.__all__ + orrc.solvers.game.__all__ + orrc.comparison.__all__
              + orrc.tradeoff.__all__ + orrc.controllers.gpc.__all__)
    untested = {"OrrcValueError", "SolverWarning", "SolverError", "SizeWarning", "NonFiniteWarning", "System",
                "StageCost", "Controller", "Observation", "Decision", "Plan", "Trajectory", "disturbances", "examples",
                "Attenuation", "Lemma1Margins", "Regret", "Lipschitz", "Theorem2Bound", "Estimate", "LinearEstimate",
                "EDMDModel", "RankWarning", "Transitions", "MinMaxConstants", "SweepError", "Decision", "GameSolution",
                "ComparisonRow", "PreviewValue", "Tradeoff", "FixedPolicy", "Lemma6Case", "Lemma6Search"}  # exceptions, base classes and records:
    # nothing to call with bad input
    missing = [name for name in public if name not in untested and name not in ids]
    assert not missing, f"no bad-input case for {missing}"
