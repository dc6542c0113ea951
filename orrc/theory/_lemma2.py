"""Lemma 2 of the paper (Section 5.1): the decay rate a, b = γ̄(α_lo/ᾱ + 1), the coefficients
M_{w,j} and the right-hand side of the bound. Re-exported by :mod:`orrc.theory.known`.
"""
from __future__ import annotations

import numpy as np

from .._validate import OrrcValueError, as_float, as_int, check_size, finite_result
from ._setting import _M, _a_min, _alphas, _b, _energies, _gamma_bar, _lemma2_setting, _require_threshold


# -- Lemma 2 --------------------------------------------------------------------------------------
@finite_result
def min_decay_rate(M, alpha_lo, alpha_hi) -> float:
    """The smallest admissible decay rate a of Lemma 2 and Theorem 1:

        a_min = 1 - (α_lo - ᾱ²/((M-1) α_lo)) / ᾱ.

    The lemma allows any a with 1 > a >= 1 - ε̃/ᾱ and 0 < ε̃ < α_lo - ᾱ²/((M-1)α_lo), so
    a_min is the infimum; the proof (Appendix B: Γ_V <= -ε̃ and the recursion
    V^{t+1} <= a V^t + b Σ‖w‖²) also goes through at ε̃ = α_lo - ᾱ²/((M-1)α_lo), so
    ``orrc`` admits a = a_min itself. Always 0 < a_min < 1 above the threshold.
    Raises when M is not above :func:`horizon_threshold`.

    Parameters
    ----------
    M : the horizon M (an integer; above the threshold where the result needs it).
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi : ᾱ >= α_lo, with V_M(x, w) <= ᾱ σ(x) + γ̄ Σ‖w‖² (Lemma 1).

    Returns
    -------
    float
        a_min, in (0, 1).

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> print(round(theory.min_decay_rate(6, alpha_lo=1.0, alpha_hi=2.0), 6))
    0.9
    """
    M = _M(M)
    alpha_lo, alpha_hi = _alphas(alpha_lo, alpha_hi)
    _require_threshold(M, alpha_lo, alpha_hi)
    return _a_min(M, alpha_lo, alpha_hi)


@finite_result
def decay_b(alpha_lo, alpha_hi, gamma_bar) -> float:
    """b = γ̄ (α_lo/ᾱ + 1)  (Lemma 2), the input gain of the recursion
    V^{t+1}_M <= a V^t_M + b Σ_{k=t}^{t+M-1} ‖w_k‖² (Appendix B).

    Parameters
    ----------
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi : ᾱ >= α_lo, with V_M(x, w) <= ᾱ σ(x) + γ̄ Σ‖w‖² (Lemma 1).
    gamma_bar : γ̄ >= 0, the disturbance constant of Lemma 1.

    Returns
    -------
    float
        b.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> theory.decay_b(alpha_lo=1.0, alpha_hi=2.0, gamma_bar=1.0)
    1.5
    """
    alpha_lo, alpha_hi = _alphas(alpha_lo, alpha_hi)
    gamma_bar = _gamma_bar(gamma_bar)
    return _b(alpha_lo, alpha_hi, gamma_bar)


