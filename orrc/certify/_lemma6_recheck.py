"""Lemma 6's worst point recomputed independently: :func:`lemma6_recheck`.

The ratio r of :mod:`orrc.certify.lemma6` at the worst state, vertex and pair of a
:class:`~orrc.certify.Lemma6Case`, with V_{W,M} solved as one conic program over all vertex
sequences (cvxpy with Clarabel, the prediction built here), not by the vertex method of
:class:`~orrc.MinMaxRHC` that the case used.
"""
from __future__ import annotations

import itertools

import numpy as np

from .._validate import OrrcValueError, _describe
from ._lemma6_case import Lemma6Case, _ratios


def lemma6_recheck(case: Lemma6Case) -> float:
    """The worst point of ``case`` recomputed independently: V_{W,M} by a conic program over all
    vertex sequences (cvxpy with Clarabel, the prediction matrices built here), the same x, w and
    pair; returns its ratio r (equal to ``case.ratio`` to solver accuracy)."""
    import cvxpy as cp

    if not isinstance(case, Lemma6Case):
        raise OrrcValueError(f"case must be a Lemma6Case (from lemma6_case); got {_describe(case)}")
    A, B, Q, R = case.system.A, case.system.B, case.cost.Q, case.cost.R
    M, n, m = case.M, A.shape[0], B.shape[1]
    verts = case.W.vertices()
    seqs = list(itertools.product(range(len(verts)), repeat=M - 1))

    def value(x):
        U = cp.Variable((M, m))
        s = cp.Variable()
        cons = []
        for seq in seqs:
            xk, cost = x, 0
            for j in range(M):
                cost = cost + cp.quad_form(xk, Q) + cp.quad_form(U[j], R)
                if j < M - 1:
                    xk = A @ xk + B @ U[j] + verts[seq[j]]
            cons.append(cost <= s)
        cp.Problem(cp.Minimize(s), cons).solve(solver=cp.CLARABEL)
        return float(s.value), np.asarray(U.value[0])

    x = np.asarray(case.x, float)
    V, u = value(x)
    inc = value(A @ x + B @ u + case.w)[0] - V
    return float(_ratios(M, float(case.cost.alpha_lo), case.W.max_norm_sq, [x @ x], [inc],
                         [case.alpha_hi_W], [case.gamma_bar_W])[0, 0])
