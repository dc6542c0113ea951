"""Bad input by class across the newer API: each class of failure, on every public function it
applies to, gets a clear ``orrc.OrrcValueError`` naming the argument (or a warning where the input is valid
and the result overflows).

The classes, in the order of the table:

1. **sizes estimated before the work starts**: a computation whose size is an argument is refused with its
   estimate, before it allocates or loops (these cases return at once: a guard that ran too late would
   exhaust memory or hang instead of failing);
2. **no silent reinterpretation**: a string is not a truth value, a float is not a count, extra experiments
   are not dropped;
3. **finite arguments, finite results**: the formulas of Section 5.2 (``orrc.theory.unknown``) and of
   Section 5.3 (``orrc.theory.nopreview``) refuse, naming every argument, where the float range overflows;
4. **arguments checked before numpy, CasADi or scipy sees them**: seeds, warm starts, plan arguments,
   matrices, the problem of a sweep;
5. **dimensions checked before the first step**, and non-finite results said out loud.

One table in the format of ``tests/bad_input.py``, then the tests of the valid edge cases of the same classes.
"""
import warnings

import numpy as np
import pytest

import orrc
from bad_input import assert_bad_input, case, params
from orrc import certify, estimation as est
from orrc.comparison import compare, preview_value
from orrc.controllers.gpc import best_fixed_policy, strong_stability
from orrc.solvers import game
from orrc.theory import nopreview as nop, unknown as unk
from orrc.tradeoff import Tradeoff, exploration_tradeoff

SYS = orrc.LinearSystem([[1.2]], [[1.0]])
QC = orrc.QuadraticCost([[1.0]], [[1.0]])
SYS2 = orrc.LinearSystem([[1.0, 0.1], [0.0, 1.0]], [[0.0], [0.1]])
QC2 = orrc.QuadraticCost(np.eye(2), [[0.1]])
SYS4 = orrc.LinearSystem(0.9 * np.eye(4), np.ones((4, 1)))
QC4 = orrc.QuadraticCost(np.eye(4), [[1.0]])
LIN = orrc.ParametricSystem.linear(1, 1)
W1 = orrc.Box(-0.3, 0.3)
BIG = 10 ** 9


def lifted():
    X = np.random.default_rng(0).standard_normal((11, 1)) * 0.5
    model = est.edmd(X, np.ones((10, 1)), est.polynomial_dictionary(1, 2))
    return orrc.LiftedRHC(model, QC, 3)


def minmax_plan(M):
    return orrc.MinMaxRHC(SYS, QC, M, W1, method="exact").plan(np.array([1.0]))


def tradeoff_record():
    Ns = np.array([4.0, 8.0, 16.0])
    z = np.zeros((1, 3))
    return Tradeoff(Ns=Ns, explore_cost=z, known_cost=z, transient=z, loss=z + 1.0, errors=z, c0=1.0, window=10,
                    burn_in=2, fit={"slope_e": 1.0, "offset_e": 0.0, "kappa": 1.0, "p": 0.5})


def all_solves_fail():
    pend = orrc.examples.inverted_pendulum()
    return certify.sampled_constants(pend.system, pend.cost, 3, n_samples=1, x_radius=1.0,
                                     solver_options={"ipopt.max_iter": 0, "sqpmethod.max_iter": 0})


# the arguments of Lemma 4-5 and of Theorem 3 (valid), for the overflow cases below
L45 = dict(alpha_V=1.0, alpha_kappa=1.0, alpha_c=1.0, alpha_tilde_f=1.0)

