"""The discrete H∞ state-feedback controller, with and without disturbance preview.

The disturbance-to-cost channel of the paper: x_{t+1} = Ax_t + Bu_t + w_t and the cost output
z_t = [Q^½x_t; R^½u_t], so Σ c_t = Σ ‖z_t‖². The H∞ controller at level γ guarantees
Σ c_t <= γ Σ ‖w_t‖² + (a constant set by the initial state) for every disturbance, the paper's
attenuation in the paper's convention (γ the squared gain). It is the minimiser's saddle-point
policy of the soft-constrained game of :mod:`orrc.solvers.game` (Başar and Bernhard 1995).

Information pattern. Without preview the controller is strictly causal: u_t = −K x_t uses the
state x_t (so, for a known linear system, w_0..w_{t−1}) but not w_t, the disturbance about to
act. Its optimal level is the best among strictly causal controllers. Full information (u_t may
also use w_t) is preview k = 1 here, and its level can be far lower: on x⁺ = 2x + u + w with
c = x² + u² the strictly causal level is 5 and the full-information level 1 (u = −2x − w).

With preview k the controller also sees w_t..w_{t+k-1}. The game is then played on the state
augmented with the preview buffer, ξ_t = [x_t; w_t; ...; w_{t+k-1}]:

    ξ_{t+1} = Ā ξ_t + B̄ u_t + Ē v_t,   v_t = w_{t+k} (the next, still unseen, disturbance),

with Ā = [[A, I, 0..], [0, 0, I, ..], ..., [0 ... 0]], B̄ = [B; 0], Ē = [0; ...; I] and the
cost weight diag(Q, 0). The only disturbance left, v_t, is not seen before it acts, so the
preview controller is strictly causal state feedback on ξ; its optimal level is the best
attenuation among controllers whose u_t uses x_0..x_t and w_0..w_{t+k-1} (the state ξ_t is
measured, so a static feedback on ξ is optimal; not a full-information level, which would let
u_t use v_t too), and the controller is
u_t = −K x_t − L vec(w_t..w_{t+k-1}), the same form as Algorithm 1's LQ law
(:class:`~orrc.PreviewRHC`). The level falls with k towards the non-causal level (a controller
that knows the whole sequence) and stops improving after a few steps.
"""
from __future__ import annotations

import numpy as np

from .._validate import as_float, as_int, check_size
from .._problem import check_problem
from ..costs import QuadraticCost
from ..solvers import game
from ..systems import LinearSystem, NonlinearSystem, System
from .base import Controller, Decision, Observation

__all__ = ["HInfinity", "preview_buffer_system"]

# gamma=None: the controller is built this far (relative) above the optimal level γ̂ (or by twice the
# level's error bound, if larger). γ̂ is itself certified feasible (orrc.solvers.game.optimal_game_level),
# so any margin >= 0 builds; the margin keeps the closed loop off the boundary, where the Riccati
# solution is ill-conditioned: it exceeds the level's error bound (about 1e-9 relative, the bisection's
# tolerance, plus the band above γ* in which double precision cannot certify a solution), so the
# controller is built where the certificate holds on every BLAS kernel.
GAMMA_MARGIN = 1e-5


def preview_buffer_system(A, B, Q, k: int):
    """(Ā, B̄, Q̄, Ē) of the system augmented with a preview buffer of k disturbances (k >= 1).

    ξ = [x; w_t; ...; w_{t+k-1}], ξ⁺ = Āξ + B̄u + Ēv with v = w_{t+k}; cost weight Q̄ = diag(Q, 0).

    Parameters
    ----------
    A, B, Q : the system and its state weight.
    k : the number of buffered disturbances, >= 1.

    Returns
    -------
    tuple of numpy.ndarray
        Ā (n(k+1), n(k+1)), B̄ (n(k+1), m), Q̄ (n(k+1), n(k+1)), Ē (n(k+1), n).

    Examples
    --------
    >>> import orrc
    >>> from orrc.controllers import gpc
    >>> di = orrc.examples.double_integrator()
    >>> from orrc.controllers import hinf
    >>> A_bar, B_bar, Q_bar, E_bar = hinf.preview_buffer_system(di.system.A,
    ...                                                         di.system.B, di.cost.Q, 2)
    >>> A_bar.shape, E_bar.shape
    ((6, 6), (6, 2))
    """
    n, m = B.shape
    N = n * (k + 1)
    Ab = np.zeros((N, N))
    Ab[:n, :n] = A
    Ab[:n, n:2 * n] = np.eye(n)                        # x⁺ = Ax + Bu + w_t (the buffer's head)
    Ab[n:N - n, 2 * n:] = np.eye(N - 2 * n)            # the buffer shifts by one
    Bb = np.zeros((N, m))
    Bb[:n] = B
    Eb = np.zeros((N, n))
    Eb[N - n:] = np.eye(n)                             # v enters at the buffer's tail
    Qb = np.zeros((N, N))
    Qb[:n, :n] = Q
    return Ab, Bb, Qb, Eb


