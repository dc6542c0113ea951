"""Theorem 1 of the paper (Section 5.1): γ_c, the explicit O(1) constant, and the remark after
Theorem 1 (γ̃ and its γ_c). Re-exported by :mod:`orrc.theory.known`.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .._validate import OrrcValueError, as_float, as_int, finite_result
from ._setting import _A_RTOL, _alphas, _b, _energies, _gamma_bar, _gamma_c, _lemma2_setting


# -- Theorem 1 ------------------------------------------------------------------------------------
@finite_result
def gamma_c(M, a, alpha_lo, alpha_hi, gamma_bar) -> float:
    """γ_c = b ((M-1)(1-a) + 1) / (1-a)²  with b = γ̄ (α_lo/ᾱ + 1)  (Theorem 1).

    The attenuation level certified by Theorem 1: R^p_T(γ) = O(1) for every γ >= γ_c.
    Raises when M is not above :func:`horizon_threshold`, when a is outside
    [:func:`min_decay_rate`, 1), or when a constant is non-positive or α_lo > ᾱ.
    γ_c decreases as a decreases, so a = min_decay_rate gives the best γ_c; it is
    always > 2γ̄ (the remark after Theorem 1).

    Parameters
    ----------
    M : the horizon M (an integer; above the threshold where the result needs it).
    a : the decay rate, in [the minimal decay rate, 1).
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi : ᾱ >= α_lo, with V_M(x, w) <= ᾱ σ(x) + γ̄ Σ‖w‖² (Lemma 1).
    gamma_bar : γ̄ >= 0, the disturbance constant of Lemma 1.

    Returns
    -------
    float
        γ_c.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> print(round(theory.gamma_c(6, a=0.9, alpha_lo=1.0, alpha_hi=2.0, gamma_bar=1.0), 6))
    225.0
    """
    M, a, alpha_lo, alpha_hi, gamma_bar = _lemma2_setting(M, a, alpha_lo, alpha_hi, gamma_bar)
    return _gamma_c(M, a, _b(alpha_lo, alpha_hi, gamma_bar))


@finite_result
def theorem1_constant(sigma0, w, T, M, a, alpha_lo, alpha_hi, gamma_bar, gamma) -> float:
    """The O(1) of Theorem 1 made explicit: a C with

        Σ_{t=0}^{T-1} c_t(x_t, u_t) - γ Σ_{t=0}^{T-1} ‖w_t‖²  <=  C      for every γ >= γ_c,

        C = ᾱ σ(x_0) (1 - a^T)/(1 - a)
            + (γ̄/(1-a) + γ_c) Σ_{j=0}^{M-1} ‖w_j‖² - γ Σ_{j=0}^{min(M,T)-1} ‖w_j‖²
            + b (M-1)/(1-a) Σ_{j=max(T,M)}^{T+M-3} ‖w_j‖².

    (0-based: the paper's σ(x_1) is σ(x_0) here.) For γ >= γ_c and T >= M the middle
    line is at most γ̄/(1-a) Σ_{j<M} ‖w_j‖², so C depends only on σ(x_0), the first M
    disturbances and the last M-2 previewed ones: it is bounded in T, which is the
    theorem's claim.

    Derivation. Appendix C sums Lemma 2 (anchored at t = 0) over the costs c_H with
    H >= M and states that the first M costs are O(1) without writing the bound (its
    sum Σ_{H=1}^{M-1} also omits one cost, and its last sums use the 1-based index). Here
    every cost is bounded, each by a consequence of the recursion of Appendix B,
    V^{t+1} <= a V^t + b S_t with S_t = Σ_{k=t}^{t+M-1} ‖w_k‖², and c_H <= V^H:

    * H >= M: Lemma 2 (:func:`lemma2_bound` with t = 0);
    * H < M: c_H <= a^H V^0 + b Σ_{i<H} a^{H-1-i} S_i
      <= a^H ᾱ σ(x_0) + a^H γ̄ Σ_{j<M} ‖w_j‖² + b (1-a^H)/(1-a) Σ_{j=0}^{H+M-2} ‖w_j‖²
      (V^0 <= ᾱ σ(x_0) + γ̄ Σ_{j<M} ‖w_j‖²).

    Summing over H = 0..T-1, the total coefficient κ_j of ‖w_j‖² is at most
    γ̄/(1-a) + γ_c for j < M (the a^H γ̄ terms, the b a^{H-M}/(1-a) terms summing to
    b/(1-a)², and at most M-1 terms b/(1-a)); at most γ_c for M <= j < T (at most M-1
    terms b/(1-a) from the costs whose window contains j, and b a^{H-j-1}/(1-a) summing
    to b/(1-a)²), so κ_j - γ <= 0 there when γ >= γ_c and those terms are dropped; and at
    most b(M-1)/(1-a) for T <= j <= T+M-3 (the preview tail, which R^p_T does not
    subtract). Adding ᾱ σ(x_0) Σ_{H<T} a^H gives C. This is exactly the paper's
    bookkeeping with the first M costs written out.

    Remark (not in the paper): summing the recursion itself, Σ_t c_t <= Σ_t V^t <=
    V^0/(1-a) + b/(1-a) Σ_t S_t, gives the same kind of bound with the smaller level
    bM/(1-a) = γ_c - ab/(1-a)²; going through Lemma 2's rounded-up coefficients costs
    that difference. The function implements the paper's γ_c.

    Parameters
    ----------
    sigma0 : σ(x_0) >= 0.
    w : (L, n) disturbances w_0, w_1, ... including the previewed tail, L >= max(T+M-2, M)
        (``Trajectory.w_all`` of a simulation has T + M rows); a 1-D array is n = 1.
    T : number of steps (T >= 1; the theorem states T >= M + 1, the bound holds for all T).
    M, a, alpha_lo, alpha_hi, gamma_bar : as in :func:`gamma_c` (M above the threshold).
    gamma : attenuation level, gamma >= gamma_c (else the theorem says nothing: raises).

    Returns
    -------
    float
        C (an array of the same shape when T is an array).

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> import numpy as np
    >>> print(round(theory.theorem1_constant(1.0, np.zeros((20, 2)), T=10, M=6, a=0.9,
    ...                                      alpha_lo=1.0, alpha_hi=2.0, gamma_bar=1.0,
    ...                                      gamma=250.0), 6))
    13.026431
    """
    s = _theorem1_setting(sigma0, T, M, a, alpha_lo, alpha_hi, gamma_bar, gamma)
    T, M = s.T, s.M
    e = _energies("w", w)
    need = max(T + M - 2, M)
    if len(e) < need:
        raise OrrcValueError(
            f"w must hold w_0..w_(T+M-3) and w_0..w_(M-1), i.e. at least max(T+M-2, M) = {need} rows "
            f"(use Trajectory.w_all, which includes the previewed tail); got {len(e)} rows")
    return float(_theorem1_constants(s, e, np.array([T]))[0])


class _Theorem1Setting(NamedTuple):
    """The checked arguments of Theorem 1 with b (Lemma 2) and γ_c, each computed once."""

    sigma0: float
    T: int
    M: int
    a: float
    alpha_lo: float
    alpha_hi: float
    gamma_bar: float
    gamma: float
    b: float
    gamma_c: float


def _theorem1_setting(sigma0, T, M, a, alpha_lo, alpha_hi, gamma_bar, gamma) -> _Theorem1Setting:
    """The checked arguments of :func:`theorem1_constant` but w (same checks, order and messages:
    the Lemma 2 setting, T, sigma0, then gamma >= γ_c), with b and γ_c computed once."""
    M, a, alpha_lo, alpha_hi, gamma_bar = _lemma2_setting(M, a, alpha_lo, alpha_hi, gamma_bar)
    T = as_int("T", T, minimum=1)
    sigma0 = as_float("sigma0", sigma0, minimum=0.0)
    b = _b(alpha_lo, alpha_hi, gamma_bar)
    gc = _gamma_c(M, a, b)
    gamma = as_float("gamma", gamma)
    if gamma < gc * (1.0 - _A_RTOL):
        raise OrrcValueError(
            f"Theorem 1 bounds R^p_T(gamma) only for gamma >= gamma_c = {gc:.6g}; got gamma={gamma:.6g}")
    return _Theorem1Setting(sigma0, T, M, a, alpha_lo, alpha_hi, gamma_bar, gamma, b, gc)


def _theorem1_constants(s: _Theorem1Setting, e, Ts) -> np.ndarray:
    """:func:`theorem1_constant` for several T at once (s from :func:`_theorem1_setting`; e = ‖w_j‖²)."""
    sigma0, M, a, alpha_hi, gamma_bar, gamma, b, gc = (s.sigma0, s.M, s.a, s.alpha_hi, s.gamma_bar, s.gamma,
                                                       s.b, s.gamma_c)
    cs = np.concatenate([[0.0], np.cumsum(e)])

    def energy(i, j):  # Σ_{i <= k < j} e_k, 0 when j <= i
        return np.where(j > i, cs[np.maximum(j, i)] - cs[i], 0.0)

    Ts = np.asarray(Ts)
    head = (gamma_bar / (1.0 - a) + gc) * cs[M] - gamma * cs[np.minimum(M, Ts)]
    tail = b * (M - 1) / (1.0 - a) * energy(np.maximum(Ts, M), Ts + M - 2)
    return alpha_hi * sigma0 * (1.0 - a ** Ts.astype(float)) / (1.0 - a) + head + tail


# -- the remark after Theorem 1 -------------------------------------------------------------------
@finite_result
def gamma_tilde(alpha_lo, alpha_hi) -> float:
    """γ̃ = ⌈ᾱ²/α_lo²⌉ α_lo / (ᾱ ((α_lo²/ᾱ²) ⌈ᾱ²/α_lo²⌉ - 1))  (remark after Theorem 1).

    It equals 1/(1 - min_decay_rate(M, α_lo, ᾱ)) at M = ⌈ᾱ²/α_lo²⌉ + 1, the choice of M
    behind the remark. It is undefined (division by zero) when ᾱ²/α_lo² is an integer
    (then that M sits exactly on the threshold): raises in that case.

    Parameters
    ----------
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi : ᾱ >= α_lo, with V_M(x, w) <= ᾱ σ(x) + γ̄ Σ‖w‖² (Lemma 1).

    Returns
    -------
    float
        γ̃.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> print(round(theory.gamma_tilde(alpha_lo=1.0, alpha_hi=2.5), 6))
    23.333333
    """
    alpha_lo, alpha_hi = _alphas(alpha_lo, alpha_hi)
    kappa = alpha_hi ** 2 / alpha_lo ** 2
    N = math.ceil(kappa)
    denom = (alpha_lo ** 2 / alpha_hi ** 2) * N - 1.0
    if not denom > 0.0:
        raise OrrcValueError(
            f"gamma_tilde is undefined when alpha_hi²/alpha_lo² is an integer (the remark's "
            f"M = ceil(alpha_hi²/alpha_lo²) + 1 is then on the threshold); got alpha_hi²/alpha_lo² = {kappa!r}")
    return N * alpha_lo / (alpha_hi * denom)


@finite_result
def gamma_c_remark(alpha_lo, alpha_hi, gamma_bar) -> float:
    """2 (1 + α_lo/ᾱ)(γ̃ ᾱ²/α_lo² + γ̃²) γ̄  (remark after Theorem 1).

    The paper says M and a can be chosen so that this value ⪆ γ_c >= 2γ̄. With
    M = ⌈ᾱ²/α_lo²⌉ + 1 and a = min_decay_rate, γ_c = b(⌈ᾱ²/α_lo²⌉ γ̃ + γ̃²), which is
    at most this value. Raises where :func:`gamma_tilde` does.

    Parameters
    ----------
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi : ᾱ >= α_lo, with V_M(x, w) <= ᾱ σ(x) + γ̄ Σ‖w‖² (Lemma 1).
    gamma_bar : γ̄ >= 0, the disturbance constant of Lemma 1.

    Returns
    -------
    float
        the remark's level.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> print(round(theory.gamma_c_remark(alpha_lo=1.0, alpha_hi=2.5, gamma_bar=1.0), 4))
    1932.7778
    """
    alpha_lo, alpha_hi = _alphas(alpha_lo, alpha_hi)
    gamma_bar = _gamma_bar(gamma_bar)
    gt = gamma_tilde(alpha_lo, alpha_hi)
    return 2.0 * (1.0 + alpha_lo / alpha_hi) * (gt * alpha_hi ** 2 / alpha_lo ** 2 + gt * gt) * gamma_bar
