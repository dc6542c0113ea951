"""Plotting and interactive figures for the book (imports matplotlib; not loaded by ``import orrc``).

Imported inside a Jupyter kernel, this package makes every matplotlib Figure display as
a wide and a narrow rendering (:func:`orrc.viz.figures.install`), so that figures stay
legible at a phone's width in the book and in JupyterLab.
"""
from . import comparison_plots, figures, minmax_plots, plots, theory_plots, unknown_plots
from .explore import Explorer, explore, figure_to_png
from .kernel import in_kernel
from .live import LiveView
from .claims import ClaimError, ClaimWarning, claim
from .notebook import Quoted, glue, glued

__all__ = ["explore", "Explorer", "LiveView", "figure_to_png", "figures", "glue", "glued", "Quoted", "claim",
           "ClaimError", "ClaimWarning", "plots", "theory_plots", "comparison_plots", "unknown_plots", "minmax_plots"]


if in_kernel():
    figures.install()