class HInfinity(Controller):
    """The H∞ state-feedback controller at level γ (the paper's convention: γ is the squared gain).

    Strictly causal without preview (u_t = −K x_t does not use w_t); with ``preview`` k it also
    uses w_t..w_{t+k-1} (k = 1 is the full-information pattern).

    Parameters
    ----------
    system : a :class:`~orrc.LinearSystem` (a :class:`~orrc.NonlinearSystem` is replaced by its
        linearisation at the origin, as :class:`~orrc.LQR` does).
    cost : the :class:`~orrc.QuadraticCost` whose stage cost is the output's energy.
    gamma : the level, or None (default) for the optimal level (the best among controllers that use
        the state and the k previewed disturbances, see the module docstring), found by bisection on the game
        Riccati equation (:func:`orrc.solvers.game.optimal_game_level`, certified feasible, with an
        error bound ``gamma_opt_error``: γ* lies in [gamma_opt − gamma_opt_error, gamma_opt]); the
        controller is then built at ``gamma_opt·(1 + 1e-5)`` (or ``gamma_opt + 2·gamma_opt_error`` if
        larger), just above it (at the optimum itself the Riccati equation has no stabilising
        solution, and just above it the solution is ill-conditioned). A given ``gamma`` at or below
        the optimal level raises :class:`~orrc.OrrcValueError` naming that level.
    preview : k >= 0, the number of future disturbances w_t..w_{t+k-1} the controller sees.

    Attributes: ``gamma`` (the level the controller is built at), ``gamma_opt`` and
    ``gamma_opt_error`` (the optimal level and its error bound, when gamma was None), ``K`` (m, n) and ``L`` (m, k n) with u = −Kx − L vec(w_t..),
    ``P`` the game's Riccati solution, ``Kw`` the worst-case disturbance gain.

    Solvers: ``scipy.linalg.solve_discrete_are`` with the indefinite weight diag(R, −γI)
    (:func:`orrc.solvers.game.stationary_game`); the closed loop's H∞ norm (the check of the
    tests and of :func:`orrc.certify.worst_case_attenuation_limit`) is python-control's
    ``system_norm``.

    Raises
    ------
    orrc.OrrcValueError
        When ``gamma`` is at or below the optimal level, or the system is not stabilisable.

    Examples
    --------
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(L=60, n=2, radius=0.1, seed=0)
    >>> hinf = orrc.HInfinity(di.system, di.cost, preview=3)
    >>> print(f"{hinf.gamma:.2f}",
    ...       f"{orrc.simulate(di.system, hinf, di.x0, w, T=50).costs.sum():.4f}")
    29.95 36.8312
    """

    name = "H∞"

    def __init__(self, system: System, cost: QuadraticCost, gamma: float | None = None, preview: int = 0):
        check_problem(system, cost, quadratic=True, who="HInfinity", why_quadratic=" (the cost output [Q^½x; R^½u])")
        self.preview = as_int("preview", preview, minimum=0)
        A, B = (system.A, system.B) if isinstance(system, LinearSystem) else system.linearize()
        game.check_stabilisable(A, B)
        n, m = B.shape
        N = n * (self.preview + 1)
        # the optimal level: a bisection of about 60 certified game AREs on the (N + m + n)-dimensional
        # pencil of the augmented system (each O(N³), with a handful of N x N work arrays)
        check_size(f"HInfinity's game on the state augmented with preview={self.preview} disturbances (n={n}: "
                   f"{N} states)", nbytes=8.0 * 40 * (N + m + n) ** 2,
                   ops=(60 if gamma is None else 2) * 200.0 * (N + m + n) ** 3, hint="lower the preview")
        if self.preview:
            Ab, Bb, Qb, Eb = preview_buffer_system(A, B, cost.Q, self.preview)
        else:
            Ab, Bb, Qb, Eb = A, B, cost.Q, np.eye(n)
        if gamma is None:
            self.gamma_opt, self.gamma_opt_error = game.optimal_game_level(Ab, Bb, Qb, cost.R, E=Eb, with_error=True)
            gamma = self.gamma_opt * (1.0 + max(GAMMA_MARGIN, 2.0 * self.gamma_opt_error / self.gamma_opt))
        else:
            gamma = as_float("gamma", gamma, minimum=0.0, strict_min=True)
            self.gamma_opt = self.gamma_opt_error = None
        self.solution = game.stationary_game(Ab, Bb, Qb, cost.R, gamma, E=Eb)
        self.gamma = float(gamma)
        Kbar = self.solution.K[0]
        self.K, self.L = Kbar[:, :n].copy(), Kbar[:, n:].copy()
        self.P, self.Kw = self.solution.P[0], self.solution.Kw[0]
        self.preview_w, self.preview_c = self.preview, 0
        self.system, self.cost = system, cost
        self.linearized = isinstance(system, NonlinearSystem)
        if self.preview:
            self.name = f"H∞, preview {self.preview}"

    def control(self, obs: Observation) -> Decision:
        u = -self.K @ obs.x
        if self.preview:
            u = u - self.L @ obs.w_preview.reshape(-1)
        return Decision(u=u)

    def __repr__(self):
        return f"HInfinity(gamma={self.gamma:.6g}, preview={self.preview}, system={self.system!r})"
