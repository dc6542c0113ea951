"""The formulas of the paper's Section 5.2 and Appendices F-G written out once more for the tests,
independently of orrc (as tests/paper.py does for Section 5.1), in the readings of paper-summary.md:
M_θ in the appendix's form, c with the appendix's α_κ."""


def alpha_f_tilde(alpha_f, S, M):
    """α̃_f = max_{0<=k<=M-2} α_f^{k+1} S^{k+1} (Lemma 4), term by term."""
    return max((alpha_f * S) ** (k + 1) for k in range(M - 1))


def Gamma_V_theta(M, alpha_lo, alpha_hi, alpha_V, alpha_kappa, alpha_c, alpha_tilde_f):
    """Γ^θ_V = 2α_V + α_c α̃_f α_κ (M-1)(ᾱ/(α_lo(M-1)) + 1) (Lemma 4)."""
    return 2 * alpha_V + alpha_c * alpha_tilde_f * alpha_kappa * (M - 1) * (alpha_hi / (alpha_lo * (M - 1)) + 1)


def c(alpha_V, alpha_kappa, alpha_c, alpha_tilde_f, M, alpha_lo, alpha_hi, eps_tilde):
    """Appendix G: c = α_V(2 + ε̃/ᾱ) + α_c α̃_f α_κ (M-1)((α_lo - ε̃)/ᾱ + 1)."""
    return (alpha_V * (2 + eps_tilde / alpha_hi)
            + alpha_c * alpha_tilde_f * alpha_kappa * (M - 1) * ((alpha_lo - eps_tilde) / alpha_hi + 1))


def M_theta(H, a, c_, alpha_V):
    """Appendix G, last display: c (1 - a^H)/(1 - a) + a^H α_V, written as the geometric sum it is."""
    return c_ * sum(a ** k for k in range(H)) + a ** H * alpha_V
