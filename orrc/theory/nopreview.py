"""The theory of Appendix D of the paper (no disturbance preview: Lemma 6, Theorem 3) as pure functions.

Algorithm 3 (min-max RHC) sees the costs M steps ahead but no future disturbance. Its
value V^t_{W,M}(x) is the worst-case cost of the min-max plan over W^M, and the class of
systems of Appendix D is defined by

    α_lo σ(x) <= V^t_{W,M}(x) <= ᾱ_W σ(x) + γ̄_W max_{w∈W} ‖w‖²     for all x, t.

The constants (the names used throughout ``orrc``):

* ``alpha_lo`` (α_lo): c_t(x, u) >= α_lo σ(x) (Assumption 2; also the lower constant of Lemma 6);
* ``alpha_hi_W`` (ᾱ_W) and ``gamma_bar_W`` (γ̄_W): the bound above, in terms of the largest
  disturbance energy ``w_max_sq`` = max_{w∈W} ‖w‖² (``W.max_norm_sq``);
* ``M``, ``a`` as in Section 5.1, with ᾱ_W in place of ᾱ.

Functions (the statement of the paper they implement):

* :func:`Gamma_WV`, :func:`Gamma_WV_gamma` -- Γ_{W,V} and Γ^γ_{W,V} of Lemma 6;
* :func:`horizon_threshold_W` -- ᾱ_W²/α_lo² + 1; Theorem 3 needs M above it;
* :func:`min_decay_rate_W` -- the smallest admissible a of Theorem 3;
* :func:`decay_b_W` -- b_W = γ̄_W (α_lo/ᾱ_W + 1), the input gain of the proof's recursion
  V^{t+1}_{W,M} <= a V^t_{W,M} + b_W max‖w‖²;
* :func:`gamma_c_W` -- γ_{c,W} = γ̄_W (α_lo/ᾱ_W + 1)/(1 - a) of Theorem 3;
* :func:`theorem3_constant` -- the O(1) of Theorem 3, made explicit.

Two readings (see the chapter's notes): Theorem 3 defines b with γ̄, but its proof and γ_{c,W}
use γ̄_W, which is implemented; and the paper's remark "γ̄_W = γ̄ M" (from the preview constants)
bounds the max-min value max_W V_M(x, W), which can be smaller than the min-max value, so
``orrc.certify.minmax_constants`` computes γ̄_W from V_{W,M} itself.

Indices are 0-based: the paper's t = 1..T is t = 0..T-1. Bad input raises
:class:`~orrc.OrrcValueError` naming the argument.
"""
from __future__ import annotations

import math

import numpy as np

from .._validate import OrrcValueError, as_float, as_int, finite_result
from ._setting import _M, _a_min, _above, _alphas, _decay, _gamma_bar, _require_threshold

__all__ = ["Gamma_WV", "Gamma_WV_gamma", "horizon_threshold_W", "min_decay_rate_W", "decay_b_W", "gamma_c_W",
           "theorem3_constant"]


_NO_GAMMA = object()


def _constants_W(alpha_lo, alpha_hi_W, gamma_bar_W=_NO_GAMMA):
    """The checked (α_lo, ᾱ_W[, γ̄_W]); the messages name the no-preview constants."""
    try:
        alpha_lo, alpha_hi_W = _alphas(alpha_lo, alpha_hi_W)
    except OrrcValueError as exc:
        raise OrrcValueError(str(exc).replace("alpha_hi", "alpha_hi_W")) from None
    if gamma_bar_W is _NO_GAMMA:
        return alpha_lo, alpha_hi_W
    try:
        return alpha_lo, alpha_hi_W, _gamma_bar(gamma_bar_W)
    except OrrcValueError as exc:
        raise OrrcValueError(str(exc).replace("gamma_bar", "gamma_bar_W")) from None


