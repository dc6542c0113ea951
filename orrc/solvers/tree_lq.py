"""The weighted linear-quadratic problem on a scenario tree: the dual bound of feedback min-max.

For leaf weights λ >= 0 (Σλ = 1), min over tree policies of Σ λ_leaf J_leaf is a linear-quadratic
problem on the tree: node i weighs its stage cost by μ_i, the total weight of the leaves below it,
and the cost-to-go of a node is a quadratic xᵀP_i x + 2q_iᵀx + r_i, computed from the leaves back to
the root by a Riccati recursion over the children's vertices. Its value at the root is a lower bound
on the feedback min-max value (max_leaf J_leaf >= Σ λ J_leaf for every policy), tight for the optimal
weights.
"""
from __future__ import annotations

import numpy as np

__all__ = ["weighted_tree_value"]


def weighted_tree_value(A, B, Qs, Rs, verts, off, parent, weights, x) -> float:
    """min over tree policies of Σ_leaf λ_leaf Σ_j c_j(x_j, u_j) from the root state x (see the module).

    Parameters
    ----------
    A, B : numpy.ndarray, shapes (n, n), (n, m)
        x_{j+1} = A x_j + B u_j + w_j.
    Qs, Rs : sequences of M arrays (n, n), (m, m)
        The stage weights of depth 0..M-1 (R_j positive definite).
    verts : numpy.ndarray, shape (V, n)
        The vertices of W that branch the tree.
    off : numpy.ndarray of int, shape (M+1,)
        Depth d occupies nodes off[d]..off[d+1]-1 (breadth-first; node off[d] + i has the vertex
        i % V and the parent off[d-1] + i // V).
    parent : numpy.ndarray of int, shape (N-1,)
        The parent of node k + 1.
    weights : numpy.ndarray, shape (V^{M-1},)
        λ, non-negative, summing to 1.
    x : numpy.ndarray, shape (n,)
        The root state.

    Returns
    -------
    float
        The weighted problem's optimal value.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.solvers.tree_lq import weighted_tree_value
    >>> A, B, I = np.array([[1.2]]), np.array([[1.0]]), np.eye(1)
    >>> verts = np.array([[-0.3], [0.3]])
    >>> off, parent = np.array([0, 1, 3, 7]), np.array([0, 0, 1, 1, 2, 2])
    >>> round(weighted_tree_value(A, B, [I] * 3, [I] * 3, verts, off, parent,
    ...                           np.full(4, 0.25), np.zeros(1)), 6)
    0.2448
    """
    M = len(off) - 1
    n, V = A.shape[0], len(verts)
    mu = np.zeros(off[-1])
    mu[off[M - 1]:] = weights
    for d in range(M - 1, 0, -1):
        a, b = off[d], off[d + 1]
        np.add.at(mu, parent[a - 1:b - 1], mu[a:b])
    a, b = off[M - 1], off[M]
    Pm = mu[a:b, None, None] * Qs[M - 1]          # the leaves: u = 0 (R > 0), no successors
    q = np.zeros((b - a, n))
    r = np.zeros(b - a)
    for d in range(M - 2, -1, -1):
        a, b = off[d], off[d + 1]
        k = b - a
        v = np.broadcast_to(verts, (k, V, n))
        Pc, qc, rc = Pm.reshape(k, V, n, n), q.reshape(k, V, n), r.reshape(k, V)
        S = Pc.sum(axis=1)
        s = np.einsum("kvij,kvj->ki", Pc, v) + qc.sum(axis=1)
        c0 = np.einsum("kvi,kvij,kvj->k", v, Pc, v) + 2 * np.einsum("kvi,kvi->k", qc, v) + rc.sum(axis=1)
        Hu = mu[a:b, None, None] * Rs[d] + np.einsum("ia,kij,jb->kab", B, S, B)
        SA = np.einsum("kij,jb->kib", S, A)
        BSA = np.einsum("ia,kib->kab", B, SA)
        Bs = s @ B
        G = np.linalg.pinv(Hu, hermitian=True)
        Pm = (mu[a:b, None, None] * Qs[d] + np.einsum("ia,kib->kab", A, SA)
              - np.einsum("kai,kab,kbj->kij", BSA, G, BSA))
        q = s @ A - np.einsum("kai,kab,kb->ki", BSA, G, Bs)
        r = c0 - np.einsum("ka,kab,kb->k", Bs, G, Bs)
    return float(x @ Pm[0] @ x + 2 * q[0] @ x + r[0])
