"""Lemma 4, Lemma 5 and Theorem 2 (unknown system, Section 5.2) checked step by step along a trajectory.

Each function takes a :class:`~orrc.Trajectory` of Algorithm 2 (:class:`~orrc.EstimateThenControl`:
its ``traj.info`` holds the estimation-phase length N, the values V_M(x_t; θ̂) of the control phase
and, when the controller was given ``theta_true`` for reporting, the error ‖θ̂ - θ‖) and the
constants, and returns the :class:`~orrc.checks.Margins` ``bound - actual`` at every step of the
control phase (t >= N): >= 0 means the inequality holds there.

The constants must be valid for the problem simulated: α_lo, ᾱ, γ̄ of the TRUE system's value
function (the class condition of Section 5.1), and Lemma 3's α_V, α_κ with α_c and α̃_f on the region
visited (:mod:`orrc.certify.lipschitz`).
"""
from __future__ import annotations

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from .. import theory
from .._validate import OrrcValueError, as_float, as_int
from ..metrics import attenuation_regret
from ..theory import unknown as th_unknown
from .known import Margins, _window_energy

__all__ = ["lemma4_margins", "lemma5_margins", "theorem2_margin"]


def _algorithm2(traj, M, theta_error):
    from ..simulate import Trajectory

    if not isinstance(traj, Trajectory):
        raise OrrcValueError(f"traj must be an orrc Trajectory (from orrc.simulate); got {type(traj).__name__}")
    info = traj.info
    if "values" not in info or "N" not in info or "phase" not in info:
        raise OrrcValueError(f"the trajectory is not one of Algorithm 2 (controller {traj.controller!r}): simulate "
                             "orrc.EstimateThenControl, which records its phases and V_M(x_t; θ̂)")
    M = as_int("M", M, minimum=2)
    if traj.preview_w != M:
        raise OrrcValueError(f"M={M} but the trajectory's controller previewed M_w={traj.preview_w} disturbances")
    N = int(info["N"])
    if N >= traj.T - 1:
        raise OrrcValueError(f"the trajectory has no control phase to check (N = {N}, T = {traj.T})")
    if theta_error is None:
        theta_error = info.get("theta_error")
        if theta_error is None:
            raise OrrcValueError("theta_error is needed: pass it, or run EstimateThenControl with theta_true=... "
                                 "so that the trajectory records ‖θ̂ - θ‖")
    theta_error = as_float("theta_error", theta_error, minimum=0.0)
    values = np.asarray(info["values"], dtype=float)
    if not np.all(np.isfinite(values[N:])):
        raise OrrcValueError("the control phase has no V_M value at every step (the controller reported none)")
    e = np.einsum("ij,ij->i", traj.w_all, traj.w_all)
    return traj, M, N, theta_error, values, e


def lemma4_margins(traj, M, alpha_lo, alpha_hi, gamma_bar, alpha_V, alpha_kappa, alpha_c, alpha_tilde_f,
                   theta_error=None) -> Margins:
    """Lemma 4 at every step t = N..T-2 of the control phase:

        margin_t = [Γ_V σ(x_t) + Γ^γ_V Σ_{k=t}^{t+M-1} ‖w_k‖² + Γ^θ_V ‖θ̂ - θ‖] - (V^{t+1}_M(·; θ̂) - V^t_M(·; θ̂)),

    with Γ_V, Γ^γ_V of Lemma 1 and Γ^θ_V of :func:`orrc.theory.Gamma_V_theta`. ``theta_error``:
    ‖θ̂ - θ‖ (default: the one the trajectory recorded).

    Parameters
    ----------
    traj : a :class:`~orrc.Trajectory` of Algorithm 2 (``EstimateThenControl``) that recorded V_M.
    M : the horizon of the control phase.
    alpha_lo, alpha_hi, gamma_bar : the constants α_lo, ᾱ, γ̄ of the true problem.
    alpha_V, alpha_kappa, alpha_c, alpha_tilde_f : the Lipschitz constants of Lemmas 3 and 4.
    theta_error : ‖θ̂ - θ‖ (default: the one the trajectory recorded).

    Returns
    -------
    Margins
        margins for t = N..T-2.

    Raises
    ------
    orrc.OrrcValueError
        When the trajectory is not one of Algorithm 2 with V_M recorded, has failed steps, or a
        constant is out of range.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks, theory
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)   # α_lo, ᾱ, γ̄, a, γ_c
    >>> # α_V, α_κ, α_c, α_f S
    >>> L = certify.lq_lipschitz(ex.system, ex.cost, M=8, radius=0.05, rho=5.0)
    >>> at = theory.alpha_f_tilde(L.alpha_f_S, 8)
    >>> etc = orrc.EstimateThenControl(orrc.ParametricSystem.linear(1, 1), ex.cost, M=8,
    ...                                N=5, theta_true=[1.2, 1.0])
    >>> w = orrc.disturbances.uniform_ball(60, 1, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, etc, ex.x0, w, 50)
    >>> lemma4 = checks.lemma4_margins(traj, 8, k.alpha_lo, k.alpha_hi, k.gamma_bar,
    ...                                L.alpha_V, L.alpha_kappa, L.alpha_c, at)
    >>> lemma4.margin.shape, lemma4.holds()
    ((44,), True)
    """
    traj, M, N, err, V, e = _algorithm2(traj, M, theta_error)
    GV = theory.Gamma_V(M, alpha_lo, alpha_hi)
    GVg = theory.Gamma_V_gamma(M, alpha_lo, alpha_hi, gamma_bar)
    GVt = th_unknown.Gamma_V_theta(M, alpha_lo, alpha_hi, alpha_V, alpha_kappa, alpha_c, alpha_tilde_f)
    T = traj.T
    t = np.arange(N, T - 1)
    S = _window_energy(e, M, T - 1)[N:]
    bound = GV * traj.sigma[N:T - 1] + GVg * S + GVt * err
    actual = V[N + 1:T] - V[N:T - 1]
    return Margins(t, bound, actual, bound - actual,
                   "V_M(x_{t+1}; θ̂) - V_M(x_t; θ̂) <= Γ_V σ + Γ^γ_V Σ‖w‖² + Γ^θ_V ‖θ̂ - θ‖ (Lemma 4)")


