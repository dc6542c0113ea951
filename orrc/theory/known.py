"""The known-system theory of the paper (Section 5.1: Lemma 1, Lemma 2, Theorem 1) as pure functions.

Every function here takes the paper's constants and returns a number (or an array
of coefficients); none of them knows about a system, a controller or a trajectory.
Computing the constants of a concrete problem is :mod:`orrc.certify`; checking the
inequalities along a simulated trajectory is :mod:`orrc.checks`.

The constants (Assumption 2 and the class of systems of Section 5.1):

* ``alpha_lo`` (α_lo, the paper's α underbar): c_t(x, u) >= α_lo σ(x);
* ``alpha_hi`` (ᾱ) and ``gamma_bar`` (γ̄): V_M(x, W) <= ᾱ σ(x) + γ̄ Σ_k ‖w_k‖² for all x, W;
* ``M``: the preview horizon (M >= 2 in Lemma 1, M > ᾱ²/α_lo² + 1 in Lemma 2 and Theorem 1);
* ``a`` (decay rate) and ``b`` = γ̄ (α_lo/ᾱ + 1) of Lemma 2.

Functions (the statement of the paper they implement):

* :func:`horizon_threshold` -- ᾱ²/α_lo² + 1; M must exceed it (Lemma 2, Theorem 1);
* :func:`min_decay_rate` -- the infimum of the admissible a (Lemma 2, Theorem 1);
* :func:`decay_b` -- b = γ̄(α_lo/ᾱ + 1) (Lemma 2);
* :func:`Gamma_V`, :func:`Gamma_V_gamma` -- Γ_V and Γ^γ_V of Lemma 1;
* :func:`lemma2_coefficients`, :func:`lemma2_bound` -- the M_{w,j} and the right-hand side of Lemma 2;
* :func:`gamma_c` -- γ_c of Theorem 1;
* :func:`theorem1_constant` -- the O(1) of Theorem 1, made explicit;
* :func:`gamma_tilde`, :func:`gamma_c_remark` -- the remark after Theorem 1.

Indices are 0-based as in the rest of ``orrc``: the paper's t = 1..T is t = 0..T-1.

Bad input (non-positive constants, α_lo > ᾱ, M not above the threshold where the
result needs it, a outside its admissible range) raises :class:`~orrc.OrrcValueError`,
a ``ValueError``, with a message naming the argument. So do finite arguments whose result
is not representable (a ZeroDivisionError or OverflowError in float arithmetic, an inf or NaN
result: e.g. alpha_lo = 1e-200 with alpha_hi = 1), with a message listing every argument
(``orrc._validate.finite_result``), and arguments whose result is too large to compute
(:func:`lemma2_coefficients` with H = 10**10: the estimate and the limit of ``orrc.config``).
"""
from __future__ import annotations

from .._validate import finite_result
from ._setting import (_A_RTOL, _M, _a_min, _above, _alphas, _b, _decay, _energies, _gamma_bar,  # noqa: F401
                       _gamma_c, _lemma2_setting, _require_threshold)
from ._lemma2 import decay_b, lemma2_bound, lemma2_coefficients, min_decay_rate
from ._theorem1 import (_Theorem1Setting, _theorem1_constants, _theorem1_setting,  # noqa: F401
                        gamma_c, gamma_c_remark, gamma_tilde, theorem1_constant)

__all__ = [
    "horizon_threshold", "above_threshold", "min_decay_rate", "decay_b", "Gamma_V", "Gamma_V_gamma",
    "lemma2_coefficients", "lemma2_bound", "gamma_c", "theorem1_constant", "gamma_tilde",
    "gamma_c_remark",
]

