"""orrc.theory against the paper's formulas (Section 5.1), written out again here.

Each test states a claim of the paper (or of its proof) and checks it on random
constants; the formulas below are transcribed independently from the paper (often in
the rearranged form the proof uses), so a transcription slip in orrc.theory shows up.
"""
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import orrc
from orrc import theory
import paper

SETTINGS = settings(max_examples=60, deadline=None, derandomize=True)


@st.composite
def constants(draw, above=True, max_M=None):
    """(M, alpha_lo, alpha_hi, gamma_bar); M above the horizon threshold when ``above``,
    and at most ``max_M`` when given."""
    alpha_lo = draw(st.floats(1e-3, 1e3))
    ratio = draw(st.floats(1.0, 20.0))
    alpha_hi = alpha_lo * ratio
    gamma_bar = draw(st.floats(1e-3, 1e3))
    thr = ratio ** 2 + 1
    if above:
        M = math.floor(thr) + 1 + draw(st.integers(0, 60))
        if max_M is not None:
            M = min(M, max_M)
        # above the threshold by more than rounding (the cap may undo it): at ᾱ² = α_lo²(M - 1)
        # exactly, ε̃ = 0 and a_min = 1, and ᾱ² and α_lo²(M - 1) are each off by a few eps, so a
        # ratio ≈ √(M - 1) passes the bare test by luck. With the relative margin 1e-9,
        # ε̃ >= 1e-9·α_lo and 1 - a_min = ε̃/ᾱ >= 1e-9/20, so 1 - a >= 1e-3·(1 - a_min) ≫ eps
        assume(alpha_hi ** 2 < alpha_lo ** 2 * (M - 1) * (1 - 1e-9))
    else:
        M = draw(st.integers(2, 500))
    return M, alpha_lo, alpha_hi, gamma_bar


@st.composite
def with_decay(draw, max_M=None):
    """constants (M <= ``max_M`` when given) plus an admissible a in [a_min, 1)."""
    M, lo, hi, gb = draw(constants(max_M=max_M))
    eps_max = lo - hi ** 2 / ((M - 1) * lo)            # the ε̃ bound of Lemma 2
    a_min = 1 - eps_max / hi
    s = draw(st.floats(0.0, 0.999))
    return M, lo, hi, gb, a_min + s * (1 - a_min)


# -- the closed-form constants -------------------------------------------------------------------
@SETTINGS
@given(constants(above=False))
def test_lemma1_constants_are_the_papers(c):
    M, lo, hi, gb = c
    assert theory.Gamma_V(M, lo, hi) == pytest.approx(hi * hi / (lo * (M - 1)) - lo, rel=1e-12, abs=1e-12 * hi)
    assert theory.Gamma_V_gamma(M, lo, hi, gb) == pytest.approx(gb * (hi / (lo * (M - 1)) + 1), rel=1e-12)
    assert theory.horizon_threshold(lo, hi) == pytest.approx((hi / lo) ** 2 + 1, rel=1e-12)
    assert theory.decay_b(lo, hi, gb) == pytest.approx(gb * (lo / hi + 1), rel=1e-12)


@SETTINGS
@given(constants(above=False))
def test_Gamma_V_is_negative_exactly_above_the_threshold(c):
    M, lo, hi, _ = c
    thr = (hi / lo) ** 2 + 1
    assume(abs(M - thr) > 1e-9 * thr)
    assert (theory.Gamma_V(M, lo, hi) < 0) == (M > thr)
    assert theory.above_threshold(M, lo, hi) == (M > thr)


