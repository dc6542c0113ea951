"""Controllers for a preview that may be wrong (:mod:`orrc.forecasts`), beyond the paper.

* :class:`LambdaConfident`: the λ-confident policy of Li et al. (2022) on Algorithm 1's exact LQ
  law, u_t = −K x_t − λ L vec ŵ_{t:t+M-1|t}: λ = 1 trusts the forecast (Algorithm 1 on it,
  certainty equivalence), λ = 0 ignores it; ``lam="self-tuning"`` learns λ_t from the forecasts'
  past errors.
* :class:`RobustPreviewRHC`: min-max over the forecast's error set E, min_U max_{ê ∈ E^M}
  J(x, U, ŵ + ê). It is Algorithm 1 on the forecast when E = {0}, and Algorithm 3's open-loop
  min-max when the forecast is zero and E = W: one set moves between the paper's two settings.
"""
from __future__ import annotations

import numpy as np

from .._validate import OrrcValueError, as_float, as_int
from ..costs import QuadraticCost
from ..disturbances import Ball, Box, Polytope
from ..solvers import lq
from ..solvers.minmax import VertexEpigraph, check_set
from ..systems import LinearSystem
from .base import Controller, Decision, Observation

__all__ = ["LambdaConfident", "RobustPreviewRHC"]


def _check_lq(name: str, system, cost) -> None:
    if not isinstance(system, LinearSystem) or not isinstance(cost, QuadraticCost):
        raise OrrcValueError(f"{name} needs an orrc.LinearSystem and an orrc.QuadraticCost; got "
                             f"{type(system).__name__} and {type(cost).__name__}")
    if (cost.n, cost.m) != (system.n, system.m):
        raise OrrcValueError(f"the cost is for n={cost.n}, m={cost.m}; the system has n={system.n}, m={system.m}")


