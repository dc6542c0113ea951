"""Scenario exchange (cutting planes) for the min-max problem of Algorithm 3, any system and cost.

    V_{W,M}(x) = min_{U ∈ U^M} φ(U),   φ(U) = max_{W ∈ W^M} J(x, U, W)     (see :mod:`orrc.solvers.minmax`)

is solved by alternating two problems, as in the classical exchange method for semi-infinite
programs:

* the **outer problem** over a finite set S of disturbance sequences (scenarios),

      lower(S) = min_{U ∈ U^M, t} t   s.t.  J(x, U, W^k) <= t  for every W^k ∈ S,

  a lower bound on V_{W,M}(x) (S ⊂ W^M) when it is solved to global optimality (it is convex
  for a linear system with a convex cost; for a nonlinear one the local solver's answer is
  reported, labelled). It is ONE CasADi NLP per number of scenario slots K (4, 8, 16, ...: the
  next power of two above |S|), single shooting, with the scenarios as parameters; unused
  slots hold a copy of the first scenario with an inactive bound (ubg = +inf). Each K is built
  once per :class:`ScenarioExchange` and cached (a build costs tens of milliseconds); nothing is
  rebuilt while the scenario count stays within K. Solver: CasADi's ``sqpmethod`` with the
  DAQP QP solver (a few tenths of a millisecond per iteration on these small dense problems),
  with IPOPT as the fallback when it fails;
* the **inner problem** max_{W ∈ W^M} J(x, U, W) for the current plan U, by multi-start local
  maximisation: the conditional-gradient (Frank-Wolfe) ascent, whose linear step maps the
  gradient to a vertex of the box (w_j = hi where ∂J/∂w_j > 0, lo where < 0) or to the sphere
  of the ball (w_j = r g_j/‖g_j‖), with backtracking when J does not increase (never for a
  convex J, where every full step increases J); it stops at a point where no direction of
  W^M increases the linearisation (a first-order local maximum). For a box, the vertices
  are the candidates: a convex J has its maximum at one. Starts: the local maxima found in
  earlier iterations, the scenarios of S, the linearisation at the centre of W, and random
  vertices (box) or random points of the sphere (ball), all evaluated in one mapped CasADi
  call per ascent step. The largest value found is ``upper``: the true φ(U) is at least that
  large, and equals it when the search found the global maximum (which a local search cannot
  certify).

**Around a nominal sequence** (``nominal=True``): the disturbance of stage j is ŵ_j + w_j, with
the nominal ŵ_j in the last n rows of that stage's parameters (the rows after the cost's), and
the maximum is over the deviations w ∈ W^M: min_U max_{W ∈ W^M} J(x, U, Ŵ + W). That is the
robust preview problem around a forecast Ŵ (:class:`orrc.RobustPreviewRHC`); the forecast is a
parameter, so nothing is rebuilt when it changes from one step to the next.

The worst sequence found joins S, and the loop repeats until upper - lower <= rtol·|upper| +
atol, or ``max_iter`` iterations (then ``success`` is False: the caller reports it). The
plan returned is the one with the smallest ``upper`` seen. With ``max_scenarios`` slots in use,
scenarios whose constraint is inactive (zero multiplier) are dropped first.
"""
from __future__ import annotations

import math
import time

import casadi as ca
import numpy as np

from .._validate import as_seed, check_size
from ..disturbances import Box
from .minmax import MinMaxPlan
from .nlp import _OPS_PER_NODE

__all__ = ["ScenarioExchange"]

_SQP = {
    "qpsol": "daqp",
    "qpsol_options": {"daqp": {"eps_prox": 1e-3}, "error_on_fail": False},
    # clip the negative eigenvalues of the Lagrangian's Hessian (nonlinear J): 5 SQP iterations on the
    # pendulum where "regularize" took 15 to 19
    "convexify_strategy": "eigen-clip",
    "max_iter": 100,
    "tol_pr": 1e-10,
    "tol_du": 1e-10,
    "print_header": False,
    "print_iteration": False,
    "print_status": False,
    "print_time": False,
    "error_on_fail": False,
}
_IPOPT = {"ipopt.print_level": 0, "ipopt.sb": "yes", "print_time": False, "ipopt.tol": 1e-10,
          "ipopt.max_iter": 500}


