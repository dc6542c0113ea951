"""The M-step min-max problem of Algorithm 3 (Appendix D of the paper): no disturbance preview.

    V_{W,M}(x) = min_{ũ_0..ũ_{M-1} ∈ U}  max_{w̃_0..w̃_{M-1} ∈ W}  J(x, ũ, w̃),
    J(x, ũ, w̃) = Σ_{j=0}^{M-1} c(x̃_j, ũ_j; p_j),   x̃_{j+1} = f(x̃_j, ũ_j, w̃_j),  x̃_0 = x.

The input sequence is chosen first and the disturbance sequence knows it (an open-loop
min-max plan, as in the paper). The last disturbance w̃_{M-1} only moves x̃_M, which is not
costed: it never changes J, so only w̃_0..w̃_{M-2} are searched.

Two exact-or-bounded methods, each reporting a lower and an upper bound on V_{W,M}(x):

* :class:`VertexEpigraph` (``method="exact"``): a :class:`~orrc.LinearSystem`, a
  :class:`~orrc.QuadraticCost` (convex) and a box W. J is then a convex function of the
  disturbance sequence, and the maximum of a convex function over a box is attained at a
  vertex, so the inner maximum is the largest of the N = V^{M-1} vertex sequences (V = 2^n
  vertices of W for a full-dimensional box; the paper's count 2^{nM} includes the irrelevant
  w̃_{M-1}). The epigraph problem min_{U, s} UᵀHU + s s.t. s >= 2 g_vᵀU + k_v for every vertex
  sequence v is a convex QP with N linear constraints; it is solved exactly by constraint
  generation (a small QP over a working set of vertex sequences with CasADi's DAQP, then every
  one of the N sequences is checked, the most violated ones join the set, until none is
  violated). Both bounds are exact up to the QP solver's accuracy.

  Where it stops being practical: the vertex tables hold N·(Mn + Mm + 2) numbers and every
  check costs O(N·M(n+m)). With n = 2: M = 6 gives N = 1024 (well under a millisecond per
  check), M = 8 gives 16 384 (a few ms), M = 9 gives 65 536, M = 10 gives 262 144 (tens of ms
  per check, 70 MB), M = 13 gives 1.7e7 (4 GiB). ``method="auto"`` uses the exact method up to
  N <= ``AUTO_EXACT_LIMIT`` = 2^14 and scenario exchange beyond; an explicit ``method="exact"``
  estimates the memory and the operations first and is refused (or warned about) by
  ``orrc._validate.check_size`` above the limits of ``orrc.config``, with the count of sequences,
  the estimate and the limit in the message.

* :class:`~orrc.solvers.exchange.ScenarioExchange` (``method="exchange"``): everything else,
  nonlinear systems, general costs and balls included (see that module).

The results are :class:`MinMaxPlan` objects (a :class:`~orrc.solvers.Plan` with the bounds).
"""
from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field

import numpy as np

from .._validate import OrrcValueError, check_size
from ..disturbances import Ball, Box, Polytope
from .plan import Plan

__all__ = ["MinMaxPlan", "VertexEpigraph", "check_set", "set_vertices", "vertex_count", "AUTO_EXACT_LIMIT"]

AUTO_EXACT_LIMIT = 2 ** 14

# DAQP needs a proximal term for the semidefinite epigraph QP (no curvature in s); 1e-3 keeps its
# answers accurate to ~1e-12 on the test problems, where 1e-6 and below lost up to 1e-3 (the lower
# bound is certified by the dual function anyway, see VertexEpigraph.solve)
_DAQP = {"daqp": {"eps_prox": 1e-3}, "error_on_fail": False}


