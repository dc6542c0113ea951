"""Sampled estimates of the constants of Section 5.1 for any problem (nonlinear, input bounds).

:func:`sampled_constants` solves Algorithm 1's M-step problem on samples of (x, W); the
suprema of the sampled ratios are *lower bounds* on the true ᾱ, γ̄ (``estimate=True``),
not certificates.
"""
from __future__ import annotations

import math
import warnings

import numpy as np

from .._validate import OrrcValueError, as_float, as_int, check_size
from .._problem import check_problem
from ..controllers.preview import PreviewRHC
from ..costs import StageCost
from ..systems import System
from .constants import Constants, _gamma_c_on_curve, _knee

__all__ = ["sampled_constants"]


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

    Parameters
    ----------
    system, cost : the problem (any system and stage cost).
    M : the horizon of Algorithm 1.
    n_samples : samples per set.
    x_radius, w_radius : the sampled radii of x and of each w_k.
    input_bounds : (lo, hi), the set U.
    seed : the samples' seed.
    grid : the points of the scan along the sampled Pareto curve.
    solver_options : options for the CasADi path.

    Returns
    -------
    Constants
        the estimated α_lo, ᾱ, γ̄, a, γ_c (``estimate`` True: lower bounds on the true constants).

    Raises
    ------
    orrc.OrrcValueError
        When an argument is out of range or the samples exceed the size limits.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.sampled_constants(ex.system, ex.cost, 8, n_samples=5, seed=0)
    >>> k.estimate, k.M
    (True, 8)
    """
    from ..disturbances import Ball, _rng

    check_problem(system, cost)
    M = as_int("M", M, minimum=2)
    n_samples = as_int("n_samples", n_samples, minimum=1)
    grid = as_int("grid", grid, minimum=20)
    x_radius = as_float("x_radius", x_radius, minimum=0.0, strict_min=True)
    w_radius = 0.1 * x_radius if w_radius is None else as_float("w_radius", w_radius, minimum=0.0, strict_min=True)
    rng = _rng(seed)
    n, m = system.n, system.m
    check_size(f"sampled_constants with n_samples={n_samples}, grid={grid} at M={M} (3 x {n_samples} M-step solves, "
               f"then the Pareto curve at {grid} points)",
               nbytes=8.0 * 6 * n_samples * M * n + 8.0 * 8 * grid,
               ops=3.0 * n_samples * M * (n + m) * 1e5 + 1e3 * grid * (3 * n_samples + 1),
               hint="lower n_samples, grid or M")
    rhc = PreviewRHC(system, cost, M, input_bounds=input_bounds, solver_options=solver_options)
    xs = Ball(x_radius, n).sample(2 * n_samples, rng)
    Ws = Ball(w_radius, n).sample(2 * n_samples * M, rng).reshape(2 * n_samples, M, n)
    zx, zW = np.zeros(n), np.zeros((M, n))
    jobs = ([(x, zW) for x in xs[:n_samples]] + [(zx, W) for W in Ws[:n_samples]]
            + [(x, W) for x, W in zip(xs[n_samples:], Ws[n_samples:])])
    sig, en, V, ratios = [], [], [], []
    failures = 0
    # c/σ along the plans skips states numerically at the origin, σ below 1e-12 of the sampled
    # states' scale (a state off the origin by rounding, ~1e-6 of the radius or less, where c/σ
    # is a ratio of rounding errors), relative so that the estimate does not depend on units
    sigma_floor = 1e-12 * max(cost.sigma(x) for x in xs)
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
                    if s > sigma_floor:
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
