"""Figures of the theory chapters (Lemma 1, Lemma 2, Theorem 1).

Every function takes the data it draws (the constants of :mod:`orrc.certify`, the
margins of :mod:`orrc.checks`, arrays of levels) and returns a
:class:`matplotlib.figure.Figure`; none of them computes a constant or a bound. A
figure is shown when it is the value of a notebook cell, and can be handed to
:func:`orrc.viz.explore` as a frame; either way :mod:`orrc.viz.figures` renders it
wide and, for a phone, with its panels stacked.

The functions live in one module per result (:mod:`orrc.viz.lemma1_plots`,
:mod:`orrc.viz.lemma2_plots`, :mod:`orrc.viz.theorem1_plots`, :mod:`orrc.viz.tables`); this module
gathers them under one name, as the chapters use them. Functions (the statement they illustrate):

* :func:`pareto_curves` -- the admissible pairs (ᾱ, γ̄) of V_M <= ᾱ σ + γ̄ Σ‖w‖² and Theorem 1's γ_c along them;
* :func:`horizon_threshold` -- M > ᾱ²/α_lo² + 1 when ᾱ itself depends on M (Lemma 1, Theorem 1);
* :func:`lemma1_check` -- V_M between its bounds, and its increments under Lemma 1's bound;
* :func:`lemma2_coefficients` -- the coefficients M_{w,j} of Lemma 2 against j;
* :func:`bounds_vs_actual` -- a measured sequence under one or more bounds (Lemma 2's cost bound);
* :func:`lemma2_frame` -- an explorer frame of Lemma 2: coefficients and the cost bound for one (M, a);
* :func:`gamma_c_map` -- γ_c of Theorem 1 against a (several M) and against M;
* :func:`attenuation_levels` -- certified γ_c beside the attenuation actually achieved, against M;
* :func:`regret_growth` -- R^p_t(γ) against t, with Theorem 1's explicit ceiling;
* :func:`adversary` -- worst-case disturbances and the stage costs they cause;
* :func:`theorem1_frame` -- an explorer frame of Theorem 1: γ_c(a) and the ceiling on R^p_t for one (M, a);
* :func:`attenuation_vs_T` -- the exact finite-T worst case against T, with its cold and stationary limits;
* :func:`constants_table`, :func:`margins_table` -- the constants, and the margins of the inequalities, as tables.
"""
from ._theory_common import _message  # noqa: F401 (used by orrc.viz.minmax_plots)
from .lemma1_plots import horizon_threshold, lemma1_check, pareto_curves
from .lemma2_plots import bounds_vs_actual, lemma2_coefficients, lemma2_frame
from .tables import constants_table, margins_table
from .theorem1_plots import adversary, attenuation_levels, attenuation_vs_T, gamma_c_map, regret_growth, theorem1_frame

__all__ = ["pareto_curves", "horizon_threshold", "lemma1_check", "lemma2_coefficients", "bounds_vs_actual",
           "lemma2_frame", "gamma_c_map", "attenuation_levels", "regret_growth", "adversary", "theorem1_frame",
           "attenuation_vs_T", "constants_table", "margins_table"]
