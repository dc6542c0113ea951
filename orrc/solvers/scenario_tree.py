"""Feedback min-max over the scenario tree of W's vertices (Scokaert and Mayne, 1998).

The feedback (closed-loop) M-step min-max value of a linear system x_{j+1} = A x_j + B u_j + w_j with
a convex quadratic stage cost and a polytope W = conv{v_1..v_k} is

    V^fb_{W,M}(x) = min_{u_0} max_{w_0} min_{u_1} max_{w_1} ... min_{u_{M-1}} Σ_{j<M} c(x_j, u_j; p_j),

the value of the M-step game in which u_j may depend on everything seen so far (x_0..x_j, hence
w_0..w_{j-1}) but not on w_j. Its dynamic program has convex value functions (a minimum over u of a
maximum of convex functions of (x, u)), and x_{j+1} is affine in w_j, so every inner maximum over W is
attained at a vertex. The game is therefore exactly the convex program on the *scenario tree*: one
node per vertex history (w_0..w_{j-1}) for j = 0..M-1 (the last disturbance w_{M-1} moves only the
uncosted x_M), one input per node, the state of a node fixed by its parent's state and input and its
own vertex, and the worst case over the V^{M-1} leaves written as nested epigraphs:

    min t_root  s.t.  t_i >= e_i + t_c (c a child of i),  t_leaf >= e_leaf,  e_i >= c(x_i, u_i),

an SOCP (the quadratic stage costs as rotated cones), solved here by cvxpy with Clarabel. Causality
holds by construction: a node's input sees only its own history. Applied in receding horizon
(:class:`~orrc.MinMaxRHC` with ``policy="feedback"``), only the root input is used.

Size: the tree has N = 1 + V + ... + V^{M-1} nodes (V the vertex count of W). It is counted before
anything is built, and a tree of more than ``TREE_NODE_LIMIT`` nodes is refused with an
:class:`~orrc.OrrcValueError` naming M, V and the limit; below it, the memory and the work of the
solve are estimated and checked by ``orrc._validate.check_size`` (``orrc.config``'s limits).

Nonlinear systems and non-quadratic costs are refused: the vertex argument needs convexity.
"""
from __future__ import annotations

import math
import time
import warnings

import numpy as np

from .minmax import MinMaxPlan
from .tree_lq import weighted_tree_value
from .tree_size import TREE_NODE_LIMIT, _check_tree, tree_nodes, tree_vertices  # noqa: F401 (re-exported)

__all__ = ["ScenarioTree", "TREE_NODE_LIMIT", "tree_nodes", "tree_vertices"]

#: up to this many nodes the program is compiled once with x as a parameter (fast re-solves in a closed
#: loop); above it cvxpy's parametric compilation costs more than compiling anew at every solve
_PARAMETRIC_NODES = 1500
#: a solve succeeds when its bounds meet to this relative gap (typically they meet to 1e-9)
RTOL = 1e-6

# Clarabel's tolerances and refinement: the tree's value to about 1e-9 relative on the book's and the tests'
# problems, badly scaled ones of the Lemma 6 search included (R up to 1e3, |A| near 2, M = 6)
_CLARABEL = {"tol_gap_abs": 1e-10, "tol_gap_rel": 1e-10, "tol_feas": 1e-10, "tol_ktratio": 1e-9,
             "iterative_refinement_reltol": 1e-14, "iterative_refinement_abstol": 1e-14,
             "iterative_refinement_max_iter": 30, "max_iter": 400}


def _sqrt_psd(S: np.ndarray) -> np.ndarray:
    """L with L Lᵀ = S for a symmetric PSD S (eigenvalues below zero by rounding clipped)."""
    lam, Q = np.linalg.eigh(0.5 * (S + S.T))
    return Q * np.sqrt(np.clip(lam, 0.0, None))


