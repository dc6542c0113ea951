"""Plotting and interactive figures for the book (imports matplotlib; not loaded by ``import orrc``)."""
from .explore import Explorer, explore, figure_to_png
from . import comparison_plots, plots, theory_plots, unknown_plots

__all__ = ["explore", "Explorer", "figure_to_png", "plots", "theory_plots", "comparison_plots", "unknown_plots"]
