"""Lemma 6 and Theorem 3 (no disturbance preview, Appendix D) checked step by step along a trajectory.

Each function takes a :class:`~orrc.Trajectory` of Algorithm 3 (:class:`~orrc.MinMaxRHC`: it
reports V^t_{W,M}(x_t) at every step in ``traj.values``), the disturbance set W and the
constants, and returns the margins ``bound - actual`` at every step (>= 0: the inequality
holds), as :mod:`orrc.checks.known` does for Section 5.1. The bounds involve the largest
disturbance energy max_{w∈W} ‖w‖² (``W.max_norm_sq``), not the realised one, and they assume
every realised w_t lies in W: the functions check that and refuse a trajectory whose
disturbances leave W.

``traj.values`` are the values the controller computed: exact (to the QP solver's accuracy)
for ``method="exact"``; for scenario exchange, the worst case over the disturbances its
search found (``traj.info["lower"]``, ``["upper"]`` bracket them within its tolerance).
"""
from __future__ import annotations

import numpy as np

from .. import theory
from .._validate import OrrcValueError, as_float, as_int
from ..theory.nopreview import _constants_W, _theorem3_constants, _theorem3_setting
from .known import Lemma1Margins, Margins, _valued_trajectory

__all__ = ["minmax_value_bound_margins", "lemma6_margins", "theorem3_margin"]


def _minmax_trajectory(traj, M, W):
    from ..solvers.minmax import check_set

    traj = _valued_trajectory(traj, "V_(W,M)", "Algorithm 3", "orrc.MinMaxRHC")
    M = as_int("M", M, minimum=2)
    if traj.preview_w != 0 or traj.preview_c != M:
        raise OrrcValueError(
            f"M={M} but the trajectory's controller previewed M_w={traj.preview_w} disturbances and M_c={traj.preview_c} "
            "costs; Lemma 6 and Theorem 3 are about Algorithm 3 (M_w = 0, M_c = M)")
    W = check_set(W, traj.x.shape[1])
    if not W.contains(traj.w, tol=1e-9 * max(1.0, np.sqrt(W.max_norm_sq))):
        raise OrrcValueError(f"the trajectory's disturbances leave W={W!r}: Lemma 6 and Theorem 3 assume w_t ∈ W")
    return traj, M, W


def minmax_value_bound_margins(traj, M, W, alpha_hi_W, gamma_bar_W) -> Margins:
    """The class condition of Appendix D at every step: margin_t = bound_t - V^t_{W,M}(x_t), t = 0..T-1,

        bound_t = ᾱ_W σ(x_t) + γ̄_W max_{w∈W} ‖w‖²   (the hypothesis of Lemma 6).

    Certified constants (:func:`orrc.certify.minmax_constants` for a linear-quadratic problem with a
    box) satisfy it for every x; sampled estimates can fail it, which shows they are too small.

    Parameters
    ----------
    traj : a :class:`~orrc.Trajectory` of Algorithm 3 (``MinMaxRHC``) that recorded V_{W,M}.
    M : the controller's horizon.
    W : the disturbance set the controller planned against.
    alpha_hi_W, gamma_bar_W : the constants ᾱ_W and γ̄_W to check.

    Returns
    -------
    Margins
        margins for t = 0..T-1.

    Raises
    ------
    orrc.OrrcValueError
        When the trajectory is not one of Algorithm 3 with its values recorded, has failed steps, or a
        constant is out of range.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> W = orrc.Box(-0.5, 0.5, n=1)
    >>> # certified α_lo, ᾱ_W, γ̄_W, a, γ_{c,W}
    >>> k = certify.minmax_constants(ex.system, ex.cost, 6, W)
    >>> w = orrc.disturbances.uniform_box(40, 1, -0.5, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, orrc.MinMaxRHC(ex.system, ex.cost, 6, W), ex.x0,
    ...                      w, 30)
    >>> checks.minmax_value_bound_margins(traj, 6, W, k.alpha_hi_W, k.gamma_bar_W).holds()
    True
    """
    traj, M, W = _minmax_trajectory(traj, M, W)
    alpha_hi_W = as_float("alpha_hi_W", alpha_hi_W, minimum=0.0, strict_min=True)
    gamma_bar_W = as_float("gamma_bar_W", gamma_bar_W, minimum=0.0, strict_min=True)
    T = traj.T
    bound = alpha_hi_W * traj.sigma[:T] + gamma_bar_W * W.max_norm_sq
    V = traj.values
    return Margins(np.arange(T), bound, V.copy(), bound - V,
                   "V_(W,M)(x_t) <= alpha_hi_W σ(x_t) + gamma_bar_W max‖w‖²")


