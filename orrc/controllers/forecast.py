"""Controllers for a preview that may be wrong (:mod:`orrc.forecasts`), beyond the paper.

* :class:`LambdaConfident`: the λ-confident policy of Li et al. (2022) on Algorithm 1's exact LQ
  law, u_t = −K x_t − λ L vec ŵ_{t:t+M-1|t}: λ = 1 trusts the forecast (Algorithm 1 on it,
  certainty equivalence), λ = 0 ignores it; ``lam="self-tuning"`` learns λ_t from the forecasts'
  past errors.
* :class:`RobustPreviewRHC` (defined in :mod:`orrc.controllers.robust_preview`): min-max over the
  forecast's error set E, min_U max_{ê ∈ E^M} J(x, U, ŵ + ê). It is Algorithm 1 on the forecast
  when E = {0}, and Algorithm 3's open-loop min-max when the forecast is zero and E = W: one set
  moves between the paper's two settings. Exact for a linear system, a quadratic cost and a box or
  polytope E; by Algorithm 3's scenario exchange, an approximation, for any other system or cost.
"""
from __future__ import annotations

import numpy as np

from .._validate import OrrcValueError, as_float, as_int
from ..costs import QuadraticCost
from ..solvers import lq
from ..systems import LinearSystem
from .base import Controller, Decision, Observation
from .robust_preview import RobustPreviewRHC

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
