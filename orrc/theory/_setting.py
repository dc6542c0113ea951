"""The constants of Section 5.1 checked, and the formulas that the theory, the checks and the
certificates share (arguments already checked).

* the checks: α_lo and ᾱ positive with α_lo <= ᾱ (:func:`_alphas`), γ̄ > 0, M >= 2, M above the
  horizon threshold (:func:`_require_threshold`), a in [a_min, 1) (:func:`_decay`), and the
  disturbance energies ‖w_j‖² of a sequence (:func:`_energies`);
* the formulas, unvalidated: the threshold test (:func:`_above`), a_min, b and γ_c. They compute
  ratios first (ᾱ/α_lo), so that constants near the ends of the float range (α_lo = ᾱ = 1e-200)
  have the representable answers of their ratio.

:mod:`orrc.theory.known` (Lemmas 1-2, Theorem 1) and the later sections build on these; the
public functions are there.
"""
from __future__ import annotations

import math

import numpy as np

from .._validate import OrrcValueError, as_array, as_float, as_int

# relative slack allowed when a decay rate recomputed elsewhere equals min_decay_rate up to rounding
_A_RTOL = 1e-12


# -- validation ---------------------------------------------------------------------------------
def _alphas(alpha_lo, alpha_hi) -> tuple[float, float]:
    alpha_lo = as_float("alpha_lo", alpha_lo, minimum=0.0, strict_min=True)
    alpha_hi = as_float("alpha_hi", alpha_hi, minimum=0.0, strict_min=True)
    if alpha_lo > alpha_hi:
        raise OrrcValueError(
            f"alpha_lo must be <= alpha_hi (V_M(x, 0) >= c(x, u) >= alpha_lo σ(x) and V_M(x, 0) <= "
            f"alpha_hi σ(x) force it); got alpha_lo={alpha_lo}, alpha_hi={alpha_hi}")
    return alpha_lo, alpha_hi


def _gamma_bar(gamma_bar) -> float:
    return as_float("gamma_bar", gamma_bar, minimum=0.0, strict_min=True)


def _M(M) -> int:
    return as_int("M", M, minimum=2)


# -- the formulas, unvalidated (arguments already checked; used here and by orrc.certify) -------------
def _above(M: int, alpha_lo: float, alpha_hi: float) -> bool:
    """M > ᾱ²/α_lo² + 1, evaluated as (ᾱ/α_lo)² < M - 1 (the sign of Lemma 1's Γ_V)."""
    r = alpha_hi / alpha_lo      # the ratio first: α_lo = ᾱ = 1e-200 has representable answers
    return r * r < M - 1


def _a_min(M: int, alpha_lo: float, alpha_hi: float) -> float:
    """a_min = 1 - (α_lo - ᾱ²/((M-1) α_lo)) / ᾱ (Lemma 2; see :func:`min_decay_rate`)."""
    r = alpha_hi / alpha_lo
    return 1.0 - 1.0 / r + r / (M - 1)


def _b(alpha_lo: float, alpha_hi: float, gamma_bar: float) -> float:
    """b = γ̄ (α_lo/ᾱ + 1) (Lemma 2; see :func:`decay_b`)."""
    return gamma_bar * (alpha_lo / alpha_hi + 1.0)


def _gamma_c(M: int, a: float, b: float) -> float:
    """γ_c = b ((M-1)(1-a) + 1) / (1-a)² (Theorem 1; see :func:`gamma_c`), from b."""
    return b * ((M - 1) * (1.0 - a) + 1.0) / (1.0 - a) ** 2


def _require_threshold(M: int, alpha_lo: float, alpha_hi: float) -> None:
    if not _above(M, alpha_lo, alpha_hi):
        thr = (alpha_hi / alpha_lo) ** 2 + 1
        raise OrrcValueError(
            f"M={M} is not above the horizon threshold alpha_hi²/alpha_lo² + 1 = {thr:.6g} "
            f"(alpha_lo={alpha_lo:.6g}, alpha_hi={alpha_hi:.6g}); Lemma 2 and Theorem 1 need "
            f"M > threshold, i.e. M >= {math.floor(thr) + 1}")


def _decay(a, M: int, alpha_lo: float, alpha_hi: float) -> float:
    a = as_float("a", a)
    a_min = _a_min(M, alpha_lo, alpha_hi)
    if not (a >= a_min * (1.0 - _A_RTOL) and a < 1.0):
        raise OrrcValueError(
            f"a must lie in [min_decay_rate, 1) = [{a_min:.10g}, 1) for M={M}, alpha_lo={alpha_lo:.6g}, "
            f"alpha_hi={alpha_hi:.6g} (Lemma 2: 1 > a >= 1 - ε̃/alpha_hi); got a={a}")
    return a


def _lemma2_setting(M, a, alpha_lo, alpha_hi, gamma_bar):
    """The checked (M, a, α_lo, ᾱ, γ̄) of Lemma 2 / Theorem 1: M above the threshold, a admissible."""
    M = _M(M)
    alpha_lo, alpha_hi = _alphas(alpha_lo, alpha_hi)
    gamma_bar = _gamma_bar(gamma_bar)
    _require_threshold(M, alpha_lo, alpha_hi)
    return M, _decay(a, M, alpha_lo, alpha_hi), alpha_lo, alpha_hi, gamma_bar


def _energies(name: str, w) -> np.ndarray:
    """‖w_j‖² per row of a (L, n) array; a 1-D array is a scalar disturbance (n = 1)."""
    w = as_array(name, w)
    if w.ndim == 1:
        w = w[:, None]
    if w.ndim != 2:
        raise OrrcValueError(f"{name} must have shape (L, n) (or (L,) for n = 1); got shape {w.shape}")
    return np.einsum("ij,ij->i", w, w)
