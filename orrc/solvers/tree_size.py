"""The size of the scenario tree of W's vertices: its branching vertices, its node count, the guard.

The tree of feedback min-max (:mod:`orrc.solvers.scenario_tree`) has one node per vertex history
(w_0..w_{j-1}), j = 0..M-1: N = 1 + V + ... + V^{M-1} nodes for V vertices of W. It is counted before
anything is built, and refused past ``TREE_NODE_LIMIT`` nodes.
"""
from __future__ import annotations

import math

import numpy as np

from .._validate import OrrcValueError, check_size
from .minmax import set_vertices

__all__ = ["TREE_NODE_LIMIT", "tree_nodes", "tree_vertices"]

#: the largest scenario tree (nodes) that :class:`~orrc.solvers.scenario_tree.ScenarioTree` builds
TREE_NODE_LIMIT = 2 ** 15


def tree_vertices(W) -> np.ndarray:
    """The vertices of W that branch the scenario tree, shape (V, n).

    Parameters
    ----------
    W : Box or Polytope
        A box (its distinct corners: a flat coordinate lo = hi gives one value) or a polytope (its
        given points).

    Returns
    -------
    numpy.ndarray, shape (V, n)
        The vertices, in the order of ``itertools.product`` for a box.

    Examples
    --------
    >>> import orrc
    >>> from orrc.solvers.scenario_tree import tree_vertices
    >>> tree_vertices(orrc.Box([-1.0, 0.0], [1.0, 0.0])).tolist()
    [[-1.0, 0.0], [1.0, 0.0]]
    """
    return set_vertices(W)


def tree_nodes(n_vertices: int, M: int) -> int | float:
    """N = 1 + V + ... + V^{M-1}: the nodes of the scenario tree, counted without building it.

    Parameters
    ----------
    n_vertices : int
        V, the vertices of W (>= 1).
    M : int
        The horizon (>= 1).

    Returns
    -------
    int or float
        The node count; a float (possibly ``inf``) when it exceeds 2^62.

    Examples
    --------
    >>> from orrc.solvers.scenario_tree import tree_nodes
    >>> tree_nodes(2, 6), tree_nodes(4, 3), tree_nodes(1, 5)
    (63, 21, 5)
    """
    V, M = int(n_vertices), int(M)
    if V == 1:
        return M
    if M * math.log2(V) <= 62:
        return (V ** M - 1) // (V - 1)
    with np.errstate(over="ignore"):
        big = (float(V) ** M - 1.0) / (V - 1.0) if M * math.log2(V) < 1000 else math.inf
    return big


def _check_tree(V: int, M: int, n: int, m: int) -> int:
    """The node count, after the limit and the size estimate (refused with the numbers in the message)."""
    N = tree_nodes(V, M)
    if N > TREE_NODE_LIMIT:
        count = str(N) if isinstance(N, int) else f"{N:.3g}"
        raise OrrcValueError(
            f"the feedback min-max tree at M={M} with {V} vertices of W has {count} nodes (1 + V + ... + V^(M-1)); "
            f"the limit is {TREE_NODE_LIMIT} nodes (orrc.solvers.scenario_tree.TREE_NODE_LIMIT): use a shorter "
            "horizon M, a W with fewer vertices, or policy='open-loop'")
    width = 2 * (n + m) + 3     # (about 3 s for 5461 nodes with n = 2, m = 1, compilation included)
    check_size(f"the feedback min-max tree at M={M} with {V} vertices of W: {N} nodes",
               nbytes=8.0 * N * width * 60, ops=1.5e5 * N * (n + m + 1), hint="use a shorter horizon M")
    return int(N)
