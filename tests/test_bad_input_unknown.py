"""Bad input to the unknown-system half of orrc: a clear error naming the argument (one table of cases)."""
import casadi as ca
import numpy as np
import pytest

import orrc
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
    ("param-f", lambda: orrc.ParametricSystem(3, 1, 1, 1), "f must be callable"),
    ("param-n", lambda: orrc.ParametricSystem(lambda x, u, w, t: x, 0, 1, 1), "n_states"),
    ("param-p", lambda: orrc.ParametricSystem(lambda x, u, w, t: x, 1, 1, 0), "n_params"),
    ("param-trace", lambda: orrc.ParametricSystem(lambda x, u, w, t: {"next": x}, 1, 1, 1), "CasADi"),
    ("param-out", lambda: orrc.ParametricSystem(lambda x, u, w, t: ca.vertcat(x, x), 1, 1, 1), "n_states=1"),
    ("param-names", lambda: orrc.ParametricSystem(lambda x, u, w, t: x, 1, 1, 1, param_names=["a", "b"]),
     "param_names"),
    ("param-step-theta", lambda: LIN.step([0.0], [0.0], [0.0]), "without a θ"),
    ("param-at-shape", lambda: LIN.at([1.0]), "theta must have shape"),
    ("param-at-nan", lambda: LIN.at([1.0, NAN]), "theta must be finite"),
    ("param-linear-n", lambda: orrc.ParametricSystem.linear(0, 1), "n must be"),
    ("param-pack", lambda: LIN.pack(np.eye(2), [[1.0]]), "A must have shape"),
    ("rhc-theta-missing", lambda: orrc.PreviewRHC(pend(), QC.__class__(np.eye(2), [[1.0]]), 3), "theta is required"),
    ("rhc-theta-extra", lambda: orrc.PreviewRHC(SYS, QC, 3, theta=[1.0]), "theta is only for"),
    ("rhc-set-theta", lambda: orrc.PreviewRHC(SYS, QC, 3).set_theta([1.0]), "set_theta needs"),
    ("rhc-qp", lambda: orrc.PreviewRHC(SYS, QC, 3, solver="qp"), "solver='qp'"),
    # L1Cost
    ("l1-q", lambda: orrc.L1Cost([-1.0], [[1.0]]), "q must be"),
    ("l1-R", lambda: orrc.L1Cost([1.0], [[0.0]]), "R must be positive definite"),
    # excitation
    ("exc-N", lambda: est.gaussian(0, 1), "N must be"),
    ("exc-amp", lambda: est.prbs(10, 1, amplitude=0.0), "amplitude must be"),
    ("exc-std", lambda: est.gaussian(10, 1, std=-1.0), "std must be"),
    ("exc-seed", lambda: est.multisine(10, 1, seed="x"), "seed must be"),
    ("exc-hold", lambda: est.prbs(10, 1, hold=0), "hold must be"),
    ("exc-long", lambda: est.prbs(2 ** 33, 1), "too long for a PRBS"),
    ("exc-freqs", lambda: est.multisine(10, 1, n_freqs=0), "n_freqs"),
    ("exc-kind", lambda: est.excitation.make("chirp", 10, 1), "unknown excitation kind"),
    # data
    ("data-X", lambda: est.transitions(np.zeros((1, 1)), np.zeros((0, 1))), "X must have shape"),
    ("data-U", lambda: est.transitions(np.zeros((4, 1)), np.zeros((2, 1))), "U must have shape"),
    ("data-W", lambda: est.transitions(np.zeros((4, 1)), np.zeros((3, 1)), np.zeros((2, 1))), "W must have shape"),
    ("data-nan", lambda: est.transitions(np.full((4, 1), NAN), np.zeros((3, 1))), "X must be finite"),
    ("data-lists", lambda: est.transitions([np.zeros((3, 1))], [np.zeros((2, 1))] * 2), "same number of experiments"),
    ("data-W-some", lambda: est.transitions([np.zeros((3, 1))] * 2, [np.zeros((2, 1))] * 2, [None, np.zeros((2, 1))]),
     "W must be given for every experiment"),
    # estimators
    ("ls-short", lambda: est.least_squares_linear(*xu(1)), "N >= n + m = 2"),
    ("ls-rank", lambda: est.least_squares_linear(*xu(5)), "rank needed is 2"),
    ("ls-true", lambda: est.least_squares_linear(np.random.default_rng(0).standard_normal((6, 1)), np.arange(5.0),
                                                 true=(np.eye(2), [[1.0]])), "true must have A of shape"),
    ("ls-rank-option", lambda: est.least_squares_linear(np.random.default_rng(0).standard_normal((6, 1)),
                                                        np.arange(5.0), rank_deficient="ignore"), "rank_deficient"),
    ("lsp-model", lambda: est.least_squares_parametric(SYS, *xu()), "model must be an orrc.ParametricSystem"),
    ("lsp-affine", lambda: est.least_squares_parametric(
        orrc.ParametricSystem(lambda x, u, w, t: x * t[0] ** 2, 1, 1, 1), *xu()), "not affine in theta"),
    ("lsp-short", lambda: est.least_squares_parametric(LIN, *xu(1)), "N >= ceil(p/n) = 2"),
    # EDMD
    ("dict-psi", lambda: est.Dictionary(None, 2), "psi must be callable"),
    ("dict-state", lambda: est.Dictionary(lambda x: x ** 2, 2), "must contain the state"),
    ("dict-labels", lambda: est.Dictionary(lambda x: x, 2, labels=["a"]), "labels must name"),
    ("dict-size", lambda: est.polynomial_dictionary(6, 12), "above the limit"),
    ("dict-degree", lambda: est.polynomial_dictionary(2, 0), "degree must be"),
    ("rbf-width", lambda: est.rbf_dictionary(np.zeros((2, 2)), 0.0), "width must be"),
    ("rbf-centers", lambda: est.rbf_dictionary(np.zeros(3), 1.0), "centers must have shape"),
    ("edmd-dict", lambda: est.edmd(*xu(), dictionary="poly"), "dictionary must be"),
    ("edmd-ridge", lambda: est.edmd(*xu(), est.polynomial_dictionary(1, 2), ridge=-1.0), "ridge must be"),
    ("edmd-n", lambda: est.edmd(*xu(5, 2), est.polynomial_dictionary(1, 2)), "X must have n = 1"),
    ("edmd-predict", lambda: vdp_model().predict([0.0, 0.0], np.zeros((3, 2))), "U must have shape"),
    ("pred-horizon", lambda: est.prediction_error(SYS, *xu(), horizon=0), "horizon must be"),
    ("pred-short", lambda: est.prediction_error(SYS, *xu(3), horizon=5), "long enough"),
    ("pred-model", lambda: est.prediction_error("model", *xu(), horizon=2), "model must be"),
    # Algorithm 2
    ("etc-model", lambda: orrc.EstimateThenControl(SYS, QC, 3, 5), "model must be an orrc.ParametricSystem"),
    ("etc-N", lambda: orrc.EstimateThenControl(LIN, QC, 3, 0), "N must be"),
    ("etc-N-short", lambda: orrc.EstimateThenControl(LIN, QC, 3, 1), "N >= n + m = 2"),
    ("etc-excitation", lambda: orrc.EstimateThenControl(LIN, QC, 3, 5, excitation=np.ones((3, 1))),
     "excitation must have shape"),
    ("etc-estimator", lambda: orrc.EstimateThenControl(LIN, QC, 3, 5, estimator="ls"), "estimator must be"),
    ("etc-theta-true", lambda: orrc.EstimateThenControl(LIN, QC, 3, 5, theta_true=[1.0]), "theta_true must have"),
    ("etc-edmd-theta", lambda: orrc.EstimateThenControl(est.EDMD(est.polynomial_dictionary(1, 2)), QC, 3, 5,
                                                        theta_true=[1.0]), "theta_true is for"),
    ("etc-affine", lambda: orrc.EstimateThenControl(orrc.ParametricSystem(lambda x, u, w, t: x * t[0] ** 2 + u, 1,
                                                                          1, 1), QC, 3, 5), "not affine in theta"),
    ("etc-gain", lambda: orrc.EstimateThenControl(LIN, QC, 3, 5, exploration_gain=np.ones((2, 2))),
     "exploration_gain must have shape"),
    ("etc-rank-option", lambda: orrc.EstimateThenControl(LIN, QC, 3, 5, rank_deficient="no"), "rank_deficient"),
    ("lifted-model", lambda: orrc.LiftedRHC(SYS, QC, 3), "model must be a lifted linear model"),
    # Lemma 3's constants
    ("lip-system", lambda: certify.lq_lipschitz(LIN, QC, 3, 0.1, 1.0), "system must be an orrc LinearSystem"),
    ("lip-cost", lambda: certify.lq_lipschitz(SYS, orrc.L1Cost([1.0], [[1.0]]), 3, 0.1, 1.0), "cost must be"),
    ("lip-radius", lambda: certify.lq_lipschitz(SYS, QC, 3, 0.0, 1.0), "radius must be"),
    ("lip-rho", lambda: certify.lq_lipschitz(SYS, QC, 3, 0.1, NAN), "rho must be finite"),
    ("lip-points", lambda: certify.lq_lipschitz(SYS, QC, 3, 0.1, 1.0, points="lattice"), "points must be"),
    ("lip-grid-size", lambda: certify.lq_lipschitz(orrc.examples.two_mass_spring().system,
                                                   orrc.examples.two_mass_spring().cost, 3, 0.1, 1.0, grid=3),
     "above the limit"),
    ("lip-M", lambda: certify.lq_lipschitz(SYS, QC, 500, 0.1, 1.0), "M = 500 is above 200"),
    ("slip-model", lambda: certify.sampled_lipschitz(SYS, QC, 3, [0.5, 1.0], 0.1), "model must be"),
    ("slip-samples", lambda: certify.sampled_lipschitz(LIN, QC, 3, [0.5, 1.0], 0.1, n_samples=10 ** 6),
     "n_samples"),
    ("slip-theta", lambda: certify.sampled_lipschitz(LIN, QC, 3, [0.5], 0.1), "theta must have shape"),
    # theory
    ("th-aft", lambda: theory.alpha_f_tilde(-1.0, 3), "alpha_f_S must be"),
    ("th-aft-M", lambda: theory.alpha_f_tilde(1.0, 1), "M must be"),
    ("th-GVt", lambda: theory.Gamma_V_theta(3, 1.0, 1.2, -1.0, 1.0, 1.0, 1.0), "alpha_V must be"),
    ("th-c-eps", lambda: theory.lemma5_c(4, 0.6, 1.0, 1.1, 1.0, 1.0, 1.0, 1.0, eps_tilde=5.0), "eps_tilde"),
    ("th-Mtheta-a", lambda: theory.lemma5_M_theta(3, 1.0, 1.0, 1.0), "a must be"),
    ("th-4-err", lambda: theory.lemma4_bound(1.0, 1.0, NAN, 3, 1.0, 1.2, 1.0, 1.0, 1.0, 1.0, 1.0),
     "theta_error must be finite"),
    ("th-T2-N", lambda: theory.theorem2_constant(np.ones(5), np.zeros((20, 1)), 0.0, 0.1, 5, 5, 4, 0.6, 1.0, 1.1,
                                                 0.1, 10.0, 1.0, 1.0, 1.0, 1.0), "N < T"),
    ("th-T2-costs", lambda: theory.theorem2_constant(np.ones(3), np.zeros((20, 1)), 0.0, 0.1, 10, 5, 4, 0.6, 1.0,
                                                     1.1, 0.1, 10.0, 1.0, 1.0, 1.0, 1.0), "estimation_costs"),
    ("th-T2-w", lambda: theory.theorem2_constant(np.ones(5), np.zeros((6, 1)), 0.0, 0.1, 10, 5, 4, 0.6, 1.0, 1.1,
                                                 0.1, 10.0, 1.0, 1.0, 1.0, 1.0), "w must hold"),
    # checks
    ("chk-traj", lambda: checks.lemma4_margins("traj", 3, 1.0, 1.2, 1.0, 1.0, 1.0, 1.0, 1.0), "traj must be"),
    ("chk-error", lambda: checks.lemma4_margins(etc_traj(), 3, 1.0, 1.2, 1.0, 1.0, 1.0, 1.0, 1.0), "theta_error"),
    ("chk-M", lambda: checks.lemma4_margins(etc_traj(), 4, 1.0, 1.2, 1.0, 1.0, 1.0, 1.0, 1.0, theta_error=0.1),
     "M=4 but"),
    ("chk-H", lambda: checks.lemma5_margins(etc_traj(), 3, 2, 0.9, 1.0, 1.1, 1.0, 1.0, 1.0, 1.0, 1.0,
                                            theta_error=0.1), "H >= M"),
    # the trade-off study
    ("to-Ns", lambda: exploration_tradeoff(SYS, LIN, QC, 2, [5, 4, 6]), "Ns must be"),
    ("to-burn", lambda: exploration_tradeoff(SYS, LIN, QC, 2, np.array([4, 6, 8]), window=5, burn_in=5), "burn_in"),
    ("to-size", lambda: exploration_tradeoff(SYS, LIN, QC, 2, np.array([10, 10 ** 5, 10 ** 6]), seeds=10),
     "above the limit"),
    ("to-Ts", lambda: tradeoff().best_N([0.5]), "Ts must be >= 1"),
    ("to-slope", lambda: tradeoff().slope([100.0]), "at least two horizons"),
]


@pytest.mark.parametrize("call, words", [(c, w) for _, c, w in CASES], ids=[i for i, _, _ in CASES])
def test_bad_input_is_a_clear_error_naming_the_argument(call, words):
    with pytest.raises(orrc.OrrcValueError) as info:
        call()
    assert words in str(info.value), str(info.value)