class LambdaConfident(Controller):
    """The λ-confident policy on Algorithm 1's LQ law: u_t = −K x_t − λ_t L vec ŵ_{t:t+M-1|t}.

    K and L are the feedback and preview gains of the exact M-step receding-horizon law
    (:class:`orrc.solvers.lq.LQPreviewLaw`), so λ = 1 is :class:`~orrc.PreviewRHC` run on the
    forecast and λ = 0 the same law with no preview. ``lam="self-tuning"``: λ_t is the λ that
    would have made the feed-forward best in hindsight over the windows already revealed,

        λ_t = clip( Σ_s f_sᵀ G f̂_s / Σ_s f̂_sᵀ G f̂_s , 0, 1 ),  f_s = L vec w_{s:s+M-1},
        f̂_s = L vec ŵ_{s:s+M-1|s},  G = R + BᵀP_1B,

    over the steps s with s + M <= t (their whole window has been revealed); before the first
    such step λ_t = ``lam0``. This is the idea of the self-tuning rule of Li et al. (2022): the
    weight of the prediction follows how well it predicted.

    Parameters
    ----------
    system : LinearSystem
    cost : QuadraticCost
    M : int
        The horizon (the forecast's length), M >= 1.
    lam : float in [0, 1] or "self-tuning", default "self-tuning"
    lam0 : float in [0, 1], default 0.5
        λ before any window has been revealed (self-tuning only).

    Returns
    -------
    A controller for :func:`orrc.simulate` (``forecast=`` gives it a forecast); its
    ``record()`` (``Trajectory.info``) holds ``lam`` (T,), the λ_t it used.

    Examples
    --------
    >>> import orrc
    >>> from orrc.controllers.forecast import LambdaConfident
    >>> from orrc.forecasts import Noisy
    >>> ex = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(L=60, n=2, radius=0.2, seed=0)
    >>> ctl = LambdaConfident(ex.system, ex.cost, M=5)
    >>> traj = orrc.simulate(ex.system, ctl, ex.x0, w, T=50, forecast=Noisy(0.1))
    >>> 0.0 <= float(traj.info["lam"][-1]) <= 1.0
    True
    """

    def __init__(self, system: LinearSystem, cost: QuadraticCost, M: int, lam="self-tuning", lam0: float = 0.5):
        _check_lq("LambdaConfident", system, cost)
        self.system, self.cost = system, cost
        self.M = as_int("M", M, minimum=1)
        if isinstance(lam, str):
            if lam != "self-tuning":
                raise OrrcValueError(f'lam must be a number in [0, 1] or "self-tuning"; got {lam!r}')
            self.lam = lam
        else:
            self.lam = as_float("lam", lam, minimum=0.0, maximum=1.0)
        self.lam0 = as_float("lam0", lam0, minimum=0.0, maximum=1.0)
        self.law = lq.LQPreviewLaw(system.A, system.B, cost.Q, cost.R, self.M)
        B, P1 = system.B, self.law.P[1]
        self.G = cost.R + B.T @ P1 @ B
        self.preview_w = self.M
        self.name = f"λ-confident (λ={lam if isinstance(lam, str) else f'{self.lam:g}'}, M={self.M})"
        self.reset()

    def reset(self) -> None:
        self._fhat: list[np.ndarray] = []     # f̂_s = L vec ŵ_{s:s+M-1|s}
        self._w: list[np.ndarray] = []        # the revealed w_0, w_1, ...
        self._num = self._den = 0.0
        self._used = 0                        # steps s whose true window entered the sums
        self._lams: list[float] = []

    def _current_lam(self, t: int) -> float:
        if self.lam != "self-tuning":
            return self.lam
        M, n = self.M, self.system.n
        while self._used + M <= t:            # w_s..w_{s+M-1} all revealed
            s = self._used
            f = self.law.L @ np.concatenate(self._w[s:s + M]) if len(self._w) >= s + M else None
            if f is None:
                break
            fh = self._fhat[s]
            self._num += float(f @ self.G @ fh)
            self._den += float(fh @ self.G @ fh)
            self._used += 1
        if self._used == 0 or self._den <= 1e-300 * max(1.0, abs(self._num)) or n == 0:
            return self.lam0
        return float(np.clip(self._num / self._den, 0.0, 1.0))

    def control(self, obs: Observation) -> Decision:
        if obs.w_past is not None:
            self._w.append(np.array(obs.w_past, dtype=float))
        W = np.asarray(obs.w_preview, dtype=float)
        if W.shape != (self.M, self.system.n):
            W = np.vstack([W, np.zeros((self.M - len(W), self.system.n))])
        fhat = self.law.L @ W.reshape(-1)
        lam = self._current_lam(obs.t)
        self._fhat.append(fhat)
        self._lams.append(lam)
        return Decision(u=-self.law.K @ obs.x - lam * fhat, status="λ-confident law", solver="lq")

    def record(self) -> dict:
        """``lam``: (T,) the λ_t of each step."""
        return {"lam": np.array(self._lams)}


