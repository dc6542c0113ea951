"""The constants of Section 5.1 for a linear-quadratic problem, exactly.

* :class:`Constants` -- the result (also returned by :func:`orrc.certify.sampled_constants`);
* :func:`lq_constants` -- exact certificates for x_{t+1} = Ax_t + Bu_t + w_t with a quadratic
  cost: V_M(x, W) = zᵀ H z, so (ᾱ, γ̄) bound V_M exactly when diag(ᾱ I_n, γ̄ I_{Mn}) - H ⪰ 0,
  a Pareto curve of pairs; the pair that minimises Theorem 1's γ_c is picked;
* :func:`alpha_hi_floor`, :func:`smallest_certified_M` -- λ_max(P_0(M)) and the first
  certified horizon.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import theory
from .._validate import (PY_CALL_OPS, OrrcValueError, as_float, as_int, check_finite_result, check_size,
                         eigvalsh_tol)
from ..costs import QuadraticCost
from ..solvers.lq import LQPreviewLaw, riccati_step, riccati_steps_size
from ..systems import LinearSystem

__all__ = ["Constants", "lq_constants", "smallest_certified_M", "alpha_hi_floor"]


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

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)
    >>> print(k.alpha_lo, round(k.alpha_hi, 4), round(k.gamma_bar, 4), round(k.gamma_c, 2))
    1.0 2.1808 4.1834 572.85
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
        """alpha_hi σ(x) + gamma_bar Σ_k ‖w_k‖², the bound on V_M (σ >= 0 and energy >= 0 given)."""
        sigma = as_float("sigma", sigma, minimum=0.0)
        w_energy = as_float("w_energy", w_energy, minimum=0.0)
        return check_finite_result("Constants.bound", float(self.alpha_hi * sigma + self.gamma_bar * w_energy),
                                   f"sigma={sigma:g}, w_energy={w_energy:g}")

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
    if not (alpha_lo > 0 and theory.known._above(M, alpha_lo, alpha_hi)):
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
        # every λ_i(H_ww) is known to within its rounding error (eigvalsh_tol, N·eps·‖H_ww‖₂): a
        # γ̄ that exceeds λ_max(H_ww) by no more than that does not make γ̄ I - H_ww ≻ 0 certain,
        # and ᾱ(γ̄) there is dominated by rounding (its relative error is about tol/(γ̄ - λ_max))
        self.tol = eigvalsh_tol(Hww)
        self.G = Hxw @ V
        self.Hxx = 0.5 * (Hxx + Hxx.T)
        self.alpha_inf = float(np.linalg.eigvalsh(self.Hxx)[-1])
        self.coupling = float(np.sum(self.G ** 2))

    def __call__(self, gamma_bar: float) -> float:
        d = gamma_bar - self.lam
        if not np.all(d > self.tol):
            raise OrrcValueError(
                f"gamma_bar must exceed λ_max(H_ww) = {self.lam_max:.6g} (below it no alpha_hi is "
                f"admissible) by more than its rounding error {self.tol:.3g}; got {gamma_bar:.6g}")
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
    (P_0 of the M-step problem is the M-th iterate from P = 0, whatever the longest horizon),
    kept only at the requested horizons. Refused when max(Ms) Riccati steps exceed the limits
    of ``orrc.config``.

    Parameters
    ----------
    system : a :class:`~orrc.LinearSystem`.
    cost : a :class:`~orrc.QuadraticCost`.
    Ms : the horizons, integers >= 1.

    Returns
    -------
    numpy.ndarray
        (len(Ms),) λ_max(P_0(M)) for each M.

    Raises
    ------
    orrc.OrrcValueError
        When the system is not linear or the cost not quadratic, an argument is out of range, or the
        computation exceeds the size limits of ``orrc.config``.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> certify.alpha_hi_floor(ex.system, ex.cost, [2, 5, 8]).round(4)
    array([1.72  , 1.9511, 1.9522])
    """
    _lq_check(system, cost)
    if isinstance(Ms, (str, bytes)) or not np.iterable(Ms):
        raise OrrcValueError(f"Ms must be an iterable of integers >= 1; got {type(Ms).__name__}")
    Ms = [as_int(f"Ms[{i}]", M, minimum=1) for i, M in enumerate(Ms)]
    if not Ms:
        raise OrrcValueError("Ms must hold at least one horizon M >= 1; got an empty iterable")
    wanted = set(Ms)
    floor = {M: value for M, value in _floors(system, cost, max(Ms), f"alpha_hi_floor at max(Ms)={max(Ms)}")
             if M in wanted}
    return np.array([floor[M] for M in Ms], dtype=float)