@finite_result
def above_threshold(M, alpha_lo, alpha_hi) -> bool:
    """True when M > ᾱ²/α_lo² + 1 (the horizon condition of Lemma 2 and Theorem 1).

    Evaluated as (ᾱ/α_lo)² < M - 1, the same comparison as Γ_V < 0 in Lemma 1.

    Parameters
    ----------
    M : the horizon M (an integer; above the threshold where the result needs it).
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi : ᾱ >= α_lo, with V_M(x, w) <= ᾱ σ(x) + γ̄ Σ‖w‖² (Lemma 1).

    Returns
    -------
    bool
        whether M > ᾱ²/α_lo² + 1.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> theory.above_threshold(6, alpha_lo=1.0, alpha_hi=2.0)
    True
    """
    M = _M(M)
    alpha_lo, alpha_hi = _alphas(alpha_lo, alpha_hi)
    return _above(M, alpha_lo, alpha_hi)


# -- Lemma 1 --------------------------------------------------------------------------------------
@finite_result
def horizon_threshold(alpha_lo, alpha_hi) -> float:
    """ᾱ²/α_lo² + 1: Lemma 2 and Theorem 1 hold for every integer M strictly above it.

    It is the M at which Lemma 1's Γ_V = ᾱ²/(α_lo(M-1)) - α_lo changes sign: above it
    V_M decreases along the closed loop when there is no disturbance.

    Parameters
    ----------
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi : ᾱ >= α_lo, with V_M(x, w) <= ᾱ σ(x) + γ̄ Σ‖w‖² (Lemma 1).

    Returns
    -------
    float
        ᾱ²/α_lo² + 1.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> theory.horizon_threshold(alpha_lo=1.0, alpha_hi=2.0)
    5.0
    """
    alpha_lo, alpha_hi = _alphas(alpha_lo, alpha_hi)
    return (alpha_hi / alpha_lo) ** 2 + 1.0


@finite_result
def Gamma_V(M, alpha_lo, alpha_hi) -> float:
    """Γ_V = ᾱ²/(α_lo (M-1)) - α_lo  (Lemma 1; Appendix A, last display).

    The coefficient of σ(x_t) in V^{t+1}_M - V^t_M <= Γ_V σ(x_t) + Γ^γ_V Σ_{k=t}^{t+M-1} ‖w_k‖².
    Negative exactly when M > ᾱ²/α_lo² + 1 (:func:`horizon_threshold`). Needs M >= 2.

    Parameters
    ----------
    M : the horizon M (an integer; above the threshold where the result needs it).
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi : ᾱ >= α_lo, with V_M(x, w) <= ᾱ σ(x) + γ̄ Σ‖w‖² (Lemma 1).

    Returns
    -------
    float
        Γ_V (negative above the threshold).

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> print(round(theory.Gamma_V(6, alpha_lo=1.0, alpha_hi=2.0), 6))
    -0.2
    """
    M = _M(M)
    alpha_lo, alpha_hi = _alphas(alpha_lo, alpha_hi)
    return alpha_lo * ((alpha_hi / alpha_lo) ** 2 / (M - 1) - 1.0)


@finite_result
def Gamma_V_gamma(M, alpha_lo, alpha_hi, gamma_bar) -> float:
    """Γ^γ_V = γ̄ (ᾱ/(α_lo (M-1)) + 1)  (Lemma 1; Appendix A, last display).

    The coefficient of the previewed disturbance energy Σ_{k=t}^{t+M-1} ‖w_k‖² in the
    increment bound of Lemma 1. Needs M >= 2.

    Parameters
    ----------
    M : the horizon M (an integer; above the threshold where the result needs it).
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi : ᾱ >= α_lo, with V_M(x, w) <= ᾱ σ(x) + γ̄ Σ‖w‖² (Lemma 1).
    gamma_bar : γ̄ >= 0, the disturbance constant of Lemma 1.

    Returns
    -------
    float
        Γ^γ_V.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> print(round(theory.Gamma_V_gamma(6, alpha_lo=1.0, alpha_hi=2.0, gamma_bar=1.0), 6))
    1.4
    """
    M = _M(M)
    alpha_lo, alpha_hi = _alphas(alpha_lo, alpha_hi)
    gamma_bar = _gamma_bar(gamma_bar)
    return gamma_bar * (alpha_hi / (alpha_lo * (M - 1)) + 1.0)