CASES = [
    # 1. sizes estimated before the work starts ------------------------------------------------------
    case("worst_case_regret-T-too-large", lambda: certify.worst_case_regret(SYS4, orrc.LQR(SYS4, QC4), 5000),
         "worst_case_regret", "T=5000", "too large"),
    case("sweep-grid-before-seeds", lambda: orrc.sweep(lambda a, b, seed: 0, {"a": range(10 ** 5), "b": range(10 ** 5)},
                                                       seeds=10 ** 6), "orrc.sweep", "seeds", "too large"),
    case("sweep-grid-before-common-seeds", lambda: orrc.sweep(lambda a, seed: 0, {"a": range(10 ** 6)}, seeds=10 ** 9,
                                                              common_seeds=True), "orrc.sweep", "seeds", "too large"),
    case("gaussian-N-too-large", lambda: est.gaussian(BIG, 4), "N=1000000000", "too large"),
    case("prbs-N-too-large", lambda: est.prbs(BIG, 4), "N=1000000000", "too large"),
    case("multisine-N-too-large", lambda: est.multisine(10 ** 8, 4), "N=100000000", "too large"),
    case("EstimateThenControl-default-excitation-too-large", lambda: orrc.EstimateThenControl(LIN, QC, 3, BIG),
         "N=1000000000", "too large"),
    case("MinMaxRHC-game-M-too-large", lambda: orrc.MinMaxRHC(SYS, QC, BIG, W1, method="game", gamma=50.0),
         "M=1000000000", "too large"),
    case("MinMaxRHC-exchange-M-too-large", lambda: orrc.MinMaxRHC(SYS, QC, 10 ** 7, W1, method="exchange"),
         "M=10000000", "too large"),
    case("finite_horizon_game-M-too-large", lambda: game.finite_horizon_game([[1.2]], [[1.0]], [[1.0]], [[1.0]], 50.0,
                                                                             BIG),
         "M=1000000000", "too large"),
    case("HInfinity-preview-too-large", lambda: orrc.HInfinity(SYS4, QC4, preview=2000), "preview=2000", "too large"),
    case("MinMaxRHC-exact-M-too-large", lambda: orrc.MinMaxRHC(SYS, QC, BIG, W1, method="exact"), "M=1000000000",
         "inf vertex sequences", "too large"),
    case("minmax_constants-n_samples-too-large", lambda: certify.minmax_constants(SYS, QC, 3, W1, n_samples=BIG),
         "n_samples=1000000000", "too large"),
    case("minmax_constants-grid-too-large", lambda: certify.minmax_constants(SYS, QC, 3, W1, n_samples=3, grid=BIG),
         "grid=1000000000", "too large"),
    case("sampled_constants-grid-too-large", lambda: certify.sampled_constants(SYS, QC, 3, n_samples=2, grid=BIG),
         "grid=1000000000", "too large"),
    case("optimal_game_level-n-too-large", lambda: game.optimal_game_level(np.eye(2000), np.ones((2000, 1)),
                                                                           np.eye(2000), [[1.0]]), "n=2000",
         "too large"),
    case("EstimateThenControl-M-too-large", lambda: orrc.EstimateThenControl(LIN, QC, BIG, 4), "EstimateThenControl",
         "M=1000000000", "too large"),
    case("GPC-H-too-large", lambda: orrc.GPC(SYS, QC, H=BIG), "H=1000000000", "too large"),
    case("best_fixed_policy-T-H-too-large", lambda: best_fixed_policy(SYS, QC, np.zeros((10 ** 6, 1)), 10 ** 6, 1000),
         "T=1000000", "H=1000", "too large"),
    case("EDMDModel.predict-h-too-large", lambda: lifted().model.predict([0.0], np.zeros((10 ** 8, 1))),
         "h=100000000", "too large"),

    # 2. no silent reinterpretation ------------------------------------------------------------------
    case("GPC-decay-string", lambda: orrc.GPC(SYS, QC, decay="no"), "decay", "True or False", "'no'"),
    case("EstimateThenControl-use_w-string", lambda: orrc.EstimateThenControl(LIN, QC, 3, 4, use_w="no"), "use_w",
         "True or False"),
    case("polynomial_dictionary-include_constant-int", lambda: est.polynomial_dictionary(1, 2, include_constant=1),
         "include_constant", "True or False"),
    case("rbf_dictionary-include_constant-string", lambda: est.rbf_dictionary([[0.0]], 1.0, include_constant="yes"),
         "include_constant", "True or False"),
    case("compare-worst_case-string", lambda: compare(SYS, QC, {"lqr": orrc.LQR(SYS, QC)}, np.zeros((5, 1)), 5, 1.0,
                                                      worst_case="no"), "worst_case", "True or False"),
    case("Tradeoff.best_N-fitted-string", lambda: tradeoff_record().best_N([100], fitted="no"), "fitted",
         "True or False"),
    case("exploration_tradeoff-use_w-string", lambda: exploration_tradeoff(SYS, LIN, QC, 2, np.array([4, 6, 8]),
                                                                           seeds=1, window=10, use_w="no"), "use_w"),
    case("preview_value-float-horizon", lambda: preview_value(SYS, QC, 3, [0, 1.5, 2], np.zeros((10, 1)), 5),
         "ks[1]", "integer", "1.5"),
    case("preview_value-ks-string", lambda: preview_value(SYS, QC, 3, "012", np.zeros((10, 1)), 5), "ks", "list"),
    case("prediction_error-extra-experiments", lambda: est.prediction_error(SYS, [np.zeros((6, 1))] * 2,
                                                                            [np.zeros((5, 1))], horizon=2),
         "X, U and W", "same number of experiments", "2, 1"),

    # 3. finite arguments, finite results (Section 5.2 and 5.3) ---------------------------------------
    case("alpha_f_tilde-overflow", lambda: unk.alpha_f_tilde(1e10, 100), "alpha_f_tilde", "alpha_f_S=", "M=100"),
    case("Gamma_V_theta-overflow", lambda: unk.Gamma_V_theta(3, 1e-300, 1e300, 1e300, 1e300, 1.0, 1.0),
         "Gamma_V_theta", "alpha_lo=1e-300", "not finite"),
    case("lemma4_bound-overflow", lambda: unk.lemma4_bound(1.0, 1.0, 1e308, 3, 1.0, 1.0, 1.0, **L45),
         "lemma4_bound", "theta_error=1e+308", "not finite"),
    case("lemma5_c-overflow", lambda: unk.lemma5_c(3, 0.9, 1.0, 1.0, 1e308, 1e308, 1.0, 1.0), "lemma5_c",
         "alpha_V=1e+308", "not finite"),
    case("lemma5_M_theta-overflow", lambda: unk.lemma5_M_theta(5, 0.5, 1e308, 1.0), "lemma5_M_theta", "c=1e+308",
         "not finite"),
    case("lemma5_bound-overflow", lambda: unk.lemma5_bound(1.0, np.ones(6), 1e308, 3, 4, 0.9, 1.0, 1.0, 1.0, **L45),
         "lemma5_bound", "theta_error=1e+308", "not finite"),
    case("theorem2_constant-overflow", lambda: unk.theorem2_constant(np.ones(2), np.ones((10, 1)), 1e308, 1e308, 5, 2,
                                                                     3, 0.9, 1.0, 1.0, 1.0, 1e3, **L45),
         "theorem2_constant", "theta_error=1e+308", "not finite"),
    case("Gamma_WV-overflow", lambda: nop.Gamma_WV(3, 1e-300, 1e300), "Gamma_WV", "alpha_hi_W=1e+300", "not finite"),
    case("Gamma_WV_gamma-overflow", lambda: nop.Gamma_WV_gamma(3, 1e-300, 1e300, 1e300), "Gamma_WV_gamma",
         "gamma_bar_W=1e+300", "not finite"),
    case("horizon_threshold_W-overflow", lambda: nop.horizon_threshold_W(1e-200, 1.0), "horizon_threshold_W",
         "alpha_lo=1e-200", "not representable"),
    case("decay_b_W-overflow", lambda: nop.decay_b_W(1.0, 1.0, 1e308), "decay_b_W", "gamma_bar_W=1e+308", "not finite"),
    case("gamma_c_W-overflow", lambda: nop.gamma_c_W(3, 0.9, 1.0, 1.0, 1e308), "gamma_c_W", "gamma_bar_W=1e+308",
         "not finite"),
    case("theorem3_constant-overflow", lambda: nop.theorem3_constant(1e308, 5, 3, 0.9, 1.0, 1.0, 1.0, 1.0, 1e3),
         "theorem3_constant", "sigma0=1e+308", "not finite"),

    # 4. arguments checked before numpy, CasADi or scipy -----------------------------------------------
    case("MinMaxRHC-exchange-seed-negative", lambda: orrc.MinMaxRHC(SYS, QC, 3, W1, method="exchange", seed=-1),
         "seed", "non-negative integer"),
    case("MinMaxRHC-seed-string", lambda: orrc.MinMaxRHC(SYS, QC, 3, W1, method="exact", seed="one"), "seed", "'one'"),
    case("sampled_lipschitz-seed", lambda: certify.sampled_lipschitz(LIN, QC, 3, [1.2, 1.0], 0.1, n_samples=1,
                                                                     seed=-3), "seed", "-3"),
    case("lq_lipschitz-seed", lambda: certify.lq_lipschitz(SYS, QC, 3, 0.1, 1.0, points=4, seed=1.5), "seed", "1.5"),
    case("MinMaxRHC.plan-warm_start-other-horizon", lambda: orrc.MinMaxRHC(SYS, QC, 4, W1, method="exact").plan(
        [1.0], warm_start=minmax_plan(3)), "warm_start.inputs", "(4, 1)", "(3, 1)"),
    case("LiftedRHC.plan-x-shape", lambda: lifted().plan([1.0, 2.0], np.zeros((3, 1))), "x", "shape (1)"),
    case("LiftedRHC.plan-w_preview-type", lambda: lifted().plan([1.0], "none"), "w_preview", "numeric"),
    case("LiftedRHC.plan-w_preview-shape", lambda: lifted().plan([1.0], np.zeros((2, 1))), "w_preview", "(3, 1)"),
    case("strong_stability-non-square", lambda: strong_stability(np.ones((2, 3))), "A_cl", "square"),
    case("strong_stability-unstable", lambda: strong_stability([[1.5]]), "A_cl", "Schur stable", "ρ = 1.5"),
    case("strong_stability-non-finite", lambda: strong_stability([[np.nan]]), "A_cl", "finite"),
    case("exploration_tradeoff-system", lambda: exploration_tradeoff("sys", LIN, QC, 2, np.array([4, 6, 8]), seeds=1,
                                                                     window=10), "system", "str"),
    case("exploration_tradeoff-model-kind", lambda: exploration_tradeoff(SYS, SYS, QC, 2, np.array([4, 6, 8]), seeds=1,
                                                                         window=10), "model", "LinearSystem"),
    case("exploration_tradeoff-model-dimension", lambda: exploration_tradeoff(
        SYS, orrc.ParametricSystem.linear(2, 1), QC, 2, np.array([4, 6, 8]), seeds=1, window=10), "model", "n=2"),

    case("L1Cost.value-x-shape", lambda: orrc.L1Cost([1.0, 2.0], [[0.1]]).value([1.0], [0.0]), "x", "shape (2)"),
    case("L1Cost.value-u-type", lambda: orrc.L1Cost([1.0], [[0.1]]).value([1.0], "u"), "u", "numeric"),
    case("L1Cost.value-overflow", lambda: orrc.L1Cost([1.0, 1.0], [[0.1]]).value([1e308, 1e308], [0.0]), "l1 cost",
         "not finite"),
    case("L1Cost.sigma-x-shape", lambda: orrc.L1Cost([1.0, 2.0], [[0.1]]).sigma([1.0, 2.0, 3.0]), "x", "shape (2)"),
    case("stationary_game-gamma", lambda: game.stationary_game([[1.2]], [[1.0]], [[1.0]], [[1.0]], -1.0), "gamma",
         "> 0"),
    case("optimal_game_level-A-nan", lambda: game.optimal_game_level([[np.nan]], [[1.0]], [[1.0]], [[1.0]]), "A",
         "finite"),
    case("check_stabilisable-A-type", lambda: game.check_stabilisable("A", [[0.0]]), "A", "numeric"),
    case("check_stabilisable-B-shape", lambda: game.check_stabilisable([[2.0]], [[0.0], [1.0]]), "B", "(1, any)"),
    case("FailureLadder-max_failures", lambda: orrc.controllers.FailureLadder(3, max_failures=0), "max_failures",
         ">= 1"),

    # messages name the argument given, by its own name
    case("theorem2_constant-sigma_N-named", lambda: unk.theorem2_constant(np.ones(2), np.ones((10, 1)), -1.0, 0.1, 5, 2,
                                                                          3, 0.9, 1.0, 1.0, 1.0, 1e3, **L45),
         "sigma_N", ">= 0"),
    case("theorem2_constant-M-type", lambda: unk.theorem2_constant(np.ones(2), np.ones((10, 1)), 1.0, 0.1, 5, 2, "3",
                                                                   0.9, 1.0, 1.0, 1.0, 1e3, **L45), "M", "integer"),
    case("theorem2_constant-estimation_costs-type", lambda: unk.theorem2_constant(
        "zz", np.ones((10, 1)), 1.0, 0.1, 5, 2, 3, 0.9, 1.0, 1.0, 1.0, 1e3, **L45), "estimation_costs", "numeric"),
    case("gamma_c_W-gamma_bar_W-none", lambda: nop.gamma_c_W(3, 0.9, 1.0, 1.0, None), "gamma_bar_W", "None"),
    case("GPC-system-none", lambda: orrc.GPC(None, QC), "system", "NoneType"),
    case("MinMaxRHC-system-none", lambda: orrc.MinMaxRHC(None, QC, 3, W1), "system", "NoneType"),
    case("HInfinity-system-none", lambda: orrc.HInfinity(None, QC), "system", "NoneType"),

    # 5. dimensions before the first step, non-finite results said --------------------------------------
    case("EstimateThenControl-other-dimension", lambda: orrc.simulate(
        SYS2, orrc.EstimateThenControl(LIN, QC, 3, 40), np.zeros(2), np.zeros((50, 2)), 45), "n=1", "n=2"),
    case("sampled_constants-every-solve-fails", all_solves_fail, "too few successful solves", "3 of 3 failed"),
]


