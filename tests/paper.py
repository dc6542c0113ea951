"""The paper's formulas written out once more for the tests, independently of orrc.

Transcribed from Section 5.1 of Muthirayan and Khargonekar (2021) and Eq. (2), without
importing orrc, so that the tests compare orrc against the paper and not against itself.
(tests/test_theory.py also checks orrc.theory against rearranged forms of these, as the
proofs write them.)
"""
import numpy as np


def a_min(M, alpha_lo, alpha_hi):
    """The smallest admissible decay rate of Lemma 2: 1 - (α_lo - ᾱ²/((M-1)α_lo)) / ᾱ."""
    return 1 - (alpha_lo - alpha_hi ** 2 / ((M - 1) * alpha_lo)) / alpha_hi


def b(alpha_lo, alpha_hi, gamma_bar):
    """Lemma 2's b = γ̄ (α_lo/ᾱ + 1)."""
    return gamma_bar * (alpha_lo / alpha_hi + 1)


def gamma_c(M, a, alpha_lo, alpha_hi, gamma_bar):
    """Theorem 1's γ_c = b ((M-1)(1-a) + 1) / (1-a)²."""
    return b(alpha_lo, alpha_hi, gamma_bar) * ((M - 1) * (1 - a) + 1) / (1 - a) ** 2


def lemma2_coefficients(M, H, a, gamma_bar, b):
    """M_{w,j} of Lemma 2 case by case, for j - t = 0..H+M-2."""
    out = []
    for k in range(H + M - 1):          # k = j - t
        if k <= M - 1:
            out.append(b * a ** (H - M) / (1 - a) + a ** H * gamma_bar)
        elif k <= H - 1:
            out.append(b / (1 - a) * a ** (H - k - 1))
        else:
            out.append(b / (1 - a))
    return np.array(out)


def running_regret(costs, w, gamma):
    """R^p_t(γ) = Σ_{s<t} c_s - γ Σ_{s<t} ‖w_s‖² (Eq. 2) for t = 1..T, with w of T rows."""
    return np.cumsum(costs) - gamma * np.cumsum(np.sum(np.asarray(w) ** 2, axis=1))


# -- Appendix D (no disturbance preview) ----------------------------------------------------------
def Gamma_WV(M, alpha_lo, alpha_hi_W):
    """Lemma 6: Γ_{W,V} = ᾱ_W²/((M-1)α_lo) - α_lo."""
    return alpha_hi_W ** 2 / ((M - 1) * alpha_lo) - alpha_lo


def Gamma_WV_gamma(M, alpha_lo, alpha_hi_W, gamma_bar_W):
    """Lemma 6: Γ^γ_{W,V} = γ̄_W (ᾱ_W/((M-1)α_lo) + 1)."""
    return gamma_bar_W * (alpha_hi_W / ((M - 1) * alpha_lo) + 1)


def gamma_c_W(a, alpha_lo, alpha_hi_W, gamma_bar_W):
    """Theorem 3: γ_{c,W} = γ̄_W/(1-a) (α_lo/ᾱ_W + 1)."""
    return gamma_bar_W / (1 - a) * (alpha_lo / alpha_hi_W + 1)