@finite_result
def lemma2_coefficients(M, H, a, alpha_hi, gamma_bar, b) -> np.ndarray:
    """The coefficients M_{w,j} of Lemma 2, for j = t, ..., t_H + M - 2 (returned with offset j - t).

    With t_H = t + H and H >= M (Lemma 2; Appendix B, last display):

        M_{w,j} = b a^{H-M}/(1-a) + a^H γ̄     for t <= j <= t+M-1,
        M_{w,j} = b a^{t_H-j-1}/(1-a)         for t+M <= j <= t_H-1,
        M_{w,j} = b/(1-a)                     for t_H <= j <= t_H+M-2.

    Returns an array of length H + M - 1 (entry k is M_{w,t+k}). ``alpha_hi`` is only
    validated (the coefficients do not depend on it; it sets M_λ = ᾱ in
    :func:`lemma2_bound`). The caller is responsible for a being admissible for the
    constants (see :func:`min_decay_rate`); here 0 < a < 1 is checked.

    Parameters
    ----------
    M : the horizon M (an integer; above the threshold where the result needs it).
    H : the look-ahead H >= M.
    a : the decay rate, in [the minimal decay rate, 1).
    alpha_hi : ᾱ >= α_lo, with V_M(x, w) <= ᾱ σ(x) + γ̄ Σ‖w‖² (Lemma 1).
    gamma_bar : γ̄ >= 0, the disturbance constant of Lemma 1.
    b : the input gain b of Lemma 2 (:func:`decay_b`).

    Returns
    -------
    numpy.ndarray
        (H + M - 1,) the coefficients M_{w,t+k}, k = 0..H+M-2.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> theory.lemma2_coefficients(M=6, H=6, a=0.9, alpha_hi=2.0,
    ...                            gamma_bar=1.0, b=1.5).shape
    (11,)
    """
    M = _M(M)
    H = as_int("H", H, minimum=1)
    if H < M:
        raise OrrcValueError(f"Lemma 2 needs H >= M; got H={H}, M={M}")
    a = as_float("a", a, minimum=0.0, maximum=1.0, strict_min=True, strict_max=True)
    as_float("alpha_hi", alpha_hi, minimum=0.0, strict_min=True)
    gamma_bar = _gamma_bar(gamma_bar)
    b = as_float("b", b, minimum=0.0, strict_min=True)
    check_size(f"the H + M - 1 coefficients of Lemma 2 at H={H}, M={M}", nbytes=8.0 * 4 * (H + M - 1),
               ops=10.0 * (H + M - 1), hint="lower H")
    k = np.arange(H + M - 1)
    out = np.empty(H + M - 1)
    first = k < M
    middle = (k >= M) & (k < H)
    last = k >= H
    out[first] = b * a ** (H - M) / (1.0 - a) + a ** H * gamma_bar
    out[middle] = b * a ** (H - k[middle] - 1) / (1.0 - a)
    out[last] = b / (1.0 - a)
    return out


@finite_result
def lemma2_bound(sigma_t, w_window, M, H, a, alpha_lo, alpha_hi, gamma_bar) -> float:
    """The right-hand side of Lemma 2: c_{t+H} <= ᾱ a^H σ(x_t) + Σ_{j=t}^{t_H+M-2} M_{w,j} ‖w_j‖².

    The statement's M_λ e^{-λH} with M_λ = ᾱ, λ = -ln a is ᾱ a^H; the appendix's
    "M_λ = a^H ᾱ" would count a^H twice (see paper-summary.md), so the statement's
    reading is implemented. Coefficients: :func:`lemma2_coefficients`.

    Parameters
    ----------
    sigma_t : σ(x_t) >= 0.
    w_window : (H + M - 1, n) the disturbances w_t..w_{t+H+M-2} (a 1-D array is read as a scalar
        disturbance sequence).
    M : the horizon M (an integer; above the threshold where the result needs it).
    H : the look-ahead H >= M.
    a : the decay rate, in [min_decay_rate(M, α_lo, ᾱ), 1).
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi : ᾱ >= α_lo, with V_M(x, w) <= ᾱ σ(x) + γ̄ Σ‖w‖² (Lemma 1).
    gamma_bar : γ̄ >= 0, the disturbance constant of Lemma 1.

    Returns
    -------
    float
        the bound on c_{t+H}.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> import numpy as np
    >>> print(round(theory.lemma2_bound(1.0, np.zeros((11, 2)), M=6, H=6, a=0.9,
    ...                                 alpha_lo=1.0, alpha_hi=2.0, gamma_bar=1.0), 6))
    1.062882
    """
    M, a, alpha_lo, alpha_hi, gamma_bar = _lemma2_setting(M, a, alpha_lo, alpha_hi, gamma_bar)
    sigma_t = as_float("sigma_t", sigma_t, minimum=0.0)
    H = as_int("H", H, minimum=1)
    if H < M:
        raise OrrcValueError(f"Lemma 2 needs H >= M; got H={H}, M={M}")
    e = _energies("w_window", w_window)
    if len(e) != H + M - 1:
        raise OrrcValueError(
            f"w_window must hold the H + M - 1 = {H + M - 1} disturbances w_t..w_(t+H+M-2); "
            f"got {len(e)} rows")
    coef = lemma2_coefficients(M, H, a, alpha_hi, gamma_bar, _b(alpha_lo, alpha_hi, gamma_bar))
    return float(alpha_hi * a ** H * sigma_t + coef @ e)