@pytest.mark.parametrize("call, exc, words", params(CASES))
def test_bad_input_gets_a_clear_error_naming_the_argument(call, exc, words):
    assert_bad_input(call, exc, words)


def test_the_valid_extreme_constants_answer_as_in_the_known_system_theory():
    """α_lo = ᾱ = 1e-200 is valid and its answers are representable: the threshold is 2, a_min at M = 3 is 1/2."""
    th = orrc.theory
    assert th.horizon_threshold(1e-200, 1e-200) == th.horizon_threshold_W(1e-200, 1e-200) == 2.0
    assert th.above_threshold(3, 1e-200, 1e-200) and not th.above_threshold(2, 1e-200, 1e-200)
    assert th.min_decay_rate(3, 1e-200, 1e-200) == th.min_decay_rate_W(3, 1e-200, 1e-200) == pytest.approx(0.5)
    assert th.Gamma_V(3, 1e-200, 1e-200) == th.Gamma_WV(3, 1e-200, 1e-200) == pytest.approx(-0.5e-200, rel=1e-12)
    tiny, unit = (unk.lemma5_c(3, 0.5, s, s, 1.0, 1.0, 1.0, 1.0) for s in (1e-200, 1.0))
    scale = tiny / unit
    assert scale == pytest.approx(1.0, rel=1e-12), "c depends on α_lo and ᾱ only through their ratio here"


