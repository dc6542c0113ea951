"""The unknown-system theory of the paper (Section 5.2: Lemma 4, Lemma 5, Theorem 2) as pure functions.

The constants, beyond those of Section 5.1 (:mod:`orrc.theory.known`):

* ``alpha_V``, ``alpha_kappa`` (Lemma 3): |V_M(·; θ̂) - V_M(·; θ)| <= α_V ‖θ̂ - θ‖ and
  ‖κ_M(·; θ̂) - κ_M(·; θ)‖ <= α_κ ‖θ̂ - θ‖ (:mod:`orrc.certify.lipschitz` computes them);
* ``alpha_c``: the cost's Lipschitz constant (Assumption 2);
* ``alpha_f_S``: the Lipschitz constant α_f S of f in (x, u) over Θ (Assumption (v)-(vi):
  ‖f(x', u') - f(x, u)‖ <= α_f ‖θ‖ (‖x' - x‖ + ‖u' - u‖), ‖θ‖ <= S);
* ``theta_error``: ‖θ̂ - θ‖ (at most g(N) after N exciting steps).

Functions (the statement of the paper they implement):

* :func:`alpha_f_tilde` -- α̃_f = max_{0<=k<=M-2} (α_f S)^{k+1} (Lemma 4);
* :func:`Gamma_V_theta`, :func:`lemma4_bound` -- Γ^θ_V and the right-hand side of Lemma 4;
* :func:`lemma5_c`, :func:`lemma5_M_theta`, :func:`lemma5_bound` -- c, M_θ and the right-hand side of
  Lemma 5 (M_θ in the appendix's form c(1 - a^H)/(1 - a) + a^H α_V; the statement's
  "c(1 - a^H)(1 - a)" is a typo, and the statement's c lacks the α_κ of the appendix);
* :func:`theorem2_constant` -- the bound of Theorem 2 made explicit, with its three parts.

Indices are 0-based as in the rest of ``orrc``. Bad input raises :class:`~orrc.OrrcValueError`.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._validate import OrrcValueError, as_array, as_float, as_int, finite_result
from . import known
from ._lemma4 import Gamma_V_theta, _lipschitz_constants, _nonneg, alpha_f_tilde, lemma4_bound

__all__ = ["alpha_f_tilde", "Gamma_V_theta", "lemma4_bound", "lemma5_c", "lemma5_M_theta", "lemma5_bound",
           "theorem2_constant", "Theorem2Bound"]


def _eps_tilde(eps_tilde, M, a, alpha_lo, alpha_hi) -> float:
    """ε̃ of Lemma 5: default ᾱ(1 - a) (then a = 1 - ε̃/ᾱ, the proof's choice); else within
    [ᾱ(1 - a), α_lo - ᾱ²/((M-1)α_lo)]."""
    lo = alpha_hi * (1.0 - a)
    hi = alpha_lo * (1.0 - (alpha_hi / alpha_lo) ** 2 / (M - 1))
    if eps_tilde is None:
        return lo
    e = as_float("eps_tilde", eps_tilde)
    if not (lo * (1 - 1e-12) <= e <= hi * (1 + 1e-12)):
        raise OrrcValueError(f"eps_tilde must lie in [alpha_hi (1 - a), alpha_lo - alpha_hi²/((M-1) alpha_lo)] = "
                             f"[{lo:.6g}, {hi:.6g}] (Lemma 5: a >= 1 - eps_tilde/alpha_hi); got {e}")
    return e


@finite_result
def lemma5_c(M, a, alpha_lo, alpha_hi, alpha_V, alpha_kappa, alpha_c, alpha_tilde_f, eps_tilde=None) -> float:
    """c = α_V (2 + ε̃/ᾱ) + α_c α̃_f α_κ (M-1) ((α_lo - ε̃)/ᾱ + 1)  (Lemma 5; Appendix G).

    The θ-term of the recursion V^{t+1}_M <= a V^t_M + b Σ_{k=t}^{t+M-1} ‖w_k‖² + c ‖θ̂ - θ‖. The
    appendix's c carries α_κ (the statement omits it: a typo, the proof needs it). ``eps_tilde`` (ε̃)
    defaults to ᾱ(1 - a), which makes a = 1 - ε̃/ᾱ exactly; M above the threshold, a admissible.

    Parameters
    ----------
    M : the horizon M (an integer; above the threshold where the result needs it).
    a : the decay rate, in [the minimal decay rate, 1).
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi : ᾱ >= α_lo, with V_M(x, w) <= ᾱ σ(x) + γ̄ Σ‖w‖² (Lemma 1).
    alpha_V : α_V, the Lipschitz constant of V_M in θ (Lemma 3).
    alpha_kappa : α_κ, the Lipschitz constant of the control law in θ (Lemma 3).
    alpha_c : α_c, the Lipschitz constant of the cost in x.
    alpha_tilde_f : α̃_f (:func:`alpha_f_tilde`).
    eps_tilde : ε̃ (default ᾱ(1 - a)).

    Returns
    -------
    float
        c.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> print(round(theory.lemma5_c(6, 0.9, 1.0, 2.0, alpha_V=0.5, alpha_kappa=0.5,
    ...                             alpha_c=1.0, alpha_tilde_f=2.48832), 6))
    9.75912
    """
    M, a, alpha_lo, alpha_hi, _ = known._lemma2_setting(M, a, alpha_lo, alpha_hi, 1.0)
    aV, ak, ac, af = _lipschitz_constants(alpha_V, alpha_kappa, alpha_c, alpha_tilde_f)
    e = _eps_tilde(eps_tilde, M, a, alpha_lo, alpha_hi)
    return aV * (2.0 + e / alpha_hi) + ac * af * ak * (M - 1) * ((alpha_lo - e) / alpha_hi + 1.0)


@finite_result
def lemma5_M_theta(H, a, c, alpha_V) -> float:
    """M_θ = c (1 - a^H)/(1 - a) + a^H α_V  (Lemma 5, in the appendix's form; the statement's
    "c(1 - a^H)(1 - a)" is a typo): the coefficient of ‖θ̂ - θ‖ in the cost bound at t + H.

    Parameters
    ----------
    H : the look-ahead H >= M.
    a : the decay rate, in [the minimal decay rate, 1).
    c : the θ-gain c of Lemma 5 (:func:`lemma5_c`).
    alpha_V : α_V, the Lipschitz constant of V_M in θ (Lemma 3).

    Returns
    -------
    float
        M_θ.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> print(round(theory.lemma5_M_theta(H=10, a=0.9, c=9.75912, alpha_V=0.5), 4))
    63.7376
    """
    H = as_int("H", H, minimum=0)
    a = as_float("a", a, minimum=0.0, maximum=1.0, strict_min=True, strict_max=True)
    c = _nonneg("c", c)
    aV = _nonneg("alpha_V", alpha_V)
    return c * (1.0 - a ** H) / (1.0 - a) + a ** H * aV


@finite_result
def lemma5_bound(sigma_t, w_window, theta_error, M, H, a, alpha_lo, alpha_hi, gamma_bar, alpha_V, alpha_kappa,
                 alpha_c, alpha_tilde_f, eps_tilde=None) -> float:
    """The right-hand side of Lemma 5: Lemma 2's bound (:func:`orrc.theory.lemma2_bound`) + M_θ ‖θ̂ - θ‖,

        c_{t+H} <= ᾱ a^H σ(x_t) + Σ_{j=t}^{t_H+M-2} M_{w,j} ‖w_j‖² + M_θ ‖θ̂ - θ‖.

    Parameters
    ----------
    sigma_t : σ(x_t) >= 0.
    w_window : (H + M - 1, n) the disturbances w_t..w_{t+H+M-2}.
    theta_error : ‖θ̂ - θ‖ >= 0.
    M : the horizon M (an integer; above the threshold where the result needs it).
    H : the look-ahead H >= M.
    a : the decay rate, in [the minimal decay rate, 1).
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi : ᾱ >= α_lo, with V_M(x, w) <= ᾱ σ(x) + γ̄ Σ‖w‖² (Lemma 1).
    gamma_bar : γ̄ >= 0, the disturbance constant of Lemma 1.
    alpha_V : α_V, the Lipschitz constant of V_M in θ (Lemma 3).
    alpha_kappa : α_κ, the Lipschitz constant of the control law in θ (Lemma 3).
    alpha_c : α_c, the Lipschitz constant of the cost in x.
    alpha_tilde_f : α̃_f (:func:`alpha_f_tilde`).
    eps_tilde : ε̃ (default ᾱ(1 - a)).

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
    >>> print(round(theory.lemma5_bound(1.0, np.zeros((11, 2)), 0.01, 6, 6, 0.9, 1.0, 2.0,
    ...                                 1.0, 0.5, 0.5, 1.0, 2.48832), 6))
    1.522812
    """
    base = known.lemma2_bound(sigma_t, w_window, M, H, a, alpha_lo, alpha_hi, gamma_bar)
    c = lemma5_c(M, a, alpha_lo, alpha_hi, alpha_V, alpha_kappa, alpha_c, alpha_tilde_f, eps_tilde)
    return float(base + lemma5_M_theta(H, a, c, alpha_V) * _nonneg("theta_error", theta_error))


class Theorem2Bound(NamedTuple):
    """The bound of Theorem 2 in its three parts (their sum is ``total``; arrays for several T).

    Attributes
    ----------
    estimation : Σ_{t<N} (c_t - γ‖w_t‖²), the estimation phase (the O(N));
    known : Theorem 1's explicit constant for the control phase from x_N (the O(1));
    model_error : Σ_{H=0}^{T-N-1} M_θ(H) ‖θ̂ - θ‖ (the O((T - N + 1) g(N))).

    Examples
    --------
    >>> import numpy as np
    >>> from orrc import theory
    >>> bound = theory.theorem2_constant(np.ones(5), np.zeros((30, 2)), 1.0, 0.01, T=20,
    ...                                  N=5, M=6, a=0.9, alpha_lo=1.0, alpha_hi=2.0,
    ...                                  gamma_bar=1.0, gamma=250.0, alpha_V=0.5,
    ...                                  alpha_kappa=0.5, alpha_c=1.0,
    ...                                  alpha_tilde_f=2.48832)
    >>> bound.estimation
    5.0
    """

    estimation: float | np.ndarray
    known: float | np.ndarray
    model_error: float | np.ndarray

    @property
    def total(self):
        return self.estimation + self.known + self.model_error


@finite_result
def theorem2_constant(estimation_costs, w, sigma_N, theta_error, T, N, M, a, alpha_lo, alpha_hi, gamma_bar, gamma,
                      alpha_V, alpha_kappa, alpha_c, alpha_tilde_f, eps_tilde=None) -> Theorem2Bound:
    """The bound of Theorem 2 made explicit: R^p_T(γ) <= estimation + known + model_error, for γ >= γ_c.

    * estimation = Σ_{t<N} (c_t - γ‖w_t‖²) with the measured costs of the estimation phase (the paper
      bounds it by O(N) through BIBO stability; here it is the exact sum);
    * known = :func:`orrc.theory.theorem1_constant` for the T - N steps of the control phase, started at
      x_N (σ(x_N) = ``sigma_N``) with the disturbances w_N, w_{N+1}, ...;
    * model_error = ‖θ̂ - θ‖ Σ_{H=0}^{T-N-1} M_θ(H): every stage cost of the control phase is bounded by
      Lemma 5 (for H < M by the same recursion, which gives the same M_θ(H)), so the θ-terms add up.
      Σ_H M_θ(H) <= (T - N) c/(1 - a) + α_V/(1 - a): the O((T - N + 1) g(N)) of the theorem.

    ``estimation_costs`` (N,) c_0..c_{N-1}; ``w`` (L, n) all the disturbances w_0, w_1, ... with the
    preview tail (L >= T + M - 2); ``T`` > N, an integer or a 1-D array of horizons (then every part is
    an array, one entry per horizon: the bound for all T at once).

    Parameters
    ----------
    estimation_costs : (N,) the stage costs c_t measured in the estimation phase.
    w : (L, n) the disturbances w_0, w_1, ... (enough rows for the previewed ones).
    sigma_N : σ(x_N) >= 0, at the end of the estimation phase.
    theta_error : ‖θ̂ - θ‖ >= 0.
    T : the number of steps.
    N : the length of the estimation phase.
    M : the horizon M (an integer; above the threshold where the result needs it).
    a : the decay rate, in [the minimal decay rate, 1).
    alpha_lo : α_lo > 0, with c(x, u) >= α_lo σ(x) (Assumption 2).
    alpha_hi : ᾱ >= α_lo, with V_M(x, w) <= ᾱ σ(x) + γ̄ Σ‖w‖² (Lemma 1).
    gamma_bar : γ̄ >= 0, the disturbance constant of Lemma 1.
    gamma : the attenuation level γ (at least the certified level).
    alpha_V : α_V, the Lipschitz constant of V_M in θ (Lemma 3).
    alpha_kappa : α_κ, the Lipschitz constant of the control law in θ (Lemma 3).
    alpha_c : α_c, the Lipschitz constant of the cost in x.
    alpha_tilde_f : α̃_f (:func:`alpha_f_tilde`).
    eps_tilde : ε̃ (default ᾱ(1 - a)).

    Returns
    -------
    Theorem2Bound
        the three parts and their ``total``.

    Raises
    ------
    orrc.OrrcValueError
        When a constant is out of range (non-positive, α_lo > ᾱ, a outside its interval, M not
        above the threshold where the result needs it) or the result overflows.

    Examples
    --------
    >>> from orrc import theory
    >>> import numpy as np
    >>> bound = theory.theorem2_constant(np.ones(5), np.zeros((30, 2)), 1.0, 0.01, T=20,
    ...                                  N=5, M=6, a=0.9, alpha_lo=1.0, alpha_hi=2.0,
    ...                                  gamma_bar=1.0, gamma=250.0, alpha_V=0.5,
    ...                                  alpha_kappa=0.5, alpha_c=1.0,
    ...                                  alpha_tilde_f=2.48832)
    >>> print(round(bound.estimation, 4), round(bound.total, 4))
    5.0 27.8108
    """
    Ts = np.atleast_1d(np.asarray(T))
    if Ts.ndim != 1 or Ts.size == 0 or not np.issubdtype(Ts.dtype, np.integer):
        raise OrrcValueError(f"T must be an integer or a 1-D array of integers; got {T!r}")
    N = as_int("N", N, minimum=1)
    if Ts.min() <= N:
        raise OrrcValueError(f"Theorem 2 needs a control phase: N < T; got N={N}, T={int(Ts.min())}")
    T_max = int(Ts.max())
    M = known._M(M)
    ce = as_array("estimation_costs", estimation_costs)
    if ce.shape != (N,):
        raise OrrcValueError(f"estimation_costs must be N = {N} finite stage costs c_0..c_(N-1); got shape {ce.shape}")
    sigma_N = _nonneg("sigma_N", sigma_N)
    e = known._energies("w", w)
    if len(e) < max(T_max + M - 2, N + M):
        raise OrrcValueError(f"w must hold the disturbances w_0..w_(T+M-3) (with the preview tail); got {len(e)} rows")
    s = known._theorem1_setting(sigma_N, T_max - N, M, a, alpha_lo, alpha_hi, gamma_bar, gamma)
    est = float(ce.sum() - s.gamma * e[:N].sum())
    kn = known._theorem1_constants(s, e[N:], Ts - N)
    c = lemma5_c(s.M, s.a, s.alpha_lo, s.alpha_hi, alpha_V, alpha_kappa, alpha_c, alpha_tilde_f, eps_tilde)
    Hs = np.arange(T_max - N)
    Mt = np.cumsum(c * (1.0 - s.a ** Hs) / (1.0 - s.a) + s.a ** Hs * float(alpha_V))[Ts - N - 1]
    model = Mt * _nonneg("theta_error", theta_error)
    if np.ndim(T) == 0:
        return Theorem2Bound(est, float(kn[0]), float(model[0]))
    return Theorem2Bound(np.full(Ts.size, est), kn, model)
