"""The paper's inequalities checked step by step along simulated trajectories, one module per section.

* :mod:`orrc.checks.known` -- the known system (Section 5.1): the class condition on V_M,
  Lemma 1, Lemma 2 and Theorem 1.
* :mod:`orrc.checks.unknown` -- the unknown system (Section 5.2): Lemma 4, Lemma 5 and Theorem 2 along a
  trajectory of Algorithm 2.
* :mod:`orrc.checks.nopreview` -- no disturbance preview (Appendix D): the class condition on
  V_{W,M}, Lemma 6 and Theorem 3.

Each function takes a :class:`~orrc.Trajectory` and the paper's constants and returns the
margins ``bound - actual`` at every step (:class:`Margins`; >= 0 means the inequality
holds there). Every public name is importable from ``orrc.checks`` directly.
"""
from .known import Lemma1Margins, Margins, lemma1_margins, lemma2_margins, theorem1_margin, value_bound_margins
from .nopreview import lemma6_margins, minmax_value_bound_margins, theorem3_margin
from .unknown import lemma4_margins, lemma5_margins, theorem2_margin
from . import known, nopreview, unknown

__all__ = ["Margins", "Lemma1Margins", "value_bound_margins", "lemma1_margins", "lemma2_margins",
           "theorem1_margin", "lemma4_margins", "lemma5_margins", "theorem2_margin", "minmax_value_bound_margins",
           "lemma6_margins", "theorem3_margin"]