def test_an_unstable_lifted_prediction_warns_where_it_overflows():
    model = lifted().model
    model_unstable = type(model)(**{**model.__dict__, "A": 1e3 * np.eye(model.K)})
    with pytest.warns(orrc.NonFiniteWarning, match="overflows the float range from step"):
        X = model_unstable.predict([1.0], np.zeros((200, 1)))
    assert not np.all(np.isfinite(X)) and np.all(np.isfinite(X[:5]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")               # a stable prediction says nothing
        assert np.all(np.isfinite(model.predict([0.1], np.zeros((5, 1)))))


def test_a_huge_grid_is_refused_before_its_seeds_are_drawn(monkeypatch):
    """The sweep derives no seed before the size check (drawing them was the hang)."""
    drawn = []

    class Recording(np.random.SeedSequence):
        def spawn(self, k):
            drawn.append(k)
            return super().spawn(k)

    monkeypatch.setattr(np.random, "SeedSequence", Recording)
    with pytest.raises(orrc.OrrcValueError, match="too large"):
        orrc.sweep(lambda a, seed: 0, {"a": range(10 ** 9)}, seeds=2)
    assert drawn == []


def test_the_seeds_of_a_sweep_are_those_of_spawning_every_point():
    """The lazy seeds are the children of SeedSequence(seed).spawn(n_points), as before the change."""
    table = orrc.sweep(lambda a, seed: seed, {"a": [1, 2, 3]}, seeds=2, seed=7, backend="serial")
    children = np.random.SeedSequence(7).spawn(3)
    want = [int(c.generate_state(1, np.uint64)[0] >> np.uint64(1)) for p in children for c in p.spawn(2)]
    assert [row["value"] for row in table] == want
