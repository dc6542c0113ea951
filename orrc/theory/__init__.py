"""The paper's theory as pure functions of its constants, one module per section.

* :mod:`orrc.theory.known` -- the known system (Section 5.1): the horizon threshold,
  Lemma 1's Γ_V and Γ^γ_V, Lemma 2's decay rate a, b and coefficients M_{w,j}, Theorem 1's
  γ_c and its explicit constant, the remark's γ̃.
* :mod:`orrc.theory.unknown` -- the unknown system (Section 5.2): Lemma 4's α̃_f and Γ^θ_V, Lemma 5's
  c and M_θ, the explicit bound of Theorem 2.
* :mod:`orrc.theory.nopreview` -- no disturbance preview (Appendix D): Lemma 6's Γ_{W,V} and
  Γ^γ_{W,V}, the horizon threshold and decay rate with ᾱ_W, Theorem 3's γ_{c,W} and its explicit
  constant.

Every function takes the paper's constants and returns a number (or an array of
coefficients); none of them knows about a system, a controller or a trajectory.
Computing the constants of a concrete problem is :mod:`orrc.certify`; checking the
inequalities along a simulated trajectory is :mod:`orrc.checks`. Every public name is
importable from ``orrc.theory`` directly.
"""
from .known import (Gamma_V, Gamma_V_gamma, above_threshold, decay_b, gamma_c, gamma_c_remark, gamma_tilde,
                    horizon_threshold, lemma2_bound, lemma2_coefficients, min_decay_rate, theorem1_constant)
from .nopreview import (Gamma_WV, Gamma_WV_gamma, decay_b_W, gamma_c_W, horizon_threshold_W, min_decay_rate_W,
                        theorem3_constant)
from .unknown import (Gamma_V_theta, Theorem2Bound, alpha_f_tilde, lemma4_bound, lemma5_M_theta, lemma5_bound,
                      lemma5_c, theorem2_constant)
from . import known, nopreview, unknown

__all__ = [
    "horizon_threshold", "above_threshold", "min_decay_rate", "decay_b", "Gamma_V", "Gamma_V_gamma",
    "lemma2_coefficients", "lemma2_bound", "gamma_c", "theorem1_constant", "gamma_tilde",
    "gamma_c_remark",
    "alpha_f_tilde", "Gamma_V_theta", "lemma4_bound", "lemma5_c", "lemma5_M_theta", "lemma5_bound",
    "theorem2_constant", "Theorem2Bound",
    "Gamma_WV", "Gamma_WV_gamma", "horizon_threshold_W", "min_decay_rate_W", "decay_b_W", "gamma_c_W",
    "theorem3_constant",
]