class ScenarioExchange:
    """Scenario exchange for the min-max problem of Algorithm 3, Eq. (D.1):
    V_{W,M}(x) = min_U max_{W ∈ W^M} J(x, U, W) (see the module docstring).

    Parameters
    ----------
    system, cost, M : the model, the stage-cost family and the horizon.
    W : an :class:`~orrc.Box` or :class:`~orrc.Ball` (validated by the caller).
    input_bounds : (lo, hi) arrays of length m, or None.
    rtol, atol : stop when upper - lower <= rtol·|upper| + atol.
    max_iter : exchange iterations (outer + inner solves) before giving up.
    n_starts : starts of the inner multi-start ascent.
    max_scenarios : the most scenarios kept in the outer problem.
    solver : "sqpmethod" (DAQP QPs; default) or "ipopt", for the outer problem.
    solver_options : options added to that solver's (a dict), or None.
    seed : seed of the random starts (each solve draws them afresh from it: deterministic).
    fw_iter : the most conditional-gradient steps of one inner ascent.
    verify_factor : the wider search that confirms convergence uses ``verify_factor * n_starts`` starts.
    nominal : when True, the disturbance is ŵ_j + w_j with ŵ_j the last n entries of the stage's
        parameter row: ``solve``'s P is then (M, n_params + n), and W bounds the deviation w_j.

    Examples
    --------
    x⁺ = x + u + w, c = x² + 0.1u², W = [-0.5, 0.5], M = 3: a linear system with a convex cost, so
    the exchange closes its gap, and its value is the exact one of the vertex method:

    >>> import numpy as np
    >>> import orrc
    >>> from orrc.solvers.exchange import ScenarioExchange
    >>> system = orrc.LinearSystem([[1.0]], [[1.0]])
    >>> cost = orrc.QuadraticCost([[1.0]], [[0.1]])
    >>> W = orrc.Box([-0.5], [0.5])
    >>> exchange = ScenarioExchange(system, cost, 3, W)
    >>> plan = exchange.solve(np.ones(1),
    ...                       np.broadcast_to(cost.default_params, (3, cost.n_params)))
    >>> bool(plan.success and plan.upper - plan.lower <= 1e-6 * plan.upper)
    True
    >>> exact = orrc.MinMaxRHC(system, cost, 3, W, method="exact").plan(np.ones(1))
    >>> bool(abs(plan.value - exact.value) <= 1e-6 * exact.value)
    True
    """

    def __init__(self, system, cost, M: int, W, input_bounds=None, rtol: float = 1e-6, atol: float = 1e-10,
                 max_iter: int = 30, n_starts: int = 8, max_scenarios: int = 64, solver: str = "sqpmethod",
                 solver_options=None, seed=0, fw_iter: int = 50, verify_factor: int = 4, nominal: bool = False):
        as_seed("seed", seed)      # a seed numpy cannot use is refused here, not at the first solve
        # the expression graphs built now: J over M stages, its gradient, the rollout and the first outer
        # problem (4 scenario slots); larger outer problems are built when the exchange needs them
        npar = cost.n_params
        per_stage = 30 + 4 * (system.n + system.m + npar + (system.n if nominal else 0))
        nodes = 8.0 * M * per_stage
        check_size(f"the scenario exchange's CasADi problems at the horizon M={M} (n={system.n}, m={system.m})",
                   nbytes=400.0 * nodes, ops=_OPS_PER_NODE * nodes, hint="lower M")
        self.M, self.n, self.m, self.W = M, system.n, system.m, W
        self.rtol, self.atol, self.max_iter = rtol, atol, max_iter
        self.n_starts, self.max_scenarios, self.fw_iter, self.seed = n_starts, max_scenarios, fw_iter, seed
        self.solver_name, self.solver_options = solver, dict(solver_options or {})
        self.nominal = bool(nominal)
        n, m = self.n, self.m
        x = ca.SX.sym("x", n)
        U = ca.SX.sym("U", m, M)
        Wm = ca.SX.sym("W", n, M)
        P = ca.SX.sym("P", npar + (n if self.nominal else 0), M)   # cost parameters, then ŵ_j (nominal)
        J, xj, states = 0, x, [x]
        for j in range(M):
            J += cost.expr(xj, U[:, j], P[:npar, j])
            xj = system.symbolic(xj, U[:, j], Wm[:, j] + P[npar:, j] if self.nominal else Wm[:, j])
            states.append(xj)
        self._J = ca.Function("J", [x, U, Wm, P], [J])
        self._rollout = ca.Function("rollout", [x, U, Wm, P], [ca.horzcat(*states)])
        self._JG = ca.Function("JG", [x, U, Wm, P], [J, ca.gradient(J, Wm)])
        self._d = n * (M - 1)                    # the coordinates of w_0..w_{M-2} (w_{M-1} is not costed)
        # batched evaluations (one CasADi call per ascent step: the call overhead dominates on these
        # small problems): J and ∂J/∂W for n_starts or n_verify sequences, and J alone for the single
        # flips (box only) of the best n_flip local maxima of a search, or of the best n_starts in the
        # wider search that confirms convergence
        self.n_verify = verify_factor * n_starts
        self.n_flip = min(2, n_starts)
        self._JG_maps = {k: self._JG.map(k, "serial") for k in {n_starts, self.n_verify}}
        self._J_maps = {}
        if isinstance(W, Box) and self._d:
            self._J_maps = {k: self._J.map(k * self._d, "serial") for k in {self.n_flip, n_starts}}
        self._outer = {}
        ulo, uhi = (np.full(m, -np.inf), np.full(m, np.inf)) if input_bounds is None else input_bounds
        self.lbz = np.concatenate([np.tile(ulo, M), [-np.inf]])
        self.ubz = np.concatenate([np.tile(uhi, M), [np.inf]])
        if isinstance(W, Box):
            self._lo, self._hi = W.lo.astype(float), W.hi.astype(float)
            self._center = 0.5 * (self._lo + self._hi)
        else:
            self._center = np.zeros(n)
        self.scale = math.sqrt(W.max_norm_sq) if W.max_norm_sq > 0 else 1.0

    # -- the outer problem: one NLP per number of slots K ----------------------------------------
    def _outer_solver(self, K: int, solver: str):
        key = (K, solver)
        if key not in self._outer:
            M, n, m = self.M, self.n, self.m
            U = ca.SX.sym("U", m, M)
            t = ca.SX.sym("t")
            x = ca.SX.sym("x", self.n)
            P = ca.SX.sym("P", self._J.size1_in(3), M)
            Ws = ca.SX.sym("Ws", n, M * K)
            g = [self._J(x, U, Ws[:, k * M:(k + 1) * M], P) - t for k in range(K)]
            prob = {"x": ca.vertcat(ca.vec(U), t), "f": t, "g": ca.vertcat(*g),
                    "p": ca.vertcat(x, ca.vec(P), ca.vec(Ws))}
            opts = dict(_SQP if solver == "sqpmethod" else _IPOPT)
            opts.update(self.solver_options if solver == self.solver_name else {})
            self._outer[key] = ca.nlpsol(f"minmax_outer_{K}", solver, prob, opts)
        return self._outer[key]

    def _solve_outer(self, x, P, S, z0):
        k = len(S)
        K = max(4, 1 << (k - 1).bit_length())
        Ws = np.concatenate([S, np.repeat(S[:1], K - k, axis=0)])          # (K, M, n)
        p = np.concatenate([x, P.reshape(-1), Ws.reshape(-1)])           # vec(W^k) = rows of (M, n)
        ubg = np.where(np.arange(K) < k, 0.0, np.inf)
        tried = []
        for solver in dict.fromkeys([self.solver_name, "ipopt"]):
            nlp = self._outer_solver(K, solver)
            sol = nlp(x0=z0, p=p, lbx=self.lbz, ubx=self.ubz, lbg=-np.inf, ubg=ubg)
            st = nlp.stats()
            z = np.asarray(sol["x"]).ravel()
            tried.append(f"{solver}: {st.get('return_status', 'unknown')}")
            if st.get("success", False) and np.all(np.isfinite(z)):
                return z, np.asarray(sol["lam_g"]).ravel()[:k], True, "; ".join(tried), int(st.get("iter_count", 0))
        return z, np.zeros(k), False, "; ".join(tried), int(st.get("iter_count", 0))

    # -- the inner problem: multi-start conditional-gradient ascent --------------------------------
    @staticmethod
    def _pad(Ws, size):
        return np.concatenate([Ws, np.repeat(Ws[:1], size - len(Ws), axis=0)]) if len(Ws) < size else Ws

    def _evaluate(self, args, Ws):
        """J and ∂J/∂W at the sequences Ws (S, M, n) in one mapped call (args: x, Uᵀ, Pᵀ as DM)."""
        S = len(Ws)
        size = min(k for k in self._JG_maps if k >= S)
        Jv, G = self._JG_maps[size](args[0], args[1], self._pad(Ws, size).reshape(-1, self.n).T, args[2])
        return np.asarray(Jv).ravel()[:S], np.asarray(G).T.reshape(size, self.M, self.n)[:S]

    def _oracle(self, G, Wc):
        """The point of W^M that maximises the linearisation ⟨G, W⟩ (ties keep the current point)."""
        if isinstance(self.W, Box):
            return np.where(G > 0, self._hi, np.where(G < 0, self._lo, Wc))
        norms = np.linalg.norm(G, axis=2, keepdims=True)
        tiny = norms <= 1e-300
        return np.where(tiny, Wc, self.W.radius * G / np.where(tiny, 1.0, norms))

    def _ascend(self, args, starts):
        """Local maxima of J(x, U, ·) from each start (S, M, n): (W (S, M, n), J (S,), evaluations)."""
        Wc = starts.copy()
        Jc, G = self._evaluate(args, Wc)
        evals = len(Wc)
        active = np.ones(len(Wc), bool)
        for _ in range(self.fw_iter):
            Sv = self._oracle(G, Wc)
            gap = np.einsum("smn,smn->s", G, Sv - Wc)
            active &= gap > 1e-12 * np.maximum(np.abs(Jc), 1e-300)
            if not active.any():
                break
            tau = np.where(active, 1.0, 0.0)
            for _ in range(8):                                   # backtracking on the starts still trying
                Wn = Wc + tau[:, None, None] * (Sv - Wc)
                Jn, Gn = self._evaluate(args, Wn)
                evals += int(np.count_nonzero(tau))
                up = (tau > 0) & (Jn > Jc)
                Wc[up], Jc[up], G[up] = Wn[up], Jn[up], Gn[up]
                tau = np.where(up, 0.0, 0.5 * tau)
                if not tau.any():
                    break
            active &= ~(tau > 0)                                 # no increase even after backtracking: stop there
        return Wc, Jc, evals

    def _flip(self, args, Wc, Jc, size):
        """One round of single-coordinate flips at box vertices: every coordinate of w_0..w_{M-2} of
        every start moved to the other end of its interval, all evaluated in one mapped call; each
        start takes its best improving flip. Returns (W, J, improved (S,), evaluations)."""
        S, d = len(Wc), self._d
        flat = Wc.reshape(S, -1)[:, :d]
        lo, hi = np.tile(self._lo, self.M - 1), np.tile(self._hi, self.M - 1)
        other = np.where(np.abs(flat - lo) <= np.abs(flat - hi), hi, lo)       # (S, d)
        cand = np.repeat(Wc.reshape(S, 1, -1), d, axis=1)                      # (S, d, Mn)
        cand[:, np.arange(d), np.arange(d)] = other
        cand = cand.reshape(S * d, self.M, self.n)
        Jv = np.asarray(self._J_maps[size](args[0], args[1], self._pad(cand, size * d).reshape(-1, self.n).T,
                                           args[2])).ravel()[:S * d].reshape(S, d)
        k = np.argmax(Jv, axis=1)
        improved = Jv[np.arange(S), k] > Jc * (1 + 1e-12) + 1e-300
        W2, J2 = Wc.copy(), Jc.copy()
        for s in np.flatnonzero(improved):
            W2[s] = cand.reshape(S, d, self.M, self.n)[s, k[s]]
            J2[s] = Jv[s, k[s]]
        return W2, J2, improved, S * d

    def _random_starts(self, rng, count: int) -> np.ndarray:
        M, n = self.M, self.n
        if count <= 0:
            return np.zeros((0, M, n))
        if isinstance(self.W, Box):   # a random vertex at every stage: each coordinate at lo or hi
            return np.where(rng.random((count, M, n)) < 0.5, self._lo, self._hi)
        d = rng.standard_normal((count, M, n))
        return self.W.radius * d / np.maximum(np.linalg.norm(d, axis=2, keepdims=True), 1e-300)

    def _search(self, x, U, P, starts, n_flip):
        """Ascend from every start, refine the best ``n_flip`` by flips (box): the local maxima sorted
        by J (largest first) and the number of evaluations."""
        args = (ca.DM(x), ca.DM(U.T), ca.DM(P.T))
        Wloc, Jloc, evals = self._ascend(args, starts)
        if self._J_maps:
            # a vertex where the ascent stops may still have a better neighbour (one coordinate at
            # its other end): flip, re-ascend, until no flip is better
            top = np.argsort(-Jloc)[:n_flip]
            Wt, Jt = Wloc[top], Jloc[top]
            for _ in range(4 * self._d):
                Wf, _, improved, e = self._flip(args, Wt, Jt, n_flip)
                evals += e
                if not improved.any():
                    break
                W2, J2, e = self._ascend(args, Wf[improved])
                evals += e
                Wt[improved], Jt[improved] = W2, J2
            Wloc[top], Jloc[top] = Wt, Jt
        order = np.argsort(-Jloc)
        return Wloc[order], Jloc[order], evals

    def _inner(self, x, U, P, seeds, rng):
        """The multi-start search of every iteration: n_starts starts, at most half of them distinct
        ``seeds``, then the linearisation at the centre of W (when there is no seed) and random points."""
        chosen = []
        for w in seeds:
            if len(chosen) >= self.n_starts // 2:
                break
            if self._distinct(w, chosen):
                chosen.append(w)
        extra = self._random_starts(rng, self.n_starts - len(chosen))
        if not chosen and len(extra):
            extra[0] = self._center
        starts = np.concatenate([np.array(chosen).reshape(-1, self.M, self.n), extra])
        return self._search(x, U, P, starts, self.n_flip)

    def _verify(self, x, U, P, rng):
        """The wider search that confirms convergence: n_verify random starts, the best n_starts local
        maxima refined by flips (box)."""
        return self._search(x, U, P, self._random_starts(rng, self.n_verify), self.n_starts)

    # -- the exchange loop -----------------------------------------------------------------------
    @staticmethod
    def shifted(prev: MinMaxPlan, k: int) -> tuple[np.ndarray, list[np.ndarray]]:
        """The warm start of a receding-horizon step from a plan solved k >= 1 steps earlier: its
        inputs and its scenarios (those active in its last outer problem, and its worst sequence),
        each shifted k stages (the last row repeated), as ``solve``'s ``guess_U`` and ``scenarios``."""
        def shift(rows):
            return np.vstack([rows[k:], np.repeat(rows[-1:], k, axis=0)])

        seqs = list(prev.extra.get("active_scenarios", [])) + [prev.worst_w]
        return shift(prev.inputs), [shift(s) for s in seqs]

    def _distinct(self, W, S) -> bool:
        """W differs from every sequence of S in w_0..w_{M-2} (w_{M-1} is not costed)."""
        return all(np.max(np.abs(W[:-1] - s[:-1]), initial=0.0) > 1e-9 * self.scale for s in S)

    def solve(self, x, P, guess_U=None, scenarios=None) -> MinMaxPlan:
        """Solve Eq. (D.1), min_U max_W J(x, U, W), from state x by scenario exchange.

        Parameters
        ----------
        x : ndarray
            The state (n,).
        P : ndarray
            The cost parameters of the M stages, (M, n_params); with ``nominal``, each row followed
            by the nominal disturbance ŵ_j of its stage, (M, n_params + n).
        guess_U : ndarray, optional
            A guess of the plan, (M, m) (clipped to the input bounds).
        scenarios : ndarray, optional
            Disturbance sequences (k, M, n) that start the scenario set. With ``guess_U``, e.g. the
            previous step's, shifted one stage: both only speed the solve up.

        Returns
        -------
        MinMaxPlan
            The plan with the smallest upper bound found, its worst disturbance sequence, the bounds
            ``lower`` and ``upper`` and the exchange's report (``success`` False after ``max_iter``).

        Examples
        --------
        See :class:`ScenarioExchange`.
        """
        t0 = time.perf_counter()
        M, m = self.M, self.m
        rng = np.random.default_rng(self.seed)
        U = np.zeros((M, m)) if guess_U is None else np.clip(np.asarray(guess_U, float), self.lbz[:-1].reshape(M, m),
                                                             self.ubz[:-1].reshape(M, m))
        S = [] if scenarios is None else [np.asarray(s, float) for s in scenarios]
        if S:   # warm start: the outer problem starts from the given scenarios
            Wloc, evals = np.array(S), 0
            t_guess = max(float(self._J(x, U.T, s.T, P.T)) for s in S)
        else:   # cold start: the worst case of the guessed plan is the first scenario
            Wloc, Jloc, evals = self._inner(x, U, P, S, rng)
            S, t_guess = [Wloc[0]], float(Jloc[0])
        z = np.concatenate([U.reshape(-1), [t_guess]])
        records = []          # [upper bound found for the plan, plan, its worst W, verified]
        active = list(S)      # the scenarios with a non-zero multiplier in the last outer problem
        lower, history, ok, status, iters, new = -np.inf, [], False, "", 0, []
        outer_status, need_outer = "not run", True
        while True:
            if need_outer:
                iters += 1
                if iters > self.max_iter:
                    iters -= 1
                    status = f"no convergence in {self.max_iter} iterations"
                    break
                z, lam, good, outer_status, _ = self._solve_outer(x, P, np.array(S), z)
                if not good:
                    status = f"outer problem failed ({outer_status})"
                    break
                U, t = z[:-1].reshape(M, m), float(z[-1])
                lower = max(lower, t)
                active = [S[i] for i in range(len(S)) if abs(lam[i]) > 0]
                # seeds: the scenarios active at the plan (largest multiplier first: their J is the
                # outer value), then the local maxima of the last search
                seeds = [S[i] for i in np.argsort(-np.abs(lam)) if abs(lam[i]) > 0] + list(Wloc)
                Wloc, Jloc, e = self._inner(x, U, P, seeds, rng)
                evals += e
                records.append([float(Jloc[0]), U.copy(), Wloc[0].copy(), False])
                tol_t = self.rtol * abs(Jloc[0]) + self.atol
                new = []
                for w, j in zip(Wloc, Jloc):
                    if len(new) < 2 and j > t + tol_t and self._distinct(w, S) and self._distinct(w, new):
                        new.append(w)
            k = min(range(len(records)), key=lambda i: records[i][0])
            upper = records[k][0]
            history.append((lower, upper))
            tol = self.rtol * abs(upper) + self.atol
            if upper - lower <= tol:
                if records[k][3]:
                    ok, status = True, "converged"
                    break
                # converged on the maxima found so far: confirm with a wider search at that plan
                Wv, Jv, e = self._verify(x, records[k][1], P, rng)
                evals += e
                records[k][3] = True
                if Jv[0] <= upper + tol:
                    ok, status = True, "converged"
                    break
                records[k][0], records[k][2] = float(Jv[0]), Wv[0].copy()   # its worst case was higher
                new = [w for w in Wv[:1] if self._distinct(w, S)]
                need_outer = bool(new)
                S = S + new
                continue
            if not new:
                status = f"stalled: no new scenario above the outer value (gap {upper - lower:.3g})"
                break
            if len(S) + len(new) > self.max_scenarios:
                keep = [s for s, l in zip(S, lam) if abs(l) > 0]
                S = keep[-(self.max_scenarios - len(new)):]
            S = S + new
            new, need_outer = [], True
            z = np.concatenate([U.reshape(-1), [max(t, float(Jloc[0]))]])
        if records:
            k = min(range(len(records)), key=lambda i: records[i][0])
            upper, Ub, Wb = records[k][0], records[k][1], records[k][2]
        else:
            upper, Ub, Wb = float(Jloc[0]), U, Wloc[0]
        if not ok:
            status += f" (lower {lower:.6g}, upper {upper:.6g})"
        states = np.asarray(self._rollout(x, Ub.T, Wb.T, P.T)).T
        return MinMaxPlan(inputs=Ub, states=states, value=float(upper), success=ok, status=status, solver=self.solver_name,
                          iterations=iters, solve_time=time.perf_counter() - t0, worst_w=Wb, lower=float(lower),
                          upper=float(upper), method="exchange", certified=False, scenarios=len(S),
                          evaluations=evals, history=np.array(history).reshape(-1, 2),
                          extra={"scenario_set": np.array(S), "active_scenarios": np.array(active).reshape(-1, M, self.n),
                                 "outer_status": outer_status})
