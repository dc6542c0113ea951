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
                    "gamma_tilde", "gamma_c_remark"],
    "orrc.certify": ["Constants", "Attenuation", "lq_constants", "sampled_constants", "smallest_certified_M",
                     "alpha_hi_floor", "worst_case_attenuation", "worst_case_attenuation_limit",
                     "Regret", "worst_case_regret"],
    "orrc.solvers.game": ["GameSolution", "finite_horizon_game", "stationary_game", "optimal_game_level",
                          "check_stabilisable"],
    "orrc.controllers": ["Controller", "Decision", "Observation", "PreviewRHC", "LQR", "Clairvoyant", "ZeroInput",
                         "HInfinity", "GPC", "DisturbanceAction", "RegretOptimal"],
    "orrc.checks": ["Margins", "Lemma1Margins", "value_bound_margins", "lemma1_margins", "lemma2_margins",
                    "theorem1_margin"],
    "orrc": ["OrrcValueError", "SolverWarning", "SolverError", "SizeWarning", "NonFiniteWarning"],
    "orrc.solvers": ["Plan", "SolverWarning", "SolverError"],
    "orrc.controllers": ["Controller", "Decision", "Observation", "PreviewRHC", "LQR", "Clairvoyant", "ZeroInput",
                         "FailureLadder"],
}

SECTIONS = {
    "orrc.theory": ["known"],
    "orrc.certify": ["constants", "sampled", "attenuation", "regret"],
    "orrc.checks": ["known"],
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
