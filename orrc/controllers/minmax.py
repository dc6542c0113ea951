"""Algorithm 3 (Appendix D of the paper): min-max receding-horizon control, no disturbance preview."""
from __future__ import annotations

import warnings

import numpy as np

from .._validate import OrrcValueError, as_array, as_float, as_int, as_seed
from .._problem import check_problem
from ..costs import QuadraticCost, StageCost
from ..disturbances import Box, Polytope
from ..systems import LinearSystem, System
from ..solvers.minmax import AUTO_EXACT_LIMIT, MinMaxPlan, VertexEpigraph, check_set, vertex_count
from ..solvers.plan import SolverWarning
from ..solvers.scenario_tree import ScenarioTree
from .base import Controller, Decision, Observation
from .failures import DEFAULT_MAX_FAILURES, FailureLadder
from ._preview_setup import _bounds

METHODS = ("auto", "exact", "exchange", "game")
POLICIES = ("open-loop", "feedback")


class MinMaxRHC(Controller):
    """Algorithm 3 of the paper: at each t solve Eq. (D.1),

        min_{ũ_t..ũ_{t+M-1} ∈ U}  max_{w̃_t..w̃_{t+M-1} ∈ W}  Σ_{j=t}^{t+M-1} c_j(x̃_j, ũ_j)
        s.t.  x̃_{j+1} = f(x̃_j, ũ_j, w̃_j),  x̃_t = x_t,

    with the previewed costs c_{t:t+M-1} and NO preview of the disturbance (``preview_w = 0``,
    ``preview_c = M``: the simulator hands it no future w), and apply the first input
    u_t = κ_{W,M}(x_t). The optimal value is V^t_{W,M}(x_t).

    Open-loop (Algorithm 3 as written) and feedback min-max are two policies of one solver:

    * ``policy="open-loop"`` (default): the minimum is over input *sequences* ũ_t..ũ_{t+M-1}, chosen
      before any disturbance (the paper's problem);
    * ``policy="feedback"``: the minimum is over causal *policies*, ũ_j may depend on x̃_t..x̃_j
      (Scokaert and Mayne, 1998), the controller for which Lemma 6 is proved. For a
      :class:`~orrc.LinearSystem`, a :class:`~orrc.QuadraticCost` and a polytope W (an
      :class:`~orrc.Box` or an :class:`~orrc.Polytope`) it is one convex program on the scenario tree of
      W's vertices (:class:`orrc.solvers.scenario_tree.ScenarioTree`), exact; its value is
      V^fb_{W,M}(x) <= V_{W,M}(x). Only the root input is applied. The tree has 1 + V + ... + V^{M-1}
      nodes (V vertices); past ``orrc.solvers.scenario_tree.TREE_NODE_LIMIT`` it is refused with an
      :class:`~orrc.OrrcValueError`. Nonlinear systems, other costs and balls are refused.

    Parameters
    ----------
    system, cost : the model and the stage-cost family.
    M : the horizon (M >= 1).
    W : the disturbance set, an :class:`~orrc.Box` or :class:`~orrc.Ball` of dimension n (or an
        :class:`~orrc.Polytope` with ``policy="feedback"``).
    input_bounds : (lo, hi), the set U (scalars or length-m arrays).
    policy : "open-loop" (default) or "feedback", see above.
    method : "auto" (default), "exact", "exchange" or "game" (with ``policy="feedback"``: "auto" or
        "exact", both the scenario tree):

        * "exact" -- the vertex epigraph (:class:`orrc.solvers.minmax.VertexEpigraph`): a
          LinearSystem, a QuadraticCost and a box W; lower and upper bounds certified;
        * "exchange" -- scenario exchange (:class:`orrc.solvers.exchange.ScenarioExchange`):
          any system, cost and W;
        * "game" -- NOT the paper's problem: the soft-constrained linear-quadratic game
          min_u max_w Σ c - γ Σ ‖w‖² over feedback policies (``orrc.solvers.game``), for a
          LinearSystem and a QuadraticCost without input bounds; needs ``gamma``. W is not
          used by it (the disturbance is penalised instead of bounded);
        * "auto" -- "exact" when it applies and the vertex sequences number at most
          ``orrc.solvers.minmax.AUTO_EXACT_LIMIT`` (2^14), else "exchange".

    tol : relative tolerance on upper - lower (default 1e-9 exact, 1e-6 exchange).
    gamma : the game's penalty level (method="game" only).
    seed : seed of the exchange's random starts.
    exchange_options : extra keywords of ``ScenarioExchange`` (max_iter, n_starts, max_scenarios,
        solver, solver_options, verify_factor, atol).
    max_failures : consecutive failed steps before :class:`~orrc.SolverError` (the failure ladder of
        :mod:`orrc.controllers.failures`; None: never stop).

    Returns
    -------
    MinMaxRHC
        A controller for :func:`orrc.simulate`; :meth:`plan` solves one M-step problem.

    Examples
    --------
    >>> import numpy as np, orrc
    >>> ex = orrc.examples.scalar_unstable(A=1.2)
    >>> W = orrc.Box(-0.3, 0.3)
    >>> open_loop = orrc.MinMaxRHC(ex.system, ex.cost, 4, W)
    >>> feedback = orrc.MinMaxRHC(ex.system, ex.cost, 4, W, policy="feedback")
    >>> v_ol, v_fb = open_loop.plan(np.zeros(1)).value, feedback.plan(np.zeros(1)).value
    >>> bool(v_fb < v_ol), round(v_fb, 4)
    (True, 0.5274)

    A closed loop (``orrc.simulate``) warm-starts each step from the last successful plan (its
    inputs and its active scenarios or vertex sequences, shifted) and records, per step, the
    bounds, the iterations, the scenario and evaluation counts and the worst-case disturbance
    sequence found (``Trajectory.info``, from :meth:`record`). A failed solve climbs the failure
    ladder shared by the receding-horizon controllers: a cold retry, then the shifted last
    successful plan, then :class:`~orrc.SolverError`; ``orrc.simulate`` warns once per run. A direct
    :meth:`plan` call that fails warns once (:class:`~orrc.SolverWarning`) and returns the best plan
    found with ``success=False``.
    """

    name = "min-max RHC"

    def __init__(self, system: System, cost: StageCost, M: int, W, input_bounds=None, method: str = "auto",
                 tol: float | None = None, gamma: float | None = None, seed=0, exchange_options: dict | None = None,
                 max_failures: int | None = DEFAULT_MAX_FAILURES, policy: str = "open-loop"):
        check_problem(system, cost)
        self.M = as_int("M", M, minimum=1)
        self.system, self.cost = system, cost
        self.W = check_set(W, system.n)
        self.preview_w, self.preview_c = 0, self.M
        self.input_bounds = _bounds("input_bounds", input_bounds, system.m)
        if policy not in POLICIES:
            raise OrrcValueError(f"policy must be one of {list(POLICIES)}; got {policy!r}")
        self.policy = policy
        if method not in METHODS:
            raise OrrcValueError(f"method must be one of {list(METHODS)}; got {method!r}")
        if policy == "feedback":
            self._init_feedback(method, seed, max_failures)
            return
        if isinstance(self.W, Polytope):
            raise OrrcValueError("W is an orrc.Polytope: the open-loop methods take an orrc.Box or an orrc.Ball; "
                                 "use policy='feedback' (the scenario tree over the polytope's vertices) or a box")
        if exchange_options is not None and not isinstance(exchange_options, dict):
            raise OrrcValueError(f"exchange_options must be a dict; got {type(exchange_options).__name__}")
        lq = isinstance(system, LinearSystem) and isinstance(cost, QuadraticCost)
        exact_ok = lq and isinstance(self.W, Box)
        if method == "exact" and not exact_ok:
            raise OrrcValueError(
                "method='exact' needs a LinearSystem, a QuadraticCost (a convex cost) and a box W (the maximum of a "
                f"convex function over a box is at a vertex); got {type(system).__name__}, {type(cost).__name__}, "
                f"{type(self.W).__name__}: use method='exchange'")
        if method == "game" and not (lq and self.input_bounds is None):
            raise OrrcValueError("method='game' (the soft-constrained LQ game) needs a LinearSystem, a QuadraticCost "
                                 "and no input bounds")
        if method == "auto":
            method = "exact" if exact_ok and vertex_count(self.W, self.M) <= AUTO_EXACT_LIMIT else "exchange"
        self.method = method
        as_seed("seed", seed)      # checked whatever the method (only the exchange draws from it)
        self.seed = seed
        if tol is not None:
            tol = as_float("tol", tol, minimum=0.0, strict_min=True, maximum=1.0)
        self.gamma = None
        self._solver = None
        if method == "exact":
            self._solver = VertexEpigraph(system, cost, self.M, self.W, self.input_bounds,
                                          rtol=1e-9 if tol is None else tol)
        elif method == "exchange":
            from ..solvers.exchange import ScenarioExchange

            opts = dict(exchange_options or {})
            self._solver = ScenarioExchange(system, cost, self.M, self.W, self.input_bounds,
                                            rtol=1e-6 if tol is None else tol, seed=seed, **_exchange_options(opts))
        else:
            if gamma is None:
                raise OrrcValueError("method='game' needs gamma, the penalty on Σ‖w‖² of the soft-constrained game")
            self.gamma = as_float("gamma", gamma, minimum=0.0, strict_min=True)
            from ..solvers import game

            self._game = game.finite_horizon_game(system.A, system.B, cost.Q, cost.R, self.gamma, self.M)
        self._ladder = FailureLadder(self.M, max_failures, name=self.name)
        self.reset()

    def _init_feedback(self, method, seed, max_failures) -> None:
        """policy="feedback": the scenario tree of W's vertices (linear system, quadratic cost, polytope W)."""
        system, cost = self.system, self.cost
        if not (isinstance(system, LinearSystem) and isinstance(cost, QuadraticCost)):
            raise OrrcValueError(
                "policy='feedback' needs a LinearSystem and a QuadraticCost (the worst case of a convex cost over a "
                f"polytope sits at its vertices, so the scenario tree is exact); got {type(system).__name__}, "
                f"{type(cost).__name__}: for a nonlinear system use policy='open-loop' with method='exchange'")
        if not isinstance(self.W, (Box, Polytope)):
            raise OrrcValueError(f"policy='feedback' needs a polytope W (an orrc.Box or an orrc.Polytope); got "
                                 f"{type(self.W).__name__}")
        if method not in ("auto", "exact"):
            raise OrrcValueError(f"policy='feedback' solves the scenario tree exactly: method must be 'auto' or "
                                 f"'exact'; got {method!r}")
        as_seed("seed", seed)
        self.seed, self.gamma, self.method = seed, None, "exact"
        self.name = "feedback min-max RHC"
        self._solver = ScenarioTree(system, cost, self.M, self.W, self.input_bounds)
        self._ladder = FailureLadder(self.M, max_failures, name=self.name)
        self.reset()

    # -- the M-step problem -------------------------------------------------------
    def _params(self, cost_params):
        """The (M, n_params) cost parameters of c_t..c_{t+M-1}, or None for the time-invariant cost."""
        if cost_params is None:
            return None
        P = as_array("cost_params", cost_params)
        n = self.system.n
        if P.ndim == 2 and P.shape[1] == n and self.cost.n_params != n:
            raise OrrcValueError(
                f"cost_params has shape {P.shape}, like a disturbance preview (M, n) = ({self.M}, {n}); Algorithm 3 has "
                "no disturbance preview (preview_w = 0): plan(x) takes the state and, optionally, the parameters "
                f"(M, {self.cost.n_params}) of the previewed costs")
        P = self.cost.check_params(P)
        if P.shape[0] < self.M:
            raise OrrcValueError(f"cost_params must have at least M={self.M} rows; got shape {P.shape}")
        return P[: self.M]

    def plan(self, x, cost_params=None, warm_start: MinMaxPlan | None = None, **kwargs) -> MinMaxPlan:
        """Solve the min-max problem (D.1) from state ``x`` (n,): a :class:`~orrc.solvers.minmax.MinMaxPlan`.

        ``.inputs`` (M, m), ``.value`` = V_{W,M}(x) (the worst-case cost of the plan over the
        disturbances searched), ``.worst_w`` (M, n) the worst-case disturbance sequence found,
        ``.lower`` <= V_{W,M}(x) <= ``.upper`` (certified for the exact method, see
        ``.certified``), ``.status`` and ``.success``. ``cost_params`` (M, n_params): the
        previewed costs (default: the cost's own). ``warm_start``: a previous plan, shifted one
        stage (only speeds the solve up). There is no disturbance argument: Algorithm 3 does not
        preview w.
        """
        if kwargs:
            names = sorted(kwargs)
            if any(k in ("w", "W", "w_preview", "disturbance", "disturbances") for k in names):
                raise OrrcValueError(
                    f"MinMaxRHC.plan got {names}: Algorithm 3 has no disturbance preview (preview_w = 0); it plans "
                    "against every disturbance sequence in W")
            raise OrrcValueError(f"MinMaxRHC.plan got unknown arguments {names}; allowed: x, cost_params, warm_start")
        x = as_array("x", x, (self.system.n,))
        self._check_warm_start(warm_start)
        P = self._params(cost_params)
        plan = FailureLadder.attempt(self._rungs(x, P, warm_start, 1))
        if not plan.success:
            plan.fallback = "the best plan the solver found"
            warnings.warn(f"MinMaxRHC.plan: the {self.method} min-max solve did not succeed ({plan.status}); the plan "
                          f"holds {plan.fallback} (plan.success is False)", SolverWarning, stacklevel=2)
        return plan

    def _check_warm_start(self, warm_start) -> None:
        """A warm start is a MinMaxPlan of this problem's shapes (a plan of another horizon or system is refused)."""
        if warm_start is None:
            return
        if not isinstance(warm_start, MinMaxPlan):
            raise OrrcValueError(f"warm_start must be a MinMaxPlan from MinMaxRHC.plan; got "
                                 f"{type(warm_start).__name__}")
        M, n, m = self.M, self.system.n, self.system.m
        as_array("warm_start.inputs", warm_start.inputs, (M, m))
        if warm_start.worst_w is not None:
            as_array("warm_start.worst_w", warm_start.worst_w, (M, n))

    def _rungs(self, x, P, prev: MinMaxPlan | None, k: int):
        """The ways of solving one min-max problem, in the order the failure ladder tries them: warm-started
        from ``prev`` (a successful plan k steps old) when given, then cold."""
        rungs = []
        if prev is not None:
            if self.policy == "open-loop":      # the tree program has no warm start
                rungs.append(("warm start", lambda: self._solve(x, P, prev, k)))
        rungs.append(("cold start", lambda: self._solve(x, P, None, 0)))
        return rungs

    def _solve(self, x, P, prev: MinMaxPlan | None, k: int) -> MinMaxPlan:
        """One solve; ``prev`` (a plan k >= 1 steps old) shifted by k stages is the warm start."""
        M = self.M
        if self.policy == "feedback":
            return self._solver.solve(x, P)
        guess = None if prev is None else np.vstack([prev.inputs[k:], np.repeat(prev.inputs[-1:], k, axis=0)])
        if self.method == "exact":
            working = None if prev is None else self._solver.shift(prev.extra.get("active", []), k)
            return self._solver.solve(x, P, guess, working)
        if self.method == "exchange":
            Pm = np.broadcast_to(self.cost.default_params, (M, self.cost.n_params)) if P is None else P
            guess, scen = (None, None) if prev is None else self._solver.shifted(prev, k)
            return self._solver.solve(x, np.asarray(Pm, float), guess, scen)
        return self._game_plan(x, P)

    def _game_plan(self, x, P) -> MinMaxPlan:
        """The saddle point of the soft-constrained game from x: u_j = -K_j x_j, w_j = Kw_j x_j."""
        if P is not None:
            raise OrrcValueError("method='game' uses the time-invariant QuadraticCost; time-varying cost_params "
                                 "are not supported")
        g = self._game
        M, n = self.M, self.system.n
        A, B = self.system.A, self.system.B
        X = np.empty((M + 1, n))
        U = np.empty((M, self.system.m))
        Wg = np.empty((M, n))
        X[0] = x
        for j in range(M):
            U[j] = -g.K[j] @ X[j]
            Wg[j] = g.Kw[j] @ X[j]
            X[j + 1] = A @ X[j] + B @ U[j] + Wg[j]
        v = float(g.value(x))
        return MinMaxPlan(inputs=U, states=X, value=v, worst_w=Wg, lower=v, upper=v, method="game", certified=True,
                          status=f"soft-constrained game (gamma={self.gamma:g}): the value of min_u max_w "
                                 "Σ c - gamma Σ‖w‖², not V_(W,M)")

    # -- the controller -----------------------------------------------------------
    def reset(self) -> None:
        self._ladder.reset()
        self._good: tuple[int, MinMaxPlan] | None = None
        self._log = []

    def control(self, obs: Observation) -> Decision:
        if obs.w_preview is not None and np.size(obs.w_preview):
            raise OrrcValueError(
                f"MinMaxRHC got a disturbance preview of shape {np.shape(obs.w_preview)}; Algorithm 3 has no "
                "disturbance preview (preview_w = 0): it plans against every sequence in W")
        P = None if obs.cost_params is None else obs.cost_params[: self.M]
        prev, k = None, 0
        if self._good is not None and 1 <= obs.t - self._good[0] < self.M:
            k, prev = obs.t - self._good[0], self._good[1]
        plan = self._ladder.step(obs.t, self._rungs(obs.x, P, prev, k))
        if plan.success:
            self._good = (obs.t, plan)
        self._log.append(plan)
        return Decision(u=plan.inputs[0].copy(), value=plan.value, success=plan.success, status=plan.status,
                        iterations=plan.iterations, solve_time=plan.solve_time, fallback=plan.fallback)

    def record(self) -> dict:
        """Per step t: ``lower``, ``upper`` (the bounds on V^t_{W,M}), ``gap``, ``iterations``,
        ``scenarios`` (outer problem size), ``evaluations``, ``certified`` and ``worst_w``
        (T, M, n), the worst-case disturbance sequence found; ``method`` (a string)."""
        log = self._log
        if not log:
            return {"method": self.method}
        lower = np.array([p.lower for p in log])
        upper = np.array([p.upper for p in log])
        return {"method": self.method, "lower": lower, "upper": upper, "gap": upper - lower,
                "iterations": np.array([p.iterations for p in log]),
                "scenarios": np.array([p.scenarios for p in log]),
                "evaluations": np.array([p.evaluations for p in log]),
                "certified": np.array([p.certified for p in log]),
                "worst_w": np.array([p.worst_w for p in log])}

    def __repr__(self):
        return (f"MinMaxRHC(M={self.M}, policy={self.policy!r}, method={self.method!r}, W={self.W!r}, "
                f"system={self.system!r})")


_EXCHANGE_KEYS = ("max_iter", "n_starts", "max_scenarios", "solver", "solver_options", "verify_factor", "atol")


def _exchange_options(opts: dict) -> dict:
    from .._validate import check_options

    check_options("exchange_options", opts, _EXCHANGE_KEYS)
    out = dict(opts)
    for key in ("max_iter", "n_starts", "max_scenarios", "verify_factor"):
        if key in out:
            out[key] = as_int(f"exchange_options[{key!r}]", out[key], minimum=1)
    if "solver" in out and out["solver"] not in ("sqpmethod", "ipopt"):
        raise OrrcValueError(f"exchange_options['solver'] must be 'sqpmethod' or 'ipopt'; got {out['solver']!r}")
    if "atol" in out:
        out["atol"] = as_float("exchange_options['atol']", out["atol"], minimum=0.0)
    if "solver_options" in out and not isinstance(out["solver_options"], dict):
        raise OrrcValueError(f"exchange_options['solver_options'] must be a dict; got "
                             f"{type(out['solver_options']).__name__}")
    return out