def _theorem3_setting(M, a, alpha_lo, alpha_hi_W, gamma_bar_W):
    """The checked (M, a, α_lo, ᾱ_W, γ̄_W) of Theorem 3: M above the threshold, a admissible."""
    M = _M(M)
    alpha_lo, alpha_hi_W, gamma_bar_W = _constants_W(alpha_lo, alpha_hi_W, gamma_bar_W)
    try:
        _require_threshold(M, alpha_lo, alpha_hi_W)
        a = _decay(a, M, alpha_lo, alpha_hi_W)
    except OrrcValueError as exc:
        raise OrrcValueError(str(exc).replace("alpha_hi", "alpha_hi_W").replace("Lemma 2 and Theorem 1 need",
                                                                             "Theorem 3 needs")
                             .replace("Lemma 2:", "Theorem 3:").replace("[min_decay_rate,", "[min_decay_rate_W,")) from None
    return M, a, alpha_lo, alpha_hi_W, gamma_bar_W


# -- Lemma 6 --------------------------------------------------------------------------------------
@finite_result
def Gamma_WV(M, alpha_lo, alpha_hi_W) -> float:
    """Γ_{W,V} = ᾱ_W²/((M-1) α_lo) - α_lo  (Lemma 6; Appendix D, last display of the proof).

    The coefficient of σ(x_t) in V^{t+1}_{W,M} - V^t_{W,M} <= Γ_{W,V} σ(x_t) + Γ^γ_{W,V} max‖w‖².
    Negative exactly when M > ᾱ_W²/α_lo² + 1 (:func:`horizon_threshold_W`). Needs M >= 2.

    Parameters
    ----------
    M : the horizon M (an integer; above the threshold where the result needs it).
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi_W : ᾱ_W >= α_lo, the constant of Appendix D: V_{W,M}(x) <= ᾱ_W σ(x) + γ̄_W max‖w‖².

    Returns
    -------
    float
        Γ_{W,V}.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> print(round(theory.Gamma_WV(6, alpha_lo=1.0, alpha_hi_W=2.0), 6))
    -0.2
    """
    M = _M(M)
    alpha_lo, alpha_hi_W = _constants_W(alpha_lo, alpha_hi_W)
    return alpha_lo * ((alpha_hi_W / alpha_lo) ** 2 / (M - 1) - 1.0)


@finite_result
def Gamma_WV_gamma(M, alpha_lo, alpha_hi_W, gamma_bar_W) -> float:
    """Γ^γ_{W,V} = γ̄_W (ᾱ_W/((M-1) α_lo) + 1)  (Lemma 6).

    The coefficient of the LARGEST disturbance energy max_{w∈W} ‖w‖² in Lemma 6's increment
    bound (Lemma 1 has the previewed energy Σ_{k=t}^{t+M-1} ‖w_k‖² there). Needs M >= 2.

    Parameters
    ----------
    M : the horizon M (an integer; above the threshold where the result needs it).
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi_W : ᾱ_W >= α_lo, the constant of Appendix D: V_{W,M}(x) <= ᾱ_W σ(x) + γ̄_W max‖w‖².
    gamma_bar_W : γ̄_W >= 0, the disturbance constant of Appendix D.

    Returns
    -------
    float
        Γ^γ_{W,V}.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> print(round(theory.Gamma_WV_gamma(6, 1.0, 2.0, gamma_bar_W=1.0), 6))
    1.4
    """
    M = _M(M)
    alpha_lo, alpha_hi_W, gamma_bar_W = _constants_W(alpha_lo, alpha_hi_W, gamma_bar_W)
    return gamma_bar_W * (alpha_hi_W / ((M - 1) * alpha_lo) + 1.0)


@finite_result
def horizon_threshold_W(alpha_lo, alpha_hi_W) -> float:
    """ᾱ_W²/α_lo² + 1: Theorem 3 holds for every integer M strictly above it (then Γ_{W,V} < 0).

    Parameters
    ----------
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi_W : ᾱ_W >= α_lo, the constant of Appendix D: V_{W,M}(x) <= ᾱ_W σ(x) + γ̄_W max‖w‖².

    Returns
    -------
    float
        ᾱ_W²/α_lo² + 1.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> theory.horizon_threshold_W(alpha_lo=1.0, alpha_hi_W=2.0)
    5.0
    """
    alpha_lo, alpha_hi_W = _constants_W(alpha_lo, alpha_hi_W)
    return (alpha_hi_W / alpha_lo) ** 2 + 1.0


