"""The paper's constants for a concrete problem, and the attenuation a linear closed loop achieves.

* :func:`lq_constants` -- exact certificates for a :class:`~orrc.LinearSystem` with a
  :class:`~orrc.QuadraticCost` (σ(x) = ‖x‖²). V_M(x, W) = zᵀ H z with z = [x; vec W]
  (``orrc.solvers.lq.LQPreviewLaw``), so (ᾱ, γ̄) bound V_M (the class of systems of
  Section 5.1) exactly when diag(ᾱ I_n, γ̄ I_{Mn}) - H ⪰ 0: a Pareto curve of pairs. The
  pair that minimises Theorem 1's γ_c is picked, with the smallest admissible a.
* :func:`sampled_constants` -- for nonlinear problems (or input bounds): V_M solved on
  samples; the ratios are *lower bounds* on the true constants (``estimate=True``).
* :func:`worst_case_attenuation` -- for a linear closed loop (Algorithm 1 on the LQ path,
  LQR, zero input) the exact smallest γ with R^p_T(γ) <= 0 for every disturbance
  sequence of length T from x_0 = 0, and the disturbance that attains it.
* :func:`worst_case_attenuation_limit` -- its T → ∞ limit: the squared H∞ norm of the
  closed loop from w to the cost output (python-control).
* :func:`smallest_certified_M` -- the first M at which an admissible pair exists.
* :func:`alpha_hi_floor` -- λ_max(P_0(M)), the smallest admissible alpha_hi at each horizon M.

SciPy is imported inside the functions that use it, so that ``import orrc`` does not load it.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from . import theory
from ._validate import OrrcValueError, as_float, as_int
from .controllers.base import Controller
from .controllers.baselines import LQR, ZeroInput
from .controllers.preview import PreviewRHC
from .costs import QuadraticCost, StageCost
from .solvers.lq import LQPreviewLaw, _backward_gains
from .systems import LinearSystem, System

__all__ = ["Constants", "Attenuation", "lq_constants", "sampled_constants", "smallest_certified_M",
           "alpha_hi_floor", "worst_case_attenuation", "worst_case_attenuation_limit"]


# ---------------------------------------------------------------------------------------------
# the result: constants of a problem
# ---------------------------------------------------------------------------------------------
@dataclass
class Constants:
    """The constants of Section 5.1 for one problem and one horizon M.

    Attributes
    ----------
    M : the horizon.
    alpha_lo : c(x, u) >= alpha_lo σ(x) (Assumption 2).
    alpha_hi, gamma_bar : the chosen pair with V_M(x, W) <= alpha_hi σ(x) + gamma_bar Σ‖w_k‖²:
        the point of the Pareto curve that minimises γ_c. When no pair is admissible at
        this M (``gamma_c = inf``), the pair minimising alpha_hi·gamma_bar (the knee of
        the curve): still valid for Lemma 1, which holds for every M >= 2.
    a : the smallest admissible decay rate for that pair (:func:`orrc.theory.min_decay_rate`);
        1.0 when no pair is admissible (no decay certified).
    b : (property) Lemma 2's b = gamma_bar (alpha_lo/alpha_hi + 1) for that pair; ``inf`` when
        no pair is admissible, like gamma_c.
    gamma_c : Theorem 1's attenuation level for (M, a, alpha_lo, alpha_hi, gamma_bar), or
        ``inf`` with ``reason`` saying why.
    pareto : (K, 2) array of points (gamma_bar, alpha_hi) on the Pareto curve (K = grid size).
    pareto_gamma_c : (K,) γ_c at each point (with a = min_decay_rate), inf where that
        alpha_hi is not below the horizon threshold α_lo √(M-1).
    reason : None, or why gamma_c is infinite.
    estimate : False for an exact certificate (LQ); True for sampled estimates, which are
        lower bounds on the true alpha_hi, gamma_bar (not certificates).
    method : a short description of how the numbers were obtained.
    info : extra data (the value matrix H for LQ; the samples for sampled estimates).
    """

    M: int
    alpha_lo: float
    alpha_hi: float
    gamma_bar: float
    a: float
    gamma_c: float
    pareto: np.ndarray
    pareto_gamma_c: np.ndarray
    reason: str | None = None
    estimate: bool = False
    method: str = ""
    info: dict = field(default_factory=dict, repr=False)
    _curve: object = field(default=None, repr=False)

    @property
    def admissible(self) -> bool:
        """True when Theorem 1 applies at this M (some pair is above the horizon threshold)."""
        return math.isfinite(self.gamma_c)

    @property
    def b(self) -> float:
        """b = γ̄ (α_lo/ᾱ + 1) of Lemma 2 for the chosen pair (:func:`orrc.theory.decay_b`).

        ``inf`` when no pair is admissible at this M (``gamma_c = inf``, ``a = 1``): Lemma 2's
        recursion V^{t+1} <= a V^t + b Σ‖w‖² is then not certified (and with alpha_lo = 0,
        b is not defined), so it is reported the way gamma_c is.
        """
        if not self.admissible:
            return math.inf
        return theory.decay_b(self.alpha_lo, self.alpha_hi, self.gamma_bar)

    @property
    def threshold(self) -> float:
        """ᾱ²/α_lo² + 1 for the chosen pair (:func:`orrc.theory.horizon_threshold`)."""
        if self.alpha_lo <= 0:
            return math.inf
        return theory.horizon_threshold(self.alpha_lo, self.alpha_hi)

    def alpha_hi_at(self, gamma_bar) -> float:
        """The smallest admissible alpha_hi paired with ``gamma_bar`` (a point of the Pareto curve).

        Exact for :func:`lq_constants` (λ_max of the Schur complement), the sampled curve
        for :func:`sampled_constants`. Raises when gamma_bar is below the curve's range.
        """
        gamma_bar = as_float("gamma_bar", gamma_bar, minimum=0.0, strict_min=True)
        return float(self._curve(gamma_bar))

    def bound(self, sigma, w_energy) -> float:
        """alpha_hi σ(x) + gamma_bar Σ_k ‖w_k‖², the bound on V_M (σ and energy given)."""
        return float(self.alpha_hi * sigma + self.gamma_bar * w_energy)

    def __repr__(self):
        kind = "estimated" if self.estimate else "certified"
        s = (f"Constants({kind}, M={self.M}, alpha_lo={self.alpha_lo:.4g}, alpha_hi={self.alpha_hi:.4g}, "
             f"gamma_bar={self.gamma_bar:.4g}, a={self.a:.4g}, gamma_c={self.gamma_c:.4g}")
        return s + (f", reason={self.reason!r})" if self.reason else ")")


def _knee(points: np.ndarray) -> int:
    prod = points[:, 0] * points[:, 1]
    return int(np.argmin(prod))


def _gamma_c_on_curve(M: int, alpha_lo: float, alpha_hi: float, gamma_bar: float) -> tuple[float, float, float]:
    """(γ_c, a, ᾱ) for one Pareto point (alpha_hi, gamma_bar), with ᾱ = max(alpha_hi, alpha_lo) and
    a = min_decay_rate(M, α_lo, ᾱ) (Theorem 1); (inf, 1.0, ᾱ) when alpha_lo <= 0 or ᾱ is not
    below the horizon threshold α_lo √(M-1)."""
    alpha_hi = max(alpha_hi, alpha_lo)
    if not (alpha_lo > 0 and theory._above(M, alpha_lo, alpha_hi)):
        return math.inf, 1.0, alpha_hi
    a = theory.min_decay_rate(M, alpha_lo, alpha_hi)
    return theory.gamma_c(M, a, alpha_lo, alpha_hi, gamma_bar), a, alpha_hi


# ---------------------------------------------------------------------------------------------
# exact LQ certificates
# ---------------------------------------------------------------------------------------------
class _SchurCurve:
    """ᾱ(γ̄) = λ_max(H_xx + H_xw (γ̄ I - H_ww)⁻¹ H_wx) for γ̄ > λ_max(H_ww): the Pareto curve."""

    def __init__(self, H: np.ndarray, n: int):
        Hxx, Hxw, Hww = H[:n, :n], H[:n, n:], H[n:, n:]
        lam, V = np.linalg.eigh(0.5 * (Hww + Hww.T))
        self.lam = lam
        self.lam_max = float(lam[-1])
        self.G = Hxw @ V
        self.Hxx = 0.5 * (Hxx + Hxx.T)
        self.alpha_inf = float(np.linalg.eigvalsh(self.Hxx)[-1])
        self.coupling = float(np.sum(self.G ** 2))

    def __call__(self, gamma_bar: float) -> float:
        d = gamma_bar - self.lam
        if not np.all(d > 0):
            raise OrrcValueError(
                f"gamma_bar must exceed λ_max(H_ww) = {self.lam_max:.6g} (below it no alpha_hi is "
                f"admissible); got {gamma_bar:.6g}")
        S = self.Hxx + (self.G / d) @ self.G.T
        return float(np.linalg.eigvalsh(0.5 * (S + S.T))[-1])


def _check_linear_system(system):
    if not isinstance(system, LinearSystem):
        raise OrrcValueError(f"system must be an orrc LinearSystem; got {type(system).__name__}")


def _check_quadratic_cost(system, cost, message=None):
    if not isinstance(cost, QuadraticCost):
        raise OrrcValueError(message or f"cost must be an orrc QuadraticCost; got {type(cost).__name__}")
    cost.check_dims(system.n, system.m)


def _lq_check(system, cost):
    _check_linear_system(system)
    _check_quadratic_cost(system, cost)


def alpha_hi_floor(system: LinearSystem, cost: QuadraticCost, Ms) -> np.ndarray:
    """λ_max(P_0(M)) for each horizon M in ``Ms``: the smallest admissible alpha_hi at horizon M.

    V_M(x, W) = zᵀHz with H_xx = P_0(M), the Riccati matrix of the M-step problem
    (V_M(x, 0) = xᵀP_0x, ``orrc.solvers.lq``). The class condition of Lemma 1,
    V_M(x, W) <= ᾱ σ(x) + γ̄ Σ‖w_k‖², holds for an LQ problem iff the certificate
    diag(ᾱ I, γ̄ I) - H ⪰ 0 holds; its x-block needs ᾱ I - P_0(M) ⪰ 0, and along the Pareto
    curve ᾱ(γ̄) decreases to λ_max(P_0(M)) as γ̄ → ∞. So ᾱ >= λ_max(P_0(M)) for every
    admissible pair, and this floor is the value ``lq_constants(system, cost, M).info["alpha_hi_inf"]``
    reports (bit for bit). Theorem 1 needs ᾱ < α_lo √(M-1), hence :func:`smallest_certified_M`.

    ``Ms``: an iterable of integers >= 1 (M = 1 gives λ_max(Q)). Returns a 1-D float array
    aligned with ``Ms``; all values come from ONE backward Riccati recursion up to max(Ms)
    (P_0 of the M-step problem is the M-th iterate from P = 0, whatever the longest horizon).
    """
    _lq_check(system, cost)
    if isinstance(Ms, (str, bytes)) or not np.iterable(Ms):
        raise OrrcValueError(f"Ms must be an iterable of integers >= 1; got {type(Ms).__name__}")
    Ms = [as_int(f"Ms[{i}]", M, minimum=1) for i, M in enumerate(Ms)]
    if not Ms:
        raise OrrcValueError("Ms must hold at least one horizon M >= 1; got an empty iterable")
    M_max, n, m = max(Ms), system.n, system.m
    P = _backward_gains(system.A, system.B, np.broadcast_to(cost.Q, (M_max, n, n)),
                        np.broadcast_to(cost.R, (M_max, m, m)), None)[0]
    return np.array([np.linalg.eigvalsh(P[M_max - M])[-1] for M in Ms], dtype=float)  # P_0(M)


def smallest_certified_M(system: LinearSystem, cost: QuadraticCost, M_max: int = 200) -> int | None:
    """The smallest M >= 2 at which :func:`lq_constants` finds an admissible pair, or None up to M_max.

    Along the Pareto curve ᾱ decreases to λ_max(P_0(M)) (P_0 the M-step Riccati matrix,
    V_M(x, 0) = xᵀP_0x) as γ̄ → ∞, so an admissible pair exists iff
    λ_max(P_0(M)) < α_lo √(M-1) (the horizon threshold M > ᾱ²/α_lo² + 1, Lemma 2 and
    Theorem 1). The floors λ_max(P_0(M)) are :func:`alpha_hi_floor`'s, from one recursion.
    """
    _lq_check(system, cost)
    M_max = as_int("M_max", M_max, minimum=2)
    alpha_lo = float(cost.alpha_lo)
    if alpha_lo <= 0:
        return None
    Ms = np.arange(2, M_max + 1)
    ok = np.flatnonzero(alpha_hi_floor(system, cost, Ms) < alpha_lo * np.sqrt(Ms - 1))
    return int(Ms[ok[0]]) if ok.size else None


def lq_constants(system: LinearSystem, cost: QuadraticCost, M: int, grid: int = 200) -> Constants:
    """Exact constants of Section 5.1 for x_{t+1} = Ax_t + Bu_t + w_t, c = xᵀQx + uᵀRu, σ = ‖x‖².

    V_M(x, W) = zᵀ H z, z = [x; vec W], with H = ``LQPreviewLaw(A, B, Q, R, M).H`` (the value
    of Algorithm 1's problem, no terminal cost). Then

    * α_lo = ``cost.alpha_lo`` (λ_min(Q) by default): c(x, u) >= α_lo ‖x‖²;
    * (ᾱ, γ̄) is admissible iff diag(ᾱ I_n, γ̄ I_{Mn}) - H ⪰ 0. For γ̄ > λ_max(H_ww) the
      smallest admissible ᾱ is λ_max(H_xx + H_xw (γ̄ I - H_ww)⁻¹ H_wx) (Schur complement):
      the Pareto curve, decreasing from +∞ to λ_max(H_xx) as γ̄ grows;
    * along the curve, a = min_decay_rate(M, α_lo, ᾱ) and γ_c = gamma_c(M, a, α_lo, ᾱ, γ̄)
      (γ_c grows with ᾱ at fixed γ̄ and with γ̄ at fixed ᾱ, so its minimum over all
      admissible pairs lies on the curve); the minimising pair is found by a scan of
      ``grid`` log-spaced points followed by a bounded scalar search around the best one.

    The block of H for the last previewed disturbance w_{t+M-1} is zero (it acts after
    the last costed state): that is expected. When no pair is admissible at this M,
    ``gamma_c = inf`` and ``reason`` says why (and which M would do).
    """
    from scipy import optimize

    _lq_check(system, cost)
    M = as_int("M", M, minimum=2)
    grid = as_int("grid", grid, minimum=20)
    n = system.n
    law = LQPreviewLaw(system.A, system.B, cost.Q, cost.R, M)
    H = law.H
    curve = _SchurCurve(H, n)
    alpha_lo = float(cost.alpha_lo)
    scale = max(curve.lam_max, curve.alpha_inf, math.sqrt(curve.coupling), 1e-300)
    thr_alpha = alpha_lo * math.sqrt(M - 1)  # ᾱ must be below this (horizon threshold)
    feasible = alpha_lo > 0 and curve.alpha_inf < thr_alpha
    d_lo, d_hi = 1e-6 * scale, 1e6 * scale
    if feasible:  # make sure the grid reaches the part of the curve below the threshold
        d_hi = max(d_hi, 4.0 * curve.coupling / (thr_alpha - curve.alpha_inf))

    def gc_at(d):
        gb = curve.lam_max + d
        return _gamma_c_on_curve(M, alpha_lo, curve(gb), gb)[0]

    for _ in range(6):  # widen the scan while the best point sits at an end
        ds = np.geomspace(d_lo, d_hi, grid)
        gbs = curve.lam_max + ds
        ahs = np.array([curve(g) for g in gbs])
        gcs = np.array([_gamma_c_on_curve(M, alpha_lo, ah, gb)[0] for gb, ah in zip(gbs, ahs)])
        if not feasible or not np.isfinite(gcs).any():
            break
        i = int(np.argmin(gcs))
        if i == 0 and curve.lam_max > 0 and d_lo > 1e-14 * scale:
            d_lo *= 1e-3
        elif i == grid - 1:
            d_hi *= 1e3
        else:
            break
    pareto = np.column_stack([gbs, ahs])
    info = {"H": H, "lambda_max_Hww": curve.lam_max, "alpha_hi_inf": curve.alpha_inf,
            "alpha_hi_max_for_threshold": thr_alpha}
    method = "exact LQ certificate: diag(alpha_hi I, gamma_bar I) - H ⪰ 0"
    if feasible and np.isfinite(gcs).any():
        i = int(np.argmin(gcs))
        lo_i, hi_i = max(i - 1, 0), min(i + 1, grid - 1)
        f = lambda s: gc_at(math.exp(s))  # noqa: E731
        res = optimize.minimize_scalar(f, bounds=(math.log(ds[lo_i]), math.log(ds[hi_i])),
                                       method="bounded", options={"xatol": 1e-10})
        d_best = math.exp(res.x) if (res.success and res.fun < gcs[i]) else ds[i]
        gb = curve.lam_max + d_best
        gc, a, ah = _gamma_c_on_curve(M, alpha_lo, curve(gb), gb)
        return Constants(M, alpha_lo, ah, gb, a, gc, pareto, gcs, None, False, method, info, curve)
    if alpha_lo <= 0:
        reason = (f"alpha_lo = {alpha_lo:.3g}: Q is singular, so c(x, u) >= alpha_lo ‖x‖² holds only with "
                  "alpha_lo = 0 and the horizon threshold alpha_hi²/alpha_lo² + 1 is infinite")
    else:
        M_ok = smallest_certified_M(system, cost, M_max=max(200, 2 * M))
        hint = (f"the smallest certified M is {M_ok}" if M_ok is not None
                else "no M up to 200 is certified")
        reason = (f"no admissible (alpha_hi, gamma_bar) at M={M}: alpha_hi >= λ_max(P_0) = "
                  f"{curve.alpha_inf:.6g} on the whole Pareto curve, but M > alpha_hi²/alpha_lo² + 1 needs "
                  f"alpha_hi < alpha_lo √(M-1) = {thr_alpha:.6g}; {hint}")
    k = _knee(pareto)
    return Constants(M, alpha_lo, float(ahs[k]), float(gbs[k]), 1.0, math.inf, pareto, gcs, reason, False,
                     method, info, curve)


# ---------------------------------------------------------------------------------------------
# sampled estimates (nonlinear problems)
# ---------------------------------------------------------------------------------------------
class _SampledCurve:
    """ᾱ(γ̄) = max_i (V_i - γ̄ e_i)/σ_i over samples with σ_i > 0, for γ̄ >= max over σ_i = 0 of V_i/e_i."""

    def __init__(self, sig, en, V):
        pos = sig > 0
        self.sig, self.en, self.V = sig[pos], en[pos], V[pos]
        zero = (~pos) & (en > 0)
        self.gamma_min = float(np.max(V[zero] / en[zero])) if zero.any() else 0.0

    def __call__(self, gamma_bar: float) -> float:
        if gamma_bar < self.gamma_min:
            raise OrrcValueError(
                f"gamma_bar must be >= {self.gamma_min:.6g} (a sampled V_M(0, W) needs it); got {gamma_bar:.6g}")
        return float(np.max((self.V - gamma_bar * self.en) / self.sig))


def sampled_constants(system: System, cost: StageCost, M: int, n_samples: int = 20, x_radius: float = 1.0,
                      w_radius: float | None = None, input_bounds=None, seed=0, grid: int = 200,
                      solver_options=None) -> Constants:
    """Sampled estimates of α_lo, ᾱ, γ̄ for any problem (nonlinear dynamics, input bounds).

    Solves Algorithm 1's M-step problem (``PreviewRHC(system, cost, M, input_bounds).plan``)
    on three sets of ``n_samples`` samples each: (x, 0) with x uniform in the ball
    ‖x‖ <= x_radius, (0, W) with each w_k uniform in ‖w‖ <= w_radius (default
    0.1·x_radius), and joint (x, W). Then

    * ``info['alpha_hi_x']`` = max V_M(x, 0)/σ(x) and ``info['gamma_bar_w']`` =
      max V_M(0, W)/Σ‖w_k‖²;
    * the sampled Pareto curve ᾱ(γ̄) = max_i (V_i - γ̄ Σ‖w‖²_i)/σ_i, and on it the pair
      (``alpha_hi``, ``gamma_bar``) that minimises γ_c (or the knee, as in
      :func:`lq_constants`): a pair that bounds every sampled V_M;
    * α_lo = ``cost.alpha_lo`` when the cost declares it, else min c(x̃, ũ)/σ(x̃) over the
      sampled plans (an upper bound on the true α_lo).

    These are ESTIMATES (``estimate=True``): a supremum over samples is a lower bound
    on the true ᾱ and γ̄ (which are suprema over all x, W), valid only in the sampled
    region. They are not certificates; Theorem 1 computed from them is indicative.
    Solves that fail are dropped (``info['failures']``).
    """
    from .disturbances import Ball, _rng

    if not isinstance(system, System):
        raise OrrcValueError(f"system must be an orrc LinearSystem or NonlinearSystem; got {type(system).__name__}")
    if not isinstance(cost, StageCost):
        raise OrrcValueError(f"cost must be an orrc stage cost; got {type(cost).__name__}")
    M = as_int("M", M, minimum=2)
    n_samples = as_int("n_samples", n_samples, minimum=1)
    grid = as_int("grid", grid, minimum=20)
    x_radius = as_float("x_radius", x_radius, minimum=0.0, strict_min=True)
    w_radius = 0.1 * x_radius if w_radius is None else as_float("w_radius", w_radius, minimum=0.0, strict_min=True)
    rng = _rng(seed)
    rhc = PreviewRHC(system, cost, M, input_bounds=input_bounds, solver_options=solver_options)
    n = system.n
    xs = Ball(x_radius, n).sample(2 * n_samples, rng)
    Ws = Ball(w_radius, n).sample(2 * n_samples * M, rng).reshape(2 * n_samples, M, n)
    zx, zW = np.zeros(n), np.zeros((M, n))
    jobs = ([(x, zW) for x in xs[:n_samples]] + [(zx, W) for W in Ws[:n_samples]]
            + [(x, W) for x, W in zip(xs[n_samples:], Ws[n_samples:])])
    sig, en, V, ratios = [], [], [], []
    failures = 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for x, W in jobs:
            plan = rhc.plan(x, W)
            if not plan.success or not np.isfinite(plan.value):
                failures += 1
                continue
            sig.append(cost.sigma(x))
            en.append(float(np.sum(W * W)))
            V.append(float(plan.value))
            if cost.alpha_lo is None:
                for xk, uk in zip(plan.states[:-1], plan.inputs):
                    s = cost.sigma(xk)
                    if s > 1e-12:
                        ratios.append(cost.value(xk, uk) / s)
    sig, en, V = np.array(sig), np.array(en), np.array(V)
    pos, has_w = sig > 0, en > 0
    pure_x = pos & (en == 0)
    joint = pos & has_w
    if not pure_x.any() or not ((sig == 0) & has_w).any():
        raise OrrcValueError(
            f"too few successful solves to estimate the constants ({failures} of {len(jobs)} failed); "
            "reduce x_radius/w_radius or check the problem")
    alpha_hi_x = float(np.max(V[pure_x] / sig[pure_x]))
    if cost.alpha_lo is not None:
        alpha_lo, lo_note = float(cost.alpha_lo), "declared by the cost"
    elif ratios:
        alpha_lo, lo_note = float(min(ratios)), "estimated: min c/σ over sampled plans (an upper bound)"
    else:
        raise OrrcValueError("cannot estimate alpha_lo: the cost declares none and no sampled state had σ > 0")
    curve = _SampledCurve(sig, en, V)
    # max V_M(0, W)/Σ‖w‖² over the samples with σ = 0 (σ >= 0: the curve's samples with σ <= 0)
    gamma_bar_w = curve.gamma_min
    g0 = max(curve.gamma_min, 1e-300)
    g1 = g0
    if joint.any():  # beyond g1 every joint sample is inactive and ᾱ(γ̄) = alpha_hi_x
        g1 = max(g0, float(np.max((V[joint] - alpha_hi_x * sig[joint]) / en[joint])))
    gbs = np.geomspace(g0, max(10.0 * g1, 10.0 * g0), grid)
    ahs = np.array([max(curve(g), alpha_lo) for g in gbs])
    on_curve = [_gamma_c_on_curve(M, alpha_lo, ah, gb) for gb, ah in zip(gbs, ahs)]
    gcs = np.array([gc for gc, _, _ in on_curve])
    pareto = np.column_stack([gbs, ahs])
    info = {"alpha_hi_x": alpha_hi_x, "gamma_bar_w": gamma_bar_w, "alpha_lo_source": lo_note,
            "n_solved": int(len(V)), "failures": failures, "sigma": sig, "energy": en, "V": V,
            "x_radius": x_radius, "w_radius": w_radius}
    method = (f"sampled estimate ({len(V)} solves): lower bounds on the true alpha_hi, gamma_bar, "
              f"valid only for ‖x‖ <= {x_radius:g}, ‖w‖ <= {w_radius:g}; not a certificate")
    if np.isfinite(gcs).any():
        i = int(np.argmin(gcs))
        gc, a, ah = on_curve[i]
        return Constants(M, alpha_lo, float(ah), float(gbs[i]), a, float(gc), pareto, gcs, None, True, method,
                         info, curve)
    reason = (f"no sampled pair is above the horizon threshold at M={M}: alpha_hi >= {float(ahs.min()):.6g} "
              f"but M > alpha_hi²/alpha_lo² + 1 needs alpha_hi < alpha_lo √(M-1) = "
              f"{alpha_lo * math.sqrt(M - 1):.6g}" if alpha_lo > 0 else f"alpha_lo = {alpha_lo:.3g}")
    k = _knee(pareto)
    return Constants(M, alpha_lo, float(ahs[k]), float(gbs[k]), 1.0, math.inf, pareto, gcs, reason, True,
                     method, info, curve)


# ---------------------------------------------------------------------------------------------
# worst-case attenuation of a linear closed loop
# ---------------------------------------------------------------------------------------------
@dataclass
class Attenuation:
    """The attenuation a linear closed loop achieves against the worst disturbance.

    gamma : the smallest γ with R^p_T(γ) <= 0 for every disturbance (finite T), or the
        squared H∞ norm (T = None, the limit T → ∞); ``inf`` when the loop is unstable.
    w : (T, n) the worst-case disturbance, unit total energy Σ‖w_t‖² = 1 (None for the limit).
    T : horizon, or None for the limit.
    G : the matrix with Σ_{t<T} c_t = ‖G vec(w)‖² (finite T), else None.
    closed_loop : the python-control ``StateSpace`` from the newest previewed disturbance to the
        cost output (the limit), else None.
    reason : None, or why gamma is infinite.
    start : "cold" for finite T and the cold-start limit, "stationary" for the H∞ level.
    """

    gamma: float
    w: np.ndarray | None = None
    T: int | None = None
    G: np.ndarray | None = field(default=None, repr=False)
    closed_loop: object = field(default=None, repr=False)
    reason: str | None = None
    start: str = "cold"


def _sqrt_psd(S: np.ndarray) -> np.ndarray:
    """A matrix F with FᵀF = S for a symmetric PSD S."""
    lam, V = np.linalg.eigh(0.5 * (S + S.T))
    return np.sqrt(np.clip(lam, 0.0, None))[:, None] * V.T


def _linear_loop(system, controller, cost):
    """(K, L, M_w, Q, R): u_t = -K x_t - L vec(w_t..w_{t+M_w-1}) for the supported controllers."""
    _check_linear_system(system)
    if not isinstance(controller, Controller):
        raise OrrcValueError(f"controller must be an orrc Controller; got {type(controller).__name__}")
    n, m = system.n, system.m
    if isinstance(controller, PreviewRHC):
        if controller.solver != "lq":  # PreviewRHC.law is None exactly off the LQ path
            raise OrrcValueError(
                "worst_case_attenuation needs a linear controller: PreviewRHC on the exact LQ path "
                f"(LinearSystem, QuadraticCost, no bounds); this one uses solver={controller.solver!r}")
        if controller.system is not system and not (
                np.array_equal(controller.system.A, system.A) and np.array_equal(controller.system.B, system.B)):
            raise OrrcValueError("the PreviewRHC controller was built for a different (A, B) than `system`")
        K, L, Mw = controller.law.K, controller.law.L, controller.M
    elif isinstance(controller, LQR):
        K, L, Mw = controller.K, np.zeros((m, 0)), 0
    elif isinstance(controller, ZeroInput):
        K, L, Mw = np.zeros((m, n)), np.zeros((m, 0)), 0
    else:
        raise OrrcValueError(
            f"worst_case_attenuation supports PreviewRHC (LQ path), LQR and ZeroInput; got {type(controller).__name__}")
    if K.shape != (m, n):
        raise OrrcValueError(f"the controller's gain has shape {K.shape}; the system needs ({m}, {n})")
    cost = controller.cost if cost is None else cost
    _check_quadratic_cost(system, cost, "worst_case_attenuation needs the problem's QuadraticCost: pass "
                                        f"cost=... (the controller has {type(cost).__name__})")
    return np.asarray(K, float), np.asarray(L, float), Mw, cost.Q, cost.R


def _top_singular(G: np.ndarray) -> tuple[float, np.ndarray]:
    """(σ_max(G)², top right singular vector): dense SVD for small G, else ARPACK (``svds``,
    tol=0, i.e. to machine precision; deterministic start vector), dense if it fails."""
    if min(G.shape) > 200:
        from scipy.sparse.linalg import ArpackError, ArpackNoConvergence, svds

        v0 = np.random.default_rng(0).standard_normal(G.shape[1])
        try:
            _, s, Vt = svds(G, k=1, tol=0, v0=v0, solver="arpack", maxiter=20 * G.shape[1])
            return float(s[0] ** 2), Vt[0]
        except (ArpackNoConvergence, ArpackError):
            pass
    from scipy import linalg

    _, s, Vt = linalg.svd(G, full_matrices=False)
    return float(s[0] ** 2), Vt[0]


def worst_case_attenuation(system: LinearSystem, controller: Controller, T: int, cost=None) -> Attenuation:
    """The exact smallest γ with R^p_T(γ) <= 0 for every disturbance w_0..w_{T-1} (x_0 = 0).

    For a linear closed loop (Algorithm 1 on the LQ path, u = -Kx - L vec(w_t..w_{t+M-1});
    LQR; zero input), x_t and u_t are linear in W = (w_0, ..., w_{T-1}) and
    Σ_{t<T} c_t(x_t, u_t) = ‖G vec W‖² with G stacking [Q^{1/2} x_t; R^{1/2} u_t]. So
    R^p_T(γ) = vec Wᵀ (GᵀG - γ I) vec W <= 0 for all W iff γ >= γ* = λ_max(GᵀG) = σ_max(G)²
    (Eq. 2 of the paper with the worst adversary), and the top right singular vector of G
    is the disturbance that attains it: the adversary made explicit. (Dense SVD for small
    problems, ARPACK to machine precision for large T.)

    With preview (M >= 2) the worst finite-T disturbance concentrates at the start, where
    the controller meets w_0..w_{M-2} unannounced; its T → ∞ limit is
    ``worst_case_attenuation_limit(..., start="cold")``, which can exceed the stationary
    H∞ level that governs R^p_T(γ) = O(1) (see :func:`worst_case_attenuation_limit`).

    The preview past T sees zeros (the :func:`orrc.simulate` convention when w has exactly
    T rows), so ``orrc.simulate(system, controller, 0, result.w, T)`` gives
    R^p_T(γ*) = 0 up to rounding. ``cost`` defaults to the controller's own cost.
    """
    K, L, Mw, Q, R = _linear_loop(system, controller, cost)
    T = as_int("T", T, minimum=1)
    A, B = system.A, system.B
    n = system.n
    Qh, Rh = _sqrt_psd(Q), _sqrt_psd(R)
    N = T * n
    X = np.zeros((n, N))  # x_t = X vec W
    rows = []
    for t in range(T):
        U = -K @ X
        for i in range(Mw):
            k = t + i
            if k < T:
                U[:, k * n:(k + 1) * n] -= L[:, i * n:(i + 1) * n]
        rows.append(Qh @ X)
        rows.append(Rh @ U)
        X = A @ X + B @ U
        X[:, t * n:(t + 1) * n] += np.eye(n)
    G = np.vstack(rows)
    gamma, v = _top_singular(G)
    w = v.reshape(T, n)
    j = int(np.argmax(np.abs(w.ravel())))
    if w.ravel()[j] < 0:
        w = -w
    return Attenuation(gamma=gamma, w=w, T=T, G=G)


def _closed_loop_ss(system, K, L, Mw, Q, R):
    """State space (A, B, C, D) from the newest previewed disturbance to z = [Q^{1/2}x; R^{1/2}u]."""
    A, Bu = system.A, system.B
    n, m = Bu.shape
    Qh, Rh = _sqrt_psd(Q), _sqrt_psd(R)
    if Mw <= 1:
        # LQR / zero input: the input is w_t itself. Preview M = 1: u = -Kx - L_0 w_t.
        L0 = L[:, :n] if Mw == 1 else np.zeros((m, n))
        Ac = A - Bu @ K
        Bc = np.eye(n) - Bu @ L0
        Cc = np.vstack([Qh, -Rh @ K])
        Dc = np.vstack([np.zeros((Qh.shape[0], n)), -Rh @ L0])
        return Ac, Bc, Cc, Dc
    # state ξ = [x; b_0; ...; b_{M-2}] with b_i = w_{t+i}; input v = w_{t+M-1}
    nb = (Mw - 1) * n
    Lb, Lv = L[:, :nb], L[:, nb:]
    Ac = np.zeros((n + nb, n + nb))
    Ac[:n, :n] = A - Bu @ K
    Ac[:n, n:] = -Bu @ Lb
    Ac[:n, n:2 * n] += np.eye(n)                     # + w_t = b_0
    Ac[n:nb, 2 * n:] = np.eye(nb - n)                # b_i⁺ = b_{i+1}
    Bc = np.zeros((n + nb, n))
    Bc[:n] = -Bu @ Lv
    Bc[nb:] = np.eye(n)                              # b_{M-2}⁺ = v
    Cc = np.vstack([np.hstack([Qh, np.zeros((Qh.shape[0], nb))]), np.hstack([-Rh @ K, -Rh @ Lb])])
    Dc = np.vstack([np.zeros((Qh.shape[0], n)), -Rh @ Lv])
    return Ac, Bc, Cc, Dc


def worst_case_attenuation_limit(system: LinearSystem, controller: Controller, cost=None,
                                 start: str = "stationary", tol: float = 1e-9) -> Attenuation:
    """The T → ∞ attenuation of a linear closed loop: the squared H∞ norm from w to the cost output.

    The cost output is z_t = [Q^{1/2} x_t; R^{1/2} u_t], so Σ c_t = Σ ‖z_t‖².
    For Algorithm 1 the input u_t depends on w_t..w_{t+M-1}; the loop is causal in the
    newest previewed disturbance v_t = w_{t+M-1} once the state is augmented with the
    buffer (w_t, ..., w_{t+M-2}): ξ_{t+1} = A_c ξ_t + B_c v_t, z_t = C_c ξ_t + D_c v_t
    (``result.closed_loop``). The map v → z is the map w → z delayed by M - 1 steps.

    ``start="stationary"`` (default): γ_∞ = ‖v → z‖²_{H∞}. This is the attenuation level
    in the sense of Theorem 1: for bounded disturbances, R^p_T(γ) stays O(1) for every
    disturbance sequence when γ > γ_∞, and a sinusoid at the peak frequency makes it grow
    linearly in T when γ < γ_∞. This is the number to set beside the certified γ_c.

    ``start="cold"``: the limit of :func:`worst_case_attenuation` (x_0 = 0, the exact
    "R^p_T(γ) <= 0 for every w" level) as T → ∞. For LQR, zero input and M = 1 it equals
    the stationary value. With preview M >= 2 it can be larger: at t = 0 the controller
    meets w_0..w_{M-2} without having seen them coming (in the stationary loop it would
    have acted on them M - 1 steps earlier), so they act like an initial state
    ξ_0 = [0; w_0..w_{M-2}] and the worst finite-T disturbance concentrates at the start.
    This start-up effect is O(1): it does not change the stationary level. Computed
    exactly: for γ > γ_∞, sup_v Σ (‖z_t‖² - γ‖v_t‖²) from ξ_0 is ξ_0ᵀ X_γ ξ_0 with X_γ the
    stabilising solution of the H∞ (bounded-real) Riccati equation
    X = A_cᵀXA_c + C_cᵀC_c + (A_cᵀXB_c + C_cᵀD_c)(γI - D_cᵀD_c - B_cᵀXB_c)⁻¹(B_cᵀXA_c + D_cᵀC_c)
    (``scipy.linalg.solve_discrete_are`` with the indefinite weight D_cᵀD_c - γI), so the
    cold-start level is max(γ_∞, the root of λ_max(X_γ restricted to the buffer) = γ).

    The H∞ norm is python-control's ``control.system_norm(sys, p='inf')``. Without Slycot,
    python-control refuses discrete-time systems with poles at z = 0 (the buffer has
    them), so the system is first mapped to continuous time by the inverse bilinear
    transform s = 2(z - 1)/(z + 1), which maps the unit circle onto the imaginary axis and
    preserves the H∞ norm (the same map python-control applies internally); and since its
    routine (0.10.2) assumes a square transfer matrix, zero input columns are appended
    (σ_max([G 0]) = σ_max(G)). An unstable closed loop has no finite limit: ``gamma = inf``
    with a ``reason``.
    """
    import control

    K, L, Mw, Q, R = _linear_loop(system, controller, cost)
    if start not in ("stationary", "cold"):
        raise OrrcValueError(f"start must be 'stationary' or 'cold'; got {start!r}")
    tol = as_float("tol", tol, minimum=0.0, strict_min=True)
    Ad, Bd, Cd, Dd = _closed_loop_ss(system, K, L, Mw, Q, R)
    sys_d = control.ss(Ad, Bd, Cd, Dd, dt=True)
    rho = float(np.max(np.abs(np.linalg.eigvals(Ad))))
    if rho >= 1.0 - 1e-12:
        return Attenuation(gamma=math.inf, closed_loop=sys_d, start=start,
                           reason=f"the closed loop is not stable (spectral radius {rho:.6g} >= 1): "
                                  "the worst-case attenuation grows without bound with T")
    I = np.eye(Ad.shape[0])
    Ainv = np.linalg.inv(Ad + I)
    Ac, Bc, Cc, Dc = 2 * (Ad - I) @ Ainv, 2 * Ainv @ Bd, 2 * Cd @ Ainv, Dd - Cd @ Ainv @ Bd
    # python-control 0.10.2's scipy L∞ routine assumes as many outputs as inputs; zero
    # input columns / output rows make the system square without changing its norm
    p, q = Cc.shape[0], Bc.shape[1]
    if p > q:
        Bc, Dc = np.hstack([Bc, np.zeros((Bc.shape[0], p - q))]), np.hstack([Dc, np.zeros((p, p - q))])
    elif q > p:
        Cc, Dc = np.vstack([Cc, np.zeros((q - p, Cc.shape[1]))]), np.vstack([Dc, np.zeros((q - p, q))])
    sys_c = control.ss(Ac, Bc, Cc, Dc)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        norm = float(control.system_norm(sys_c, p="inf", tol=tol, method="scipy"))
    gamma_inf = norm ** 2
    n = system.n
    if start == "stationary" or Ad.shape[0] == n or gamma_inf == 0.0:
        return Attenuation(gamma=gamma_inf, closed_loop=sys_d, start=start)
    return Attenuation(gamma=_cold_start_level(Ad, Bd, Cd, Dd, n, gamma_inf, tol), closed_loop=sys_d,
                       start=start)


def _cold_start_level(A, B, C, D, n, gamma_inf, tol):
    """max(γ_∞, root of λ_max(X_γ[buffer]) = γ) (see :func:`worst_case_attenuation_limit`)."""
    from scipy import linalg, optimize

    q = B.shape[1]
    DtD, CtD, CtC = D.T @ D, C.T @ D, C.T @ C

    def excess(g):
        X = linalg.solve_discrete_are(A, B, CtC, DtD - g * np.eye(q), s=CtD)
        S = g * np.eye(q) - DtD - B.T @ X @ B
        if np.linalg.eigvalsh(0.5 * (S + S.T))[0] <= 0:
            raise np.linalg.LinAlgError("not the stabilising bounded-real solution")
        Xbb = X[n:, n:]
        return float(np.linalg.eigvalsh(0.5 * (Xbb + Xbb.T))[-1]) - g

    lo = None
    for rel in (1e-9, 1e-7, 1e-5, 1e-3):  # the Riccati equation degenerates at γ_∞ itself
        try:
            f_lo = excess(gamma_inf * (1 + rel))
            lo = gamma_inf * (1 + rel)
            break
        except (np.linalg.LinAlgError, ValueError):
            continue
    if lo is None:
        raise RuntimeError("the bounded-real Riccati equation could not be solved near the H∞ level")
    if f_lo <= 0:
        return gamma_inf
    hi = 2 * lo
    while excess(hi) > 0:
        hi *= 2
    return float(optimize.brentq(excess, lo, hi, xtol=tol * hi, rtol=4 * np.finfo(float).eps))