@dataclass
class MinMaxPlan(Plan):
    """A min-max plan: ``inputs`` (M, m), the worst-case disturbance sequence found ``worst_w``
    (M, n) and the predicted ``states`` (M+1, n) under it, and bounds on V_{W,M}(x).

    ``value`` is the worst-case cost of the returned inputs over the disturbances the method
    searched (= ``upper``). ``lower`` <= V_{W,M}(x) <= ``upper`` when ``certified`` is True
    (exact method: every vertex sequence was checked). For scenario exchange, ``lower`` is the
    value of the outer problem over the scenarios found (a lower bound when that problem is
    solved to global optimality, e.g. a linear system with a convex cost) and ``upper`` the
    largest cost the multi-start local search found for the plan (an upper bound only if it
    found the global maximum, which a local search cannot certify): ``certified`` is False.

    ``method``: "exact", "exchange" or "game"; ``iterations``: exchange iterations or
    constraint-generation rounds; ``scenarios``: the number of disturbance sequences in the
    final outer problem; ``evaluations``: disturbance sequences at which J was evaluated;
    ``sequences``: N, the vertex sequences of the exact method (0 otherwise);
    ``history``: (lower, upper) after each iteration, shape (iterations, 2). A solve that did not
    succeed returns the best plan found with ``success=False``; the solvers do not warn (the
    controller does, see :class:`~orrc.MinMaxRHC`).
    """

    worst_w: np.ndarray = None
    lower: float = math.nan
    upper: float = math.nan
    method: str = ""
    certified: bool = False
    scenarios: int = 0
    evaluations: int = 0
    sequences: int = 0
    history: np.ndarray = field(default=None, repr=False)

    @property
    def gap(self) -> float:
        """upper - lower."""
        return float(self.upper - self.lower)


def check_set(W, n: int):
    """``W`` checked as the compact disturbance set of Assumption 1.

    Parameters
    ----------
    W : Box, Ball or Polytope (a box needs finite bounds and lo <= hi, a ball a finite radius)
    n : int, the state dimension (w_t enters the state)

    Returns
    -------
    Box, Ball or Polytope: ``W`` itself; an :class:`~orrc.OrrcValueError` naming W otherwise.

    Examples
    --------
    >>> import orrc
    >>> from orrc.solvers.minmax import check_set
    >>> check_set(orrc.Box(-0.3, 0.3), 1)
    Box(lo=[-0.3], hi=[0.3])
    """
    if not isinstance(W, (Box, Ball, Polytope)):
        raise OrrcValueError(f"W must be an orrc.Box(lo, hi), orrc.Ball(radius, n) or orrc.Polytope(vertices), the "
                             f"compact disturbance set; got {type(W).__name__}")
    if W.n != n:
        raise OrrcValueError(f"W must have the state dimension n={n} (w_t enters the state); got a set in R^{W.n}")
    if isinstance(W, Box):
        if not (np.all(np.isfinite(W.lo)) and np.all(np.isfinite(W.hi))):
            raise OrrcValueError(f"W must be bounded (compact); got a box with lo={W.lo}, hi={W.hi}")
        if np.any(W.lo > W.hi):
            raise OrrcValueError(f"W is empty: a box needs lo <= hi in every coordinate; got lo={W.lo}, hi={W.hi}")
    elif isinstance(W, Ball) and not (math.isfinite(W.radius) and W.radius >= 0):
        raise OrrcValueError(f"W must be a ball with a finite radius >= 0; got radius={W.radius}")
    return W


def _box_vertices(W: Box) -> np.ndarray:
    """The distinct vertices of a box (coordinates with lo = hi contribute one value); call it only
    after a size check (:func:`vertex_count`)."""
    return np.array(list(itertools.product(*[(lo,) if lo == hi else (lo, hi) for lo, hi in zip(W.lo, W.hi)])),
                    dtype=float)


def set_vertices(W) -> np.ndarray:
    """The vertices of a box (its distinct corners: coordinates with lo = hi contribute one value)
    or of a polytope (the points it was given), as rows; call it on a box only after a size check
    (:func:`vertex_count`). The worst case of a convex cost over W sits at these points.

    Parameters
    ----------
    W : Box or Polytope

    Returns
    -------
    ndarray, shape (V, n)

    Examples
    --------
    >>> import orrc
    >>> from orrc.solvers.minmax import set_vertices
    >>> set_vertices(orrc.Box([-1.0, 0.0], [1.0, 0.0])).tolist()
    [[-1.0, 0.0], [1.0, 0.0]]
    """
    if isinstance(W, Box):
        return _box_vertices(W)
    if isinstance(W, Polytope):
        return W.vertices()
    raise OrrcValueError(f"W must be an orrc.Box or an orrc.Polytope (a polytope, so that the worst case of a convex "
                         f"cost sits at its vertices); got {type(W).__name__}")