@SETTINGS
@given(constants())
def test_min_decay_rate_is_one_minus_eps_over_alpha_hi(c):
    """Lemma 2: a >= 1 - ε̃/ᾱ with ε̃ < α_lo - ᾱ²/((M-1)α_lo); the infimum, in (0, 1)."""
    M, lo, hi, _ = c
    a_min = theory.min_decay_rate(M, lo, hi)
    eps = lo - hi ** 2 / ((M - 1) * lo)
    assert a_min == pytest.approx(1 - eps / hi, rel=1e-12)
    assert 0 < a_min < 1
    # the two facts Appendix B draws from ε̃ <= -Γ_V: Γ_V <= -ε̃ and Γ^γ_V <= γ̄((α_lo-ε̃)/ᾱ + 1)
    assert theory.Gamma_V(M, lo, hi) <= -eps * (1 - 1e-12) + 1e-15
    assert theory.Gamma_V_gamma(M, lo, hi, 1.0) <= ((lo - eps) / hi + 1) * (1 + 1e-12)


@SETTINGS
@given(with_decay())
def test_gamma_c_is_the_theorems_formula(c):
    M, lo, hi, gb, a = c
    b = gb * (lo / hi + 1)
    # Appendix C collects b/(1-a)² (decayed terms) and b(M-1)/(1-a) (the window terms)
    expected = b / (1 - a) ** 2 + b * (M - 1) / (1 - a)
    assert theory.gamma_c(M, a, lo, hi, gb) == pytest.approx(expected, rel=1e-10)


@SETTINGS
@given(with_decay(), st.floats(0.0, 1.0))
def test_gamma_c_decreases_as_a_decreases(c, s):
    M, lo, hi, gb, a = c
    a_min = theory.min_decay_rate(M, lo, hi)
    a_smaller = a_min + s * (a - a_min)
    assume(a - a_smaller > 1e-9 * a)
    assert theory.gamma_c(M, a_smaller, lo, hi, gb) < theory.gamma_c(M, a, lo, hi, gb)


@SETTINGS
@given(with_decay())
def test_gamma_c_is_above_twice_gamma_bar(c):
    """The remark after Theorem 1: the RHC approach cannot beat 2γ̄."""
    M, lo, hi, gb, a = c
    assert theory.gamma_c(M, a, lo, hi, gb) >= 2 * gb


@SETTINGS
@given(st.floats(1e-2, 1e2), st.floats(1.0, 10.0), st.floats(1e-2, 1e2))
def test_remark_gamma_tilde_and_its_gamma_c(lo, ratio, gb):
    """γ̃ = 1/(1 - a_min) at M = ⌈ᾱ²/α_lo²⌉ + 1; there γ_c = b(Nγ̃ + γ̃²) <= the remark's value."""
    hi = lo * ratio
    kappa = hi ** 2 / lo ** 2
    N = math.ceil(kappa)
    assume(N - kappa > 1e-6)  # at an integer ratio γ̃ is undefined (tested below)
    gt = theory.gamma_tilde(lo, hi)
    assert gt == pytest.approx(N * lo / (hi * (lo ** 2 / hi ** 2 * N - 1)), rel=1e-12)
    a_min = theory.min_decay_rate(N + 1, lo, hi)
    assert gt == pytest.approx(1 / (1 - a_min), rel=1e-8)
    b = theory.decay_b(lo, hi, gb)
    gc = theory.gamma_c(N + 1, a_min, lo, hi, gb)
    assert gc == pytest.approx(b * (N * gt + gt * gt), rel=1e-8)
    remark = theory.gamma_c_remark(lo, hi, gb)
    assert remark == pytest.approx(2 * (1 + lo / hi) * (gt * kappa + gt * gt) * gb, rel=1e-12)
    assert 2 * gb <= gc <= remark * (1 + 1e-12)


# -- Lemma 2 -------------------------------------------------------------------------------------
def exact_window_coefficients(M, H, a, b, gamma_bar):
    """Coefficient of ‖w_{t+k}‖² in a^H V^t + Σ_{i<H} a^{H-1-i} b S_{t+i}, V^t <= ᾱσ + γ̄ Σ_{k<M} (brute force)."""
    out = np.zeros(H + M - 1)
    for i in range(H):
        for k in range(i, i + M):
            out[k] += b * a ** (H - 1 - i)
    out[:M] += a ** H * gamma_bar
    return out