def lemma5_margins(traj, M, H, a, alpha_lo, alpha_hi, gamma_bar, alpha_V, alpha_kappa, alpha_c, alpha_tilde_f,
                   theta_error=None, eps_tilde=None) -> Margins:
    """Lemma 5 at every anchor t = N..T-1-H of the control phase: margin_t = bound_t - c_{t+H},

        bound_t = ᾱ a^H σ(x_t) + Σ_{j=t}^{t+H+M-2} M_{w,j} ‖w_j‖² + M_θ ‖θ̂ - θ‖   (:func:`orrc.theory.lemma5_bound`).

    Parameters
    ----------
    traj : a :class:`~orrc.Trajectory` of Algorithm 2 (``EstimateThenControl``) that recorded V_M.
    M : the horizon of the control phase.
    H : the look-ahead, M <= H.
    a : the decay rate, in [min_decay_rate, 1).
    alpha_lo, alpha_hi, gamma_bar : the constants α_lo, ᾱ, γ̄ of the true problem.
    alpha_V, alpha_kappa, alpha_c, alpha_tilde_f : the Lipschitz constants of Lemmas 3 and 4.
    theta_error : ‖θ̂ - θ‖ (default: the one the trajectory recorded).
    eps_tilde : ε̃ (default ᾱ(1 - a)).

    Returns
    -------
    Margins
        margins for the anchors t = N..T-1-H.

    Raises
    ------
    orrc.OrrcValueError
        When the trajectory is not one of Algorithm 2 with V_M recorded, has failed steps, or a
        constant is out of range.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks, theory
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)   # α_lo, ᾱ, γ̄, a, γ_c
    >>> # α_V, α_κ, α_c, α_f S
    >>> L = certify.lq_lipschitz(ex.system, ex.cost, M=8, radius=0.05, rho=5.0)
    >>> at = theory.alpha_f_tilde(L.alpha_f_S, 8)
    >>> etc = orrc.EstimateThenControl(orrc.ParametricSystem.linear(1, 1), ex.cost, M=8,
    ...                                N=5, theta_true=[1.2, 1.0])
    >>> w = orrc.disturbances.uniform_ball(60, 1, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, etc, ex.x0, w, 50)
    >>> lemma5 = checks.lemma5_margins(traj, 8, 8, k.a, k.alpha_lo, k.alpha_hi, k.gamma_bar,
    ...                                L.alpha_V, L.alpha_kappa, L.alpha_c, at)
    >>> lemma5.margin.shape, lemma5.holds()
    ((37,), True)
    """
    traj, M, N, err, _, e = _algorithm2(traj, M, theta_error)
    H = as_int("H", H, minimum=1)
    T = traj.T
    if N + H >= T:
        raise OrrcValueError(f"H must be < T - N = {T - N} (c_(t+H) must lie in the control phase); got H={H}")
    M, a, alpha_lo, alpha_hi, gamma_bar = theory.known._lemma2_setting(M, a, alpha_lo, alpha_hi, gamma_bar)
    if H < M:
        raise OrrcValueError(f"Lemma 5 needs H >= M; got H={H}, M={M}")
    b = theory.known._b(alpha_lo, alpha_hi, gamma_bar)
    coef = theory.lemma2_coefficients(M, H, a, alpha_hi, gamma_bar, b)
    c = th_unknown.lemma5_c(M, a, alpha_lo, alpha_hi, alpha_V, alpha_kappa, alpha_c, alpha_tilde_f, eps_tilde)
    Mt = th_unknown.lemma5_M_theta(H, a, c, alpha_V)
    count = T - H - N
    windows = sliding_window_view(e, H + M - 1)[N:N + count]
    bound = alpha_hi * a ** H * traj.sigma[N:N + count] + windows @ coef + Mt * err
    actual = traj.costs[N + H:N + H + count]
    return Margins(np.arange(N, N + count), bound, actual, bound - actual,
                   f"c_(t+H) <= alpha_hi a^H σ(x_t) + Σ M_(w,j) ‖w_j‖² + M_θ ‖θ̂ - θ‖ (Lemma 5, H={H})")