def _floors(system, cost, M_max: int, what: str):
    """(M, λ_max(P_0(M))) for M = 1..M_max from one backward Riccati recursion (P_0(M) is its M-th
    iterate from P = 0), one matrix kept at a time; the size checked first."""
    A, B, Q, R = system.A, system.B, cost.Q, cost.R
    n, m = B.shape
    riccati_steps_size(f"{what} (that many Riccati steps, n={n}, m={m})", M_max, n, m, stored=0)
    P = np.zeros((n, n))
    for M in range(1, M_max + 1):
        P = riccati_step(A, B, P, Q, R)[0]
        top = float(np.linalg.eigvalsh(P)[-1])
        if not np.isfinite(top):
            raise OrrcValueError(f"{what}: the Riccati matrix P_0(M) overflows at M={M} (an unstabilisable mode "
                                 "grows like its eigenvalue^(2M)); lower the horizon or rescale Q, R")
        yield M, top


def smallest_certified_M(system: LinearSystem, cost: QuadraticCost, M_max: int = 200) -> int | None:
    """The smallest M >= 2 at which :func:`lq_constants` finds an admissible pair, or None up to M_max.

    Along the Pareto curve ᾱ decreases to λ_max(P_0(M)) (P_0 the M-step Riccati matrix,
    V_M(x, 0) = xᵀP_0x) as γ̄ → ∞, so an admissible pair exists iff
    λ_max(P_0(M)) < α_lo √(M-1) (the horizon threshold M > ᾱ²/α_lo² + 1, Lemma 2 and
    Theorem 1). The floors λ_max(P_0(M)) are :func:`alpha_hi_floor`'s, from one recursion that
    stops at the first certified M. Refused when M_max Riccati steps (the worst case) exceed the
    limits of ``orrc.config``.

    Parameters
    ----------
    system : a :class:`~orrc.LinearSystem`.
    cost : a :class:`~orrc.QuadraticCost`.
    M_max : the largest horizon tried.

    Returns
    -------
    int or None
        the smallest certified M, or None up to ``M_max``.

    Raises
    ------
    orrc.OrrcValueError
        When the system is not linear or the cost not quadratic, an argument is out of range, or the
        computation exceeds the size limits of ``orrc.config``.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> certify.smallest_certified_M(ex.system, ex.cost)
    5
    """
    _lq_check(system, cost)
    M_max = as_int("M_max", M_max, minimum=2)
    alpha_lo = float(cost.alpha_lo)
    if alpha_lo <= 0:
        return None
    for M, floor in _floors(system, cost, M_max, f"smallest_certified_M up to M_max={M_max}"):
        if M >= 2 and floor < alpha_lo * math.sqrt(M - 1):  # the search stops at the first certified M
            return M
    return None


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

    Parameters
    ----------
    system : a :class:`~orrc.LinearSystem`.
    cost : a :class:`~orrc.QuadraticCost`.
    M : the horizon of Algorithm 1.
    grid : the points of the scan along the Pareto curve.

    Returns
    -------
    Constants
        α_lo, ᾱ, γ̄, a and γ_c (``inf`` with a ``reason`` when no pair is admissible at M), the Pareto
        curve ``pareto`` (grid, 2) and γ_c along it.

    Raises
    ------
    orrc.OrrcValueError
        When the system is not linear or the cost not quadratic, an argument is out of range, or the
        computation exceeds the size limits of ``orrc.config``.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)
    >>> print(round(k.gamma_c, 2), k.pareto.shape)
    572.85 (200, 2)
    """
    from scipy import optimize

    _lq_check(system, cost)
    M = as_int("M", M, minimum=2)
    grid = as_int("grid", grid, minimum=20)
    n = system.n
    check_size(f"lq_constants' scan of the Pareto curve with grid={grid} at M={M} (n={n})",
               ops=6 * grid * (4 * PY_CALL_OPS + 2.0 * n * n * M * n + 10.0 * n ** 3), hint="lower grid")
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
        # extend to the left only where the curve is resolved: ᾱ(λ_max + d) has a relative
        # rounding error of about curve.tol / d, so d stays above 1e6·curve.tol (error <= ~1e-6)
        if i == 0 and curve.lam_max > 0 and d_lo * 1e-3 > 1e6 * curve.tol:
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
