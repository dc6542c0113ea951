"""Baselines a reader compares Algorithm 1 against, as controllers of the same simulator.

* :class:`LQR` -- the infinite-horizon discrete LQR/H2 gain u = -K x, no preview
  (``control.dlqr``);
* :class:`Clairvoyant` -- the best input sequence in hindsight: it sees the whole
  disturbance and cost sequence (preview T) and plays the T-step optimum; its cost
  is the comparator of dynamic regret;
* :class:`ZeroInput` -- u = 0, the open loop.
"""
from __future__ import annotations

import numpy as np

from .._validate import OrrcValueError, as_int
from .._problem import check_problem
from ..costs import QuadraticCost, StageCost
from ..systems import LinearSystem, System
from .base import Controller, Decision, Observation
from .failures import LAST_ITERATE
from .preview import PreviewRHC


class LQR(Controller):
    """u_t = -K x_t with K the infinite-horizon discrete LQR gain for (A, B, Q, R).

    ``control.dlqr`` solves the discrete algebraic Riccati equation. For a
    :class:`~orrc.NonlinearSystem` the gain of its linearisation at the origin is used.
    No preview: it never sees w or future costs.

    Parameters
    ----------
    system : a :class:`~orrc.LinearSystem` (or a :class:`~orrc.NonlinearSystem`, linearised at 0).
    cost : the :class:`~orrc.QuadraticCost` (Q, R).

    Examples
    --------
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(L=60, n=2, radius=0.1, seed=0)
    >>> lqr = orrc.LQR(di.system, di.cost)
    >>> lqr.K.round(4)
    array([[2.7623, 2.5075]])
    >>> print(f"{orrc.simulate(di.system, lqr, di.x0, w, T=50).costs.sum():.4f}")
    10.5812
    """

    name = "LQR"

    def __init__(self, system: System, cost: QuadraticCost):
        import control

        check_problem(system, cost, quadratic=True, who="LQR")
        A, B = (system.A, system.B) if isinstance(system, LinearSystem) else system.linearize()
        try:
            K, S, _ = control.dlqr(A, B, cost.Q, cost.R)
        except Exception as exc:
            raise OrrcValueError(f"no stabilising LQR gain for this (A, B, Q, R): {exc}") from exc
        self.K, self.S = np.asarray(K), np.asarray(S)
        self.system, self.cost = system, cost

    def control(self, obs: Observation) -> Decision:
        return Decision(u=-self.K @ obs.x)


class ZeroInput(Controller):
    """u_t = 0 (the uncontrolled system).

    Parameters
    ----------
    m : the number of inputs.
    cost : the stage cost to record along the run (or pass ``costs=`` to :func:`orrc.simulate`).

    Examples
    --------
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(L=60, n=2, radius=0.1, seed=0)
    >>> traj = orrc.simulate(di.system, orrc.ZeroInput(1, di.cost), di.x0, w, T=50)
    >>> print(f"{traj.costs.sum():.4f}", float(abs(traj.u).max()))
    61.6160 0.0
    """

    name = "zero input"

    def __init__(self, m: int, cost: StageCost | None = None):
        self.m = as_int("m", m, minimum=1)
        if cost is not None and not isinstance(cost, StageCost):
            raise OrrcValueError(f"cost must be an orrc stage cost or None; got {type(cost).__name__}")
        self.cost = cost

    def control(self, obs: Observation) -> Decision:
        return Decision(u=np.zeros(self.m))


class Clairvoyant(Controller):
    """The optimum in hindsight over T steps: min Σ_{t<T} c_t(x_t, u_t) knowing all of w and c.

    It declares a preview of T (it is not a causal controller), solves the T-step
    problem once at t = 0 with the same machinery as Algorithm 1 (exact Riccati
    for LQ, CasADi otherwise) and plays the plan. Its trajectory cost is the
    comparator of :func:`orrc.dynamic_regret`. It must be simulated for the T it was built for.

    A failed solve (retried once from a cold start) is one failure, at t = 0: that step is
    marked ``success=False`` with its fallback (the solver's last iterate, played for the whole
    run); the later steps solve nothing and are not failures. :func:`orrc.simulate` warns once.

    Parameters
    ----------
    system, cost : the model and the stage-cost family.
    T : the horizon it is built and simulated for.
    input_bounds : (lo, hi), the set U.
    solver_options : options for the CasADi path.

    Examples
    --------
    The reference of the dynamic regret:

    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(L=60, n=2, radius=0.1, seed=0)
    >>> best = orrc.simulate(di.system, orrc.Clairvoyant(di.system, di.cost, T=50),
    ...                      di.x0, w, T=50)
    >>> print(f"{best.costs.sum():.4f}")
    9.6894
    """

    name = "clairvoyant optimum"

    def __init__(self, system: System, cost: StageCost, T: int, input_bounds=None, solver_options=None):
        self.T = as_int("T", T, minimum=1)
        self.preview_w = self.preview_c = self.T
        self.cost = cost
        self._rhc = PreviewRHC(system, cost, self.T, input_bounds=input_bounds, solver_options=solver_options)
        self.system = self._rhc.system
        self._plan = None

    def check_run(self, system, T: int) -> None:
        super().check_run(system, T)
        if T != self.T:
            raise OrrcValueError(f"Clairvoyant(T={self.T}) plans the {self.T}-step optimum in hindsight; simulate "
                                 f"it for T={self.T} (got T={T}), or build Clairvoyant(..., T={T})")

    def reset(self) -> None:
        self._plan = None

    def control(self, obs: Observation) -> Decision:
        if obs.t == 0:
            x, W, P = self._rhc._check_preview(obs.x, obs.w_preview, obs.cost_params)
            self._plan = self._rhc._plan(x, W, P, obs.cost_params is None, None)
            if not self._plan.success:
                self._plan.fallback = LAST_ITERATE
        elif self._plan is None:
            raise OrrcValueError("Clairvoyant must be run from t = 0 (call orrc.simulate)")
        if obs.t >= self.T:
            raise OrrcValueError(f"Clairvoyant(T={self.T}) has no input for step t={obs.t}; simulate it for "
                                 f"T={self.T}")
        p = self._plan
        if obs.t > 0:  # no solve at this step: played from the plan of t = 0
            return Decision(u=p.inputs[obs.t].copy(), status="played from the plan of t = 0")
        value = p.value if p.success else float("nan")
        return Decision(u=p.inputs[0].copy(), value=value, success=p.success, status=p.status,
                        iterations=p.iterations, solve_time=p.solve_time, fallback=p.fallback)