@SETTINGS
@given(with_decay(max_M=40), st.integers(0, 30))
def test_lemma2_coefficients_are_the_papers_and_bound_the_recursion(c, extra):
    M, lo, hi, gb, a = c
    H = M + extra
    b = theory.decay_b(lo, hi, gb)
    coef = theory.lemma2_coefficients(M, H, a, hi, gb, b)
    assert coef.shape == (H + M - 1,)
    np.testing.assert_allclose(coef, paper.lemma2_coefficients(M, H, a, gb, b), rtol=1e-12)
    # the paper's coefficients upper-bound the exact unrolled recursion (Appendix B)
    assert np.all(coef >= exact_window_coefficients(M, H, a, b, gb) * (1 - 1e-12))


@SETTINGS
@given(with_decay(max_M=30), st.integers(0, 20), st.integers(0, 2 ** 32 - 1))
def test_lemma2_bound_dominates_the_extremal_recursion(c, extra, seed):
    """Run V^{t+1} = a V^t + b S_t with equality from V^t = ᾱσ + γ̄Σ: c_{t+H} <= V^{t+H} <= the bound."""
    M, lo, hi, gb, a = c
    H = M + extra
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 4))
    w = rng.standard_normal((H + M - 1, n)) * rng.uniform(0, 2)
    e = np.sum(w * w, axis=1)
    sigma = float(rng.uniform(0, 5))
    b = theory.decay_b(lo, hi, gb)
    V = hi * sigma + gb * e[:M].sum()
    for i in range(H):
        V = a * V + b * e[i:i + M].sum()
    bound = theory.lemma2_bound(sigma, w, M, H, a, lo, hi, gb)
    assert V <= bound * (1 + 1e-10) + 1e-12
    # and the σ term is the statement's M_λ e^{-λH} = ᾱ a^H (not the appendix's a^H ᾱ a^H)
    assert theory.lemma2_bound(1.0, np.zeros((H + M - 1, n)), M, H, a, lo, hi, gb) == pytest.approx(hi * a ** H)


# -- Theorem 1 -----------------------------------------------------------------------------------
@SETTINGS
@given(with_decay(max_M=25), st.integers(1, 120), st.floats(1.0, 3.0), st.integers(0, 2 ** 32 - 1))
def test_theorem1_constant_bounds_the_extremal_recursion(c, T, factor, seed):
    """Costs c_H = V^H along the extremal recursion (the worst case the proof allows):
    Σ_{H<T} c_H - γ Σ_{t<T} ‖w_t‖² <= C for every γ >= γ_c."""
    M, lo, hi, gb, a = c
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 3))
    w = rng.standard_normal((T + M, n)) * rng.uniform(0, 2, (T + M, 1))
    e = np.sum(w * w, axis=1)
    sigma0 = float(rng.uniform(0, 5))
    b = theory.decay_b(lo, hi, gb)
    gamma = factor * theory.gamma_c(M, a, lo, hi, gb)
    V = hi * sigma0 + gb * e[:M].sum()
    total = 0.0
    for t in range(T):
        total += V
        V = a * V + b * e[t:t + M].sum()
    R = total - gamma * e[:T].sum()
    C = theory.theorem1_constant(sigma0, w, T, M, a, lo, hi, gb, gamma)
    assert R <= C + 1e-9 * (abs(C) + total + gamma * e[:T].sum())


def test_theorem1_constant_is_bounded_in_T():
    """For γ >= γ_c, C depends on σ(x_0), the first M and the last M-2 disturbances only."""
    M, lo, hi, gb = 6, 1.0, 2.0, 0.5
    a = theory.min_decay_rate(M, lo, hi)
    gamma = theory.gamma_c(M, a, lo, hi, gb)
    w = np.ones((2000, 1))
    Cs = [theory.theorem1_constant(1.0, w, T, M, a, lo, hi, gb, gamma) for T in (10, 100, 1000, 1500)]
    limit = hi / (1 - a) + gb / (1 - a) * M + theory.decay_b(lo, hi, gb) * (M - 1) / (1 - a) * (M - 2)
    assert all(C <= limit * (1 + 1e-12) for C in Cs)
    assert Cs[3] == pytest.approx(Cs[2], rel=1e-12) and Cs[2] == pytest.approx(limit, rel=1e-12)