def vertex_count(W, M: int) -> int | float:
    """N = V^{M-1}: the vertex sequences (w_0..w_{M-2}) the exact method enumerates (V = the
    distinct vertices of the box W, 2^n for a full-dimensional one, or the points a polytope was
    given), counted without listing them: an exact integer up to 2^62, beyond it a float (``inf``
    past the float range), so that a long horizon costs nothing to count (2^(M-1) as an integer
    takes seconds to build and to print)."""
    V = len(W.vertices()) if isinstance(W, Polytope) else 2 ** int(np.count_nonzero(W.lo < W.hi))
    bits = (M - 1) * math.log2(V)
    if bits <= 62:
        return V ** (M - 1)
    return 2.0 ** bits if bits < 1024 else math.inf


def condensed(A: np.ndarray, B: np.ndarray, M: int):
    """Φ (Mn, n), G_u (Mn, Mm), G_w (Mn, Mn) with [x_0; ...; x_{M-1}] = Φ x + G_u vec U + G_w vec W
    for x_{j+1} = A x_j + B u_j + w_j (the states of the costed stages). G_u and G_w are the batch
    operators of :func:`orrc.solvers.condensed.condensed` (no pre-stabilisation); Φ stacks A^j."""
    from .condensed import condensed as batch

    n, m = B.shape
    ops = batch(A, B, np.eye(n), np.eye(m), M)
    Phi = np.zeros((M * n, n))
    power = np.eye(n)
    for j in range(M):
        Phi[j * n:(j + 1) * n] = power
        power = A @ power
    return Phi, ops.F, ops.G


class _WorkingSetQP:
    """min_z ½ zᵀ H z + gᵀz s.t. A z <= b (rows of a working set), lbx <= z <= ubx, with CasADi's
    DAQP (a dual active-set solver for small dense QPs). One solver per number of rows, built
    once and cached; unused rows get b = +inf."""

    def __init__(self, nz: int):
        self.nz = nz
        self._solvers = {}

    def solver(self, rows: int):
        import casadi as ca

        if rows not in self._solvers:
            sp_h = ca.Sparsity.dense(self.nz, self.nz)
            sp_a = ca.Sparsity.dense(rows, self.nz)
            self._solvers[rows] = ca.conic("minmax_qp", "daqp", {"h": sp_h, "a": sp_a}, dict(_DAQP))
        return self._solvers[rows]

    def solve(self, H, g, A, b, lbx, ubx):
        rows = max(8, 1 << (len(b) - 1).bit_length())  # slots: the next power of two (cached solvers)
        Af = np.zeros((rows, self.nz))
        Af[:len(b)] = A
        bf = np.full(rows, np.inf)
        bf[:len(b)] = b
        S = self.solver(rows)
        sol = S(h=H, g=g, a=Af, lba=-np.inf, uba=bf, lbx=lbx, ubx=ubx)
        stats = S.stats()
        return (np.asarray(sol["x"]).ravel(), np.asarray(sol["lam_a"]).ravel()[:len(b)],
                np.asarray(sol["lam_x"]).ravel(), bool(stats.get("success", False)),
                str(stats.get("return_status", "unknown")))