# -- Theorem 3 ------------------------------------------------------------------------------------
@finite_result
def min_decay_rate_W(M, alpha_lo, alpha_hi_W) -> float:
    """The smallest admissible decay rate of Theorem 3, a_min = 1 - (α_lo - ᾱ_W²/((M-1) α_lo))/ᾱ_W.

    The theorem allows 1 > a >= 1 - ε̃/ᾱ_W with 0 < ε̃ < α_lo - ᾱ_W²/((M-1)α_lo); as for Theorem 1
    (:func:`orrc.theory.min_decay_rate`) the proof also goes through at the infimum, which is
    admitted. Raises when M is not above :func:`horizon_threshold_W`.

    Parameters
    ----------
    M : the horizon M (an integer; above the threshold where the result needs it).
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi_W : ᾱ_W >= α_lo, the constant of Appendix D: V_{W,M}(x) <= ᾱ_W σ(x) + γ̄_W max‖w‖².

    Returns
    -------
    float
        a_min.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> print(round(theory.min_decay_rate_W(6, 1.0, 2.0), 6))
    0.9
    """
    M = _M(M)
    alpha_lo, alpha_hi_W = _constants_W(alpha_lo, alpha_hi_W)
    if not _above(M, alpha_lo, alpha_hi_W):
        thr = (alpha_hi_W / alpha_lo) ** 2 + 1
        raise OrrcValueError(
            f"M={M} is not above the horizon threshold alpha_hi_W²/alpha_lo² + 1 = {thr:.6g} (alpha_lo={alpha_lo:.6g}, "
            f"alpha_hi_W={alpha_hi_W:.6g}); Theorem 3 needs M > threshold, i.e. M >= {math.floor(thr) + 1}")
    return _a_min(M, alpha_lo, alpha_hi_W)


@finite_result
def decay_b_W(alpha_lo, alpha_hi_W, gamma_bar_W) -> float:
    """b_W = γ̄_W (α_lo/ᾱ_W + 1), the input gain of the recursion V^{t+1}_{W,M} <= a V^t_{W,M} +
    b_W max‖w‖² in the proof of Theorem 3 (the statement writes γ̄ for γ̄_W; the proof uses γ̄_W).

    Parameters
    ----------
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi_W : ᾱ_W >= α_lo, the constant of Appendix D: V_{W,M}(x) <= ᾱ_W σ(x) + γ̄_W max‖w‖².
    gamma_bar_W : γ̄_W >= 0, the disturbance constant of Appendix D.

    Returns
    -------
    float
        b_W.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> theory.decay_b_W(1.0, 2.0, gamma_bar_W=1.0)
    1.5
    """
    alpha_lo, alpha_hi_W, gamma_bar_W = _constants_W(alpha_lo, alpha_hi_W, gamma_bar_W)
    return gamma_bar_W * (alpha_lo / alpha_hi_W + 1.0)


@finite_result
def gamma_c_W(M, a, alpha_lo, alpha_hi_W, gamma_bar_W) -> float:
    """γ_{c,W} = γ̄_W (α_lo/ᾱ_W + 1) / (1 - a)  (Theorem 3): b_W/(1 - a).

    The level of Theorem 3: Σ_{t<T} c_t - γ T max‖w‖² = O(1) for every γ >= γ_{c,W}. Raises when M
    is not above :func:`horizon_threshold_W` or a is outside [:func:`min_decay_rate_W`, 1).

    Parameters
    ----------
    M : the horizon M (an integer; above the threshold where the result needs it).
    a : the decay rate, in [the minimal decay rate, 1).
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi_W : ᾱ_W >= α_lo, the constant of Appendix D: V_{W,M}(x) <= ᾱ_W σ(x) + γ̄_W max‖w‖².
    gamma_bar_W : γ̄_W >= 0, the disturbance constant of Appendix D.

    Returns
    -------
    float
        γ_{c,W}.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> print(round(theory.gamma_c_W(6, 0.9, 1.0, 2.0, 1.0), 6))
    15.0
    """
    M, a, alpha_lo, alpha_hi_W, gamma_bar_W = _theorem3_setting(M, a, alpha_lo, alpha_hi_W, gamma_bar_W)
    return gamma_bar_W * (alpha_lo / alpha_hi_W + 1.0) / (1.0 - a)


