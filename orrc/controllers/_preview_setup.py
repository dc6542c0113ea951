"""The M-step problem that ``PreviewRHC``'s arguments define, and the solver that fits it.

:class:`~orrc.controllers.preview.PreviewRHC` (Algorithm 1) solves Eq. (3) at each step. Its
arguments fix the problem (the set U of ``input_bounds``, the extensions ``state_bounds`` and
``terminal_cost``) and the solver: the exact Riccati law of ``orrc.solvers.lq`` for a
LinearSystem with a QuadraticCost and no bounds, the exact QP of ``orrc.solvers.qp`` for an
L1Cost, CasADi (``orrc.solvers.nlp``) otherwise. This module checks those arguments and picks
the solver; the controller that uses them is :mod:`orrc.controllers.preview`.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from .._validate import OrrcValueError, _describe, as_array, as_square, check_evaluates, check_psd
from ..costs import L1Cost, QuadraticCost
from ..solvers.nlp import IPOPT, NLP_SOLVERS, SQP
from ..systems import LinearSystem

#: the values of ``PreviewRHC(solver=...)``
SOLVER_CHOICES = ("auto", "lq", "qp", "nlp", "sqp", "ipopt")
#: the CasADi solvers each NLP choice tries, in order (the rungs of the failure ladder)
_NLP_LADDERS = {"nlp": NLP_SOLVERS, "sqp": (SQP,), "ipopt": (IPOPT,)}


def _bounds(name, bounds, dim):
    """(lo, hi) arrays of length dim from a pair of scalars or length-dim arrays (±inf allowed)."""
    if bounds is None:
        return None
    if not isinstance(bounds, (tuple, list)) or len(bounds) != 2:
        raise OrrcValueError(f"{name} must be a pair (lo, hi) of scalars or length-{dim} arrays; got "
                             f"{_describe(bounds)}")
    out = []
    for i, b in enumerate(bounds):
        b = as_array(f"{name}[{i}]", b, allow_nonfinite=True)
        if b.ndim > 1 or (b.ndim == 1 and b.shape[0] not in (1, dim)):
            raise OrrcValueError(f"{name}[{i}] must be a scalar or a length-{dim} array; got shape {b.shape}")
        out.append(np.broadcast_to(b.reshape(-1) if b.ndim else b, (dim,)).astype(float))
    lo, hi = out
    if np.any(np.isnan(lo)) or np.any(np.isnan(hi)) or np.any(lo > hi):
        raise OrrcValueError(f"{name} needs lo <= hi (no NaN) in every coordinate; got lo={lo}, hi={hi}")
    return lo, hi


def _terminal_callable(fn, n: int):
    """A terminal cost callable checked: it must trace to a finite scalar CasADi expression of x."""
    xs = ca.SX.sym("x", n)
    try:
        out = ca.SX(fn(xs))
    except Exception as exc:
        raise OrrcValueError("terminal_cost must be written with CasADi operations on x (ca.sumsqr(x), ...); "
                             f"tracing it failed with: {exc}") from exc
    if out.shape != (1, 1):
        raise OrrcValueError(f"terminal_cost(x) must return a scalar; got shape {out.shape}")
    f = ca.Function("terminal", [xs], [out])
    check_evaluates("terminal_cost", "terminal_cost(x)", lambda x, u: f(x), n, 1)
    return fn



def _check_solver(solver):
    """``solver`` is one of :data:`SOLVER_CHOICES`."""
    if not isinstance(solver, str) or solver not in SOLVER_CHOICES:
        raise OrrcValueError(f"solver must be one of {', '.join(map(repr, SOLVER_CHOICES))}; got {solver!r}")


def _terminal(terminal_cost, n: int):
    """(Pf, term_fn) of a terminal cost: a PSD (n, n) matrix Pf with term_fn(x) = xᵀ Pf x, or
    (None, the checked callable); (None, None) without one."""
    if terminal_cost is None:
        return None, None
    if callable(terminal_cost):
        return None, _terminal_callable(terminal_cost, n)
    Pf = as_square("terminal_cost", terminal_cost, n)
    check_psd("terminal_cost", Pf)
    return Pf, lambda x, Pf=Pf: (x.T @ Pf @ x)


def _pick_solver(solver, system, cost, input_bounds, state_bounds, terminal_cost, Pf) -> str:
    """The solver of the problem: "lq" where the exact Riccati law applies (a LinearSystem, a
    QuadraticCost, no bounds, a matrix terminal cost or none), "qp" for an L1Cost on a
    LinearSystem (no state bounds, no terminal cost), else "nlp"; an explicit choice is checked."""
    lq_ok = (isinstance(system, LinearSystem) and isinstance(cost, QuadraticCost)
             and input_bounds is None and state_bounds is None
             and (terminal_cost is None or Pf is not None))
    if solver == "lq" and not lq_ok:
        raise OrrcValueError(
            "solver='lq' needs a LinearSystem, a QuadraticCost, no input/state bounds and a "
            "quadratic (matrix) terminal cost or none; use solver='nlp' or 'auto'")
    picked = ("lq" if lq_ok else "nlp") if solver == "auto" else solver
    # an ℓ1 state cost on a linear system: one exact QP per step (orrc.solvers.qp)
    qp_ok = (isinstance(system, LinearSystem) and isinstance(cost, L1Cost) and state_bounds is None
             and terminal_cost is None)
    if solver == "qp" and not qp_ok:
        raise OrrcValueError("solver='qp' needs a LinearSystem, an L1Cost, no state bounds and no terminal cost")
    if solver == "auto" and qp_ok:
        picked = "qp"
    return picked
