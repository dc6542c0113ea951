"""Lemma 1, Lemma 2 and Theorem 1 (known system, Section 5.1) checked step by step along a trajectory.

Each function takes a :class:`~orrc.Trajectory` of Algorithm 1 (``PreviewRHC``: it
reports V_M at every step in ``traj.values``) and the paper's constants, and returns
the margins ``bound - actual`` of the inequality at every step: a margin >= 0 means the
inequality holds there. Use ``result.holds()`` to test all steps up to rounding.

A trajectory with failed solves (``traj.success`` not all True) or overflowed values is
refused with an :class:`~orrc.OrrcValueError`: its V_M at those steps is not Algorithm 1's optimal
value (``Trajectory.values`` holds NaN there), so the lemmas say nothing about it.

Indices are 0-based (t = 0..T-1 for the paper's t = 1..T). The increment of V_M at
step t involves the previewed window w_t..w_{t+M-1}, which ``traj.w_all`` holds (it
includes the preview tail past T, as the controller saw it).

The constants must be valid for the problem that was simulated: σ(x) = ``traj.sigma``,
c_t >= alpha_lo σ(x), V_M(x, W) <= alpha_hi σ(x) + gamma_bar Σ‖w_k‖² (for instance from
:func:`orrc.certify.lq_constants`), and the time-invariant cost used by the controller.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from .. import theory
from .._validate import OrrcValueError, as_float, as_int, check_size
from ..metrics import attenuation_regret

__all__ = ["Margins", "value_bound_margins", "lemma1_margins", "lemma2_margins", "theorem1_margin"]


@dataclass
class Margins:
    """Step-by-step margins of one inequality of the paper.

    Attributes
    ----------
    t : the step index of each margin (the meaning is given by ``what``).
    bound, actual : the two sides; margin = bound - actual (>= 0: the inequality holds).
    what : which inequality, in words.
    scale : the size of the terms the two sides are sums of, at every step (Σ of their absolute
        values: for the increment |V^{t+1}| + |V^t| + |Γ_V| σ + Γ^γ_V Σ‖w‖², for Theorem 1
        C + Σ c_t + γ Σ‖w_t‖²). Rounding errors are relative to these terms, not to their
        difference, which may cancel to nearly zero. None: |bound| + |actual| (the sides are
        sums of non-negative terms).

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)    # certified α_lo, ᾱ, γ̄, a, γ_c
    >>> w = orrc.disturbances.uniform_ball(60, 1, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 8), ex.x0,
    ...                      w, 50)
    >>> m = checks.value_bound_margins(traj, 8, k.alpha_hi, k.gamma_bar)
    >>> m.margin.shape, m.holds()
    ((50,), True)
    """

    t: np.ndarray
    bound: np.ndarray
    actual: np.ndarray
    margin: np.ndarray
    what: str
    scale: np.ndarray | None = None

    def _slack(self, rtol: float, atol: float) -> np.ndarray:
        """The allowance rtol·scale + atol at every step."""
        rtol, atol = as_float("rtol", rtol, minimum=0.0), as_float("atol", atol, minimum=0.0)
        scale = np.abs(self.bound) + np.abs(self.actual) if self.scale is None else self.scale
        return rtol * scale + atol

    def holds(self, rtol: float = 1e-9, atol: float = 0.0) -> bool:
        """All margins >= -(rtol·scale + atol): the inequality holds up to rounding.

        The default rtol = 1e-9 (about 4.5·10⁶ eps) allows the relative error of V_M: on the LQ
        path it is rounding in the M-step Riccati solution and the quadratic form zᵀHz (a few
        hundred eps for the well-conditioned problems of the book), on the NLP path IPOPT's
        tolerance (1e-9, :mod:`orrc.solvers.nlp`); the sums over T steps add T·eps each, covered
        for T up to ~10⁶. The allowance is relative to ``scale``, so a problem and the same
        problem in other units (all costs times s) pass or fail alike; an absolute ``atol``
        (default 0) would hide real violations of problems whose costs are small.

        A NaN margin does not hold (and is not listed by :meth:`violations`, which lists the
        steps that fail beyond rounding), hence not ``violations(...).size == 0``.
        """
        return bool(np.all(self.margin >= -self._slack(rtol, atol)))

    def violations(self, rtol: float = 1e-9, atol: float = 0.0) -> np.ndarray:
        """The steps t where the inequality fails beyond rounding."""
        return self.t[self.margin < -self._slack(rtol, atol)]

    def __len__(self):
        return len(self.margin)

    def __repr__(self):
        m = float(self.margin.min()) if len(self.margin) else float("nan")
        return f"Margins({self.what}: {len(self.margin)} steps, smallest margin {m:.4g})"


@dataclass
class Lemma1Margins:
    """Both parts of Lemma 1: ``lower`` (V^t_M >= α_lo σ(x_t)) and ``increment``
    (V^{t+1}_M - V^t_M <= Γ_V σ(x_t) + Γ^γ_V Σ_{k=t}^{t+M-1} ‖w_k‖²), with Γ_V, Γ^γ_V.

    Attributes
    ----------
    lower, increment : the :class:`Margins` of the two claims.
    Gamma_V, Gamma_V_gamma : the coefficients Γ_V and Γ^γ_V.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)    # certified α_lo, ᾱ, γ̄, a, γ_c
    >>> w = orrc.disturbances.uniform_ball(60, 1, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 8), ex.x0,
    ...                      w, 50)
    >>> lemma1 = checks.lemma1_margins(traj, 8, k.alpha_lo, k.alpha_hi, k.gamma_bar)
    >>> lemma1.lower.holds(), lemma1.increment.holds(), bool(lemma1.Gamma_V < 0)
    (True, True, True)
    """

    lower: Margins
    increment: Margins
    Gamma_V: float
    Gamma_V_gamma: float

    def holds(self, rtol: float = 1e-9, atol: float = 0.0) -> bool:
        return self.lower.holds(rtol, atol) and self.increment.holds(rtol, atol)


def _valued_trajectory(traj, value: str, algorithm: str, controller: str):
    """``traj`` when it is a :class:`~orrc.Trajectory` whose every step holds ``value`` (e.g. "V_M")
    as the optimum of a successful solve, with finite costs and σ; else an error saying why (the
    lemmas are about ``algorithm``'s optimal values, which ``controller`` reports)."""
    from ..simulate import Trajectory

    if not isinstance(traj, Trajectory):
        raise OrrcValueError(f"traj must be an orrc Trajectory (from orrc.simulate); got {type(traj).__name__}")
    if traj.values is None:
        raise OrrcValueError(
            f"the trajectory has no {value} values (controller {traj.controller!r}); simulate {algorithm} "
            f"({controller}), which reports {value} at every step")
    if traj.n_failures or (traj.value_valid is not None and not traj.value_valid.all()):
        bad = np.flatnonzero(~traj.success) if traj.n_failures else np.flatnonzero(~traj.value_valid)
        raise OrrcValueError(
            f"traj has {bad.size} steps without a valid {value} (t = {bad[:8].tolist()}{'...' if bad.size > 8 else ''}: "
            f"{'the solve failed there' if traj.n_failures else 'the value is not finite'}; see Trajectory.success "
            f"and value_valid): the lemmas are about {algorithm}'s optimal values, which these steps do not have. "
            "Re-run with solver options that converge (e.g. a larger ipopt.max_iter)")
    if not (np.all(np.isfinite(traj.costs)) and np.all(np.isfinite(traj.sigma))):
        raise OrrcValueError("traj has non-finite stage costs or σ (the run overflowed; see the NonFiniteWarning "
                             "of orrc.simulate): the inequalities cannot be checked")
    return traj


def _trajectory(traj, M):
    traj = _valued_trajectory(traj, "V_M", "Algorithm 1", "orrc.PreviewRHC")
    M = as_int("M", M, minimum=2)
    if traj.preview_w < traj.preview_c:
        raise OrrcValueError(
            f"the trajectory's controller planned over M_c = {traj.preview_c} steps but saw only "
            f"M_w = {traj.preview_w} future disturbances (PreviewRHC(..., preview_w={traj.preview_w})): "
            "Lemma 1, Lemma 2 and Theorem 1 are about Algorithm 1, which sees the whole window "
            "(preview_w = M)")
    if traj.preview_w != M:
        raise OrrcValueError(
            f"M={M} but the trajectory's controller previewed M_w={traj.preview_w} disturbances; the "
            "lemmas are about the controller's own horizon")
    e = np.einsum("ij,ij->i", traj.w_all, traj.w_all)
    if len(e) < traj.T + M - 1:
        raise OrrcValueError(f"traj.w_all has {len(e)} rows; expected at least T + M - 1 = {traj.T + M - 1}")
    return traj, M, e


def _window_energy(e: np.ndarray, M: int, count: int) -> np.ndarray:
    """S_t = Σ_{k=t}^{t+M-1} ‖w_k‖² for t = 0..count-1."""
    cs = np.concatenate([[0.0], np.cumsum(e)])
    t = np.arange(count)
    return cs[t + M] - cs[t]


def value_bound_margins(traj, M, alpha_hi, gamma_bar) -> Margins:
    """The class condition of Section 5.1 at every step: margin_t = bound_t - V^t_M for t = 0..T-1,

        bound_t = ᾱ σ(x_t) + γ̄ Σ_{k=t}^{t+M-1} ‖w_k‖²   (the hypothesis of Lemma 1).

    Certified constants (:func:`orrc.certify.lq_constants`) satisfy it for every x and W;
    sampled estimates (:func:`orrc.certify.sampled_constants`) are lower bounds on the true
    constants, and a negative margin here shows that an estimate is too small.

    Parameters
    ----------
    traj : a :class:`~orrc.Trajectory` of Algorithm 1 (``PreviewRHC``) that recorded V_M at every step.
    M : the controller's horizon.
    alpha_hi, gamma_bar : the constants ᾱ and γ̄ to check.

    Returns
    -------
    Margins
        margins for t = 0..T-1; ``holds()`` says whether all are non-negative up to rounding.

    Raises
    ------
    orrc.OrrcValueError
        When the trajectory has failed steps or no V_M, M does not match its controller, or a
        constant is out of range.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)    # certified α_lo, ᾱ, γ̄, a, γ_c
    >>> w = orrc.disturbances.uniform_ball(60, 1, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 8), ex.x0,
    ...                      w, 50)
    >>> checks.value_bound_margins(traj, 8, k.alpha_hi, k.gamma_bar).holds()
    True
    """
    traj, M, e = _trajectory(traj, M)
    alpha_hi = as_float("alpha_hi", alpha_hi, minimum=0.0, strict_min=True)
    gamma_bar = as_float("gamma_bar", gamma_bar, minimum=0.0, strict_min=True)
    T = traj.T
    bound = alpha_hi * traj.sigma[:T] + gamma_bar * _window_energy(e, M, T)
    V = traj.values
    return Margins(np.arange(T), bound, V.copy(), bound - V,
                   "V_M(x_t) <= alpha_hi σ(x_t) + gamma_bar Σ_{k=t}^{t+M-1} ‖w_k‖²")


def lemma1_margins(traj, M, alpha_lo, alpha_hi, gamma_bar) -> Lemma1Margins:
    """Lemma 1 at every step of a trajectory of Algorithm 1.

    * ``lower``: V^t_M - α_lo σ(x_t) for t = 0..T-1 (the first claim, V_M >= α_lo σ);
    * ``increment``: [Γ_V σ(x_t) + Γ^γ_V Σ_{k=t}^{t+M-1} ‖w_k‖²] - (V^{t+1}_M - V^t_M) for
      t = 0..T-2, with Γ_V, Γ^γ_V of :func:`orrc.theory.Gamma_V` / ``Gamma_V_gamma``.

    Lemma 1 holds for every M >= 2 (Γ_V may be positive below the horizon threshold).

    Parameters
    ----------
    traj : a :class:`~orrc.Trajectory` of Algorithm 1 (``PreviewRHC``) that recorded V_M at every step.
    M : the controller's horizon (>= 2).
    alpha_lo, alpha_hi, gamma_bar : the constants α_lo, ᾱ, γ̄.

    Returns
    -------
    Lemma1Margins
        ``lower`` (T margins), ``increment`` (T - 1 margins), Γ_V and Γ^γ_V.

    Raises
    ------
    orrc.OrrcValueError
        When the trajectory has failed steps or no V_M, M does not match its controller, or a
        constant is out of range.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)    # certified α_lo, ᾱ, γ̄, a, γ_c
    >>> w = orrc.disturbances.uniform_ball(60, 1, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 8), ex.x0,
    ...                      w, 50)
    >>> lemma1 = checks.lemma1_margins(traj, 8, k.alpha_lo, k.alpha_hi, k.gamma_bar)
    >>> lemma1.lower.margin.shape, lemma1.increment.margin.shape
    ((50,), (49,))
    """
    traj, M, e = _trajectory(traj, M)
    GV = theory.Gamma_V(M, alpha_lo, alpha_hi)
    GVg = theory.Gamma_V_gamma(M, alpha_lo, alpha_hi, gamma_bar)
    V, sig, T = traj.values, traj.sigma, traj.T
    t = np.arange(T)
    lower_bound = float(alpha_lo) * sig[:T]
    lower = Margins(t, V.copy(), lower_bound, V - lower_bound, "V_M(x_t) >= alpha_lo σ(x_t)")
    ti = np.arange(T - 1)
    S = _window_energy(e, M, T - 1)
    inc_bound = GV * sig[:T - 1] + GVg * S
    inc_actual = V[1:] - V[:-1]
    inc_scale = abs(GV) * sig[:T - 1] + abs(GVg) * S + np.abs(V[1:]) + np.abs(V[:-1])
    increment = Margins(ti, inc_bound, inc_actual, inc_bound - inc_actual,
                        "V_M(x_{t+1}) - V_M(x_t) <= Γ_V σ(x_t) + Γ^γ_V Σ_{k=t}^{t+M-1} ‖w_k‖²", inc_scale)
    return Lemma1Margins(lower, increment, GV, GVg)


def lemma2_margins(traj, M, H, a, alpha_lo, alpha_hi, gamma_bar) -> Margins:
    """Lemma 2 at every anchor t of a trajectory: margin_t = bound_t - c_{t+H} for t = 0..T-1-H,

        bound_t = ᾱ a^H σ(x_t) + Σ_{j=t}^{t+H+M-2} M_{w,j} ‖w_j‖²   (:func:`orrc.theory.lemma2_bound`).

    Needs M above the horizon threshold, a in [min_decay_rate, 1), M <= H < T.

    Parameters
    ----------
    traj : a :class:`~orrc.Trajectory` of Algorithm 1 (``PreviewRHC``) that recorded V_M at every step.
    M : the controller's horizon, above the threshold.
    H : the look-ahead, M <= H < T.
    a : the decay rate, in [min_decay_rate, 1).
    alpha_lo, alpha_hi, gamma_bar : the constants α_lo, ᾱ, γ̄.

    Returns
    -------
    Margins
        margins for the anchors t = 0..T-1-H.

    Raises
    ------
    orrc.OrrcValueError
        When the trajectory has failed steps or no V_M, M does not match its controller, or a
        constant is out of range.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)    # certified α_lo, ᾱ, γ̄, a, γ_c
    >>> w = orrc.disturbances.uniform_ball(60, 1, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 8), ex.x0,
    ...                      w, 50)
    >>> lemma2 = checks.lemma2_margins(traj, 8, 8, k.a, k.alpha_lo, k.alpha_hi, k.gamma_bar)
    >>> lemma2.margin.shape, lemma2.holds()
    ((42,), True)
    """
    traj, M, e = _trajectory(traj, M)
    H = as_int("H", H, minimum=1)
    T = traj.T
    if H >= T:
        raise OrrcValueError(f"H must be < T = {T} (the cost c_(t+H) must be in the trajectory); got H={H}")
    # the checks of theory.lemma2_bound, in its order and with its messages (the windows of
    # traj.w_all are finite and long enough: orrc.simulate and _trajectory ensure it)
    M, a, alpha_lo, alpha_hi, gamma_bar = theory.known._lemma2_setting(M, a, alpha_lo, alpha_hi, gamma_bar)
    as_float("sigma_t", traj.sigma[0], minimum=0.0)
    if H < M:
        raise OrrcValueError(f"Lemma 2 needs H >= M; got H={H}, M={M}")
    coef = theory.lemma2_coefficients(M, H, a, alpha_hi, gamma_bar, theory.known._b(alpha_lo, alpha_hi, gamma_bar))
    count = T - H
    check_size(f"Lemma 2's bound at the {count} anchors of the trajectory with H={H}, M={M}",
               nbytes=8.0 * count, ops=2.0 * count * (H + M), hint="lower H or check a shorter trajectory")
    windows = sliding_window_view(e, H + M - 1)[:count]
    bound = alpha_hi * a ** H * traj.sigma[:count] + windows @ coef
    actual = traj.costs[H:H + count]
    return Margins(np.arange(count), bound, actual, bound - actual,
                   f"c_(t+H) <= alpha_hi a^H σ(x_t) + Σ M_(w,j) ‖w_j‖² (H={H})")


def theorem1_margin(traj, M, a, alpha_lo, alpha_hi, gamma_bar, gamma) -> Margins:
    """Theorem 1 along the trajectory: for every horizon T' = 1..T,

        margin_{T'} = C_{T'}(γ) - R^p_{T'}(γ),   R^p_{T'}(γ) = Σ_{t<T'} c_t - γ Σ_{t<T'} ‖w_t‖²,

    with C the explicit constant of :func:`orrc.theory.theorem1_constant` (it depends on
    σ(x_0), the first M and the last M-2 previewed disturbances). Needs γ >= γ_c.
    ``t`` holds T' and ``actual`` the running R^p_{T'}(γ).

    Parameters
    ----------
    traj : a :class:`~orrc.Trajectory` of Algorithm 1 (``PreviewRHC``) that recorded V_M at every step.
    M : the controller's horizon, above the threshold.
    a : the decay rate, in [min_decay_rate, 1).
    alpha_lo, alpha_hi, gamma_bar : the constants α_lo, ᾱ, γ̄.
    gamma : the level, γ >= γ_c.

    Returns
    -------
    Margins
        margins for T' = 1..T.

    Raises
    ------
    orrc.OrrcValueError
        When the trajectory has failed steps or no V_M, M does not match its controller, or a
        constant is out of range.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)    # certified α_lo, ᾱ, γ̄, a, γ_c
    >>> w = orrc.disturbances.uniform_ball(60, 1, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 8), ex.x0,
    ...                      w, 50)
    >>> theorem1 = checks.theorem1_margin(traj, 8, k.a, k.alpha_lo, k.alpha_hi,
    ...                                   k.gamma_bar, k.gamma_c)
    >>> theorem1.margin.shape, theorem1.holds()
    ((50,), True)
    """
    traj, M, e = _trajectory(traj, M)
    # the checks of theory.theorem1_constant (threshold, a, gamma >= gamma_c), b and γ_c once
    s = theory.known._theorem1_setting(traj.sigma[0], traj.T, M, a, alpha_lo, alpha_hi, gamma_bar, gamma)
    Ts = np.arange(1, s.T + 1)
    C = theory.known._theorem1_constants(s, e, Ts)
    R = attenuation_regret(traj, s.gamma, cumulative=True)
    # R = Σ c_t - γ Σ‖w_t‖² cancels: its rounding is relative to the two sums
    scale = np.abs(C) + np.cumsum(np.abs(traj.costs)) + s.gamma * np.cumsum(e[:s.T])
    return Margins(Ts, C, R, C - R, "R^p_T(gamma) <= C (Theorem 1, explicit O(1))", scale)