@finite_result
def theorem3_constant(sigma0, T, M, a, alpha_lo, alpha_hi_W, gamma_bar_W, w_max_sq, gamma) -> float:
    """The O(1) of Theorem 3 made explicit: a C with

        Σ_{t=0}^{T-1} c_t(x_t, u_t) - γ T max_{w∈W} ‖w‖²  <=  C     for every γ >= γ_{c,W},

        C = (ᾱ_W σ(x_0) + γ̄_W w̄²) (1 - a^T)/(1 - a) - b_W w̄² (1 - a^T)/(1 - a)² + (γ_{c,W} - γ) T w̄²,

    with w̄² = max_{w∈W} ‖w‖² (``w_max_sq``) and b_W = :func:`decay_b_W`. Derivation (the proof of
    Theorem 3): Lemma 6 above the threshold and V <= ᾱ_W σ + γ̄_W w̄² give V^{t+1} <= a V^t + b_W w̄²,
    so V^t <= a^t V^0 + b_W w̄² (1 - a^t)/(1 - a); c_t <= V^t (the first stage cost of the min-max
    plan is paid whatever w_t is) and V^0 <= ᾱ_W σ(x_0) + γ̄_W w̄²; sum over t < T, using
    Σ_{t<T} (1 - a^t)/(1 - a) = T/(1 - a) - (1 - a^T)/(1 - a)² and b_W/(1 - a) = γ_{c,W}. The last
    term is <= 0 for γ >= γ_{c,W}, so C is bounded in T. The paper's last line, ᾱ_W σ(x_1)/(1 - a),
    drops the γ̄_W w̄² of V^0 (it uses V^t <= ᾱ_W σ only there); this C keeps it.

    Note that the guarantee charges T max‖w‖², the energy of the LARGEST possible disturbances,
    whatever the disturbances actually were. Raises when γ < γ_{c,W} (the theorem says nothing).

    Parameters
    ----------
    sigma0 : σ(x_0) >= 0.
    T : the number of steps.
    M : the horizon M (an integer; above the threshold where the result needs it).
    a : the decay rate, in [the minimal decay rate, 1).
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi_W : ᾱ_W >= α_lo, the constant of Appendix D: V_{W,M}(x) <= ᾱ_W σ(x) + γ̄_W max‖w‖².
    gamma_bar_W : γ̄_W >= 0, the disturbance constant of Appendix D.
    w_max_sq : max_{w∈W} ‖w‖².
    gamma : the attenuation level γ (at least the certified level).

    Returns
    -------
    float
        C.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> print(round(theory.theorem3_constant(1.0, T=10, M=6, a=0.9, alpha_lo=1.0,
    ...                                      alpha_hi_W=2.0, gamma_bar_W=1.0, w_max_sq=0.01,
    ...                                      gamma=20.0), 6))
    11.614581
    """
    M, a, alpha_lo, alpha_hi_W, gamma_bar_W = _theorem3_setting(M, a, alpha_lo, alpha_hi_W, gamma_bar_W)
    T = as_int("T", T, minimum=1)
    sigma0 = as_float("sigma0", sigma0, minimum=0.0)
    w_max_sq = as_float("w_max_sq", w_max_sq, minimum=0.0)
    gamma = as_float("gamma", gamma)
    b = gamma_bar_W * (alpha_lo / alpha_hi_W + 1.0)
    gc = b / (1.0 - a)
    if gamma < gc * (1.0 - 1e-12):
        raise OrrcValueError(
            f"Theorem 3 bounds Σc - gamma T max‖w‖² only for gamma >= gamma_c_W = {gc:.6g}; got gamma={gamma:.6g}")
    return float(_theorem3_constants(sigma0, np.array([float(T)]), a, alpha_hi_W, gamma_bar_W, w_max_sq, gamma, b)[0])


def _theorem3_constants(sigma0, Ts, a, alpha_hi_W, gamma_bar_W, w_max_sq, gamma, b):
    """:func:`theorem3_constant` for an array of horizons Ts (arguments already checked)."""
    gc = b / (1.0 - a)
    geo = (1.0 - a ** Ts) / (1.0 - a)
    return ((alpha_hi_W * sigma0 + gamma_bar_W * w_max_sq) * geo - b * w_max_sq * geo / (1.0 - a)
            + (gc - gamma) * Ts * w_max_sq)