class VertexEpigraph:
    """The exact min-max value for x_{j+1} = A x_j + B u_j + w_j, c = xᵀQ_jx + uᵀR_ju, W a box
    or a polytope.

    With the condensed prediction X = Φx + G_u U + G_w W (stages 0..M-1) and Q̄ = diag(Q_j),
    R̄ = diag(R_j), J(U, W) = (X)ᵀQ̄X + UᵀR̄U = UᵀHU + 2 g(W)ᵀU + k(W), H = G_uᵀQ̄G_u + R̄,
    g(W) = G_uᵀQ̄(Φx + G_wW), k(W) = ‖Φx + G_wW‖²_Q̄. H does not depend on W, so

        V_{W,M}(x) = min_U UᵀHU + max_v (2 g_vᵀU + k_v)        (v over the vertex sequences)

    is the QP  min_{U,s} UᵀHU + s  s.t.  2 g_vᵀU + k_v <= s  (and the input bounds), exact
    because a convex function's maximum over a box or a polytope is attained at a vertex. See the module
    docstring for the sizes: the tables' memory and the operations of the construction and of
    ten constraint-generation rounds are estimated and checked first (``check_size``).
    """

    def __init__(self, system, cost, M: int, W: Box | Polytope, input_bounds=None, rtol: float = 1e-9,
                 max_rounds: int = 200):
        self.M, self.n, self.m = M, system.n, system.m
        n, m = self.n, self.m
        V = len(W.vertices()) if isinstance(W, Polytope) else 2 ** int(np.count_nonzero(W.lo < W.hi))
        N = vertex_count(W, M)
        width = M * n + M * m + 2
        count = str(N) if isinstance(N, int) else f"{N:.3g}"
        check_size(f"the exact min-max method at M={M}, n={n}: N = {V}^(M-1) = {count} vertex sequences",
                   nbytes=8.0 * N * (width + M * n), ops=float(N) * (M * n) ** 2 + 10.0 * 4 * N * width,
                   hint="use method='exchange' (scenario exchange), or a shorter horizon M")
        verts = set_vertices(W)
        self.N, self.W, self.verts = N, W, verts
        self.A, self.B, self.cost = system.A, system.B, cost
        self.Phi, self.Gu, self.Gw = condensed(system.A, system.B, M)
        d = (M - 1) * n
        # sequence i = Σ_k v_k V^(M-2-k): row i holds (v_0, ..., v_{M-2}), as itertools.product orders them
        idx = (np.arange(N)[:, None] // len(verts) ** np.arange(M - 2, -1, -1)) % len(verts) if M > 1 \
            else np.zeros((1, 0), dtype=np.int64)
        self.idx = idx
        Wv = verts[idx].reshape(N, d)                      # w_0..w_{M-2} of every sequence
        self.D = Wv @ self.Gw[:, :d].T                     # (N, Mn): G_w W_v
        ulo, uhi = (np.full(m, -np.inf), np.full(m, np.inf)) if input_bounds is None else input_bounds
        self.lbx = np.concatenate([np.tile(ulo, M), [-np.inf]])
        self.ubx = np.concatenate([np.tile(uhi, M), [np.inf]])
        self.rtol, self.max_rounds = rtol, max_rounds
        self._qp = _WorkingSetQP(M * m + 1)
        self._tables = None
        self._tables_key = None

    def _weights(self, P):
        """(Q̄, R̄ blocks) for the cost parameters P (M, n_params), None = time-invariant."""
        M, n, m = self.M, self.n, self.m
        if P is None:
            return np.broadcast_to(self.cost.Q, (M, n, n)), np.broadcast_to(self.cost.R, (M, m, m))
        pairs = [self.cost.unpack(p) for p in P]
        return np.array([q for q, _ in pairs]), np.array([r for _, r in pairs])

    def _prepare(self, P):
        """H, Q̄G_u and the vertex tables E = D Q̄ G_u (N, Mm), DQ = D Q̄ (N, Mn), kd = diag(D Q̄ Dᵀ)."""
        key = None if P is None else np.asarray(P).tobytes()
        if self._tables is not None and key == self._tables_key:
            return self._tables
        Qs, Rs = self._weights(P)
        Qb, Rb = _block_diag(Qs), _block_diag(Rs)
        QGu = Qb @ self.Gu
        H = self.Gu.T @ QGu + Rb
        DQ = self.D @ Qb
        tables = (0.5 * (H + H.T), Qb, QGu, DQ @ self.Gu, DQ, np.einsum("ij,ij->i", DQ, self.D))
        self._tables, self._tables_key = tables, key
        return tables

    def solve(self, x, P=None, guess_U=None, working=None) -> MinMaxPlan:
        """V_{W,M}(x) with its plan. ``guess_U`` (M, m) and ``working`` (indices of vertex
        sequences, e.g. the previous step's active ones shifted) only speed it up.

        The QP is solved around the nominal plan U_nom = -H⁻¹g(0) (the optimum for w = 0):
        with U = U_nom + Δ, J(U, W_v) = V_M(x, 0) + ΔᵀHΔ + 2E_vᵀΔ + β_v, where V_M(x, 0) is the
        nominal value and β_v the disturbance's share, so the QP's data are of the size of the
        disturbance's effect (scaled to order one) whatever the size of x."""
        t0 = time.perf_counter()
        M, m = self.M, self.m
        H, Qb, QGu, E, DQ, kd = self._prepare(P)
        c0 = self.Phi @ x
        g0 = QGu.T @ c0                                    # g(W_v) = g0 + E_v
        U_nom = -np.linalg.solve(H, g0)
        nominal = float(c0 @ Qb @ c0 + g0 @ U_nom)         # V_M(x, 0) = k(0) - g0ᵀH⁻¹g0
        beta = kd + 2.0 * (DQ @ c0) + 2.0 * (E @ U_nom)   # J(U_nom + Δ, W_v) - V_M(x, 0) - ΔᵀHΔ - 2E_vᵀΔ
        lbd, ubd = self.lbx[:-1] - U_nom, self.ubx[:-1] - U_nom
        top = float(np.max(np.abs(beta)))
        rho = math.sqrt(top) if top > 0 else 1.0           # the QP in Δ/ρ, s/ρ²
        nz = M * m + 1
        Hq = np.zeros((nz, nz))
        Hq[:-1, :-1] = 2.0 * H
        gq = np.zeros(nz)
        gq[-1] = 1.0
        lbz = np.concatenate([lbd / rho, [-np.inf]])
        ubz = np.concatenate([ubd / rho, [np.inf]])
        D0 = np.zeros(M * m) if guess_U is None else np.clip(np.asarray(guess_U, float).reshape(-1) - U_nom, lbd, ubd)

        def phi(D):
            return 2.0 * (E @ D) + beta                    # the disturbance's share for every v

        ws = [] if working is None else [int(i) for i in working if 0 <= int(i) < self.N]
        ws.append(int(np.argmax(phi(D0))))
        ws = list(dict.fromkeys(ws))
        add = M * m + 1
        history, lower, upper, best = [], -np.inf, np.inf, None
        ok, status, rounds, lam = True, "optimal", 0, np.zeros(len(ws))
        D = D0
        for rounds in range(1, self.max_rounds + 1):
            rows = np.array(ws)
            Aw = 2.0 * E[rows]
            A = np.hstack([Aw / rho, -np.ones((len(rows), 1))])
            z, lam, lam_x, good, qp_status = self._qp.solve(Hq, gq, A, -beta[rows] / rho ** 2, lbz, ubz)
            if not good or not np.all(np.isfinite(z)):
                ok, status = False, f"QP solver (daqp) failed: {qp_status}"
                break
            D, s_D = z[:-1] * rho, z[-1] * rho ** 2
            quad = float(D @ H @ D)
            lower = max(lower, nominal + self._dual_bound(H, Aw, beta[rows], lam, lam_x[:-1] * rho, lbd, ubd))
            vals = phi(D)
            v = int(np.argmax(vals))
            ub = nominal + quad + float(vals[v])
            if ub < upper:
                upper, best = ub, (U_nom + D, v, rows[np.abs(lam) > 0])
            history.append((lower, upper))
            tol = self.rtol * max(abs(upper), 1e-300)
            if upper - lower <= tol:
                break
            k = min(self.N, add + len(ws))                 # the k largest, most violated first
            cand = np.argpartition(-vals, k - 1)[:k] if k < self.N else np.arange(self.N)
            cand = cand[np.argsort(-vals[cand])]
            in_ws = set(ws)
            new = [int(i) for i in cand if vals[i] > s_D + tol and int(i) not in in_ws][:add]
            if not new:  # the most violated sequences are in the set: the QP's own accuracy is the limit
                status = "optimal (QP solver accuracy)"
                break
            keep = [i for i, lm in zip(ws, lam) if abs(lm) > 0] if len(ws) + len(new) > 4 * add else ws
            ws = keep + new
        else:
            ok, status = False, f"no convergence in {self.max_rounds} constraint-generation rounds"
        if best is None:
            best = (U_nom + D, int(np.argmax(phi(D))), np.array(ws))
            upper = nominal + float(D @ H @ D) + float(np.max(phi(D)))
        U, v, active = best
        worst = self._sequence(v)
        Uin = U.reshape(M, m)
        states = self._rollout(x, Uin, worst)
        return MinMaxPlan(inputs=Uin, states=states, value=float(upper), success=ok, status=status, solver="daqp",
                          iterations=rounds, solve_time=time.perf_counter() - t0, worst_w=worst,
                          lower=float(lower), upper=float(upper), method="exact", certified=ok,
                          scenarios=len(ws), evaluations=self.N * rounds, sequences=self.N,
                          history=np.array(history).reshape(-1, 2), extra={"active": np.asarray(active)})

    @staticmethod
    def _dual_bound(H, Aw, bw, lam, mu, lb, ub) -> float:
        """A certified lower bound on min_{lb <= Δ <= ub} ΔᵀHΔ + max_v (a_vᵀΔ + b_v) from any multipliers
        (weak duality), whatever the QP solver's accuracy: with λ >= 0 on the working set's rows
        a_vᵀΔ + b_v <= s, scaled to Σλ = 1 (stationarity in s), and μ on the bounds (μ > 0 upper,
        μ < 0 lower),

            d = Σ λ_v b_v - ¼ (Σ λ_v a_v + μ)ᵀ H⁻¹ (Σ λ_v a_v + μ) - Σ μ⁺ ub + Σ μ⁻ lb  <=  the minimum."""
        lam = np.maximum(lam, 0.0)
        if lam.sum() <= 0:
            return -np.inf
        lam = lam / lam.sum()
        mu = np.where(((mu > 0) & np.isfinite(ub)) | ((mu < 0) & np.isfinite(lb)), mu, 0.0)
        r = lam @ Aw + mu
        bounds = float(np.sum(np.where(mu > 0, mu * np.where(np.isfinite(ub), ub, 0.0), 0.0))
                       + np.sum(np.where(mu < 0, mu * np.where(np.isfinite(lb), lb, 0.0), 0.0)))
        return float(lam @ bw - 0.25 * r @ np.linalg.solve(H, r) - bounds)

    def _sequence(self, v: int) -> np.ndarray:
        """The disturbance sequence (M, n) of vertex sequence v (w_{M-1} copies w_{M-2}; it is not costed)."""
        M, n = self.M, self.n
        if M == 1:
            return self.verts[:1].copy()
        seq = self.verts[self.idx[v]]
        return np.vstack([seq, seq[-1:]])

    def _rollout(self, x, U, Wseq):
        X = np.empty((self.M + 1, self.n))
        X[0] = x
        for j in range(self.M):
            X[j + 1] = self.A @ X[j] + self.B @ U[j] + Wseq[j]
        return X

    def shift(self, active, k: int = 1) -> list[int]:
        """Warm-start indices k steps later: each active sequence (v_0..v_{M-2}) shifted by k stages,
        (v_k..v_{M-2}, v_{M-2}, ..., v_{M-2}) (the receding horizon moves k stages)."""
        if self.M <= 2 or len(active) == 0 or k < 1:
            return []
        V = len(self.verts)
        seqs = self.idx[np.asarray(active, dtype=np.int64)]
        k = min(k, self.M - 1)
        shifted = np.hstack([seqs[:, k:], np.repeat(seqs[:, -1:], k, axis=1)])
        weights = V ** np.arange(self.M - 2, -1, -1)
        return [int(i) for i in shifted @ weights]


def _block_diag(blocks) -> np.ndarray:
    """diag(blocks[0], ..., blocks[-1]) for equal square blocks (M, k, k)."""
    M, k = len(blocks), blocks[0].shape[0]
    out = np.zeros((M * k, M * k))
    for j, b in enumerate(blocks):
        out[j * k:(j + 1) * k, j * k:(j + 1) * k] = b
    return out

