"""Bad input to the min-max pieces (Algorithm 3, Lemma 6, Theorem 3): a clear orrc.OrrcValueError.

One table in the shared format of tests/bad_input.py: each case an id, a zero-argument callable
and the words its message must contain (at least the argument's name).
"""
import numpy as np
import pytest

import orrc
from orrc import certify, checks, theory
from orrc.solvers.minmax import check_set
from bad_input import assert_bad_input, case, params

EX = orrc.examples.scalar_unstable(A=1.2)
SYS, COST = EX.system, EX.cost
PEND = orrc.examples.inverted_pendulum()
W1 = orrc.Box(-0.3, 0.3)


def _box(**changes):
    b = orrc.Box(-0.3, 0.3)
    for k, v in changes.items():
        setattr(b, k, np.array([v]))
    return b


def _rhc(**kw):
    return orrc.MinMaxRHC(SYS, COST, kw.pop("M", 4), kw.pop("W", W1), **kw)


def _traj():
    return orrc.simulate(SYS, _rhc(), np.array([1.0]), W1.sample(6, 0), 5)


CASES = [
    # the controller
    case("MinMaxRHC-W-wrong-dimension", lambda: orrc.MinMaxRHC(SYS, COST, 4, orrc.Box(-1, 1, 2)), "W", "dimension n=1"),
    case("MinMaxRHC-ball-wrong-dimension", lambda: orrc.MinMaxRHC(SYS, COST, 4, orrc.Ball(0.1, 3)), "W", "n=1"),
    case("MinMaxRHC-W-not-a-set", lambda: orrc.MinMaxRHC(SYS, COST, 4, (-0.3, 0.3)), "W must be an orrc.Box", "tuple"),
    case("MinMaxRHC-W-none", lambda: orrc.MinMaxRHC(SYS, COST, 4, None), "W must be", "NoneType"),
    case("MinMaxRHC-W-empty-box", lambda: orrc.MinMaxRHC(SYS, COST, 4, orrc.Box(1.0, -1.0)), "lo <= hi"),
    case("MinMaxRHC-W-emptied-box", lambda: orrc.MinMaxRHC(SYS, COST, 4, _box(lo=0.5)), "W is empty", "lo <= hi"),
    case("MinMaxRHC-W-unbounded-box", lambda: orrc.MinMaxRHC(SYS, COST, 4, orrc.Box(-np.inf, 1.0)), "lo", "finite"),
    case("MinMaxRHC-W-unbounded-mutated", lambda: orrc.MinMaxRHC(SYS, COST, 4, _box(hi=np.inf)), "W must be bounded"),
    case("MinMaxRHC-W-unbounded-ball", lambda: orrc.MinMaxRHC(SYS, COST, 4, orrc.Ball(np.inf, 1)), "radius", "finite"),
    case("MinMaxRHC-M-zero", lambda: orrc.MinMaxRHC(SYS, COST, 0, W1), "M must be an integer >= 1", "0"),
    case("MinMaxRHC-M-negative", lambda: orrc.MinMaxRHC(SYS, COST, -3, W1), "M must be an integer >= 1"),
    case("MinMaxRHC-M-float", lambda: orrc.MinMaxRHC(SYS, COST, 2.5, W1), "M must be an integer", "2.5"),
    case("MinMaxRHC-system-type", lambda: orrc.MinMaxRHC("sys", COST, 4, W1), "system must be"),
    case("MinMaxRHC-cost-type", lambda: orrc.MinMaxRHC(SYS, "cost", 4, W1), "cost must be"),
    case("MinMaxRHC-method-unknown", lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, method="best"), "method must be one of", "best"),
    case("MinMaxRHC-exact-nonlinear", lambda: orrc.MinMaxRHC(PEND.system, PEND.cost, 4, orrc.Box(-0.1, 0.1, 2), method="exact"),
         "method='exact' needs a LinearSystem", "exchange"),
    case("MinMaxRHC-exact-ball", lambda: orrc.MinMaxRHC(SYS, COST, 4, orrc.Ball(0.3, 1), method="exact"), "method='exact'",
         "box W"),
    case("MinMaxRHC-too-many-vertices", lambda: orrc.MinMaxRHC(orrc.LinearSystem(np.eye(2), np.ones((2, 1))),
                                                     orrc.QuadraticCost(np.eye(2), [[1.0]]), 14, orrc.Box(-1, 1, 2),
                                                     method="exact"),
         "M=14", "4^(M-1) = 67108864 vertex sequences", "too large", "limit", "method='exchange'"),
    case("MinMaxRHC-too-many-vertices-long-horizon", lambda: orrc.MinMaxRHC(SYS, COST, 27, W1, method="exact"), "M=27",
         "2^(M-1) = 67108864", "too large"),
    case("MinMaxRHC-input-bounds-reversed", lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, input_bounds=(1.0, -1.0)), "input_bounds", "lo <= hi"),
    case("MinMaxRHC-tol-zero", lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, tol=0.0), "tol must be > 0"),
    case("MinMaxRHC-tol-nan", lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, tol=np.nan), "tol must be finite"),
    case("MinMaxRHC-exchange-option-unknown", lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, method="exchange",
                                                           exchange_options={"starts": 3}),
         "unknown exchange_options", "starts"),
    case("MinMaxRHC-exchange-option-range", lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, method="exchange",
                                                         exchange_options={"n_starts": 0}),
         "exchange_options['n_starts']", ">= 1"),
    case("MinMaxRHC-exchange-solver", lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, method="exchange",
                                                   exchange_options={"solver": "snopt"}),
         "exchange_options['solver']", "snopt"),
    case("MinMaxRHC-exchange-options-type", lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, exchange_options=[1]),
         "exchange_options must be a dict"),
    case("MinMaxRHC-max-failures", lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, max_failures=0), "max_failures", ">= 1"),
    # a disturbance preview handed to it
    case("MinMaxRHC-plan-w-preview-keyword", lambda: _rhc().plan(np.array([1.0]), w_preview=np.zeros((4, 1))), "no disturbance preview", "w_preview"),
    case("MinMaxRHC-plan-w-preview-positional", lambda: _rhc().plan(np.array([1.0]), np.zeros((4, 1))), "cost_params", "like a disturbance preview"),
    case("MinMaxRHC-control-w-preview", lambda: _rhc().control(orrc.Observation(0, np.array([1.0]), None, np.zeros((4, 1)),
                                                                      None)),
         "disturbance preview of shape (4, 1)", "preview_w = 0"),
    case("MinMaxRHC-plan-unknown-argument", lambda: _rhc().plan(np.array([1.0]), foo=1), "unknown arguments", "foo"),
    case("MinMaxRHC-plan-x-shape", lambda: _rhc().plan(np.array([1.0, 2.0])), "x must have shape (1)", "(2,)"),
    case("MinMaxRHC-plan-x-nan", lambda: _rhc().plan(np.array([np.nan])), "x must be finite"),
    case("MinMaxRHC-plan-cost-params-short", lambda: _rhc().plan(np.array([1.0]), np.ones((2, 2))), "cost_params must have at least M=4 rows"),
    case("MinMaxRHC-warm-start", lambda: _rhc().plan(np.array([1.0]), warm_start="plan"), "warm_start must be a MinMaxPlan"),
    # the set check of the solvers
    case("check_set-dim", lambda: check_set(orrc.Box(-1, 1, 2), 3), "W must have the state dimension n=3"),
    # Lemma 6, Theorem 3
    case("Gamma_WV-M", lambda: theory.Gamma_WV(1, 1.0, 2.0), "M must be an integer >= 2"),
    case("Gamma_WV-alpha_lo", lambda: theory.Gamma_WV(5, 0.0, 2.0), "alpha_lo must be > 0"),
    case("Gamma_WV-order", lambda: theory.Gamma_WV(5, 2.0, 1.0), "alpha_lo must be <= alpha_hi_W"),
    case("Gamma_WV_gamma-gb", lambda: theory.Gamma_WV_gamma(5, 1.0, 2.0, -1.0), "gamma_bar_W must be > 0"),
    case("Gamma_WV_gamma-inf", lambda: theory.Gamma_WV_gamma(5, 1.0, np.inf, 1.0), "alpha_hi_W must be finite"),
    case("horizon_threshold_W-type", lambda: theory.horizon_threshold_W(1.0, "2"), "alpha_hi_W must be a real number"),
    case("min_decay_rate_W-below-threshold", lambda: theory.min_decay_rate_W(4, 1.0, 2.0), "M=4", "threshold", "Theorem 3"),
    case("decay_b_W-gb", lambda: theory.decay_b_W(1.0, 2.0, 0.0), "gamma_bar_W must be > 0"),
    case("gamma_c_W-a", lambda: theory.gamma_c_W(10, 1.0, 1.0, 2.0, 3.0), "a must lie in [min_decay_rate_W, 1)"),
    case("gamma_c_W-complex", lambda: theory.gamma_c_W(10, 0.9, 1.0, 2.0, 3.0 + 0j), "gamma_bar_W must be a real number"),
    case("theorem3_constant-T", lambda: theory.theorem3_constant(1.0, 0, 10, 0.9, 1.0, 2.0, 3.0, 0.25, 100.0), "T must be an integer >= 1"),
    case("theorem3_constant-sigma0", lambda: theory.theorem3_constant(-1.0, 5, 10, 0.9, 1.0, 2.0, 3.0, 0.25, 100.0), "sigma0 must be >= 0"),
    case("theorem3_constant-w", lambda: theory.theorem3_constant(1.0, 5, 10, 0.9, 1.0, 2.0, 3.0, -0.25, 100.0), "w_max_sq must be >= 0"),
    case("theorem3_constant-gamma", lambda: theory.theorem3_constant(1.0, 5, 10, 0.9, 1.0, 2.0, 3.0, 0.25, 1.0), "gamma >= gamma_c_W"),
    # the checks
    case("lemma6_margins-traj", lambda: checks.lemma6_margins("traj", 4, W1, 1.0, 2.0, 3.0), "traj must be an orrc Trajectory"),
    case("lemma6_margins-M", lambda: checks.lemma6_margins(_traj(), 5, W1, 1.0, 2.0, 3.0), "M=5", "M_c=4"),
    case("lemma6_margins-W", lambda: checks.lemma6_margins(_traj(), 4, orrc.Box(-1, 1, 2), 1.0, 2.0, 3.0), "W must have the state"),
    case("minmax_value_bound_margins-alpha", lambda: checks.minmax_value_bound_margins(_traj(), 4, W1, 0.0, 3.0), "alpha_hi_W must be > 0"),
    case("theorem3_margin-threshold", lambda: checks.theorem3_margin(_traj(), 4, W1, 0.5, 1.0, 2.0, 3.0, 1e6), "M=4", "threshold"),
    # the constants
    case("minmax_constants-M", lambda: certify.minmax_constants(SYS, COST, 1, W1), "M must be an integer >= 2"),
    case("minmax_constants-W-zero", lambda: certify.minmax_constants(SYS, COST, 4, orrc.Box(0.0, 0.0)), "non-zero disturbance"),
    case("minmax_constants-samples", lambda: certify.minmax_constants(SYS, COST, 4, W1, n_samples=0), "n_samples must be an integer >= 1"),
    case("minmax_constants-radius", lambda: certify.minmax_constants(SYS, COST, 4, W1, x_radius=-1.0), "x_radius must be > 0"),
    case("minmax_constants-W-type", lambda: certify.minmax_constants(SYS, COST, 4, [0.3]), "W must be"),
    case("minmax_constants-no-alpha-lo", lambda: certify.minmax_constants(SYS, orrc.Cost(lambda x, u: x[0] ** 2 + u[0] ** 2,
                                                                                  1, 1), 4, W1), "alpha_lo"),
    case("minmax_constants-policy", lambda: certify.minmax_constants(SYS, COST, 4, W1, policy="closed"),
         "policy must be", "'closed'"),
    # feedback min-max (the scenario tree) and the max-min value
    case("MinMaxRHC-policy", lambda: _rhc(policy="closed-loop"), "policy must be one of", "'closed-loop'"),
    case("MinMaxRHC-feedback-tree-too-large", lambda: _rhc(M=40, policy="feedback"), "M=40", "2 vertices",
         "limit is"),
    case("MinMaxRHC-feedback-nonlinear", lambda: orrc.MinMaxRHC(PEND.system, PEND.cost, 3, orrc.Box(-0.1, 0.1, 2),
                                                               policy="feedback"), "policy='feedback' needs a LinearSystem"),
    case("MinMaxRHC-feedback-ball", lambda: _rhc(W=orrc.Ball(0.3, 1), policy="feedback"), "polytope W", "Ball"),
    case("MinMaxRHC-feedback-method", lambda: _rhc(policy="feedback", method="game"), "method must be 'auto' or 'exact'"),
    case("MinMaxRHC-open-loop-polytope", lambda: _rhc(W=orrc.Polytope([[-0.3], [0.3]])), "orrc.Polytope",
         "policy='feedback'"),
    case("Polytope-shape", lambda: orrc.Polytope([0.1, 0.2]), "vertices"),
    case("Polytope-empty", lambda: orrc.Polytope(np.zeros((0, 2))), "vertices", "k >= 1"),
    case("Polytope-nan", lambda: orrc.Polytope([[np.nan]]), "vertices"),
    case("maxmin_value-M", lambda: certify.maxmin_value(SYS, COST, 0, W1), "M must be an integer >= 1"),
    case("maxmin_value-too-many", lambda: certify.maxmin_value(SYS, COST, 40, W1), "M=40", "limit is"),
    case("maxmin_value-nonlinear", lambda: certify.maxmin_value(PEND.system, PEND.cost, 3, orrc.Box(-0.1, 0.1, 2)),
         "maxmin_value"),
    case("lemma6_case-policy", lambda: certify.lemma6_case(SYS, COST, 3, W1, policy="x"), "policy must be"),
    case("lemma6_search-policy", lambda: certify.lemma6_search(n=1, n_problems=1, policy="x"), "policy must be"),
]


@pytest.mark.parametrize("call, exc, words", params(CASES))
def test_bad_input_gets_a_clear_error(call, exc, words):
    assert_bad_input(call, exc, words)
