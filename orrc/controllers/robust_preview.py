"""Robust preview RHC: min-max receding-horizon control around a forecast, beyond the paper.

At step t, with the forecast ŵ_{t:t+M-1|t} and a set E that holds each forecast error,

    min_{ũ_0..ũ_{M-1} ∈ U}  max_{ê_0..ê_{M-1} ∈ E}  Σ_{j=0}^{M-1} c(x̃_j, ũ_j),
    x̃_{j+1} = f(x̃_j, ũ_j, ŵ_{t+j|t} + ê_j),  x̃_0 = x_t,

and u_t = ũ_0. E = {0} is Algorithm 1 on the forecast; a zero forecast and E = W is Algorithm 3's
open-loop min-max (Eq. D.1). Two methods, both Algorithm 3's (:class:`~orrc.MinMaxRHC`):

* ``method="exact"``: a linear system, a convex quadratic cost and a box or polytope E; the
  forecast window is appended to the state (a shift register) and the problem is Algorithm 3's
  vertex epigraph on that augmented system;
* ``method="exchange"``: any system and stage cost, E a box or a ball; Algorithm 3's scenario
  exchange with the forecast entering as a parameter (``ScenarioExchange(nominal=True)``): an
  approximation, see :class:`RobustPreviewRHC`.
"""
from __future__ import annotations

import warnings

import numpy as np

from .._problem import check_problem
from .._validate import OrrcValueError, as_array, as_float, as_seed, as_int
from ..costs import QuadraticCost, StageCost
from ..disturbances import Ball, Box, Polytope
from ..solvers.exchange import ScenarioExchange
from ..solvers.minmax import MinMaxPlan, VertexEpigraph, check_set
from ..solvers.plan import SolverWarning
from ..systems import LinearSystem, System
from ._preview_setup import _bounds
from .base import Controller, Decision, Observation
from .failures import DEFAULT_MAX_FAILURES, FailureLadder
from .minmax import _exchange_options

__all__ = ["RobustPreviewRHC"]

METHODS = ("auto", "exact", "exchange")