class ScenarioTree:
    """The feedback min-max problem of the module docstring, for one system, cost, horizon and W.

    Parameters
    ----------
    system : LinearSystem
        x_{j+1} = A x_j + B u_j + w_j.
    cost : QuadraticCost
        c(x, u) = xᵀQx + uᵀRu (time-varying weights through ``solve(x, P)``).
    M : int
        The horizon (>= 1).
    W : Box or Polytope
        The disturbance set; its vertices branch the tree.
    input_bounds : tuple of two arrays (m,), optional
        (lo, hi), the set U, applied at every node.

    Examples
    --------
    >>> import numpy as np, orrc
    >>> from orrc.solvers.scenario_tree import ScenarioTree
    >>> ex = orrc.examples.scalar_unstable(A=1.2)
    >>> tree = ScenarioTree(ex.system, ex.cost, 3, orrc.Box(-0.3, 0.3))
    >>> tree.nodes, tree.leaves
    (7, 4)
    >>> plan = tree.solve(np.zeros(1))
    >>> plan.inputs.shape, plan.certified
    ((3, 1), True)
    """

    def __init__(self, system, cost, M: int, W, input_bounds=None):
        self.M, self.n, self.m = int(M), system.n, system.m
        self.A, self.B, self.cost, self.W = system.A, system.B, cost, W
        verts = tree_vertices(W)
        self.verts = verts
        V = len(verts)
        self.nodes = _check_tree(V, self.M, self.n, self.m)
        self.leaves = V ** (self.M - 1)
        # nodes in breadth-first order: depth d occupies [off[d], off[d+1]); node off[d] + i has parent
        # off[d-1] + i // V and vertex i % V (so the leaves' vertex histories are base-V digits)
        self.off = np.concatenate([[0], np.cumsum([V ** d for d in range(self.M)])]).astype(np.int64)
        child = np.arange(1, self.nodes)
        depth = np.searchsorted(self.off, child, side="right") - 1
        local = child - self.off[depth]
        self.parent = self.off[depth - 1] + local // V
        self.vertex = local % V
        self.depth = np.concatenate([[0], depth])
        self.input_bounds = input_bounds
        w2 = float(np.max(np.sum(verts ** 2, axis=1)))
        self.scale = math.sqrt(w2) if w2 > 0 else 1.0    # w̄: the program's unit of length
        self._problems = {}

    # -- the SOCP -------------------------------------------------------------------
    def _weights(self, P):
        M = self.M
        if P is None:
            return [self.cost.Q] * M, [self.cost.R] * M
        pairs = [self.cost.unpack(p) for p in P]
        return [q for q, _ in pairs], [r for _, r in pairs]

    def _riccati(self, P):
        """The nominal LQ recursion with the stage weights: P_d (M+1, n, n), K_d (M, m, n), H_d (M, m, m)."""
        Qs, Rs = self._weights(P)
        M, n, m, A, B = self.M, self.n, self.m, self.A, self.B
        Ps, Ks, Hs = np.zeros((M + 1, n, n)), np.zeros((M, m, n)), np.zeros((M, m, m))
        for d in range(M - 1, -1, -1):
            Pn = Ps[d + 1]
            Hs[d] = Rs[d] + B.T @ Pn @ B
            Ks[d] = np.linalg.solve(Hs[d], B.T @ Pn @ A)
            S = Qs[d] + A.T @ Pn @ A - A.T @ Pn @ B @ Ks[d]
            Ps[d] = 0.5 * (S + S.T)
        return Ps, Ks, Hs

    def _build(self, P):
        """The SOCP in deviations from the nominal LQ plan, scaled by w̄ = max‖w‖.

        With the nominal LQ recursion (P_d, K_d, H_d) and u_i = ū_d + w̄ ν_i, x_i = x̄_d + w̄ ξ_i (x̄, ū the
        nominal plan from x with w = 0), completing the square along every path gives
        J = xᵀP_0x + w̄² Σ_nodes [‖ν_i + K_d ξ_i‖²_{H_d} + 2 ξ_iᵀP_d v̂_i + κ_i], with v̂ = v/w̄ the node's vertex
        and κ_i = 2 x̄_dᵀP_d v̂_i / w̄ - v̂_iᵀP_d v̂_i (0 at the root): the constraints do not depend on x,
        which enters through κ (and the input bounds) only, and the program's numbers are of order one
        whatever the size of x.
        """
        import cvxpy as cp

        N, n, m, M = self.nodes, self.n, self.m, self.M
        Ps, Ks, Hs = self._riccati(P)
        vh = self.verts / self.scale
        kappa = cp.Parameter(N)
        xi, nu = cp.Variable((N, n)), cp.Variable((N, m))
        e, t = cp.Variable(N), cp.Variable(N)
        V = len(vh)
        cons = [xi[0] == 0]
        for d in range(1, M):      # the children of depth d-1 with vertex v: rows a + v, a + v + V, ... of depth d
            a, b, pa, pb = self.off[d], self.off[d + 1], self.off[d - 1], self.off[d]
            drive = xi[pa:pb] @ self.A.T + nu[pa:pb] @ self.B.T
            cons += [xi[a + v:b:V] == drive + vh[v] for v in range(V)]
        Z, lin = [], []
        for d in range(M):
            a, b = self.off[d], self.off[d + 1]
            Z.append((nu[a:b] + xi[a:b] @ Ks[d].T) @ _sqrt_psd(Hs[d]))
            if d > 0:
                lin.append(2 * cp.sum(cp.multiply(xi[a:b], vh[self.vertex[a - 1:b - 1]] @ Ps[d]), axis=1))
        Z = cp.vstack(Z) if M > 1 else Z[0]
        # e_i >= ‖z_i‖²  <=>  ‖(2 z_i, e_i - 1)‖ <= e_i + 1
        cons.append(cp.SOC(e + 1, cp.vstack([2 * Z.T, cp.reshape(e - 1, (1, N), order="C")]), axis=0))
        g = e + kappa
        if M > 1:
            g = g + cp.hstack([np.zeros(1), cp.hstack(lin)])
        leaf0 = self.off[M - 1]
        for d in range(1, M):
            a, b, pa, pb = self.off[d], self.off[d + 1], self.off[d - 1], self.off[d]
            cons += [t[pa:pb] >= g[pa:pb] + t[a + v:b:V] for v in range(V)]
        leaf_con = t[leaf0:] >= g[leaf0:]            # its multipliers: the leaves' weights (the dual bound)
        cons.append(leaf_con)
        bounds = None
        if self.input_bounds is not None:
            bounds = (cp.Parameter((M, m)), cp.Parameter((M, m)))
            depth_of = self.depth
            cons += [nu >= bounds[0][depth_of], nu <= bounds[1][depth_of]]
        prob = cp.Problem(cp.Minimize(t[0]), cons)
        return {"prob": prob, "kappa": kappa, "nu": nu, "leaf_con": leaf_con, "bounds": bounds,
                "riccati": (Ps, Ks, Hs), "vh": vh}

    def _problem(self, P):
        key = None if P is None else np.asarray(P, float).tobytes()
        if key not in self._problems:
            if len(self._problems) > 4:
                self._problems.clear()
            self._problems[key] = self._build(P)
        return self._problems[key]

    # -- exact evaluation of a tree policy --------------------------------------------
    def _leaf_costs(self, x, Un, P):
        """(states (N, n), the cost Σ_j c(x_j, u_j) along every leaf's path (V^{M-1},)) of node inputs Un."""
        N, n = self.nodes, self.n
        Qs, Rs = self._weights(P)
        X = np.empty((N, n))
        X[0] = x
        if N > 1:
            for d in range(1, self.M):   # one depth at a time (parents are computed before children)
                a, b = self.off[d], self.off[d + 1]
                par = self.parent[a - 1:b - 1]
                X[a:b] = X[par] @ self.A.T + Un[par] @ self.B.T + self.verts[self.vertex[a - 1:b - 1]]
        stage = np.empty(N)
        for d in range(self.M):
            a, b = self.off[d], self.off[d + 1]
            stage[a:b] = np.einsum("ij,jk,ik->i", X[a:b], Qs[d], X[a:b]) + np.einsum("ij,jk,ik->i", Un[a:b], Rs[d],
                                                                                     Un[a:b])
        path = stage.copy()
        for d in range(1, self.M):
            a, b = self.off[d], self.off[d + 1]
            path[a:b] += path[self.parent[a - 1:b - 1]]
        return X, path[self.off[self.M - 1]:]

    def dual_bound(self, x, weights, P=None) -> float:
        """A lower bound on V^fb_{W,M}(x) from any weights λ >= 0 on the leaves (weak duality).

        For every tree policy, max_leaf J_leaf >= Σ λ_leaf J_leaf / Σ λ, so V^fb >= min over tree policies
        of the weighted cost, a linear-quadratic problem on the tree solved exactly by a backward Riccati
        recursion (node i weighs its stage cost by μ_i, the weight of the leaves below it). The
        multipliers of the leaves' epigraph constraints make it tight; any λ gives a valid bound, so the
        bound does not depend on the conic solver's accuracy.

        Parameters
        ----------
        x : array_like, shape (n,)
            The root state.
        weights : array_like, shape (V^{M-1},) or None
            λ, the leaves' weights (negative entries are clipped to 0); None: -inf.
        P : array_like, shape (M, n_params), optional
            The cost parameters, as in :meth:`solve`.

        Returns
        -------
        float
            The bound (-inf when the weights are all zero or None).

        Examples
        --------
        >>> import numpy as np, orrc
        >>> from orrc.solvers.scenario_tree import ScenarioTree
        >>> ex = orrc.examples.scalar_unstable(A=1.2)
        >>> tree = ScenarioTree(ex.system, ex.cost, 3, orrc.Box(-0.3, 0.3))
        >>> # equal weights: the least expected cost when the signs are fair coin flips,
        >>> # 0.09 (P_1 + P_2)
        >>> round(tree.dual_bound(np.zeros(1), np.ones(4)), 6)
        0.2448
        """
        if weights is None:
            return -math.inf
        lam = np.clip(np.asarray(weights, float).ravel(), 0.0, None)
        if lam.size != self.leaves or not lam.sum() > 0 or not np.all(np.isfinite(lam)):
            return -math.inf
        Qs, Rs = self._weights(P)
        return weighted_tree_value(self.A, self.B, Qs, Rs, self.verts, self.off, self.parent, lam / lam.sum(),
                                   np.asarray(x, float))

    def path(self, leaf: int) -> np.ndarray:
        """The node indices from the root to leaf number ``leaf`` (0 <= leaf < V^{M-1}), shape (M,).

        Parameters
        ----------
        leaf : int
            The leaf's number (its vertex history read as base-V digits, w_0 the most significant).

        Returns
        -------
        numpy.ndarray of int, shape (M,)

        Examples
        --------
        >>> import orrc
        >>> from orrc.solvers.scenario_tree import ScenarioTree
        >>> ex = orrc.examples.scalar_unstable()
        >>> ScenarioTree(ex.system, ex.cost, 3, orrc.Box(-1.0, 1.0)).path(2).tolist()
        [0, 2, 5]
        """
        node = int(self.off[self.M - 1] + leaf)
        out = [node]
        while node > 0:
            node = int(self.parent[node - 1])
            out.append(node)
        return np.array(out[::-1])

    def solve(self, x, P=None) -> MinMaxPlan:
        """V^fb_{W,M}(x) and the tree policy that attains it.

        Parameters
        ----------
        x : array_like, shape (n,)
            The state at the root.
        P : array_like, shape (M, n_params), optional
            The cost parameters of the M stages (default: the cost's own, time-invariant).

        Returns
        -------
        MinMaxPlan
            ``upper`` = ``value``: the exact worst case, over the leaves, of the node inputs returned;
            ``lower``: a lower bound by weak duality (:meth:`dual_bound` with the multipliers of the
            leaves; without input bounds ``certified`` is True: lower <= V^fb <= upper whatever the
            solver's accuracy; with input bounds ``lower`` is the solver's objective, not certified);
            ``success``: the bounds meet to ``RTOL`` (1e-6) relative; ``inputs`` (M, m): the inputs along the worst leaf's path (``inputs[0]``
            is the root input, the one a receding horizon applies); ``worst_w`` (M, n) that path's
            vertices (w_{M-1} repeats w_{M-2}; it is not costed); ``states`` (M+1, n);
            ``extra["node_inputs"]`` (N, m) and ``extra["node_states"]`` (N, n) the whole policy;
            ``method`` "feedback"; ``sequences`` the leaves V^{M-1}; ``scenarios`` the nodes N.

        Examples
        --------
        >>> import numpy as np, orrc
        >>> from orrc.solvers.scenario_tree import ScenarioTree
        >>> ex = orrc.examples.scalar_unstable(A=1.2)
        >>> p = ScenarioTree(ex.system, ex.cost, 2, orrc.Box(-0.3, 0.3)).solve(np.array([1.0]))
        >>> p.inputs.shape, p.gap < 1e-8 * p.value
        ((2, 1), True)
        """
        import cvxpy as cp

        t0 = time.perf_counter()
        x = np.asarray(x, float)
        pr = self._problem(P)
        prob, leaf_con, (Ps, Ks, _) = pr["prob"], pr["leaf_con"], pr["riccati"]
        w_s, M = self.scale, self.M
        xbar, ubar = np.empty((M, self.n)), np.empty((M, self.m))
        xbar[0] = x
        for d in range(M):                                # the nominal plan (w = 0)
            ubar[d] = -Ks[d] @ xbar[d]
            if d + 1 < M:
                xbar[d + 1] = self.A @ xbar[d] + self.B @ ubar[d]
        kap = np.zeros(self.nodes)
        if self.nodes > 1:
            d = self.depth[1:]
            vh = pr["vh"][self.vertex]
            kap[1:] = (2 * np.einsum("ki,kij,kj->k", xbar[d], Ps[d], vh) / w_s
                       - np.einsum("ki,kij,kj->k", vh, Ps[d], vh))
        pr["kappa"].value = kap
        if pr["bounds"] is not None:
            lo, hi = self.input_bounds
            pr["bounds"][0].value = (np.broadcast_to(lo, ubar.shape) - ubar) / w_s
            pr["bounds"][1].value = (np.broadcast_to(hi, ubar.shape) - ubar) / w_s
        Uv = pr["nu"]
        status, ok = "optimal", True
        try:
            with warnings.catch_warnings():          # "inaccurate" is judged below, by the bounds
                warnings.simplefilter("ignore", UserWarning)
                prob.solve(solver=cp.CLARABEL, ignore_dpp=self.nodes > _PARAMETRIC_NODES, **_CLARABEL)
            status = str(prob.status)
            ok = status in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE) and Uv.value is not None
        except cp.error.SolverError as err:
            status, ok = f"Clarabel failed: {err}", False
        Un = ubar[self.depth] + w_s * (Uv.value if Uv.value is not None else 0.0)
        if self.input_bounds is not None:
            Un = np.clip(Un, *self.input_bounds)
        X, costs = self._leaf_costs(x, Un, P)
        k = int(np.argmax(costs))
        upper = float(costs[k])
        lower = -math.inf
        if ok:
            lam = None if leaf_con.dual_value is None else np.asarray(leaf_con.dual_value, float).ravel()
            lower = min(self.dual_bound(x, lam, P), upper) if self.input_bounds is None else min(float(prob.value),
                                                                                                 upper)
        nodes = self.path(k)
        inputs = Un[nodes]
        worst = self.verts[self.vertex[nodes[1:] - 1]] if self.M > 1 else self.verts[:1]
        worst = np.vstack([worst, worst[-1:]]) if self.M > 1 else worst.copy()
        states = np.vstack([X[nodes], (self.A @ X[nodes[-1]] + self.B @ inputs[-1] + worst[-1])[None, :]])
        # the bounds are valid whatever the solver's accuracy (certified); success asks them to meet
        certified = ok and self.input_bounds is None and np.isfinite(lower)
        ok = ok and (upper - lower) <= RTOL * max(abs(upper), 1e-300)
        return MinMaxPlan(inputs=inputs, states=states, value=upper, success=ok, status=status, solver="clarabel",
                          iterations=int(getattr(prob.solver_stats, "num_iters", 0) or 0),
                          solve_time=time.perf_counter() - t0, worst_w=worst, lower=lower, upper=upper,
                          method="feedback", certified=bool(certified), scenarios=self.nodes, evaluations=self.leaves,
                          sequences=self.leaves, history=np.array([[lower, upper]]),
                          extra={"node_inputs": Un, "node_states": X, "leaf_costs": costs})
