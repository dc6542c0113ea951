"""Bad input to the unknown-system half of orrc: a clear error naming the argument.

One table of cases in the format of ``tests/bad_input.py``: ParametricSystem, L1Cost, Algorithm 2, the
estimators of ``orrc.estimation``, Lemma 3's constants, the theory and checks of Section 5.2 and the
exploration trade-off, given wrong shapes and types, non-finite values, values out of range and
computations too large to run.
"""
import casadi as ca
import numpy as np
import pytest

import orrc
from bad_input import assert_bad_input, case, params
from orrc import certify, checks, estimation as est, theory
from orrc.tradeoff import exploration_tradeoff

LIN = orrc.ParametricSystem.linear(1, 1)
SYS = orrc.LinearSystem([[0.5]], [[1.0]])
QC = orrc.QuadraticCost([[1.0]], [[0.1]])
NAN = float("nan")


def pend():
    return orrc.ParametricSystem(lambda x, u, w, th: ca.vertcat(x[0] + 0.1 * x[1], x[1] + th[0] * u[0]) + w, 2, 1, 1)


def xu(N=5, n=1, m=1):
    return np.zeros((N + 1, n)), np.ones((N, m))


def vdp_model():
    X = np.random.default_rng(0).standard_normal((11, 2)) * 0.5
    return est.edmd(X, np.ones((10, 1)), est.polynomial_dictionary(2, 2))


def etc_traj():
    etc = orrc.EstimateThenControl(LIN, QC, 3, 4)
    return orrc.simulate(SYS, etc, np.zeros(1), np.zeros((20, 1)), 10)


def tradeoff():
    t = exploration_tradeoff(SYS, LIN, orrc.L1Cost([1.0], [[0.1]]), 2, np.array([4, 6, 8]), seeds=1, window=10,
                             excitation_amplitude=0.5)
    return t


