"""The constants of Appendix D (no disturbance preview) for a concrete problem: ᾱ_W and γ̄_W.

The class of systems of Lemma 6 and Theorem 3 is V_{W,M}(x) <= ᾱ_W σ(x) + γ̄_W max_{w∈W} ‖w‖² for
every x, with V_{W,M} the min-max value of Algorithm 3. Unlike the preview value V_M of Section
5.1, V_{W,M} is not a quadratic form (it is piecewise quadratic in x), so there is no LMI; instead:

* **certified** (a :class:`~orrc.LinearSystem`, a :class:`~orrc.QuadraticCost`, no input bounds,
  σ = ‖x‖²). The plan U = L_0 x + U_c (L_0 the nominal M-step LQ law, U_c the min-max plan from
  x = 0) is feasible for the min-max problem, and its cross terms vanish by the optimality of L_0,
  so, with P_0 the M-step Riccati matrix (V_M(x, 0) = xᵀP_0x), F = (Φ + G_uL_0)ᵀQ̄G_w and
  w̄² = max_{w∈W} ‖w‖²,

      V_{W,M}(x) <= xᵀP_0x + max_W 2xᵀF W + V_{W,M}(0) <= xᵀP_0x + 2 w̄ √(M-1) ‖Fᵀx‖ + V_{W,M}(0)
                 <= xᵀ(P_0 + ε F Fᵀ)x + (V_{W,M}(0)/w̄² + (M-1)/ε) w̄²        for every ε > 0

  (Cauchy-Schwarz over the M-1 costed disturbances, then Young). So every pair
  ᾱ_W = λ_max(P_0 + ε F Fᵀ), γ̄_W = V_{W,M}(0)/w̄² + (M-1)/ε is admissible: a certified Pareto
  curve, from γ̄_W → V_{W,M}(0)/w̄² (where ᾱ_W → ∞) to ᾱ_W → λ_max(P_0) (where γ̄_W → ∞), the same
  two ends as the true curve. V_{W,M}(0) is computed exactly by the vertex method for a box W
  (when its vertex sequences number at most ``EXACT_LIMIT`` = 2^18), else bounded by λ_max(G_wᵀQ̄G_w)(M-1)w̄² (U = 0 is
  a feasible plan from x = 0), which is also certified.

  How tight it is: the exact V_{W,M}(x) at sampled x (``info["samples"]``) gives a *lower* curve
  ᾱ_W(γ̄_W) >= max(λ_max(P_0), max_i (V_i - γ̄_W w̄²)/σ(x_i)) (``info["lower_pareto"]``; V_{W,M}(x) >=
  V_M(x, 0) = xᵀP_0x); the true curve lies between.
* **estimated** otherwise (nonlinear dynamics, input bounds, other costs): V_{W,M} at sampled x by
  :class:`~orrc.MinMaxRHC` and the sampled curve, labelled ``estimate=True`` (lower bounds on the
  true constants, valid only in the sampled region).

The pair returned minimises Theorem 3's γ_{c,W} along the curve (with a = min_decay_rate_W), or
the knee when no pair is below the horizon threshold ᾱ_W < α_lo √(M-1).

With ``policy="feedback"`` the same is done for the feedback min-max value V^fb_{W,M} (the controller
Lemma 6 is proved for, :class:`~orrc.MinMaxRHC` with ``policy="feedback"``): the plan L_0 x + π(w), with π
the feedback min-max policy from x = 0, is causal, its cross terms vanish for the same reason, and the
certified curve is the one above with V^fb_{W,M}(0) in place of V_{W,M}(0) (computed exactly on the
scenario tree, any polytope W).

The paper's remark γ̄_W = γ̄ M (from the preview constants) is not used: V_M(x, W) <= ᾱ σ + γ̄ Σ‖w‖²
bounds max_W V_M(x, W), the max-min value, and the min-max value can be larger (an open-loop plan
cannot react to the disturbance it will meet).
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from .. import theory
from .._validate import OrrcValueError, as_array, as_float, as_int, check_finite_result, check_size
from .._problem import check_problem
from ..costs import QuadraticCost, StageCost
from ..disturbances import Box, _rng
from ..systems import LinearSystem, System
from .constants import Constants, _knee
from .sampled import _SampledCurve

__all__ = ["MinMaxConstants", "minmax_constants", "maxmin_value"]

#: the most vertex sequences for which V_{W,M} is computed by the exact method here (else exchange)
EXACT_LIMIT = 2 ** 18


@dataclass(repr=False)
class MinMaxConstants(Constants):
    """The constants of Appendix D for one problem, horizon M and set W.

    As :class:`~orrc.certify.Constants`, with ``alpha_hi`` = ᾱ_W, ``gamma_bar`` = γ̄_W, ``a`` the
    smallest admissible decay rate of Theorem 3 and ``gamma_c`` = γ_{c,W} (also under the names
    ``alpha_hi_W``, ``gamma_bar_W``, ``gamma_c_W``); ``w_max_sq`` = max_{w∈W} ‖w‖².
    """

    w_max_sq: float = math.nan

    @property
    def alpha_hi_W(self) -> float:
        return self.alpha_hi

    @property
    def gamma_bar_W(self) -> float:
        return self.gamma_bar

    @property
    def gamma_c_W(self) -> float:
        return self.gamma_c

    def bound(self, sigma, w_energy=None):
        """ᾱ_W σ(x) + γ̄_W max‖w‖² (``w_energy`` defaults to ``w_max_sq``); σ a number or an array."""
        sigma = as_array("sigma", sigma)
        if np.any(sigma < 0):
            raise OrrcValueError(f"sigma must be >= 0 (σ(x) of Assumption 2); got minimum {float(sigma.min())}")
        w2 = self.w_max_sq if w_energy is None else as_float("w_energy", w_energy, minimum=0.0)
        with np.errstate(over="ignore", invalid="ignore"):
            out = self.alpha_hi * sigma + self.gamma_bar * w2
        check_finite_result("MinMaxConstants.bound", out, f"sigma up to {float(np.max(sigma, initial=0.0)):g}, "
                            f"w_energy={w2:g}")
        return float(out) if out.ndim == 0 else out

    def __repr__(self):
        kind = "estimated" if self.estimate else "certified"
        s = (f"MinMaxConstants({kind}, M={self.M}, alpha_lo={self.alpha_lo:.4g}, alpha_hi_W={self.alpha_hi:.4g}, "
             f"gamma_bar_W={self.gamma_bar:.4g}, a={self.a:.4g}, gamma_c_W={self.gamma_c:.4g}")
        return s + (f", reason={self.reason!r})" if self.reason else ")")


class _YoungCurve:
    """ᾱ_W(γ̄_W) = λ_max(P_0 + ε F Fᵀ) with ε = (M-1)/(γ̄_W - γ_0), γ_0 = V_{W,M}(0)/w̄²: the certified curve."""

    def __init__(self, P0, F, gamma0: float, Mp: int):
        self.P0, self.FF, self.gamma0, self.Mp = P0, F @ F.T, gamma0, Mp
        self.alpha_inf = float(np.linalg.eigvalsh(P0)[-1])

    def __call__(self, gamma_bar: float) -> float:
        if not gamma_bar > self.gamma0:
            raise OrrcValueError(f"gamma_bar must exceed V_(W,M)(0)/max‖w‖² = {self.gamma0:.6g} on the certified curve; "
                                 f"got {gamma_bar:.6g}")
        eps = self.Mp / (gamma_bar - self.gamma0)
        S = self.P0 + eps * self.FF
        return float(np.linalg.eigvalsh(0.5 * (S + S.T))[-1])


def _gamma_cW_on_curve(M, alpha_lo, alpha_hi_W, gamma_bar_W):
    """(γ_{c,W}, a, ᾱ_W) for one pair, ᾱ_W raised to α_lo when below it; (inf, 1, ᾱ_W) below the threshold."""
    alpha_hi_W = max(alpha_hi_W, alpha_lo)
    if not (alpha_lo > 0 and theory.known._above(M, alpha_lo, alpha_hi_W)):
        return math.inf, 1.0, alpha_hi_W
    a = theory.min_decay_rate_W(M, alpha_lo, alpha_hi_W)
    return theory.gamma_c_W(M, a, alpha_lo, alpha_hi_W, gamma_bar_W), a, alpha_hi_W


def _best_on_curve(M, alpha_lo, curve, gbs):
    """The pair of the grid gbs (then refined) with the smallest γ_{c,W}: (ahs, gcs, (γ_c, a, ᾱ, γ̄) or None)."""
    from scipy import optimize

    ahs = np.array([max(curve(g), alpha_lo) for g in gbs])
    gcs = np.array([_gamma_cW_on_curve(M, alpha_lo, ah, gb)[0] for gb, ah in zip(gbs, ahs)])
    if not np.isfinite(gcs).any():
        return ahs, gcs, None
    i = int(np.argmin(gcs))
    lo, hi = math.log(gbs[max(i - 1, 0)]), math.log(gbs[min(i + 1, len(gbs) - 1)])
    f = lambda s: _gamma_cW_on_curve(M, alpha_lo, curve(math.exp(s)), math.exp(s))[0]  # noqa: E731
    res = optimize.minimize_scalar(f, bounds=(lo, hi), method="bounded", options={"xatol": 1e-10}) if hi > lo else None
    gb = math.exp(res.x) if (res is not None and res.success and res.fun < gcs[i]) else float(gbs[i])
    gc, a, ah = _gamma_cW_on_curve(M, alpha_lo, curve(gb), gb)
    return ahs, gcs, (gc, a, ah, gb)


def _samples(n: int, count: int, top: float, rng) -> np.ndarray:
    """x = 0, then ``count`` states: random directions, radii log-uniform over six decades up to ``top``."""
    d = rng.standard_normal((count, n))
    d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-300)
    r = np.exp(rng.uniform(math.log(1e-6 * top), math.log(top), (count, 1)))
    return np.vstack([np.zeros(n), d * r])


def minmax_constants(system: System, cost: StageCost, M: int, W, input_bounds=None, n_samples: int = 40,
                     x_radius: float | None = None, seed=0, grid: int = 200,
                     policy: str = "open-loop") -> MinMaxConstants:
    """ᾱ_W, γ̄_W (and Theorem 3's a, γ_{c,W}) of the min-max value, Eq. (D.1); see the module docstring.

    Parameters
    ----------
    system, cost, M, W, input_bounds : the problem of :class:`~orrc.MinMaxRHC` (M >= 2).
    n_samples : states at which V_{W,M} is computed (the lower curve when certified; the estimate
        otherwise); each is one min-max solve.
    x_radius : the largest sampled ‖x‖; radii are log-uniform over six decades below it (default
        10⁴ max‖w‖ for the certified case, where the ratios depend on x only through x/max‖w‖;
        1 for estimates).
    seed : the sampled states.
    grid : points of the Pareto curve.
    policy : "open-loop" (Algorithm 3 as written, V_{W,M}) or "feedback" (feedback min-max, V^fb_{W,M}).

    Returns
    -------
    MinMaxConstants
        The pair (ᾱ_W, γ̄_W) with the smallest γ_{c,W}, the curve (``pareto``, (grid, 2)), and in ``info``
        ``V0`` (the value at x = 0), ``gamma_bar_W_min`` (= V0/max‖w‖²) and ``samples``.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> ex = orrc.examples.scalar_unstable(A=1.2)
    >>> W = orrc.Box(-0.3, 0.3)
    >>> ol = certify.minmax_constants(ex.system, ex.cost, 6, W, n_samples=1)
    >>> fb = certify.minmax_constants(ex.system, ex.cost, 6, W, n_samples=1,
    ...                               policy="feedback")
    >>> bool(fb.info["gamma_bar_W_min"] < ol.info["gamma_bar_W_min"]), fb.estimate
    (True, False)
    """
    from ..controllers.minmax import MinMaxRHC
    from ..solvers.minmax import check_set, vertex_count

    check_problem(system, cost)
    M = as_int("M", M, minimum=2)
    W = check_set(W, system.n)
    if policy not in ("open-loop", "feedback"):
        raise OrrcValueError(f"policy must be 'open-loop' or 'feedback'; got {policy!r}")
    n_samples = as_int("n_samples", n_samples, minimum=1)
    grid = as_int("grid", grid, minimum=20)
    if x_radius is not None:
        x_radius = as_float("x_radius", x_radius, minimum=0.0, strict_min=True)
    w2 = W.max_norm_sq
    if not w2 > 0:
        raise OrrcValueError(f"W must contain a non-zero disturbance (max‖w‖² > 0) for gamma_bar_W to be defined; got {W!r}")
    if cost.alpha_lo is None:
        raise OrrcValueError("the cost must declare alpha_lo (c(x, u) >= alpha_lo σ(x)) for the constants of Lemma 6")
    alpha_lo = float(cost.alpha_lo)
    # n_samples min-max solves (about a millisecond per stage each), then the curve at grid points over the samples
    check_size(f"minmax_constants with n_samples={n_samples}, grid={grid} at M={M} (n={system.n})",
               nbytes=8.0 * (4 * n_samples * system.n + 8 * grid),
               ops=1e6 * n_samples * M + 1e3 * grid * (n_samples + 1),
               hint="lower n_samples or grid")
    rng = _rng(seed)
    certified = isinstance(system, LinearSystem) and isinstance(cost, QuadraticCost) and input_bounds is None
    if policy == "feedback":
        rhc = MinMaxRHC(system, cost, M, W, input_bounds=input_bounds, seed=seed, policy="feedback")
    else:
        exact = certified and isinstance(W, Box) and vertex_count(W, M) <= EXACT_LIMIT
        rhc = MinMaxRHC(system, cost, M, W, input_bounds=input_bounds, method="exact" if exact else "auto", seed=seed)
    top = x_radius if x_radius is not None else (1e4 * math.sqrt(w2) if certified else 1.0)
    xs = _samples(system.n, n_samples, top, rng)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plans = [rhc.plan(x) for x in xs]
    ok = np.array([p.success and np.isfinite(p.value) for p in plans])
    sig = np.array([cost.sigma(x) for x in xs])[ok]
    V = np.array([p.value for p in plans])[ok]
    lower_curve = _SampledCurve(sig, np.full(len(V), w2), V)
    info = {"samples": {"x": xs[ok], "sigma": sig, "V": V}, "failures": int((~ok).sum()), "w_max_sq": w2,
            "solve_method": rhc.method}
    if certified:
        curve, method = _certified_curve(system, cost, M, W, rhc, info)
    else:
        if lower_curve.sig.size == 0:
            raise OrrcValueError("too few successful min-max solves to estimate the constants")
        curve = lower_curve
        method = (f"sampled estimate ({len(V)} min-max solves, method {rhc.method!r}): lower bounds on the true "
                  f"alpha_hi_W, gamma_bar_W, valid only for the sampled states; not a certificate")
    g0 = max(curve.gamma0 if certified else curve.gamma_min, 1e-300)
    gbs = g0 * (1.0 + np.geomspace(1e-4, 1e6, grid)) if certified else np.geomspace(g0, 1e3 * g0 + 1e-300, grid)
    ahs, gcs, best = _best_on_curve(M, alpha_lo, curve, gbs)
    pareto = np.column_stack([gbs, ahs])
    if certified:   # the samples' curve, and ᾱ_W >= λ_max(P_0) (V_(W,M)(x) >= xᵀP_0x, the limit of large x)
        floor = max(info["alpha_hi_inf"], alpha_lo)
        info["lower_pareto"] = np.column_stack([gbs, [max(lower_curve(g), floor) if g >= lower_curve.gamma_min
                                                      else math.nan for g in gbs]])
    if best is not None:
        gc, a, ah, gb = best
        return MinMaxConstants(M, alpha_lo, ah, gb, a, gc, pareto, gcs, None, not certified, method, info, curve,
                               w_max_sq=w2)
    reason = (f"no pair below the horizon threshold at M={M}: alpha_hi_W >= {float(ahs.min()):.6g} on the curve, but "
              f"M > alpha_hi_W²/alpha_lo² + 1 needs alpha_hi_W < alpha_lo √(M-1) = {alpha_lo * math.sqrt(M - 1):.6g}"
              if alpha_lo > 0 else f"alpha_lo = {alpha_lo:.3g}")
    k = _knee(pareto)
    return MinMaxConstants(M, alpha_lo, float(ahs[k]), float(gbs[k]), 1.0, math.inf, pareto, gcs, reason,
                           not certified, method, info, curve, w_max_sq=w2)


def _certified_curve(system, cost, M, W, rhc, info):
    """The certified curve of the module docstring, with V_{W,M}(0) exact (box, exact method) or bounded."""
    from ..solvers.lq import _backward_gains
    from ..solvers.minmax import _block_diag, condensed

    n, m = system.n, system.m
    Phi, Gu, Gw = condensed(system.A, system.B, M)
    Qb = _block_diag(np.broadcast_to(cost.Q, (M, n, n)))
    Rb = _block_diag(np.broadcast_to(cost.R, (M, m, m)))
    H = Gu.T @ Qb @ Gu + Rb
    L0 = -np.linalg.solve(H, Gu.T @ Qb @ Phi)            # nominal plan U = L0 x
    F = (Phi + Gu @ L0).T @ Qb @ Gw[:, :(M - 1) * n]       # the costed disturbances w_0..w_{M-2}
    P0 = _backward_gains(system.A, system.B, np.broadcast_to(cost.Q, (M, n, n)),
                         np.broadcast_to(cost.R, (M, m, m)), None)[0][0]
    w2 = W.max_norm_sq
    if rhc.method == "exact":
        V0 = float(rhc.plan(np.zeros(n)).upper)
        how = ("V^fb_(W,M)(0) exact (scenario tree)" if rhc.policy == "feedback"
               else "V_(W,M)(0) exact (vertex method)")
    else:
        G = Gw.T @ Qb @ Gw
        V0 = float(np.linalg.eigvalsh(0.5 * (G + G.T))[-1]) * (M - 1) * w2
        how = "V_(W,M)(0) <= λ_max(G_wᵀQ̄G_w)(M-1)max‖w‖²"
    info.update({"P0": P0, "F": F, "V0": V0, "alpha_hi_inf": float(np.linalg.eigvalsh(P0)[-1]),
                 "gamma_bar_W_min": V0 / w2})
    method = f"certified: V_(W,M)(x) <= xᵀ(P_0 + εFFᵀ)x + (V_(W,M)(0)/w̄² + (M-1)/ε) w̄², {how}"
    return _YoungCurve(P0, F, V0 / w2, M - 1), method


#: the most vertex sequences :func:`maxmin_value` enumerates
MAXMIN_LIMIT = 2 ** 20


def maxmin_value(system: LinearSystem, cost: QuadraticCost, M: int, W, x=None) -> float:
    """The max-min value max_{w̃_0..w̃_{M-1} ∈ W} V_M(x, w̃) of Eq. (3): the worst case of the preview value.

    V_M(x, W) (Algorithm 1's value, the plan chosen knowing the disturbance) is a convex quadratic in
    the disturbance sequence, so its maximum over a polytope W is at a vertex sequence; the last
    disturbance is not costed, so the V^{M-1} sequences of the costed ones are enumerated, in one
    vectorised pass (V_M(x, W) = k(W) - g(W)ᵀH⁻¹g(W) from the condensed prediction). The count is
    checked first (at most ``MAXMIN_LIMIT`` = 2^20 sequences, and ``orrc.config``'s limits).

    Parameters
    ----------
    system : LinearSystem
    cost : QuadraticCost
    M : int
        The horizon (>= 1).
    W : Box or Polytope
        The disturbance set.
    x : array_like, shape (n,), optional
        The state (default 0).

    Returns
    -------
    float
        max-min value; max-min <= feedback min-max <= open-loop min-max.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> ex = orrc.examples.scalar_unstable(A=1.2)
    >>> round(certify.maxmin_value(ex.system, ex.cost, 2, orrc.Box(-0.3, 0.3)), 6)
    0.045
    """
    from ..solvers.minmax import _block_diag, check_set, condensed
    from ..solvers.scenario_tree import tree_vertices

    check_problem(system, cost, linear=True, quadratic=True, who="maxmin_value")
    M = as_int("M", M, minimum=1)
    W = check_set(W, system.n)
    n, m = system.n, system.m
    x = np.zeros(n) if x is None else as_array("x", x, (n,))
    verts = tree_vertices(W)
    V = len(verts)
    count = float(V) ** (M - 1)
    if count > MAXMIN_LIMIT:
        raise OrrcValueError(f"maxmin_value at M={M} with {V} vertices of W enumerates {count:.3g} vertex sequences; "
                             f"the limit is {MAXMIN_LIMIT} (orrc.certify.minmax.MAXMIN_LIMIT): use a shorter horizon M")
    N = int(count)
    check_size(f"maxmin_value at M={M}: {N} vertex sequences", nbytes=8.0 * N * M * (n + m) * 4,
               ops=4.0 * N * (M * n) * (M * (n + m)), hint="use a shorter horizon M")
    Phi, Gu, Gw = condensed(system.A, system.B, M)
    Qb = _block_diag(np.broadcast_to(cost.Q, (M, n, n)))
    Rb = _block_diag(np.broadcast_to(cost.R, (M, m, m)))
    H = Gu.T @ Qb @ Gu + Rb
    idx = (np.arange(N)[:, None] // V ** np.arange(M - 2, -1, -1)) % V if M > 1 else np.zeros((1, 0), int)
    seqs = verts[idx].reshape(N, (M - 1) * n)
    c = (Phi @ x)[None, :] + seqs @ Gw[:, :(M - 1) * n].T          # (N, Mn): the states' free response
    g = c @ Qb @ Gu                                                 # (N, Mm)
    k = np.einsum("si,ij,sj->s", c, Qb, c)
    vals = k - np.einsum("si,si->s", g, np.linalg.solve(H, g.T).T)
    return float(vals.max())
