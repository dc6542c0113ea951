"""Bad input to the min-max pieces (Algorithm 3, Lemma 6, Theorem 3): a clear orrc.OrrcValueError.

One table: each case is a zero-argument callable, the exception expected, and the words its
message must contain (at least the argument's name).
"""
import numpy as np
import pytest

import orrc
from orrc import certify, checks, theory
from orrc.solvers.minmax import check_set

EX = orrc.examples.scalar_unstable(a=1.2)
SYS, COST = EX.system, EX.cost
PEND = orrc.examples.inverted_pendulum()
W1 = orrc.Box(-0.3, 0.3)
E = orrc.OrrcValueError


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
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, orrc.Box(-1, 1, 2)), E, ["W", "dimension n=1"], "W-wrong-dimension"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, orrc.Ball(0.1, 3)), E, ["W", "n=1"], "ball-wrong-dimension"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, (-0.3, 0.3)), E, ["W must be an orrc.Box", "tuple"], "W-not-a-set"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, None), E, ["W must be", "NoneType"], "W-none"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, orrc.Box(1.0, -1.0)), E, ["lo <= hi"], "W-empty-box"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, _box(lo=0.5)), E, ["W is empty", "lo <= hi"], "W-emptied-box"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, orrc.Box(-np.inf, 1.0)), E, ["lo", "finite"], "W-unbounded-box"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, _box(hi=np.inf)), E, ["W must be bounded"], "W-unbounded-mutated"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, orrc.Ball(np.inf, 1)), E, ["radius", "finite"], "W-unbounded-ball"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 0, W1), E, ["M must be an integer >= 1", "0"], "M-zero"),
    (lambda: orrc.MinMaxRHC(SYS, COST, -3, W1), E, ["M must be an integer >= 1"], "M-negative"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 2.5, W1), E, ["M must be an integer", "2.5"], "M-float"),
    (lambda: orrc.MinMaxRHC("sys", COST, 4, W1), E, ["system must be"], "system-type"),
    (lambda: orrc.MinMaxRHC(SYS, "cost", 4, W1), E, ["cost must be"], "cost-type"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, method="best"), E, ["method must be one of", "best"], "method-unknown"),
    (lambda: orrc.MinMaxRHC(PEND.system, PEND.cost, 4, orrc.Box(-0.1, 0.1, 2), method="exact"), E,
     ["method='exact' needs a LinearSystem", "exchange"], "exact-nonlinear"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, orrc.Ball(0.3, 1), method="exact"), E, ["method='exact'", "box W"],
     "exact-ball"),
    (lambda: orrc.MinMaxRHC(orrc.LinearSystem(np.eye(2), np.ones((2, 1))), orrc.QuadraticCost(np.eye(2), [[1.0]]), 12,
                            orrc.Box(-1, 1, 2), method="exact"), E, ["4^(M-1) = 4194304", "max_sequences=262144",
                                                                     "MB", "method='exchange'"], "too-many-vertices"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 6, W1, method="exact", max_sequences=16), E, ["32 vertex sequences",
                                                                                   "max_sequences=16"],
     "too-many-vertices-own-limit"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, input_bounds=(1.0, -1.0)), E, ["input_bounds", "lo <= hi"],
     "input-bounds-reversed"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, tol=0.0), E, ["tol must be > 0"], "tol-zero"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, tol=np.nan), E, ["tol must be finite"], "tol-nan"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, method="exchange", exchange_options={"starts": 3}), E,
     ["unknown exchange_options", "starts"], "exchange-option-unknown"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, method="exchange", exchange_options={"n_starts": 0}), E,
     ["exchange_options['n_starts']", ">= 1"], "exchange-option-range"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, method="exchange", exchange_options={"solver": "snopt"}), E,
     ["exchange_options['solver']", "snopt"], "exchange-solver"),
    (lambda: orrc.MinMaxRHC(SYS, COST, 4, W1, exchange_options=[1]), E, ["exchange_options must be a dict"],
     "exchange-options-type"),
    # a disturbance preview handed to it
    (lambda: _rhc().plan(np.array([1.0]), w_preview=np.zeros((4, 1))), E, ["no disturbance preview", "w_preview"],
     "plan-w-preview-keyword"),
    (lambda: _rhc().plan(np.array([1.0]), np.zeros((4, 1))), E, ["cost_params", "like a disturbance preview"],
     "plan-w-preview-positional"),
    (lambda: _rhc().control(orrc.Observation(0, np.array([1.0]), None, np.zeros((4, 1)), None)), E,
     ["disturbance preview of shape (4, 1)", "preview_w = 0"], "control-w-preview"),
    (lambda: _rhc().plan(np.array([1.0]), foo=1), E, ["unknown arguments", "foo"], "plan-unknown-argument"),
    (lambda: _rhc().plan(np.array([1.0, 2.0])), E, ["x must have shape (1)", "(2,)"], "plan-x-shape"),
    (lambda: _rhc().plan(np.array([np.nan])), E, ["x must be finite"], "plan-x-nan"),
    (lambda: _rhc().plan(np.array([1.0]), np.ones((2, 2))), E, ["cost_params must have at least M=4 rows"],
     "plan-cost-params-short"),
    (lambda: _rhc().plan(np.array([1.0]), warm_start="plan"), E, ["warm_start must be a MinMaxPlan"], "warm-start"),
    # the set check of the solvers
    (lambda: check_set(orrc.Box(-1, 1, 2), 3), E, ["W must have the state dimension n=3"], "check-set-dim"),
    # Lemma 6, Theorem 3
    (lambda: theory.Gamma_WV(1, 1.0, 2.0), E, ["M must be an integer >= 2"], "Gamma_WV-M"),
    (lambda: theory.Gamma_WV(5, 0.0, 2.0), E, ["alpha_lo must be > 0"], "Gamma_WV-alpha_lo"),
    (lambda: theory.Gamma_WV(5, 2.0, 1.0), E, ["alpha_lo must be <= alpha_hi_W"], "Gamma_WV-order"),
    (lambda: theory.Gamma_WV_gamma(5, 1.0, 2.0, -1.0), E, ["gamma_bar_W must be > 0"], "Gamma_WV_gamma-gb"),
    (lambda: theory.Gamma_WV_gamma(5, 1.0, np.inf, 1.0), E, ["alpha_hi_W must be finite"], "Gamma_WV_gamma-inf"),
    (lambda: theory.horizon_threshold_W(1.0, "2"), E, ["alpha_hi_W must be a real number"], "threshold-type"),
    (lambda: theory.min_decay_rate_W(4, 1.0, 2.0), E, ["M=4", "threshold", "Theorem 3"], "decay-below-threshold"),
    (lambda: theory.decay_b_W(1.0, 2.0, 0.0), E, ["gamma_bar_W must be > 0"], "decay_b_W-gb"),
    (lambda: theory.gamma_c_W(10, 1.0, 1.0, 2.0, 3.0), E, ["a must lie in [min_decay_rate_W, 1)"], "gamma_c_W-a"),
    (lambda: theory.gamma_c_W(10, 0.9, 1.0, 2.0, 3.0 + 0j), E, ["gamma_bar_W must be a real number"],
     "gamma_c_W-complex"),
    (lambda: theory.theorem3_constant(1.0, 0, 10, 0.9, 1.0, 2.0, 3.0, 0.25, 100.0), E, ["T must be an integer >= 1"],
     "theorem3-T"),
    (lambda: theory.theorem3_constant(-1.0, 5, 10, 0.9, 1.0, 2.0, 3.0, 0.25, 100.0), E, ["sigma0 must be >= 0"],
     "theorem3-sigma0"),
    (lambda: theory.theorem3_constant(1.0, 5, 10, 0.9, 1.0, 2.0, 3.0, -0.25, 100.0), E, ["w_max_sq must be >= 0"],
     "theorem3-w"),
    (lambda: theory.theorem3_constant(1.0, 5, 10, 0.9, 1.0, 2.0, 3.0, 0.25, 1.0), E, ["gamma >= gamma_c_W"],
     "theorem3-gamma"),
    # the checks
    (lambda: checks.lemma6_margins("traj", 4, W1, 1.0, 2.0, 3.0), E, ["traj must be an orrc Trajectory"],
     "lemma6-traj"),
    (lambda: checks.lemma6_margins(_traj(), 5, W1, 1.0, 2.0, 3.0), E, ["M=5", "M_c=4"], "lemma6-M"),
    (lambda: checks.lemma6_margins(_traj(), 4, orrc.Box(-1, 1, 2), 1.0, 2.0, 3.0), E, ["W must have the state"],
     "lemma6-W"),
    (lambda: checks.minmax_value_bound_margins(_traj(), 4, W1, 0.0, 3.0), E, ["alpha_hi_W must be > 0"],
     "value-bound-alpha"),
    (lambda: checks.theorem3_margin(_traj(), 4, W1, 0.5, 1.0, 2.0, 3.0, 1e6), E, ["M=4", "threshold"],
     "theorem3-margin-threshold"),
    # the constants
    (lambda: certify.minmax_constants(SYS, COST, 1, W1), E, ["M must be an integer >= 2"], "constants-M"),
    (lambda: certify.minmax_constants(SYS, COST, 4, orrc.Box(0.0, 0.0)), E, ["non-zero disturbance"],
     "constants-W-zero"),
    (lambda: certify.minmax_constants(SYS, COST, 4, W1, n_samples=0), E, ["n_samples must be an integer >= 1"],
     "constants-samples"),
    (lambda: certify.minmax_constants(SYS, COST, 4, W1, x_radius=-1.0), E, ["x_radius must be > 0"],
     "constants-radius"),
    (lambda: certify.minmax_constants(SYS, COST, 4, [0.3]), E, ["W must be"], "constants-W-type"),
    (lambda: certify.minmax_constants(SYS, orrc.Cost(lambda x, u: x[0] ** 2 + u[0] ** 2, 1, 1), 4, W1), E,
     ["alpha_lo"], "constants-no-alpha-lo"),
]


@pytest.mark.parametrize("call, exc, words", [c[:3] for c in CASES], ids=[c[3] for c in CASES])
def test_bad_input_is_a_clear_error(call, exc, words):
    with pytest.raises(exc) as info:
        call()
    assert isinstance(info.value, ValueError)
    for word in words:
        assert word in str(info.value), f"{word!r} not in {str(info.value)!r}"