def lemma6_margins(traj, M, W, alpha_lo, alpha_hi_W, gamma_bar_W) -> Lemma1Margins:
    """Lemma 6 at every step of a trajectory of Algorithm 3.

    * ``lower``: V^t_{W,M} - α_lo σ(x_t) for t = 0..T-1 (V_{W,M} >= α_lo σ);
    * ``increment``: [Γ_{W,V} σ(x_t) + Γ^γ_{W,V} max‖w‖²] - (V^{t+1}_{W,M} - V^t_{W,M}) for t = 0..T-2,
      with Γ_{W,V}, Γ^γ_{W,V} of :func:`orrc.theory.Gamma_WV` / ``Gamma_WV_gamma``.

    Returned as :class:`~orrc.checks.Lemma1Margins` (``Gamma_V``, ``Gamma_V_gamma`` hold Γ_{W,V}, Γ^γ_{W,V}).
    Lemma 6 holds for every M >= 2.

    Parameters
    ----------
    traj : a :class:`~orrc.Trajectory` of Algorithm 3 (``MinMaxRHC``) that recorded V_{W,M}.
    M : the controller's horizon.
    W : the disturbance set the controller planned against.
    alpha_lo, alpha_hi_W, gamma_bar_W : the constants α_lo, ᾱ_W, γ̄_W.

    Returns
    -------
    Lemma1Margins
        ``lower`` (T margins), ``increment`` (T - 1 margins), Γ_{W,V} and Γ^γ_{W,V}.

    Raises
    ------
    orrc.OrrcValueError
        When the trajectory is not one of Algorithm 3 with its values recorded, has failed steps, or a
        constant is out of range.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> W = orrc.Box(-0.5, 0.5, n=1)
    >>> # certified α_lo, ᾱ_W, γ̄_W, a, γ_{c,W}
    >>> k = certify.minmax_constants(ex.system, ex.cost, 6, W)
    >>> w = orrc.disturbances.uniform_box(40, 1, -0.5, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, orrc.MinMaxRHC(ex.system, ex.cost, 6, W), ex.x0,
    ...                      w, 30)
    >>> lemma6 = checks.lemma6_margins(traj, 6, W, k.alpha_lo, k.alpha_hi_W, k.gamma_bar_W)
    >>> lemma6.lower.holds(), lemma6.increment.holds()
    (True, True)
    """
    traj, M, W = _minmax_trajectory(traj, M, W)
    alpha_lo, alpha_hi_W, gamma_bar_W = _constants_W(alpha_lo, alpha_hi_W, gamma_bar_W)
    GV = theory.Gamma_WV(M, alpha_lo, alpha_hi_W)
    GVg = theory.Gamma_WV_gamma(M, alpha_lo, alpha_hi_W, gamma_bar_W)
    V, sig, T = traj.values, traj.sigma, traj.T
    lower_bound = alpha_lo * sig[:T]
    lower = Margins(np.arange(T), V.copy(), lower_bound, V - lower_bound, "V_(W,M)(x_t) >= alpha_lo σ(x_t)")
    inc_bound = GV * sig[:T - 1] + GVg * W.max_norm_sq
    inc_actual = V[1:] - V[:-1]
    increment = Margins(np.arange(T - 1), inc_bound, inc_actual, inc_bound - inc_actual,
                        "V_(W,M)(x_(t+1)) - V_(W,M)(x_t) <= Γ_(W,V) σ(x_t) + Γ^γ_(W,V) max‖w‖²")
    return Lemma1Margins(lower, increment, GV, GVg)


def theorem3_margin(traj, M, W, a, alpha_lo, alpha_hi_W, gamma_bar_W, gamma) -> Margins:
    """Theorem 3 along the trajectory: for every horizon T' = 1..T,

        margin_{T'} = C_{T'}(γ) - (Σ_{t<T'} c_t - γ T' max_{w∈W} ‖w‖²),

    with C the explicit constant of :func:`orrc.theory.theorem3_constant`. Needs M above the
    threshold, a admissible and γ >= γ_{c,W}. ``t`` holds T' and ``actual`` the running
    Σ c - γ T' max‖w‖² (the realised energy Σ‖w_t‖² does not enter).

    Parameters
    ----------
    traj : a :class:`~orrc.Trajectory` of Algorithm 3 (``MinMaxRHC``) that recorded V_{W,M}.
    M : the controller's horizon.
    W : the disturbance set the controller planned against.
    a : the decay rate, in [min_decay_rate_W, 1).
    alpha_lo, alpha_hi_W, gamma_bar_W : the constants α_lo, ᾱ_W, γ̄_W.
    gamma : the level, γ >= γ_{c,W}.

    Returns
    -------
    Margins
        margins for T' = 1..T.

    Raises
    ------
    orrc.OrrcValueError
        When the trajectory is not one of Algorithm 3 with its values recorded, has failed steps, or a
        constant is out of range.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> W = orrc.Box(-0.5, 0.5, n=1)
    >>> # certified α_lo, ᾱ_W, γ̄_W, a, γ_{c,W}
    >>> k = certify.minmax_constants(ex.system, ex.cost, 6, W)
    >>> w = orrc.disturbances.uniform_box(40, 1, -0.5, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, orrc.MinMaxRHC(ex.system, ex.cost, 6, W), ex.x0,
    ...                      w, 30)
    >>> theorem3 = checks.theorem3_margin(traj, 6, W, k.a, k.alpha_lo, k.alpha_hi_W,
    ...                                   k.gamma_bar_W, k.gamma_c_W)
    >>> theorem3.margin.shape, theorem3.holds()
    ((30,), True)
    """
    traj, M, W = _minmax_trajectory(traj, M, W)
    M, a, alpha_lo, alpha_hi_W, gamma_bar_W = _theorem3_setting(M, a, alpha_lo, alpha_hi_W, gamma_bar_W)
    gamma = as_float("gamma", gamma)
    # the checks of theory.theorem3_constant (gamma >= γ_c,W), for all T' at once
    theory.theorem3_constant(traj.sigma[0], traj.T, M, a, alpha_lo, alpha_hi_W, gamma_bar_W, W.max_norm_sq, gamma)
    b = theory.decay_b_W(alpha_lo, alpha_hi_W, gamma_bar_W)
    Ts = np.arange(1, traj.T + 1)
    C = _theorem3_constants(float(traj.sigma[0]), Ts.astype(float), a, alpha_hi_W, gamma_bar_W, W.max_norm_sq,
                            gamma, b)
    R = np.cumsum(traj.costs) - gamma * Ts * W.max_norm_sq
    return Margins(Ts, C, R, C - R, "Σ c_t - gamma T max‖w‖² <= C (Theorem 3, explicit O(1))")