def theorem2_margin(traj, M, a, alpha_lo, alpha_hi, gamma_bar, gamma, alpha_V, alpha_kappa, alpha_c, alpha_tilde_f,
                    theta_error=None, eps_tilde=None) -> Margins:
    """Theorem 2 along the trajectory: for every horizon T' = N+1..T,

        margin_{T'} = C_{T'} - R^p_{T'}(γ),   C_{T'} = estimation + known(T' - N) + model_error(T' - N)

    (:func:`orrc.theory.theorem2_constant`, computed for all T' at once). ``t`` holds T', ``actual`` the
    running R^p_{T'}(γ). Needs γ >= γ_c.

    Parameters
    ----------
    traj : a :class:`~orrc.Trajectory` of Algorithm 2 (``EstimateThenControl``) that recorded V_M.
    M : the horizon of the control phase.
    a : the decay rate, in [min_decay_rate, 1).
    gamma : the level, γ >= γ_c.
    alpha_lo, alpha_hi, gamma_bar : the constants α_lo, ᾱ, γ̄ of the true problem.
    alpha_V, alpha_kappa, alpha_c, alpha_tilde_f : the Lipschitz constants of Lemmas 3 and 4.
    theta_error : ‖θ̂ - θ‖ (default: the one the trajectory recorded).
    eps_tilde : ε̃ (default ᾱ(1 - a)).

    Returns
    -------
    Margins
        margins for T' = N+1..T.

    Raises
    ------
    orrc.OrrcValueError
        When the trajectory is not one of Algorithm 2 with V_M recorded, has failed steps, or a
        constant is out of range.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks, theory
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)   # α_lo, ᾱ, γ̄, a, γ_c
    >>> # α_V, α_κ, α_c, α_f S
    >>> L = certify.lq_lipschitz(ex.system, ex.cost, M=8, radius=0.05, rho=5.0)
    >>> at = theory.alpha_f_tilde(L.alpha_f_S, 8)
    >>> etc = orrc.EstimateThenControl(orrc.ParametricSystem.linear(1, 1), ex.cost, M=8,
    ...                                N=5, theta_true=[1.2, 1.0])
    >>> w = orrc.disturbances.uniform_ball(60, 1, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, etc, ex.x0, w, 50)
    >>> theorem2 = checks.theorem2_margin(traj, 8, k.a, k.alpha_lo, k.alpha_hi, k.gamma_bar,
    ...                                   k.gamma_c, L.alpha_V, L.alpha_kappa,
    ...                                   L.alpha_c, at)
    >>> theorem2.margin.shape, theorem2.holds()
    ((45,), True)
    """
    traj, M, N, err, _, e = _algorithm2(traj, M, theta_error)
    T = traj.T
    Ts = np.arange(N + 1, T + 1)
    C = th_unknown.theorem2_constant(traj.costs[:N], traj.w_all, traj.sigma[N], err, Ts, N, M, a, alpha_lo,
                                     alpha_hi, gamma_bar, gamma, alpha_V, alpha_kappa, alpha_c, alpha_tilde_f,
                                     eps_tilde).total
    R = attenuation_regret(traj, float(gamma), cumulative=True)[N:]
    return Margins(Ts, C, R, C - R, "R^p_T(gamma) <= O(N) + O(1) + O((T - N + 1) g(N)) (Theorem 2, explicit)")
