"""Lemma 4 of the paper (Section 5.2): α̃_f, Γ^θ_V and the right-hand side of the lemma, with the
checks of the Lipschitz constants that Lemma 5 and Theorem 2 share. Re-exported by
:mod:`orrc.theory.unknown`.
"""
from __future__ import annotations

from .._validate import as_float, as_int, finite_result
from . import known


def _nonneg(name, value) -> float:
    return as_float(name, value, minimum=0.0)


def _lipschitz_constants(alpha_V, alpha_kappa, alpha_c, alpha_tilde_f):
    return (_nonneg("alpha_V", alpha_V), _nonneg("alpha_kappa", alpha_kappa), _nonneg("alpha_c", alpha_c),
            _nonneg("alpha_tilde_f", alpha_tilde_f))


@finite_result
def alpha_f_tilde(alpha_f_S, M) -> float:
    """α̃_f = max_{0<=k<=M-2} (α_f S)^{k+1}  (Lemma 4; Appendix F): max(α_f S, (α_f S)^{M-1}).

    It bounds how a one-step deviation of the state grows along the M - 1 remaining steps of a plan.
    Needs M >= 2 (Lemma 4 is stated for M >= 2).

    Parameters
    ----------
    alpha_f_S : α_f S, the growth of a one-step deviation (Lemma 4).
    M : the horizon M (an integer; above the threshold where the result needs it).

    Returns
    -------
    float
        α̃_f.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> print(round(theory.alpha_f_tilde(1.2, M=6), 6))
    2.48832
    """
    L = _nonneg("alpha_f_S", alpha_f_S)
    M = as_int("M", M, minimum=2)
    return max(L, L ** (M - 1))


@finite_result
def Gamma_V_theta(M, alpha_lo, alpha_hi, alpha_V, alpha_kappa, alpha_c, alpha_tilde_f) -> float:
    """Γ^θ_V = 2 α_V + α_c α̃_f α_κ (M-1) (ᾱ/(α_lo (M-1)) + 1)  (Lemma 4; Appendix F, last display).

    The coefficient of ‖θ̂ - θ‖ in the increment bound of Lemma 4: 2α_V for moving between V(·; θ̂) and
    V(·; θ) at t and t+1, and the second term for the state the wrong input κ(x; θ̂) actually reaches.

    Parameters
    ----------
    M : the horizon M (an integer; above the threshold where the result needs it).
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi : ᾱ >= α_lo, with V_M(x, w) <= ᾱ σ(x) + γ̄ Σ‖w‖² (Lemma 1).
    alpha_V : α_V, the Lipschitz constant of V_M in θ (Lemma 3).
    alpha_kappa : α_κ, the Lipschitz constant of the control law in θ (Lemma 3).
    alpha_c : α_c, the Lipschitz constant of the cost in x.
    alpha_tilde_f : α̃_f (:func:`alpha_f_tilde`).

    Returns
    -------
    float
        Γ^θ_V.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> print(round(theory.Gamma_V_theta(6, 1.0, 2.0, alpha_V=0.5, alpha_kappa=0.5,
    ...                                  alpha_c=1.0, alpha_tilde_f=2.48832), 6))
    9.70912
    """
    M = as_int("M", M, minimum=2)
    alpha_lo, alpha_hi = known._alphas(alpha_lo, alpha_hi)
    aV, ak, ac, af = _lipschitz_constants(alpha_V, alpha_kappa, alpha_c, alpha_tilde_f)
    return 2.0 * aV + ac * af * ak * (M - 1) * (alpha_hi / (alpha_lo * (M - 1)) + 1.0)


@finite_result
def lemma4_bound(sigma_t, w_energy, theta_error, M, alpha_lo, alpha_hi, gamma_bar, alpha_V, alpha_kappa, alpha_c,
                 alpha_tilde_f) -> float:
    """The right-hand side of Lemma 4 at one step:

        V^{t+1}_M(·; θ̂) - V^t_M(·; θ̂) <= Γ_V σ(x_t) + Γ^γ_V Σ_{k=t}^{t+M-1} ‖w_k‖² + Γ^θ_V ‖θ̂ - θ‖

    (Γ_V, Γ^γ_V of Lemma 1, :func:`orrc.theory.Gamma_V`). ``w_energy`` is the previewed energy
    Σ_{k=t}^{t+M-1} ‖w_k‖²; ``theta_error`` = ‖θ̂ - θ‖.

    Parameters
    ----------
    sigma_t : σ(x_t) >= 0.
    w_energy : Σ_{k=t}^{t+M-1} ‖w_k‖², the previewed energy.
    theta_error : ‖θ̂ - θ‖ >= 0.
    M : the horizon M (an integer; above the threshold where the result needs it).
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi : ᾱ >= α_lo, with V_M(x, w) <= ᾱ σ(x) + γ̄ Σ‖w‖² (Lemma 1).
    gamma_bar : γ̄ >= 0, the disturbance constant of Lemma 1.
    alpha_V : α_V, the Lipschitz constant of V_M in θ (Lemma 3).
    alpha_kappa : α_κ, the Lipschitz constant of the control law in θ (Lemma 3).
    alpha_c : α_c, the Lipschitz constant of the cost in x.
    alpha_tilde_f : α̃_f (:func:`alpha_f_tilde`).

    Returns
    -------
    float
        the bound on V^{t+1}_M - V^t_M.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> print(round(theory.lemma4_bound(1.0, 0.1, 0.01, 6, 1.0, 2.0, 1.0, alpha_V=0.5,
    ...                                 alpha_kappa=0.5, alpha_c=1.0,
    ...                                 alpha_tilde_f=2.48832), 6))
    0.037091
    """
    sigma_t = _nonneg("sigma_t", sigma_t)
    w_energy = _nonneg("w_energy", w_energy)
    err = _nonneg("theta_error", theta_error)
    GV = known.Gamma_V(M, alpha_lo, alpha_hi)
    GVg = known.Gamma_V_gamma(M, alpha_lo, alpha_hi, gamma_bar)
    GVt = Gamma_V_theta(M, alpha_lo, alpha_hi, alpha_V, alpha_kappa, alpha_c, alpha_tilde_f)
    return float(GV * sigma_t + GVg * w_energy + GVt * err)
