"""The attenuation a linear closed loop achieves against the worst disturbance.

* :func:`worst_case_attenuation` -- for a linear closed loop (Algorithm 1 on the LQ path,
  LQR, zero input) the exact smallest γ with R^p_T(γ) <= 0 for every disturbance sequence
  of length T from x_0 = 0, and the disturbance that attains it;
* :func:`worst_case_attenuation_limit` -- its T → ∞ limit: the squared H∞ norm of the
  closed loop from w to the cost output (python-control), or the cold-start level.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from .._validate import PY_CALL_OPS, OrrcValueError, as_float, as_int, check_finite_result, check_size
from ..controllers.base import Controller
from ..costs import psd_factor as _sqrt_psd
from ..solvers.plan import SolverWarning
from ..systems import LinearSystem
from ._loop import _linear_loop, _Loop, _operators, _top_singular

__all__ = ["Attenuation", "worst_case_attenuation", "worst_case_attenuation_limit"]

# the distance 1 - ρ to the unit circle below which a closed loop counts as not stable
# (the absolute 1e-8 of python-control's H∞ routine; see worst_case_attenuation_limit)
_BOUNDARY = 1e-8


@dataclass
class Attenuation:
    """The attenuation a linear closed loop achieves against the worst disturbance.

    Attributes
    ----------
    gamma : the smallest γ with R^p_T(γ) <= 0 for every disturbance (finite T), or the
        squared H∞ norm (T = None, the limit T → ∞); ``inf`` when the loop is unstable.
    w : (T, n) the worst-case disturbance, unit total energy Σ‖w_t‖² = 1 (None for the limit).
    T : horizon, or None for the limit.
    G : the matrix with Σ_{t<T} c_t = ‖G vec(w)‖² (finite T), else None.
    closed_loop : the python-control ``StateSpace`` from the newest previewed disturbance to the
        cost output (the limit), else None.
    reason : None, or why gamma is infinite.
    start : "cold" for finite T and the cold-start limit, "stationary" for the H∞ level.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> di = orrc.examples.double_integrator()
    >>> lqr = orrc.LQR(di.system, di.cost)
    >>> worst = certify.worst_case_attenuation(di.system, lqr, T=30)
    >>> print(round(worst.gamma, 3), worst.w.shape)
    95.267 (30, 2)
    """

    gamma: float
    w: np.ndarray | None = None
    T: int | None = None
    G: np.ndarray | None = field(default=None, repr=False)
    closed_loop: object = field(default=None, repr=False)
    reason: str | None = None
    start: str = "cold"


def worst_case_attenuation(system: LinearSystem, controller: Controller, T: int, cost=None) -> Attenuation:
    """The exact smallest γ with R^p_T(γ) <= 0 for every disturbance w_0..w_{T-1} (x_0 = 0).

    For a linear closed loop (Algorithm 1 on the LQ path, u = -Kx - L vec(w_t..w_{t+M-1});
    LQR; zero input), x_t and u_t are linear in W = (w_0, ..., w_{T-1}) and
    Σ_{t<T} c_t(x_t, u_t) = ‖G vec W‖² with G stacking [Q^{1/2} x_t; R^{1/2} u_t]. So
    R^p_T(γ) = vec Wᵀ (GᵀG - γ I) vec W <= 0 for all W iff γ >= γ* = λ_max(GᵀG) = σ_max(G)²
    (Eq. 2 of the paper with the worst adversary), and the top right singular vector of G
    is the disturbance that attains it: the adversary made explicit. (Dense SVD for small
    problems, ARPACK to machine precision for large T.)

    With preview (M >= 2) the worst finite-T disturbance concentrates at the start, where
    the controller meets w_0..w_{M-2} unannounced; its T → ∞ limit is
    ``worst_case_attenuation_limit(..., start="cold")``, which can exceed the stationary
    H∞ level that governs R^p_T(γ) = O(1) (see :func:`worst_case_attenuation_limit`).

    The preview past T sees zeros (the :func:`orrc.simulate` convention when w has exactly
    T rows), so ``orrc.simulate(system, controller, 0, result.w, T)`` gives
    R^p_T(γ*) = 0 up to rounding. ``cost`` defaults to the controller's own cost.

    Parameters
    ----------
    system : a :class:`~orrc.LinearSystem`.
    controller : a linear controller (Algorithm 1 on the LQ path, LQR, H∞, zero input, ...).
    T : the horizon.
    cost : the quadratic cost (default: the controller's).

    Returns
    -------
    Attenuation
        ``gamma`` = σ_max(G)², the worst disturbance ``w`` (T, n) of unit energy, ``G``.

    Raises
    ------
    orrc.OrrcValueError
        When the system is not linear or the cost not quadratic, an argument is out of range, or the
        computation exceeds the size limits of ``orrc.config``.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> di = orrc.examples.double_integrator()
    >>> lqr = orrc.LQR(di.system, di.cost)
    >>> worst = certify.worst_case_attenuation(di.system, lqr, T=30)
    >>> # the adversary made explicit
    >>> traj = orrc.simulate(di.system, lqr, [0.0, 0.0], worst.w, T=30)
    >>> print(round(traj.costs.sum(), 3))
    95.267
    """
    loop = _linear_loop(system, controller, cost)
    T = as_int("T", T, minimum=1)
    n, m = system.n, system.m
    n_rows, n_cols = T * (n + m), T * n
    # G and its row blocks (2 copies), dense SVD (small G) or ~100 ARPACK products (large G), the loop
    check_size(f"worst_case_attenuation over T={T} steps (n={n}, m={m}): a {n_rows} x {n_cols} matrix G",
               nbytes=8.0 * n_rows * n_cols * (2 if min(n_rows, n_cols) > 200 else 4),
               ops=(200.0 * n_rows * n_cols if min(n_rows, n_cols) > 200 else 10.0 * n_rows * n_cols ** 2)
               + T * ((loop.Mw + loop.Hp + 6) * PY_CALL_OPS + 6.0 * n * (n + m) * n_cols),
               hint="lower T (the level converges in T: worst_case_attenuation_limit gives T → ∞ directly)")
    Qh, Rh = _sqrt_psd(loop.Q), _sqrt_psd(loop.R)
    X, U = _operators(system, loop, T)
    G = np.vstack([np.vstack([Qh @ X[t * n:(t + 1) * n], Rh @ U[t * m:(t + 1) * m]]) for t in range(T)])
    if not np.all(np.isfinite(G)):
        raise OrrcValueError(f"worst_case_attenuation over T={T}: the closed-loop response overflows (the loop is "
                             "unstable and T too long for floating point, or the weights too large); lower T")
    gamma, v = _top_singular(G)
    check_finite_result("the worst-case attenuation level", gamma, f"T={T}", "rescale Q and R")
    w = v.reshape(T, n)
    j = int(np.argmax(np.abs(w.ravel())))
    if w.ravel()[j] < 0:
        w = -w
    return Attenuation(gamma=gamma, w=w, T=T, G=G)


def _closed_loop_ss(system, loop: _Loop):
    """State space (A, B, C, D) from the newest previewed disturbance to z = [Q^{1/2}x; R^{1/2}u]
    (for a controller with memory of past w: from w_t, the state holding w_{t-1}..w_{t-Hp})."""
    K, L, Mw, Q, R = loop.K, loop.L, loop.Mw, loop.Q, loop.R
    A, Bu = system.A, system.B
    n, m = Bu.shape
    Qh, Rh = _sqrt_psd(Q), _sqrt_psd(R)
    if loop.Hp:
        # state ξ = [x; b_1; ...; b_H] with b_i = w_{t-i}; input w_t; u = -Kx + Σ M_i b_i
        nb = loop.Hp * n
        Ac = np.zeros((n + nb, n + nb))
        Ac[:n, :n] = A - Bu @ K
        Ac[:n, n:] = Bu @ loop.Lp
        Ac[2 * n:, n:n + nb - n] = np.eye(nb - n)        # b_{i+1}⁺ = b_i
        Bc = np.zeros((n + nb, n))
        Bc[:n] = np.eye(n)
        Bc[n:2 * n] = np.eye(n)                          # b_1⁺ = w_t
        Cc = np.vstack([np.hstack([Qh, np.zeros((Qh.shape[0], nb))]), np.hstack([-Rh @ K, Rh @ loop.Lp])])
        return Ac, Bc, Cc, np.zeros((Cc.shape[0], n))
    if Mw <= 1:
        # LQR / zero input: the input is w_t itself. Preview M = 1: u = -Kx - L_0 w_t.
        L0 = L[:, :n] if Mw == 1 else np.zeros((m, n))
        Ac = A - Bu @ K
        Bc = np.eye(n) - Bu @ L0
        Cc = np.vstack([Qh, -Rh @ K])
        Dc = np.vstack([np.zeros((Qh.shape[0], n)), -Rh @ L0])
        return Ac, Bc, Cc, Dc
    # state ξ = [x; b_0; ...; b_{M-2}] with b_i = w_{t+i}; input v = w_{t+M-1}
    nb = (Mw - 1) * n
    Lb, Lv = L[:, :nb], L[:, nb:]
    Ac = np.zeros((n + nb, n + nb))
    Ac[:n, :n] = A - Bu @ K
    Ac[:n, n:] = -Bu @ Lb
    Ac[:n, n:2 * n] += np.eye(n)                     # + w_t = b_0
    Ac[n:nb, 2 * n:] = np.eye(nb - n)                # b_i⁺ = b_{i+1}
    Bc = np.zeros((n + nb, n))
    Bc[:n] = -Bu @ Lv
    Bc[nb:] = np.eye(n)                              # b_{M-2}⁺ = v
    Cc = np.vstack([np.hstack([Qh, np.zeros((Qh.shape[0], nb))]), np.hstack([-Rh @ K, -Rh @ Lb])])
    Dc = np.vstack([np.zeros((Qh.shape[0], n)), -Rh @ Lv])
    return Ac, Bc, Cc, Dc


def worst_case_attenuation_limit(system: LinearSystem, controller: Controller, cost=None,
                                 start: str = "stationary", tol: float = 1e-9) -> Attenuation:
    """The T → ∞ attenuation of a linear closed loop: the squared H∞ norm from w to the cost output.

    The cost output is z_t = [Q^{1/2} x_t; R^{1/2} u_t], so Σ c_t = Σ ‖z_t‖².
    For Algorithm 1 the input u_t depends on w_t..w_{t+M-1}; the loop is causal in the
    newest previewed disturbance v_t = w_{t+M-1} once the state is augmented with the
    buffer (w_t, ..., w_{t+M-2}): ξ_{t+1} = A_c ξ_t + B_c v_t, z_t = C_c ξ_t + D_c v_t
    (``result.closed_loop``). The map v → z is the map w → z delayed by M - 1 steps.

    ``start="stationary"`` (default): γ_∞ = ‖v → z‖²_{H∞}. This is the attenuation level
    in the sense of Theorem 1: for bounded disturbances, R^p_T(γ) stays O(1) for every
    disturbance sequence when γ > γ_∞, and a sinusoid at the peak frequency makes it grow
    linearly in T when γ < γ_∞. This is the number to set beside the certified γ_c.

    ``start="cold"``: the limit of :func:`worst_case_attenuation` (x_0 = 0, the exact
    "R^p_T(γ) <= 0 for every w" level) as T → ∞. For LQR, zero input and M = 1 it equals
    the stationary value. With preview M >= 2 it can be larger: at t = 0 the controller
    meets w_0..w_{M-2} without having seen them coming (in the stationary loop it would
    have acted on them M - 1 steps earlier), so they act like an initial state
    ξ_0 = [0; w_0..w_{M-2}] and the worst finite-T disturbance concentrates at the start.
    This start-up effect is O(1): it does not change the stationary level. Computed
    exactly: for γ > γ_∞, sup_v Σ (‖z_t‖² - γ‖v_t‖²) from ξ_0 is ξ_0ᵀ X_γ ξ_0 with X_γ the
    stabilising solution of the H∞ (bounded-real) Riccati equation
    X = A_cᵀXA_c + C_cᵀC_c + (A_cᵀXB_c + C_cᵀD_c)(γI - D_cᵀD_c - B_cᵀXB_c)⁻¹(B_cᵀXA_c + D_cᵀC_c)
    (``scipy.linalg.solve_discrete_are`` with the indefinite weight D_cᵀD_c - γI), so the
    cold-start level is max(γ_∞, the root of λ_max(X_γ restricted to the buffer) = γ).

    The H∞ norm is python-control's ``control.system_norm(sys, p='inf')``. Without Slycot,
    python-control refuses discrete-time systems with poles at z = 0 (the buffer has
    them), so the system is first mapped to continuous time by the inverse bilinear
    transform s = 2(z - 1)/(z + 1), which maps the unit circle onto the imaginary axis and
    preserves the H∞ norm (the same map python-control applies internally); and since its
    routine (0.10.2) assumes a square transfer matrix, zero input columns are appended
    (σ_max([G 0]) = σ_max(G)). Its bisection can stop short of the peak by up to ~1e-4
    (relative), so the level is the larger of its result and the peak of the frequency response
    (a grid refined by a scalar search), both lower bounds on the norm. An unstable closed loop has no finite limit: ``gamma = inf``
    with a ``reason``.

    Parameters
    ----------
    system : a :class:`~orrc.LinearSystem`.
    controller : a linear controller.
    cost : the quadratic cost (default: the controller's).
    start : "stationary" (the H∞ level) or "cold".
    tol : the tolerance of the H∞ norm's bisection.

    Returns
    -------
    Attenuation
        ``gamma`` (``inf`` with a ``reason`` for an unstable loop) and the ``closed_loop``.

    Raises
    ------
    orrc.OrrcValueError
        When the system is not linear or the cost not quadratic, an argument is out of range, or the
        computation exceeds the size limits of ``orrc.config``.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> di = orrc.examples.double_integrator()
    >>> lqr = orrc.LQR(di.system, di.cost)
    >>> print(round(certify.worst_case_attenuation_limit(di.system, lqr).gamma, 2))
    110.0
    """
    import control

    loop = _linear_loop(system, controller, cost, "worst_case_attenuation_limit")
    if loop.Phi is not None:
        raise OrrcValueError("worst_case_attenuation_limit needs a time-invariant controller; RegretOptimal is "
                             f"designed for a finite horizon (T = {loop.T_max}): use worst_case_attenuation")
    if start not in ("stationary", "cold"):
        raise OrrcValueError(f"start must be 'stationary' or 'cold'; got {start!r}")
    tol = as_float("tol", tol, minimum=0.0, strict_min=True)
    k = system.n * max(loop.Mw, loop.Hp + 1, 1)
    check_size(f"worst_case_attenuation_limit for a closed loop of {k} states (n={system.n}, preview M={loop.Mw})",
               nbytes=8.0 * 40 * k * k, ops=400.0 * k ** 3, hint="lower the controller's horizon M")
    Ad, Bd, Cd, Dd = _closed_loop_ss(system, loop)
    sys_d = control.ss(Ad, Bd, Cd, Dd, dt=True)
    rho = float(np.max(np.abs(np.linalg.eigvals(Ad))))
    # python-control's H∞ routine (method "scipy") tests poles and Hamiltonian eigenvalues for
    # lying on the imaginary axis with an absolute 1e-8 (np.isclose), after the bilinear map
    # below, which puts a pole z = ρe^{iθ} at |Re s| >= about 1 - ρ. So 1 - ρ <= 1e-8 is on the
    # stability boundary to that routine's precision (on x⁺ = (1 - δ)x it returns inf for
    # δ = 3e-9 and 5e23 for the true 1e16 at δ = 1e-8), and a double eigenvalue on the unit
    # circle is only computed to ~sqrt(eps) = 1.5e-8 anyway. Above the boundary its level is
    # resolved to about (1e-8/(1 - ρ))² relative (measured), hence the warning below.
    if rho >= 1.0 - _BOUNDARY:
        return Attenuation(gamma=math.inf, closed_loop=sys_d, start=start,
                           reason=f"the closed loop is not stable (spectral radius {rho:.12g} >= 1 - "
                                  f"{_BOUNDARY:g}, on the stability boundary to working precision): "
                                  "the worst-case attenuation grows without bound with T")
    if (_BOUNDARY / (1.0 - rho)) ** 2 > tol:
        warnings.warn(f"the closed loop's spectral radius {rho:.12g} is within {1.0 - rho:.3g} of 1: "
                      f"the H∞ level is resolved only to about {(_BOUNDARY / (1.0 - rho)) ** 2:.1g} relative, "
                      f"not to tol={tol:g}", SolverWarning, stacklevel=2)
    I = np.eye(Ad.shape[0])
    Ainv = np.linalg.inv(Ad + I)
    Ac, Bc, Cc, Dc = 2 * (Ad - I) @ Ainv, 2 * Ainv @ Bd, 2 * Cd @ Ainv, Dd - Cd @ Ainv @ Bd
    # python-control 0.10.2's scipy L∞ routine assumes as many outputs as inputs; zero
    # input columns / output rows make the system square without changing its norm
    p, q = Cc.shape[0], Bc.shape[1]
    if p > q:
        Bc, Dc = np.hstack([Bc, np.zeros((Bc.shape[0], p - q))]), np.hstack([Dc, np.zeros((p, p - q))])
    elif q > p:
        Cc, Dc = np.vstack([Cc, np.zeros((q - p, Cc.shape[1]))]), np.vstack([Dc, np.zeros((q - p, q))])
    sys_c = control.ss(Ac, Bc, Cc, Dc)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        norm = float(control.system_norm(sys_c, p="inf", tol=tol, method="scipy"))
    gamma_inf = max(norm ** 2, _peak_gain_sq(Ad, Bd, Cd, Dd))
    n = system.n
    if start == "stationary" or Ad.shape[0] == n or gamma_inf == 0.0 or loop.Hp:  # past memory starts empty
        return Attenuation(gamma=gamma_inf, closed_loop=sys_d, start=start)
    return Attenuation(gamma=_cold_start_level(Ad, Bd, Cd, Dd, n, gamma_inf, tol), closed_loop=sys_d,
                       start=start)


def _peak_gain_sq(A, B, C, D, grid: int = 256) -> float:
    """max_ω σ_max(C(e^{jω}I − A)⁻¹B + D)² on a grid of [0, π], refined by a bounded scalar search
    around the three best grid points: a lower bound on the squared H∞ norm of a stable loop.

    python-control's bisection (0.10.2) calls a Hamiltonian eigenvalue imaginary when its real part
    is within 1e-8 of zero, and on some loops stops up to ~1e-4 (relative) short of the peak; the
    level reported is the larger of the two lower bounds."""
    from scipy import optimize

    N = A.shape[0]
    I = np.eye(N)

    def gain(om):
        G = C @ np.linalg.solve(np.exp(1j * om) * I - A, B) + D
        return float(np.linalg.svd(G, compute_uv=False)[0] ** 2)

    om = np.linspace(0.0, np.pi, grid)
    g = np.array([gain(o) for o in om])
    best = float(g.max())
    for i in np.argsort(g)[-3:]:
        lo, hi = om[max(i - 1, 0)], om[min(i + 1, grid - 1)]
        res = optimize.minimize_scalar(lambda o: -gain(o), bounds=(lo, hi), method="bounded",
                                       options={"xatol": 1e-10})
        best = max(best, -float(res.fun))
    return best


def _cold_start_level(A, B, C, D, n, gamma_inf, tol):
    """max(γ_∞, root of λ_max(X_γ[buffer]) = γ) (see :func:`worst_case_attenuation_limit`)."""
    from scipy import linalg, optimize

    q = B.shape[1]
    DtD, CtD, CtC = D.T @ D, C.T @ D, C.T @ C

    def excess(g):
        X = linalg.solve_discrete_are(A, B, CtC, DtD - g * np.eye(q), s=CtD)
        S = g * np.eye(q) - DtD - B.T @ X @ B
        if np.linalg.eigvalsh(0.5 * (S + S.T))[0] <= 0:
            raise np.linalg.LinAlgError("not the stabilising bounded-real solution")
        Xbb = X[n:, n:]
        return float(np.linalg.eigvalsh(0.5 * (Xbb + Xbb.T))[-1]) - g

    lo = None
    for rel in (1e-9, 1e-7, 1e-5, 1e-3):  # the Riccati equation degenerates at γ_∞ itself
        try:
            f_lo = excess(gamma_inf * (1 + rel))
            lo = gamma_inf * (1 + rel)
            break
        except (np.linalg.LinAlgError, ValueError):
            continue
    if lo is None:
        raise RuntimeError("the bounded-real Riccati equation could not be solved near the H∞ level")
    if f_lo <= 0:
        return gamma_inf
    hi = 2 * lo
    while excess(hi) > 0:
        hi *= 2
    return float(optimize.brentq(excess, lo, hi, xtol=tol * hi, rtol=4 * np.finfo(float).eps))
