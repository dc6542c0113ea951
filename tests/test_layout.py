"""The package is organised like the paper, and every public name stays importable where it was.

``orrc.theory``, ``orrc.certify`` and ``orrc.checks`` are packages with one module per section of
the paper (theory, checks) or per kind of result (certify); their public names are importable
from the package itself, as they were when each was a single module.
"""
import importlib

import pytest

PUBLIC = {
    "orrc.theory": ["horizon_threshold", "above_threshold", "min_decay_rate", "decay_b", "Gamma_V",
                    "Gamma_V_gamma", "lemma2_coefficients", "lemma2_bound", "gamma_c", "theorem1_constant",
                    "gamma_tilde", "gamma_c_remark", "alpha_f_tilde", "Gamma_V_theta", "lemma4_bound", "lemma5_c",
                    "lemma5_M_theta", "lemma5_bound", "theorem2_constant", "Theorem2Bound", "Gamma_WV", "Gamma_WV_gamma",
                    "horizon_threshold_W", "min_decay_rate_W", "decay_b_W", "gamma_c_W", "theorem3_constant"],
    "orrc.certify": ["Constants", "Attenuation", "lq_constants", "sampled_constants", "smallest_certified_M",
                     "alpha_hi_floor", "worst_case_attenuation", "worst_case_attenuation_limit",
                     "Regret", "worst_case_regret", "Lipschitz", "lq_lipschitz", "lq_value_matrices", "sampled_lipschitz",
                     "MinMaxConstants", "minmax_constants"],
    "orrc.solvers.game": ["GameSolution", "finite_horizon_game", "stationary_game", "optimal_game_level",
                          "check_stabilisable"],
    "orrc.checks": ["Margins", "Lemma1Margins", "value_bound_margins", "lemma1_margins", "lemma2_margins",
                    "theorem1_margin", "lemma4_margins", "lemma5_margins", "theorem2_margin", "minmax_value_bound_margins",
                    "lemma6_margins", "theorem3_margin"],
    "orrc.estimation": ["Estimate", "LinearEstimate", "EDMDModel", "RankWarning", "Transitions", "transitions",
                        "gaussian", "prbs", "multisine", "least_squares_linear", "least_squares_parametric",
                        "Dictionary", "polynomial_dictionary", "rbf_dictionary", "edmd", "EDMD", "prediction_error"],
    "orrc": ["OrrcValueError", "SolverWarning", "SolverError", "SizeWarning", "NonFiniteWarning",
             "ParametricSystem", "LinearParametricSystem", "L1Cost", "EstimateThenControl", "LiftedRHC", "MinMaxRHC",
             "sweep", "Table", "SweepError"],
    "orrc.solvers": ["Plan", "MinMaxPlan", "SolverWarning", "SolverError"],
    "orrc.controllers": ["Controller", "Decision", "Observation", "PreviewRHC", "MinMaxRHC", "LQR", "Clairvoyant",
                         "ZeroInput", "FailureLadder", "HInfinity", "GPC", "DisturbanceAction", "RegretOptimal",
                         "LiftedRHC", "EstimateThenControl", "Excitation"],
    "orrc.viz": ["explore", "Explorer", "LiveView", "figure_to_png", "figures", "glue", "glued", "claim", "plots",
                 "theory_plots", "comparison_plots", "unknown_plots", "minmax_plots"],
}

SECTIONS = {
    "orrc.theory": ["known", "unknown", "nopreview"],
    "orrc.certify": ["constants", "sampled", "attenuation", "regret", "lipschitz", "minmax"],
    "orrc.checks": ["known", "unknown", "nopreview"],
    "orrc.estimation": ["excitation", "data", "linear", "parametric", "edmd"],
    "orrc.viz": ["explore", "live", "notebook", "claims"],
}


@pytest.mark.parametrize("package", sorted(PUBLIC))
def test_every_public_name_is_importable_from_the_package(package):
    mod = importlib.import_module(package)
    assert hasattr(mod, "__path__") or "." in package, f"{package} should be a package"
    missing = [name for name in PUBLIC[package] if not hasattr(mod, name)]
    assert not missing, f"{package} lost {missing}"
    assert set(PUBLIC[package]) <= set(mod.__all__)


@pytest.mark.parametrize("package", sorted(SECTIONS))
def test_each_package_has_one_module_per_section_or_result(package):
    mod = importlib.import_module(package)
    for sub in SECTIONS[package]:
        m = importlib.import_module(f"{package}.{sub}")
        assert m.__doc__, f"{package}.{sub} has no docstring"
        for name in getattr(m, "__all__", []):
            assert getattr(mod, name) is getattr(m, name), f"{package}.{name} is not {package}.{sub}.{name}"