class RobustPreviewRHC(Controller):
    """Min-max receding-horizon control around a forecast: at step t,

        min_{U}  max_{ê_0..ê_{M-1} ∈ E}  Σ_{j=0}^{M-1} c(x̃_j, ũ_j),
        x̃_{j+1} = f(x̃_j, ũ_j, ŵ_{t+j|t} + ê_j),  x̃_0 = x_t,

    and u_t = ũ_0. E = {0} gives Algorithm 1 on the forecast; a zero forecast and E = W give
    Algorithm 3's open-loop min-max (:class:`~orrc.MinMaxRHC`, Eq. D.1) by the same method.

    **method="exact"** (the default for a :class:`~orrc.LinearSystem` with a
    :class:`~orrc.QuadraticCost`): exact for a box or a polytope E, since the worst case of a convex
    cost sits at E's vertices; for a ball E (no vertices) it plans against the smallest box around
    the ball, an over-approximation whose value bounds the ball's min-max value from above
    (``exact`` is False then). The state is augmented with the forecast window (a shift register),
    so that the problem is Algorithm 3's exact vertex epigraph
    (:class:`orrc.solvers.minmax.VertexEpigraph`) on the augmented system, with the error set on the
    state's coordinates and nothing on the register's. Its size is that of Algorithm 3: V^(M-1)
    vertex sequences (V = 2^n for a box, the number of given points for a polytope), estimated and
    refused past ``orrc.config``'s limits.

    **method="exchange"** (the default otherwise: a nonlinear system or a general stage cost; a box
    or a ball E): Algorithm 3's scenario exchange (:class:`orrc.solvers.exchange.ScenarioExchange`)
    with the forecast as a parameter of its problems, so nothing is rebuilt from step to step. It
    is an approximation, and ``exact`` is False:

    * the inner maximum over E^M is searched locally (multi-start ascent from the vertices or the
      sphere of E): ``upper``, the plan's worst cost over the error sequences found, is a *lower*
      bound of that plan's true worst cost, and equals it only when the search found the global
      maximum;
    * the outer minimum over the plans is taken against the error sequences found: ``lower`` is a
      lower bound of the min-max value when that problem is solved to global optimality (a linear
      system with a convex cost), a local minimum's value otherwise.

    The exchange stops when ``upper - lower <= tol·|upper|``; ``value`` is ``upper``, and the gap
    ``upper - lower`` of each step is recorded. Nothing in it is certified (``certified`` False).
    Its CasADi problems are sized first and refused past ``orrc.config``'s limits, as Algorithm 3's.

    A failed solve (the exchange not converging, its outer problem failing) climbs the failure
    ladder shared by the receding-horizon controllers (:mod:`orrc.controllers.failures`): a cold
    retry, then the shifted last successful plan, then :class:`~orrc.SolverError` after
    ``max_failures`` consecutive failed steps; ``orrc.simulate`` reports the failed steps once. A
    direct :meth:`plan` call that fails warns (:class:`~orrc.SolverWarning`) and returns the best
    plan found with ``success=False``.

    Parameters
    ----------
    system : LinearSystem or System
        The model f(x, u, w).
    cost : QuadraticCost or StageCost
        The stage cost c(x, u) (``method="exchange"``: any stage cost; its parameters, when the
        problem's costs vary in time, are previewed M steps as Algorithm 3's).
    M : int
        The horizon, M >= 1.
    E : Box, Polytope or Ball
        The forecast's error set in R^n (``Box(0, 0, n)`` for an exact forecast). A polytope needs
        ``method="exact"``.
    input_bounds : (lo, hi), optional
        The set U (scalars or length-m arrays).
    method : "auto", "exact" or "exchange", default "auto"
        "auto": "exact" for a LinearSystem with a QuadraticCost, "exchange" otherwise.
    tol : float, optional
        Relative tolerance on upper - lower (default 1e-9 exact, 1e-6 exchange).
    seed : int, default 0
        Seed of the exchange's random starts (deterministic).
    exchange_options : dict, optional
        Extra keywords of ``ScenarioExchange``, as for :class:`~orrc.MinMaxRHC`.
    max_failures : int or None, default 3
        Consecutive failed steps before :class:`~orrc.SolverError` (None: never stop).

    Returns
    -------
    RobustPreviewRHC
        A controller for :func:`orrc.simulate` with ``forecast=``; its ``record()``
        (``Trajectory.info``) holds, per step, ``value`` (the min-max value found), ``lower``,
        ``upper`` and ``gap``; ``exact`` says whether ``value`` is the min-max over E itself.

    Examples
    --------
    The exact method: with E = {0} it is Algorithm 1 on the forecast.

    >>> import numpy as np
    >>> import orrc
    >>> ex = orrc.examples.double_integrator()
    >>> exact = orrc.RobustPreviewRHC(ex.system, ex.cost, M=4, E=orrc.Box(0.0, 0.0, n=2))
    >>> rhc = orrc.PreviewRHC(ex.system, ex.cost, M=4)
    >>> W = np.full((4, 2), 0.1)
    >>> u_robust = exact.plan(ex.x0, W).inputs[0]
    >>> bool(abs(u_robust - rhc.plan(ex.x0, W).inputs[0]).max() < 1e-8)
    True

    The nonlinear pendulum, errors of at most 0.05 on the angular velocity: the exchange's plan
    and the worst error sequence it found.

    >>> pend = orrc.examples.inverted_pendulum()
    >>> E = orrc.Box([0.0, -0.05], [0.0, 0.05])
    >>> robust = orrc.RobustPreviewRHC(pend.system, pend.cost, M=6, E=E,
    ...                                input_bounds=pend.input_bounds)
    >>> plan = robust.plan(pend.x0, np.zeros((6, 2)))
    >>> robust.method, robust.exact, plan.success, plan.worst_w.shape
    ('exchange', False, True, (6, 2))
    """

    def __init__(self, system: System, cost: StageCost, M: int, E: Box | Polytope | Ball, input_bounds=None,
                 method: str = "auto", tol: float | None = None, seed=0, exchange_options: dict | None = None,
                 max_failures: int | None = DEFAULT_MAX_FAILURES):
        check_problem(system, cost)
        self.M = as_int("M", M, minimum=1)
        if not isinstance(E, (Box, Polytope, Ball)):
            raise OrrcValueError(f"E must be an orrc.Box, an orrc.Polytope or an orrc.Ball (the forecast's error "
                                 f"set); got {type(E).__name__}")
        if E.n != system.n:
            raise OrrcValueError(f"E must have the state dimension n={system.n} (the error adds to w_t); got a set "
                                 f"in R^{E.n}")
        E = check_set(E, system.n)
        if method not in METHODS:
            raise OrrcValueError(f"method must be one of {list(METHODS)}; got {method!r}")
        lq = isinstance(system, LinearSystem) and isinstance(cost, QuadraticCost)
        if method == "auto":
            method = "exact" if lq else "exchange"
        if method == "exact" and not lq:
            raise OrrcValueError(f"method='exact' (the vertex epigraph) needs an orrc.LinearSystem and an "
                                 f"orrc.QuadraticCost; got {type(system).__name__} and {type(cost).__name__}: use "
                                 "method='exchange' (scenario exchange, any system and stage cost)")
        if method == "exchange" and isinstance(E, Polytope):
            raise OrrcValueError("E is an orrc.Polytope: method='exchange' (scenario exchange, the method for a "
                                 "nonlinear system or a general cost) takes an orrc.Box or an orrc.Ball as E")
        if exchange_options is not None and (method != "exchange" or not isinstance(exchange_options, dict)):
            raise OrrcValueError(f"exchange_options must be a dict, with method='exchange'; got "
                                 f"{type(exchange_options).__name__} with method={method!r}")
        as_seed("seed", seed)
        if tol is not None:
            tol = as_float("tol", tol, minimum=0.0, strict_min=True, maximum=1.0)
        self.system, self.cost, self.E, self.method, self.seed = system, cost, E, method, seed
        self.input_bounds = _bounds("input_bounds", input_bounds, system.m)
        self.preview_w = self.M
        self.name = f"robust preview RHC (M={self.M})"
        if method == "exact":
            self.exact = not isinstance(E, Ball)
            self._solver = self._vertex_epigraph(1e-9 if tol is None else tol)
        else:
            self.exact = False
            self.preview_c = self.M          # a time-varying cost is previewed as in Algorithm 3
            self._solver = ScenarioExchange(system, cost, self.M, E, self.input_bounds,
                                            rtol=1e-6 if tol is None else tol, seed=seed, nominal=True,
                                            **_exchange_options(dict(exchange_options or {})))
        self._ladder = FailureLadder(self.M, max_failures, name=self.name)
        self.reset()

    def _vertex_epigraph(self, rtol: float) -> VertexEpigraph:
        """Algorithm 3's vertex epigraph on the state augmented with the forecast window."""
        system, cost, E = self.system, self.cost, self.E
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
        aug, aug_cost = LinearSystem(A, Bx), QuadraticCost(Q, cost.R, alpha_lo=0.0)
        if isinstance(planned, Box):   # the error on the state's coordinates, nothing on the register's
            lo, hi = np.zeros(N), np.zeros(N)
            lo[:n], hi[:n] = planned.lo, planned.hi
            E_aug = Box(lo, hi)
        else:
            V = planned.vertices()
            E_aug = Polytope(np.hstack([V, np.zeros((len(V), N - n))]))
        return VertexEpigraph(aug, aug_cost, M, E_aug, input_bounds=self.input_bounds, rtol=rtol)

    # -- the M-step problem -------------------------------------------------------------------------
    def _window(self, w_forecast) -> np.ndarray:
        """The forecast (M, n): the rows given (at most M), zeros past them."""
        n = self.system.n
        given = as_array("w_forecast", w_forecast)
        if given.ndim != 2 or given.shape[1] != n:
            raise OrrcValueError(f"w_forecast must be an array (k, n={n}) of forecast rows (the first M={self.M} "
                                 f"are used, zeros past the last); got shape {given.shape}")
        W = np.zeros((self.M, n))
        given = given[: self.M]
        W[: len(given)] = given
        return W

    def _params(self, cost_params, W) -> np.ndarray:
        """The exchange's parameters (M, n_params + n): each stage's cost parameters, then ŵ_j."""
        cost, M = self.cost, self.M
        if cost_params is None:
            P = np.broadcast_to(cost.default_params, (M, cost.n_params))
        else:
            P = cost.check_params(as_array("cost_params", cost_params))
            if P.shape[0] < M:
                raise OrrcValueError(f"cost_params must have at least M={M} rows; got shape {P.shape}")
            P = P[:M]
        return np.hstack([np.asarray(P, dtype=float), W])

    def _solve(self, x, W, cost_params, prev: MinMaxPlan | None, k: int) -> MinMaxPlan:
        """One solve; ``prev`` (a plan k >= 1 steps old) shifted by k stages is the exchange's warm start."""
        if self.method == "exact":
            if cost_params is not None:
                raise OrrcValueError("method='exact' uses the time-invariant QuadraticCost; time-varying "
                                     "cost_params need method='exchange'")
            return self._solver.solve(np.concatenate([x, W.reshape(-1)]))
        guess, scenarios = (None, None) if prev is None else ScenarioExchange.shifted(prev, k)
        return self._solver.solve(x, self._params(cost_params, W), guess, scenarios)

    def _rungs(self, x, W, cost_params, prev, k):
        rungs = []
        if prev is not None and self.method == "exchange":
            rungs.append(("warm start", lambda: self._solve(x, W, cost_params, prev, k)))
        rungs.append(("cold start", lambda: self._solve(x, W, cost_params, None, 0)))
        return rungs

    def plan(self, x, w_forecast, cost_params=None) -> MinMaxPlan:
        """The min-max plan from x for the forecast ``w_forecast`` (M, n) (rows past its length are
        zero): an :class:`orrc.solvers.minmax.MinMaxPlan` whose ``inputs`` (M, m), ``value``,
        ``lower`` and ``upper`` are the robust plan's (method="exact": of the augmented problem,
        whose ``states`` hold the forecast register too). With method="exchange", ``worst_w`` (M, n)
        is the worst *error* sequence found and ``states`` (M+1, n) the states under ŵ + ê;
        ``cost_params`` (M, n_params) are the previewed costs' parameters (default: the cost's own)."""
        x = as_array("x", x, (self.system.n,))
        W = self._window(w_forecast)
        plan = FailureLadder.attempt(self._rungs(x, W, cost_params, None, 0))
        if not plan.success:
            plan.fallback = "the best plan the solver found"
            warnings.warn(f"RobustPreviewRHC.plan: the {self.method} min-max solve did not succeed ({plan.status}); "
                          f"the plan holds {plan.fallback} (plan.success is False)", SolverWarning, stacklevel=2)
        return plan

    # -- the controller -------------------------------------------------------------------------------
    def reset(self) -> None:
        self._ladder.reset()
        self._good: tuple[int, MinMaxPlan] | None = None
        self._log: list[MinMaxPlan] = []

    def control(self, obs: Observation) -> Decision:
        W = self._window(obs.w_preview)
        P = None if obs.cost_params is None else obs.cost_params[: self.M]
        prev, k = None, 0
        if self._good is not None and 1 <= obs.t - self._good[0] < self.M:
            k, prev = obs.t - self._good[0], self._good[1]
        plan = self._ladder.step(obs.t, self._rungs(obs.x, W, P, prev, k))
        if plan.success:
            self._good = (obs.t, plan)
        self._log.append(plan)
        return Decision(u=np.array(plan.inputs[0], dtype=float), value=plan.value, success=plan.success,
                        status=plan.status, iterations=plan.iterations, solve_time=plan.solve_time,
                        fallback=plan.fallback, solver="vertex epigraph" if self.method == "exact" else "exchange")

    def record(self) -> dict:
        """Per step: ``value`` (T,), the min-max value found (NaN at a failed step), ``lower``,
        ``upper`` and ``gap`` = upper - lower (T,); ``method`` (a string)."""
        log = self._log
        lower = np.array([p.lower for p in log])
        upper = np.array([p.upper for p in log])
        return {"method": self.method, "value": np.array([p.value for p in log]), "lower": lower, "upper": upper,
                "gap": upper - lower}

    def __repr__(self):
        return f"RobustPreviewRHC(M={self.M}, method={self.method!r}, E={self.E!r}, system={self.system!r})"