# -- error cases ---------------------------------------------------------------------------------
def test_gamma_c_errors_name_the_argument():
    M, lo, hi, gb = 10, 1.0, 2.0, 1.0
    a = theory.min_decay_rate(M, lo, hi)
    with pytest.raises(ValueError, match="threshold"):
        theory.gamma_c(5, 0.99, lo, hi, gb)         # threshold = 5, M must exceed it
    with pytest.raises(ValueError, match="a must lie"):
        theory.gamma_c(M, a * 0.99, lo, hi, gb)
    with pytest.raises(ValueError, match="a must lie"):
        theory.gamma_c(M, 1.0, lo, hi, gb)
    with pytest.raises(ValueError, match="a must lie"):
        theory.gamma_c(M, 1.5, lo, hi, gb)
    for bad in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="alpha_lo"):
            theory.gamma_c(M, a, bad, hi, gb)
        with pytest.raises(ValueError, match="gamma_bar"):
            theory.gamma_c(M, a, lo, hi, bad)
    with pytest.raises(ValueError, match="alpha_hi"):
        theory.gamma_c(M, a, lo, -2.0, gb)
    with pytest.raises(ValueError, match="alpha_lo must be <= alpha_hi"):
        theory.gamma_c(M, a, 3.0, hi, gb)
    with pytest.raises(ValueError, match="M must be an integer"):
        theory.gamma_c(10.0, a, lo, hi, gb)
    with pytest.raises(ValueError, match="M must be an integer"):
        theory.gamma_c(True, a, lo, hi, gb)
    assert isinstance(theory.gamma_c(np.int64(M), np.float64(a), lo, hi, gb), float)
    assert issubclass(orrc.OrrcValueError, ValueError)


def test_other_errors():
    with pytest.raises(ValueError, match="threshold"):
        theory.min_decay_rate(3, 1.0, 2.0)
    with pytest.raises(ValueError, match="M must be an integer >= 2"):
        theory.Gamma_V(1, 1.0, 2.0)
    with pytest.raises(ValueError, match="H >= M"):
        theory.lemma2_coefficients(5, 4, 0.5, 1.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="a must be"):
        theory.lemma2_coefficients(5, 5, 1.0, 1.0, 1.0, 1.0)
    M, lo, hi, gb = 10, 1.0, 2.0, 1.0
    a = theory.min_decay_rate(M, lo, hi)
    with pytest.raises(ValueError, match="H \\+ M - 1"):
        theory.lemma2_bound(1.0, np.zeros((M + M, 2)), M, M, a, lo, hi, gb)
    with pytest.raises(ValueError, match="H >= M"):
        theory.lemma2_bound(1.0, np.zeros((M + M - 2, 2)), M, M - 1, a, lo, hi, gb)
    with pytest.raises(ValueError, match="sigma_t"):
        theory.lemma2_bound(-1.0, np.zeros((2 * M - 1, 2)), M, M, a, lo, hi, gb)
    with pytest.raises(ValueError, match="finite"):
        theory.lemma2_bound(1.0, np.full((2 * M - 1, 2), np.nan), M, M, a, lo, hi, gb)
    gc = theory.gamma_c(M, a, lo, hi, gb)
    with pytest.raises(ValueError, match="gamma >= gamma_c"):
        theory.theorem1_constant(1.0, np.zeros((50, 1)), 20, M, a, lo, hi, gb, 0.9 * gc)
    with pytest.raises(ValueError, match="w_all"):
        theory.theorem1_constant(1.0, np.zeros((20, 1)), 20, M, a, lo, hi, gb, gc)
    with pytest.raises(ValueError, match="integer"):
        theory.gamma_tilde(1.0, 2.0)          # ᾱ²/α_lo² = 4 exactly
    with pytest.raises(ValueError, match="integer"):
        theory.gamma_c_remark(1.0, 1.0, 1.0)
