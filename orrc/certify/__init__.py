"""The paper's constants for a concrete problem, and the attenuation a linear closed loop achieves.

One module per kind of result:

* :mod:`orrc.certify.constants` -- the constants of Section 5.1 (α_lo, ᾱ, γ̄, a, γ_c):
  :func:`lq_constants`, exact certificates for a :class:`~orrc.LinearSystem` with a
  :class:`~orrc.QuadraticCost` (σ(x) = ‖x‖²). V_M(x, W) = zᵀ H z with z = [x; vec W]
  (``orrc.solvers.lq.LQPreviewLaw``), so (ᾱ, γ̄) bound V_M (the class of systems of
  Section 5.1) exactly when diag(ᾱ I_n, γ̄ I_{Mn}) - H ⪰ 0: a Pareto curve of pairs. The
  pair that minimises Theorem 1's γ_c is picked, with the smallest admissible a.
  :func:`smallest_certified_M` is the first M at which an admissible pair exists, and
  :func:`alpha_hi_floor` λ_max(P_0(M)), the smallest admissible alpha_hi at each horizon M.
* :mod:`orrc.certify.sampled` -- :func:`sampled_constants`, for nonlinear problems (or
  input bounds): V_M solved on samples; the ratios are *lower bounds* on the true
  constants (``estimate=True``).
* :mod:`orrc.certify.attenuation` -- :func:`worst_case_attenuation`, for a linear closed
  loop (Algorithm 1 on the LQ path, LQR, zero input) the exact smallest γ with
  R^p_T(γ) <= 0 for every disturbance sequence of length T from x_0 = 0, and the
  disturbance that attains it; :func:`worst_case_attenuation_limit`, its T → ∞ limit:
  the squared H∞ norm of the closed loop from w to the cost output (python-control).
* :mod:`orrc.certify.regret` -- :func:`worst_case_regret`, for a linear closed loop over T steps the
  worst-case dynamic regret against the clairvoyant optimum over ‖w‖ <= 1, and the disturbance
  attaining it (the top singular pair of the regret operator).

* :mod:`orrc.certify.lipschitz` -- Lemma 3's α_V, α_κ (and Lemma 4's α_c, α_f S): :func:`lq_lipschitz`
  from exact CasADi derivatives of the LQ value matrix and law, maximised over a grid of the
  compact set Θ (labelled as such); :func:`sampled_lipschitz`, difference quotients over samples
  for any problem (estimates).
* :mod:`orrc.certify.minmax` -- :func:`minmax_constants`, the constants ᾱ_W, γ̄_W of Appendix D
  (no disturbance preview): certified for a linear-quadratic problem without input bounds (a
  Pareto curve from the nominal plan plus the min-max plan from x = 0), sampled estimates otherwise.
* :mod:`orrc.certify.lemma6` -- :func:`lemma6_search`, a search for counterexamples to Lemma 6 on
  small LQ problems with a box W (n = 1, 2): V_{W,M} exact (vertex method), the increment's worst
  case at a vertex of W, states on a grid with local refinement, the tight and certified pairs
  (ᾱ_W, γ̄_W); :func:`lemma6_case` for one problem, :func:`lemma6_recheck` its worst point
  recomputed with cvxpy.

SciPy is imported inside the functions that use it, so that ``import orrc`` does not load it.
"""
from .attenuation import Attenuation, worst_case_attenuation, worst_case_attenuation_limit
from .constants import Constants, alpha_hi_floor, lq_constants, smallest_certified_M
from .minmax import MinMaxConstants, maxmin_value, minmax_constants
from .lemma6 import Lemma6Case, Lemma6Search, lemma6_case, lemma6_problem, lemma6_recheck, lemma6_search
from .regret import Regret, worst_case_regret
from .sampled import sampled_constants
from .lipschitz import Lipschitz, lq_lipschitz, lq_value_matrices, sampled_lipschitz

__all__ = ["Constants", "Attenuation", "lq_constants", "sampled_constants", "smallest_certified_M",
           "alpha_hi_floor", "worst_case_attenuation", "worst_case_attenuation_limit", "Regret",
           "worst_case_regret", "Lipschitz", "lq_lipschitz", "lq_value_matrices", "sampled_lipschitz",
           "MinMaxConstants", "minmax_constants", "maxmin_value", "Lemma6Case", "Lemma6Search", "lemma6_case", "lemma6_problem",
           "lemma6_recheck", "lemma6_search"]