class RobustPreviewRHC(Controller):
    """Min-max receding-horizon control around a forecast: at step t,

        min_{U}  max_{ê_0..ê_{M-1} ∈ E}  Σ_{j=0}^{M-1} c(x̃_j, ũ_j),
        x̃_{j+1} = A x̃_j + B ũ_j + ŵ_{t+j|t} + ê_j,  x̃_0 = x_t,

    and u_t = ũ_0. E = {0} gives Algorithm 1 on the forecast; a zero forecast and E = W give
    Algorithm 3 (:class:`~orrc.MinMaxRHC`, open loop). Exact for a linear system, a convex
    quadratic cost and a box or a polytope E (the worst case sits at its vertices); for a ball E
    (no vertices) it plans against the smallest box around the ball, an over-approximation whose
    value bounds the ball's min-max value from above (``exact`` is False then). The state is augmented with the forecast window (a shift register),
    so that the problem is Algorithm 3's exact vertex epigraph
    (:class:`orrc.solvers.minmax.VertexEpigraph`) on the augmented system, with the error box on the
    state's coordinates and nothing on the register's. Its size is that of Algorithm 3: V^(M-1)
    vertex sequences (V = 2^n for a box, the number of given points for a polytope), estimated and
    refused past ``orrc.config``'s limits.

    Parameters
    ----------
    system : LinearSystem
    cost : QuadraticCost
    M : int
        The horizon, M >= 1.
    E : Box, Polytope or Ball
        The forecast's error set (``Box(0, 0, n)`` for an exact forecast); a ball is planned for
        through the box around it.
    input_bounds : (lo, hi), optional

    Returns
    -------
    A controller for :func:`orrc.simulate` with ``forecast=``; its ``record()`` holds ``value``
    (T,), the min-max value of each step; ``exact`` says whether that is the min-max over E
    itself (a box or a polytope) or over the box around a ball.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> from orrc.controllers.forecast import RobustPreviewRHC
    >>> ex = orrc.examples.double_integrator()
    >>> exact = RobustPreviewRHC(ex.system, ex.cost, M=4, E=orrc.Box(0.0, 0.0, n=2))
    >>> rhc = orrc.PreviewRHC(ex.system, ex.cost, M=4)
    >>> W = np.full((4, 2), 0.1)
    >>> u_robust = exact.plan(ex.x0, W).inputs[0]
    >>> bool(abs(u_robust - rhc.plan(ex.x0, W).inputs[0]).max() < 1e-8)
    True
    """

    def __init__(self, system: LinearSystem, cost: QuadraticCost, M: int, E: Box | Polytope | Ball, input_bounds=None):
        _check_lq("RobustPreviewRHC", system, cost)
        self.M = as_int("M", M, minimum=1)
        if not isinstance(E, (Box, Polytope, Ball)):
            raise OrrcValueError(f"E must be an orrc.Box, an orrc.Polytope or an orrc.Ball (the forecast's error "
                                 f"set); got {type(E).__name__}")
        if E.n != system.n:
            raise OrrcValueError(f"E must have the state dimension n={system.n} (the error adds to w_t); got a set "
                                 f"in R^{E.n}")
        E = check_set(E, system.n)
        self.exact = not isinstance(E, Ball)
        # a ball has no vertices: plan against the smallest box around it (a documented over-approximation)
        planned = Box(-E.radius, E.radius, n=E.n) if isinstance(E, Ball) else E
        n, m, M = system.n, system.m, self.M
        N = n * (M + 1)
        # ξ = (x, ŵ_0, ..., ŵ_{M-1}): x⁺ = A x + B u + ŵ_0 + e, the register shifts (ŵ_j ← ŵ_{j+1}, 0 in)
        A = np.zeros((N, N))
        A[:n, :n] = system.A
        A[:n, n:2 * n] = np.eye(n)
        A[n:N - n, 2 * n:] = np.eye(n * (M - 1))
        Bx = np.zeros((N, m))
        Bx[:n] = system.B
        Q = np.zeros((N, N))
        Q[:n, :n] = cost.Q
        self._aug = LinearSystem(A, Bx)
        self._aug_cost = QuadraticCost(Q, cost.R, alpha_lo=0.0)
        if isinstance(planned, Box):   # the error on the state's coordinates, nothing on the register's
            lo, hi = np.zeros(N), np.zeros(N)
            lo[:n], hi[:n] = planned.lo, planned.hi
            E_aug = Box(lo, hi)
        else:
            V = planned.vertices()
            E_aug = Polytope(np.hstack([V, np.zeros((len(V), N - n))]))
        self._solver = VertexEpigraph(self._aug, self._aug_cost, M, E_aug, input_bounds=input_bounds)
        self.system, self.cost, self.E = system, cost, E
        self.preview_w = M
        self.name = f"robust preview RHC (M={M})"
        self.reset()

    def plan(self, x, w_forecast):
        """The min-max plan from x for the forecast ``w_forecast`` (M, n) (rows past its length are
        zero): an :class:`orrc.solvers.minmax.MinMaxPlan` of the augmented problem, whose
        ``inputs`` (M, m) and ``value`` are the robust plan's."""
        n = self.system.n
        x = np.asarray(x, dtype=float).reshape(n)
        W = np.zeros((self.M, n))
        given = np.asarray(w_forecast, dtype=float).reshape(-1, n)[: self.M]
        W[: len(given)] = given
        return self._solver.solve(np.concatenate([x, W.reshape(-1)]))

    def reset(self) -> None:
        self._values: list[float] = []

    def control(self, obs: Observation) -> Decision:
        plan = self.plan(obs.x, obs.w_preview)
        self._values.append(plan.value)
        return Decision(u=np.array(plan.inputs[0], dtype=float), value=plan.value, success=plan.success,
                        status=plan.status, iterations=plan.iterations, solve_time=plan.solve_time,
                        fallback=plan.fallback, solver="vertex epigraph")

    def record(self) -> dict:
        """``value``: (T,) the min-max value of each step."""
        return {"value": np.array(self._values)}
