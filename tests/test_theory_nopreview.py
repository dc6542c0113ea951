"""orrc.theory.nopreview against Appendix D of the paper (Lemma 6, Theorem 3).

The formulas are compared with tests/paper.py (transcribed without orrc) on random constants,
and the explicit constant of Theorem 3 against the recursion of its proof, run as a sequence:
the bound holds, is bounded in T for γ >= γ_{c,W}, and is attained when every step of the proof
is tight.
"""
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from orrc import theory
import paper

SETTINGS = settings(max_examples=60, deadline=None, derandomize=True)


@st.composite
def constants_W(draw, above=True):
    """(M, alpha_lo, alpha_hi_W, gamma_bar_W), M above ᾱ_W²/α_lo² + 1 when ``above``."""
    alpha_lo = draw(st.floats(1e-3, 1e3))
    ratio = draw(st.floats(1.0, 20.0))
    alpha_hi_W = alpha_lo * ratio
    gamma_bar_W = draw(st.floats(1e-3, 1e4))
    if above:
        M = math.floor(ratio ** 2 + 1) + 1 + draw(st.integers(0, 60))
        assume(alpha_hi_W ** 2 < alpha_lo ** 2 * (M - 1))
    else:
        M = draw(st.integers(2, 500))
    return M, alpha_lo, alpha_hi_W, gamma_bar_W


@st.composite
def with_decay_W(draw):
    M, lo, hi, gb = draw(constants_W())
    a_min = paper.a_min(M, lo, hi)                      # Theorem 3's a_min has Lemma 2's form with ᾱ_W
    return M, lo, hi, gb, a_min + draw(st.floats(0.0, 0.999)) * (1 - a_min)


@SETTINGS
@given(constants_W(above=False))
def test_lemma6_constants_are_the_papers(c):
    M, lo, hi, gb = c
    assert theory.Gamma_WV(M, lo, hi) == pytest.approx(paper.Gamma_WV(M, lo, hi), rel=1e-12, abs=1e-12 * hi)
    assert theory.Gamma_WV_gamma(M, lo, hi, gb) == pytest.approx(paper.Gamma_WV_gamma(M, lo, hi, gb), rel=1e-12)
    assert theory.horizon_threshold_W(lo, hi) == pytest.approx((hi / lo) ** 2 + 1, rel=1e-12)
    assert theory.decay_b_W(lo, hi, gb) == pytest.approx(paper.b(lo, hi, gb), rel=1e-12)


@SETTINGS
@given(constants_W(above=False))
def test_Gamma_WV_is_negative_exactly_above_the_threshold(c):
    M, lo, hi, gb = c
    assume(abs(hi * hi - lo * lo * (M - 1)) > 1e-9 * hi * hi)   # not on the boundary
    assert (theory.Gamma_WV(M, lo, hi) < 0) == (M > theory.horizon_threshold_W(lo, hi))


@SETTINGS
@given(with_decay_W())
def test_gamma_c_W_is_theorem3s_and_grows_as_a_approaches_one(c):
    M, lo, hi, gb, a = c
    gc = theory.gamma_c_W(M, a, lo, hi, gb)
    assert gc == pytest.approx(paper.gamma_c_W(a, lo, hi, gb), rel=1e-12)
    assert gc == pytest.approx(theory.decay_b_W(lo, hi, gb) / (1 - a), rel=1e-12)
    assert theory.min_decay_rate_W(M, lo, hi) == pytest.approx(paper.a_min(M, lo, hi), rel=1e-12, abs=1e-15)
    a2 = 0.5 * (a + 1)
    assert theory.gamma_c_W(M, a2, lo, hi, gb) > gc
    # γ_{c,W} = b_W/(1 - a) >= b_W = γ̄_W (α_lo/ᾱ_W + 1)
    assert gc >= gb * (lo / hi + 1) * (1 - 1e-12)


def _proof_recursion(T, a, alpha_hi_W, gamma_bar_W, alpha_lo, w2, sigma0):
    """The largest costs the proof of Theorem 3 allows: V^0 = ᾱ_W σ0 + γ̄_W w̄², V^{t+1} = a V^t + b_W w̄², c_t = V^t."""
    b = gamma_bar_W * (alpha_lo / alpha_hi_W + 1)
    V = np.empty(T)
    V[0] = alpha_hi_W * sigma0 + gamma_bar_W * w2
    for t in range(1, T):
        V[t] = a * V[t - 1] + b * w2
    return V


@SETTINGS
@given(with_decay_W(), st.integers(1, 400), st.floats(0.0, 10.0), st.floats(1e-4, 10.0), st.floats(1.0, 3.0))
def test_theorem3_constant_bounds_the_proofs_worst_costs_and_is_attained(c, T, sigma0, w2, factor):
    M, lo, hi, gb, a = c
    gc = theory.gamma_c_W(M, a, lo, hi, gb)
    costs = _proof_recursion(T, a, hi, gb, lo, w2, sigma0)
    for gamma in (gc, factor * gc):
        C = theory.theorem3_constant(sigma0, T, M, a, lo, hi, gb, w2, gamma)
        R = costs.sum() - gamma * T * w2
        assert R <= C + 1e-9 * (abs(C) + costs.sum() + gamma * T * w2)
        assert R == pytest.approx(C, rel=1e-7, abs=1e-9 * (costs.sum() + gamma * T * w2))   # every step tight


@SETTINGS
@given(with_decay_W(), st.floats(0.0, 10.0), st.floats(1e-4, 10.0))
def test_theorem3_constant_is_bounded_in_T_at_gamma_c_W(c, sigma0, w2):
    M, lo, hi, gb, a = c
    gc = theory.gamma_c_W(M, a, lo, hi, gb)
    Cs = [theory.theorem3_constant(sigma0, T, M, a, lo, hi, gb, w2, gc) for T in (1, 10, 100, 10_000, 10 ** 6)]
    limit = (hi * sigma0 + gb * w2) / (1 - a)        # the limit of the first term; the others are <= 0
    assert max(Cs) <= limit * (1 + 1e-9)


def test_theorem3_needs_gamma_at_least_gamma_c_W_and_M_above_the_threshold():
    gc = theory.gamma_c_W(10, 0.9, 1.0, 2.0, 3.0)
    with pytest.raises(ValueError, match="gamma_c_W"):
        theory.theorem3_constant(1.0, 10, 10, 0.9, 1.0, 2.0, 3.0, 0.25, 0.99 * gc)
    with pytest.raises(ValueError, match="Theorem 3 needs M > threshold"):
        theory.gamma_c_W(5, 0.9, 1.0, 2.0, 3.0)
    with pytest.raises(ValueError, match="min_decay_rate_W"):
        theory.gamma_c_W(10, 0.5, 1.0, 2.0, 3.0)
