"""Solvers of the M-step problems. They know nothing of time: x, W, costs in, plan out."""
from . import game
from .minmax import MinMaxPlan
from .plan import Plan, SolverError, SolverWarning

__all__ = ["Plan", "MinMaxPlan", "SolverWarning", "SolverError", "game"]