CASES = [
    # ParametricSystem
    case("ParametricSystem-f", lambda: orrc.ParametricSystem(3, 1, 1, 1), "f must be callable"),
    case("ParametricSystem-n_states", lambda: orrc.ParametricSystem(lambda x, u, w, t: x, 0, 1, 1), "n_states"),
    case("ParametricSystem-name", lambda: orrc.ParametricSystem(lambda x, u, w, t: x, 1, 1, 1, name=3), "name must be"),
    case("ParametricSystem-n_params", lambda: orrc.ParametricSystem(lambda x, u, w, t: x, 1, 1, 0), "n_params"),
    case("ParametricSystem-math-sin", lambda: orrc.ParametricSystem(lambda x, u, w, t: x * float("nan") + t[0], 1, 1,
                                                                     1), "not finite"),
    case("ParametricSystem-not-casadi", lambda: orrc.ParametricSystem(lambda x, u, w, t: {"next": x}, 1, 1, 1), "CasADi"),
    case("ParametricSystem-output-length", lambda: orrc.ParametricSystem(lambda x, u, w, t: ca.vertcat(x, x), 1, 1, 1), "n_states=1"),
    case("ParametricSystem-param_names", lambda: orrc.ParametricSystem(lambda x, u, w, t: x, 1, 1, 1, param_names=["a", "b"]),
     "param_names"),
    case("ParametricSystem-step-without-theta", lambda: LIN.step([0.0], [0.0], [0.0]), "without a θ"),
    case("ParametricSystem-at-shape", lambda: LIN.at([1.0]), "theta must have shape"),
    case("ParametricSystem-at-nan", lambda: LIN.at([1.0, NAN]), "theta must be finite"),
    case("LinearParametricSystem-n", lambda: orrc.ParametricSystem.linear(0, 1), "n must be"),
    case("LinearParametricSystem-pack", lambda: LIN.pack(np.eye(2), [[1.0]]), "A must have shape"),
    case("PreviewRHC-theta-missing", lambda: orrc.PreviewRHC(pend(), QC.__class__(np.eye(2), [[1.0]]), 3), "theta is required"),
    case("PreviewRHC-theta-extra", lambda: orrc.PreviewRHC(SYS, QC, 3, theta=[1.0]), "theta is only for"),
    case("PreviewRHC-set_theta", lambda: orrc.PreviewRHC(SYS, QC, 3).set_theta([1.0]), "set_theta needs"),
    case("PreviewRHC-solver-qp", lambda: orrc.PreviewRHC(SYS, QC, 3, solver="qp"), "solver='qp'"),
    # L1Cost
    case("L1Cost-q", lambda: orrc.L1Cost([-1.0], [[1.0]]), "q must be"),
    case("L1Cost-R", lambda: orrc.L1Cost([1.0], [[0.0]]), "R must be positive definite"),
    # excitation
    case("gaussian-N", lambda: est.gaussian(0, 1), "N must be"),
    case("prbs-amplitude", lambda: est.prbs(10, 1, amplitude=0.0), "amplitude must be"),
    case("gaussian-std", lambda: est.gaussian(10, 1, std=-1.0), "std must be"),
    case("multisine-seed", lambda: est.multisine(10, 1, seed="x"), "seed must be"),
    case("prbs-seed-negative", lambda: est.prbs(10, 1, seed=-3), "seed must be"),
    case("prbs-hold", lambda: est.prbs(10, 1, hold=0), "hold must be"),
    case("prbs-too-long", lambda: est.prbs(2 ** 33, 1), "too long for a PRBS"),
    case("multisine-n_freqs", lambda: est.multisine(10, 1, n_freqs=0), "n_freqs"),
    case("excitation-make-kind", lambda: est.excitation.make("chirp", 10, 1), "unknown excitation kind"),
    # data
    case("transitions-X", lambda: est.transitions(np.zeros((1, 1)), np.zeros((0, 1))), "X must have shape"),
    case("transitions-U", lambda: est.transitions(np.zeros((4, 1)), np.zeros((2, 1))), "U must have shape"),
    case("transitions-W", lambda: est.transitions(np.zeros((4, 1)), np.zeros((3, 1)), np.zeros((2, 1))), "W must have shape"),
    case("transitions-nan", lambda: est.transitions(np.full((4, 1), NAN), np.zeros((3, 1))), "X must be finite"),
    case("transitions-lists", lambda: est.transitions([np.zeros((3, 1))], [np.zeros((2, 1))] * 2), "same number of experiments"),
    case("transitions-W-some", lambda: est.transitions([np.zeros((3, 1))] * 2, [np.zeros((2, 1))] * 2, [None, np.zeros((2, 1))]),
     "W must be given for every experiment"),
    # estimators
    case("least_squares_linear-N-short", lambda: est.least_squares_linear(*xu(1)), "N >= n + m = 2"),
    case("least_squares_linear-rank", lambda: est.least_squares_linear(*xu(5)), "rank needed is 2"),
    case("least_squares_linear-true", lambda: est.least_squares_linear(np.random.default_rng(0).standard_normal((6, 1)), np.arange(5.0),
                                                 true=(np.eye(2), [[1.0]])), "true must have A of shape"),
    case("least_squares_linear-rank_deficient", lambda: est.least_squares_linear(np.random.default_rng(0).standard_normal((6, 1)),
                                                        np.arange(5.0), rank_deficient="ignore"), "rank_deficient"),
    case("least_squares_parametric-model", lambda: est.least_squares_parametric(SYS, *xu()), "model must be an orrc.ParametricSystem"),
    case("least_squares_parametric-affine", lambda: est.least_squares_parametric(
        orrc.ParametricSystem(lambda x, u, w, t: x * t[0] ** 2, 1, 1, 1), *xu()), "not affine in theta"),
    case("least_squares_parametric-N-short", lambda: est.least_squares_parametric(LIN, *xu(1)), "N >= ceil(p/n) = 2"),
    # EDMD
    case("Dictionary-psi", lambda: est.Dictionary(None, 2), "psi must be callable"),
    case("Dictionary-no-state", lambda: est.Dictionary(lambda x: x ** 2, 2), "must contain the state"),
    case("Dictionary-labels", lambda: est.Dictionary(lambda x: x, 2, labels=["a"]), "labels must name"),
    case("polynomial_dictionary-too-large", lambda: est.polynomial_dictionary(6, 12), "too large to compute"),
    case("polynomial_dictionary-degree", lambda: est.polynomial_dictionary(2, 0), "degree must be"),
    case("rbf_dictionary-width", lambda: est.rbf_dictionary(np.zeros((2, 2)), 0.0), "width must be"),
    case("rbf_dictionary-centers", lambda: est.rbf_dictionary(np.zeros(3), 1.0), "centers must have shape"),
    case("edmd-dictionary", lambda: est.edmd(*xu(), dictionary="poly"), "dictionary must be"),
    case("edmd-ridge", lambda: est.edmd(*xu(), est.polynomial_dictionary(1, 2), ridge=-1.0), "ridge must be"),
    case("edmd-n", lambda: est.edmd(*xu(5, 2), est.polynomial_dictionary(1, 2)), "X must have n = 1"),
    case("EDMDModel-predict-U", lambda: vdp_model().predict([0.0, 0.0], np.zeros((3, 2))), "U must have shape"),
    case("prediction_error-horizon", lambda: est.prediction_error(SYS, *xu(), horizon=0), "horizon must be"),
    case("prediction_error-short", lambda: est.prediction_error(SYS, *xu(3), horizon=5), "long enough"),
    case("prediction_error-model", lambda: est.prediction_error("model", *xu(), horizon=2), "model must be"),
    # Algorithm 2
    case("EstimateThenControl-model", lambda: orrc.EstimateThenControl(SYS, QC, 3, 5), "model must be an orrc.ParametricSystem"),
    case("EstimateThenControl-N", lambda: orrc.EstimateThenControl(LIN, QC, 3, 0), "N must be"),
    case("EstimateThenControl-N-short", lambda: orrc.EstimateThenControl(LIN, QC, 3, 1), "N >= n + m = 2"),
    case("EstimateThenControl-excitation", lambda: orrc.EstimateThenControl(LIN, QC, 3, 5, excitation=np.ones((3, 1))),
     "excitation must have shape"),
    case("EstimateThenControl-estimator", lambda: orrc.EstimateThenControl(LIN, QC, 3, 5, estimator="ls"), "estimator must be"),
    case("EstimateThenControl-theta_true", lambda: orrc.EstimateThenControl(LIN, QC, 3, 5, theta_true=[1.0]), "theta_true must have"),
    case("EstimateThenControl-EDMD-theta_true", lambda: orrc.EstimateThenControl(est.EDMD(est.polynomial_dictionary(1, 2)), QC, 3, 5,
                                                        theta_true=[1.0]), "theta_true is for"),
    case("EstimateThenControl-affine", lambda: orrc.EstimateThenControl(orrc.ParametricSystem(lambda x, u, w, t: x * t[0] ** 2 + u, 1,
                                                                          1, 1), QC, 3, 5), "not affine in theta"),
    case("EstimateThenControl-exploration_gain", lambda: orrc.EstimateThenControl(LIN, QC, 3, 5, exploration_gain=np.ones((2, 2))),
     "exploration_gain must have shape"),
    case("EstimateThenControl-rank_deficient", lambda: orrc.EstimateThenControl(LIN, QC, 3, 5, rank_deficient="no"), "rank_deficient"),
    case("LiftedRHC-model", lambda: orrc.LiftedRHC(SYS, QC, 3), "model must be a lifted linear model"),
    # Lemma 3's constants
    case("lq_lipschitz-system", lambda: certify.lq_lipschitz(LIN, QC, 3, 0.1, 1.0), "system must be an orrc LinearSystem"),
    case("lq_lipschitz-cost", lambda: certify.lq_lipschitz(SYS, orrc.L1Cost([1.0], [[1.0]]), 3, 0.1, 1.0), "cost must be"),
    case("lq_lipschitz-radius", lambda: certify.lq_lipschitz(SYS, QC, 3, 0.0, 1.0), "radius must be"),
    case("lq_lipschitz-rho", lambda: certify.lq_lipschitz(SYS, QC, 3, 0.1, NAN), "rho must be finite"),
    case("lq_lipschitz-points", lambda: certify.lq_lipschitz(SYS, QC, 3, 0.1, 1.0, points="lattice"), "points must be"),
    case("lq_lipschitz-grid-too-large", lambda: certify.lq_lipschitz(orrc.examples.two_mass_spring().system,
                                                   orrc.examples.two_mass_spring().cost, 3, 0.1, 1.0, grid=3),
     "too large to compute"),
    case("lq_lipschitz-M", lambda: certify.lq_lipschitz(SYS, QC, 500, 0.1, 1.0), "M = 500 is above 200"),
    case("sampled_lipschitz-model", lambda: certify.sampled_lipschitz(SYS, QC, 3, [0.5, 1.0], 0.1), "model must be"),
    case("sampled_lipschitz-too-many", lambda: certify.sampled_lipschitz(LIN, QC, 3, [0.5, 1.0], 0.1, n_samples=10 ** 6),
     "n_samples=1000000"),
    case("sampled_lipschitz-theta", lambda: certify.sampled_lipschitz(LIN, QC, 3, [0.5], 0.1), "theta must have shape"),
    # theory
    case("alpha_f_tilde-negative", lambda: theory.alpha_f_tilde(-1.0, 3), "alpha_f_S must be"),
    case("alpha_f_tilde-M", lambda: theory.alpha_f_tilde(1.0, 1), "M must be"),
    case("Gamma_V_theta-alpha_V", lambda: theory.Gamma_V_theta(3, 1.0, 1.2, -1.0, 1.0, 1.0, 1.0), "alpha_V must be"),
    case("lemma5_c-eps_tilde", lambda: theory.lemma5_c(4, 0.6, 1.0, 1.1, 1.0, 1.0, 1.0, 1.0, eps_tilde=5.0), "eps_tilde"),
    case("lemma5_M_theta-a", lambda: theory.lemma5_M_theta(3, 1.0, 1.0, 1.0), "a must be"),
    case("lemma4_bound-theta_error", lambda: theory.lemma4_bound(1.0, 1.0, NAN, 3, 1.0, 1.2, 1.0, 1.0, 1.0, 1.0, 1.0),
     "theta_error must be finite"),
    case("theorem2_constant-N", lambda: theory.theorem2_constant(np.ones(5), np.zeros((20, 1)), 0.0, 0.1, 5, 5, 4, 0.6, 1.0, 1.1,
                                                 0.1, 10.0, 1.0, 1.0, 1.0, 1.0), "N < T"),
    case("theorem2_constant-costs", lambda: theory.theorem2_constant(np.ones(3), np.zeros((20, 1)), 0.0, 0.1, 10, 5, 4, 0.6, 1.0,
                                                     1.1, 0.1, 10.0, 1.0, 1.0, 1.0, 1.0), "estimation_costs"),
    case("theorem2_constant-w", lambda: theory.theorem2_constant(np.ones(5), np.zeros((6, 1)), 0.0, 0.1, 10, 5, 4, 0.6, 1.0, 1.1,
                                                 0.1, 10.0, 1.0, 1.0, 1.0, 1.0), "w must hold"),
    case("lemma5_bound-H", lambda: theory.lemma5_bound(1.0, np.zeros((3, 1)), 0.1, 4, 2, 0.6, 1.0, 1.1, 0.1, 1.0, 1.0,
                                                         1.0, 1.0), "H >= M"),
    case("lq_value_matrices-theta", lambda: certify.lq_value_matrices(SYS, QC, 3, theta=[1.0]), "theta must have shape"),
    case("lq_value_matrices-system", lambda: certify.lq_value_matrices(LIN, QC, 3), "system must be"),
    # checks
    case("lemma4_margins-traj", lambda: checks.lemma4_margins("traj", 3, 1.0, 1.2, 1.0, 1.0, 1.0, 1.0, 1.0), "traj must be"),
    case("lemma4_margins-theta_error", lambda: checks.lemma4_margins(etc_traj(), 3, 1.0, 1.2, 1.0, 1.0, 1.0, 1.0, 1.0), "theta_error"),
    case("lemma4_margins-M", lambda: checks.lemma4_margins(etc_traj(), 4, 1.0, 1.2, 1.0, 1.0, 1.0, 1.0, 1.0, theta_error=0.1),
     "M=4 but"),
    case("lemma5_margins-H", lambda: checks.lemma5_margins(etc_traj(), 3, 2, 0.9, 1.0, 1.1, 1.0, 1.0, 1.0, 1.0, 1.0,
                                            theta_error=0.1), "H >= M"),
    case("theorem2_margin-gamma", lambda: checks.theorem2_margin(etc_traj(), 3, 0.7, 1.0, 1.1, 0.1, 0.0, 1.0, 1.0, 1.0,
                                                                 1.0, theta_error=0.1), "gamma >= gamma_c"),
    case("EDMD-dictionary", lambda: est.EDMD("poly"), "dictionary must be"),
    case("Excitation-excitation", lambda: orrc.controllers.Excitation(np.zeros((0, 1))), "excitation must have shape"),
    case("Excitation-past-the-end", lambda: orrc.simulate(SYS, orrc.controllers.Excitation(np.zeros((3, 1))),
                                                          np.zeros(1), np.zeros((5, 1)), 5, costs=QC),
         "the excitation has 3 steps"),
    # the trade-off study
    case("exploration_tradeoff-Ns", lambda: exploration_tradeoff(SYS, LIN, QC, 2, [5, 4, 6]), "Ns must be"),
    case("exploration_tradeoff-burn_in", lambda: exploration_tradeoff(SYS, LIN, QC, 2, np.array([4, 6, 8]), window=5, burn_in=5), "burn_in"),
    case("exploration_tradeoff-too-large", lambda: exploration_tradeoff(SYS, LIN, QC, 2, np.array([10, 10 ** 5, 10 ** 6]), seeds=10),
     "too large to compute"),
    case("Tradeoff-best_N-Ts", lambda: tradeoff().best_N([0.5]), "Ts must be >= 1"),
    case("Tradeoff-slope-Ts", lambda: tradeoff().slope([100.0]), "at least two horizons"),
]


@pytest.mark.parametrize("call, exc, words", params(CASES))
def test_bad_input_gets_a_clear_error_naming_the_argument(call, exc, words):
    assert_bad_input(call, exc, words)
