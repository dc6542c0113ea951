"""Algorithm 1: preview receding-horizon control (known system).

The controller: the M-step problem of Eq. (3) solved from each state (exact LQ law, exact QP or
CasADi with the failure ladder) and its first input applied. Which problem a set of arguments
defines (input/state bounds, terminal cost) and which solver fits it is decided in
``orrc.controllers._preview_setup``.
"""
from __future__ import annotations

import functools
import threading
import warnings

import numpy as np

from .._casadi import DropsBuffers
from .._validate import OrrcValueError, as_array, as_int
from .._problem import check_problem
from ..costs import StageCost
from ..systems import System
from ..solvers import lq
from ..solvers.nlp import SOLVER_LABELS, SQP, ShootingNLP
from ..solvers.plan import Plan, SolverWarning
from ..solvers.qp import L1QP
from ..solvers.warm_sqp import WarmSQP
from .base import Controller, Decision, Observation
# SOLVER_CHOICES stays importable from this module (the values of PreviewRHC(solver=...))
from ._preview_setup import _NLP_LADDERS, SOLVER_CHOICES, _bounds, _check_solver, _pick_solver, _terminal
from ._preview_step import _StepArguments
from .failures import DEFAULT_MAX_FAILURES, FailureLadder


class PreviewRHC(DropsBuffers, _StepArguments, Controller):
    """Algorithm 1 of the paper: at each t solve Eq. (3),

        min_{ũ_t..ũ_{t+M-1} ∈ U} Σ_{j=t}^{t+M-1} c_j(x̃_j, ũ_j)  s.t.  x̃_{j+1} = f(x̃_j, ũ_j, w_j), x̃_t = x_t,

    with the previewed costs c_{t:t+M-1} and disturbances w_{t:t+M-1}, and apply
    the first input u_t = κ_M(x_t). V^t_M(x_t, w_{t:t+M-1}) is the optimal value.

    Solvers: a :class:`~orrc.LinearSystem` with a :class:`~orrc.QuadraticCost` and
    no bounds is solved exactly by the Riccati recursion with disturbance
    feed-forward (``orrc.solvers.lq``); a LinearSystem with an :class:`~orrc.L1Cost` exactly as
    one quadratic program (``orrc.solvers.qp``, input bounds allowed); everything else by CasADi
    (``orrc.solvers.nlp``), built once and warm-started from the shifted previous plan: SQP
    (CasADi's ``sqpmethod`` with the QP solver ``qrqp``) first, IPOPT when SQP fails.

    Parameters
    ----------
    system, cost : the model and the stage-cost family.
    M : preview/prediction horizon (M >= 1); the controller sees w and c M steps ahead.
    input_bounds : (lo, hi), the set U (scalars or length-m arrays).
    terminal_cost : extension beyond the paper -- a (n, n) PSD matrix Pf (cost x̃ᵀPf x̃
        on x̃_{t+M}) or a callable in CasADi operations. The paper has none.
    state_bounds : extension beyond the paper -- (lo, hi) box on x̃_{t+1..t+M} (CasADi path).
    solver : "auto" (default: "lq" or "qp" where the problem allows it, else "nlp"), "lq" (the exact
        Riccati law), "qp" (the exact QP of an L1Cost), "nlp" (CasADi: SQP, then IPOPT as the
        fallback when SQP fails), "sqp" (SQP alone) or "ipopt" (IPOPT alone). Each step reports the
        solver that produced it (``Plan.solver``, ``Decision.solver``, ``Trajectory.solver``: "lq",
        "qrqp", "sqp" or "ipopt").
    solver_options : extra options for the CasADi solvers: keys "sqpmethod.*" for SQP (e.g.
        {"sqpmethod.max_iter": 20}), "ipopt.*" for IPOPT (e.g. {"ipopt.max_iter": 100}), other
        keys for both (``orrc.solvers.nlp``); options for a solver that is not used, and any
        options on the exact LQ path (which has none), are ignored with a warning.
    max_failures : consecutive failed steps after which :meth:`control` stops with
        :class:`~orrc.SolverError` (default 3); None never stops.
    preview_w : k with 0 <= k <= M (default M): how many future disturbances w_t..w_{t+k-1} the
        controller sees; the plan still runs over M steps, with the unseen w_{t+k..t+M-1} taken
        as zero (the paper's M_w <= M_c). k = M is Algorithm 1; k = 0 is the naive
        certainty-equivalence MPC. On the LQ path the law is exact: the feed-forward columns of
        the unseen disturbances are dropped (u = -Kx - L[:, :kn] vec(w_t..w_{t+k-1})). The
        lemmas and Theorem 1 assume k = M (``orrc.checks`` refuse a trajectory with k < M).
    theta : for a :class:`~orrc.ParametricSystem` model f(·; θ), the parameter value to plan
        with (Algorithm 2 plans with its estimate θ̂). It is a parameter of the CasADi NLP:
        :meth:`set_theta` changes it without rebuilding the solver.

    Solver failures (NLP path) follow :mod:`orrc.controllers.failures`: a failed solve is retried
    from a cold start, then (solver="nlp") with IPOPT; if that fails too, the step applies the
    previous successful plan shifted
    (while it lasts, fewer than M steps), else the solver's last iterate, and is marked
    (``success=False``, its V_M NaN, ``fallback`` naming what was applied); after
    ``max_failures`` consecutive failed steps the controller raises :class:`~orrc.SolverError`.
    :func:`orrc.simulate` summarises the failures of a run in one :class:`~orrc.SolverWarning`;
    a direct :meth:`plan` call that fails warns once.

    Size: the horizon's cost is estimated first (the exact LQ law is O(M³n²) to build and
    O(M²n²) to store; the CasADi problem grows with M(n+m)) and refused above the limits of
    ``orrc.config`` with an :class:`~orrc.OrrcValueError` stating the estimate.

    Raises
    ------
    orrc.OrrcValueError
        When an argument is out of range (e.g. M < 1), the bounds do not match the system, or the
        exact law at this horizon would exceed the size limits of ``orrc.config``.

    Examples
    --------
    On a linear system with a quadratic cost the law is exact (the Riccati recursion):

    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(L=60, n=2, radius=0.1, seed=0)
    >>> rhc = orrc.PreviewRHC(di.system, di.cost, M=10)
    >>> traj = orrc.simulate(di.system, rhc, di.x0, w, T=50)
    >>> print(f"{traj.costs.sum():.4f}", traj.solver_counts)
    9.9116 {'lq': 50}

    On the nonlinear pendulum each step is an NLP solved by SQP, warm-started from the last plan:

    >>> ex = orrc.examples.inverted_pendulum()
    >>> rhc = orrc.PreviewRHC(ex.system, ex.cost, M=10, input_bounds=ex.input_bounds)
    >>> traj = orrc.simulate(ex.system, rhc, ex.x0, orrc.disturbances.zero(30, 2), T=20)
    >>> traj.solver_counts, bool(traj.success.all())
    ({'sqp': 20}, True)
    """

    name = "preview RHC"

    def __init__(self, system: System, cost: StageCost, M: int, input_bounds=None,
                 terminal_cost=None, state_bounds=None, solver: str = "auto", solver_options=None,
                 max_failures: int | None = DEFAULT_MAX_FAILURES, preview_w: int | None = None, theta=None):
        check_problem(system, cost)
        self.M = as_int("M", M, minimum=1)
        self.system, self.cost = system, cost
        self.preview_c = self.M
        self.preview_w = self.M if preview_w is None else as_int("preview_w", preview_w, minimum=0)
        if self.preview_w > self.M:
            raise OrrcValueError(f"preview_w must be between 0 and M = {self.M} (the plan's horizon); "
                                 f"got {self.preview_w}")
        if self.preview_w < self.M:
            self.name = f"preview RHC, k = {self.preview_w}"
        self.input_bounds = _bounds("input_bounds", input_bounds, system.m)
        self.state_bounds = _bounds("state_bounds", state_bounds, system.n)
        _check_solver(solver)
        if solver_options is not None and not isinstance(solver_options, dict):
            raise OrrcValueError(f"solver_options must be a dict; got {type(solver_options).__name__}")
        self._ladder = FailureLadder(self.M, max_failures, name=f"PreviewRHC(M={self.M})")
        # the parameters of c_t..c_{t+M-1} for a time-invariant cost (read-only, made once)
        self._default_P = np.broadcast_to(cost.default_params, (self.M, cost.n_params))
        Pf, term_fn = _terminal(terminal_cost, system.n)
        self.solver = _pick_solver(solver, system, cost, self.input_bounds, self.state_bounds, terminal_cost, Pf)
        self.theta = None
        if getattr(system, "n_params", 0):  # a ParametricSystem: θ is a parameter of the NLP
            if theta is None:
                raise OrrcValueError(f"theta is required for a ParametricSystem model ({system.name}): the "
                                     f"value of its {system.n_params} parameters to plan with")
            self.theta = system.check_theta(theta)
        elif theta is not None:
            raise OrrcValueError(f"theta is only for a ParametricSystem model; {system.name} has no parameters")
        self._Pf = Pf
        if self.solver == "lq":
            self._nlp = None
            if type(self).control is PreviewRHC.control:  # a subclass that overrides control() keeps it
                self.fast_input = self._fast_lq_input
                self.fast_decision = Decision(u=None, value_deferred=True, solver="lq")
            if solver_options:
                warnings.warn(f"solver_options {sorted(solver_options)} are ignored: this problem is solved "
                              "exactly on the LQ path (Riccati recursion), which has no options; pass "
                              "solver='nlp' to solve it with CasADi (SQP, IPOPT as the fallback) instead",
                              UserWarning, stacklevel=2)
        elif self.solver == "qp":
            self._nlp = L1QP(system.A, system.B, cost.q, cost.R, self.M, self.input_bounds)
        else:
            self._nlp = ShootingNLP(system, cost, self.M, self.input_bounds, self.state_bounds,
                                    term_fn, solvers=_NLP_LADDERS[self.solver], solver_options=solver_options)

    @property
    def nlp(self):
        """The transcription this controller solves at every step, built once in the constructor: a
        :class:`~orrc.solvers.nlp.ShootingNLP` (``solver`` "nlp", "sqp" or "ipopt"; its CasADi solver is
        ``nlp.solver``) or an :class:`~orrc.solvers.qp.L1QP` ("qp"); None on the exact LQ path."""
        return self._nlp

    @property
    def fast_affine(self):
        """(K, feedforward) of the exact LQ path's fast path: u_t = −K x_t + feedforward(windows)[t], the
        feed-forward of every step's own preview window in one product (:mod:`orrc.controllers.base`);
        None off that path."""
        if self.fast_input is None:
            return None
        return self.law.K, self.law.feedforward

    def fast_nlp(self):
        """The warm SQP step (:class:`~orrc.solvers.warm_sqp.WarmSQP`) that :func:`orrc.simulate` runs for
        the common step (:mod:`orrc._fast_loops`; :attr:`failures` and :meth:`control` take the others), or
        None where :meth:`control` takes every step: off the NLP path with SQP first, a preview shorter
        than M, a subclass's own ``control``, or ``control`` or ``solve`` replaced on the object.

        The warm step is built once per controller, NLP and thread, not per run: it holds views of the
        calling thread's SQP buffer (working memory, :func:`orrc._casadi.buffered`; a pickled or copied
        controller leaves it behind, :class:`~orrc._casadi.DropsBuffers`) and no state of a run (its guess,
        answer and last accepted answer are written before they are read). Each call writes the cost's own
        parameters and the current θ into the solver's parameters, as a new one would (a :meth:`plan` with
        other cost parameters, or :meth:`set_theta`, may have changed them since)."""
        nlp = self._nlp
        if (not isinstance(nlp, ShootingNLP) or nlp.solvers[0] != SQP or self.preview_w != self.M
                or type(self).control is not PreviewRHC.control or "control" in self.__dict__
                or "solve" in nlp.__dict__):
            return None
        try:
            cache = self.__dict__["_casadi_buffers"]
        except KeyError:
            cache = self.__dict__["_casadi_buffers"] = {}
        key = ("warm SQP", threading.get_ident())
        warm = cache.get(key)
        if warm is None or warm.nlp is not nlp:
            warm = cache[key] = WarmSQP(nlp, self._default_P, self.theta)
        else:   # the cost's own parameters and θ, where WarmSQP(...) writes them
            p, nw, k = warm.p, warm.nw, warm.nw + self._default_P.size
            p[nw:k] = self._default_P.reshape(-1)
            if self.theta is not None:
                p[k:] = self.theta
        return warm

    @property
    def failures(self) -> FailureLadder:
        """The failure ladder of this controller (:mod:`orrc.controllers.failures`)."""
        return self._ladder

    def compile(self, wait: bool = False) -> bool:
        """Compile this controller's SQP solver and acceptance checks to machine code now, in the background
        (what it does by itself after :data:`orrc._jit.COMPILE_AFTER` SQP solves; see
        :meth:`ShootingNLP.compile <orrc.solvers.nlp.ShootingNLP.compile>`): the same answers bit for bit,
        about a fifth less time per pendulum step, used once ready. ``wait``: return when both are ready (or
        failed). Returns whether both are ready; False off the NLP path with SQP, without a C compiler, or
        while building (:meth:`compile_error` says why)."""
        return isinstance(self._nlp, ShootingNLP) and self._nlp.compile(wait)

    def compile_error(self) -> str | None:
        """Why this controller's SQP solver or checks are not compiled (None: compiled, building, or not
        asked for yet)."""
        nlp = self._nlp
        if not isinstance(nlp, ShootingNLP) or SQP not in nlp.solvers:
            return "no SQP solver to compile (this controller's path is not the NLP path with SQP)"
        return nlp.compile_error(SQP) or nlp.compile_error("acceptance")

    def _fast_lq_input(self, x, w_preview):
        """u_t of the exact LQ path for a time-invariant cost: what :meth:`control` returns (the
        simulator's fast path, :mod:`orrc.controllers.base`)."""
        return self.law.input(x, w_preview if self.preview_w == self.M else self._pad(w_preview))

    @functools.cached_property
    def law(self) -> lq.LQPreviewLaw | None:
        """The exact affine law u = -K x - L vec W and V_M = zᵀℋz (``H``) of the LQ path (None on the NLP path).

        Built on first use (by :meth:`control`, ``orrc.certify`` or the reader), not in the
        constructor: it costs O(M³n³) and an (n+Mn)² matrix, which :meth:`plan` does not
        need (e.g. :class:`~orrc.Clairvoyant` runs this class with M = T and only plans).
        """
        if self.solver != "lq":
            return None
        return lq.LQPreviewLaw(self.system.A, self.system.B, self.cost.Q, self.cost.R, self.M, self._Pf)

    # -- the M-step problem -------------------------------------------------------
    def plan(self, x, w_preview, cost_params=None, warm_start: Plan | None = None) -> Plan:
        """Solve Eq. (3) from state ``x`` with preview ``w_preview`` (M, n).

        ``cost_params`` (M, n_params): parameters of c_t..c_{t+M-1} (default: the
        cost's own, time-invariant). ``warm_start``: the plan of the previous step (a
        :class:`~orrc.solvers.Plan` of this horizon), shifted by one step as the initial guess
        (NLP path). Returns a :class:`~orrc.solvers.Plan` with ``.inputs`` (M, m),
        ``.states`` (M+1, n) and ``.value`` = V_M.

        A failed NLP solve is retried from a cold start (then with IPOPT, on the default NLP path);
        if every rung fails the plan has ``success=False``, its ``fallback`` says what its inputs are (the shifted warm start
        when one was given, else the solver's last iterate), and one
        :class:`~orrc.SolverWarning` says so.
        """
        x, W, P = self._check_preview(x, w_preview, cost_params)
        warm = self._check_warm_start(warm_start)
        if warm is not None:
            warm = (np.vstack([warm[0][1:], warm[0][-1:]]), np.vstack([warm[1][1:], warm[1][-1:]]))
        plan = self._plan(x, W, P, cost_params is None, warm)
        if not plan.success:
            if warm is not None:
                plan.inputs, plan.states, plan.fallback = warm[0], np.vstack([x, warm[1][1:]]), \
                    "the warm start, shifted"
            warnings.warn(f"PreviewRHC.plan: the solve ({SOLVER_LABELS.get(plan.solver, plan.solver)}) did not succeed ({plan.status}); "
                          f"the plan holds {plan.fallback} (plan.success is False)", SolverWarning, stacklevel=2)
        return plan

    def _plan(self, x, W, P, invariant, warm):
        """The plan of one M-step problem (validated arguments), climbing the failure ladder's rungs
        (no warning, no fallback: :meth:`plan` and :meth:`control` decide). ``warm``: (inputs,
        states) of a guess already shifted to this step (states x̃_0..x̃_M), or None."""
        if self.solver == "lq":
            if invariant:
                Qs = np.broadcast_to(self.cost.Q, (self.M,) + self.cost.Q.shape)
                Rs = np.broadcast_to(self.cost.R, (self.M,) + self.cost.R.shape)
            else:
                Qs, Rs = self.cost._rows(P)
            with np.errstate(over="ignore", invalid="ignore"):
                U, X, value = lq.solve(self.system.A, self.system.B, Qs, Rs, x, W, self._Pf)
            if not (np.isfinite(value) and np.all(np.isfinite(U)) and np.all(np.isfinite(X))):
                raise OrrcValueError(f"the exact M-step plan from x (|x| = {np.abs(x).max():.3g}) overflows the "
                                     "float range (inputs, states or V_M not finite); rescale x, W or the cost")
            return Plan(inputs=U, states=X, value=value)
        return FailureLadder.attempt(self._rungs(x, W, P, warm))

    def _rungs(self, x, W, P, warm):
        """The ways of solving one M-step problem on the NLP path, in the order the failure ladder
        tries them: the first solver (SQP on the default path) from the warm start (when there is
        one), then from a cold start; then each further solver (IPOPT) once, from the warm start
        when there is one, else cold. (The exact QP of an ℓ1 cost needs no guess: one rung.)"""
        if self.solver == "qp":
            return [("exact QP", lambda: self._nlp.solve(x, W))]
        first, *more = self._nlp.solvers
        guess = warm  # (inputs, states x̃_0..x̃_M); the solver replaces x̃_0 by x
        theta = self.theta  # a ParametricSystem's θ̂, an NLP parameter (None otherwise)

        def rung(solver, start):
            label = f"{SOLVER_LABELS[solver]} {'warm' if start else 'cold'} start"
            return label, lambda: self._nlp.solve(x, W, P, *(start or (None, None)), solver=solver, theta=theta)

        rungs = [rung(first, guess)] if guess is not None else []
        rungs.append(rung(first, None))
        rungs += [rung(solver, guess) for solver in more]
        return rungs

    def set_theta(self, theta) -> None:
        """Plan with the model parameters θ from now on (a ParametricSystem model; no solver rebuild).
        The previous plans were made with another model: the warm start is forgotten."""
        if self.theta is None:
            raise OrrcValueError(f"set_theta needs a ParametricSystem model; {self.system.name} has no parameters")
        self.theta = self.system.check_theta(theta)
        self._ladder.reset()

    # -- the controller -----------------------------------------------------------
    def reset(self) -> None:
        self._ladder.reset()

    def control(self, obs: Observation) -> Decision:
        W = obs.w_preview if self.preview_w == self.M else self._pad(obs.w_preview)
        if self.solver == "lq" and obs.cost_params is None:
            # (orrc.simulate takes the fast path instead, fast_input, with V_M from values_batch;
            # a controller that wraps this one gets V_M at each step, as it always did)
            u, value = self.law.input_and_value(obs.x, W)
            return Decision(u=u, value=value, solver="lq")
        P = self._default_P if obs.cost_params is None else obs.cost_params
        x, invariant = obs.x, obs.cost_params is None
        if self.solver == "lq":
            plan = self._plan(x, W, P, invariant, None)
        else:
            warm = self._ladder.warm_start(obs.t)
            warm = None if warm is None else warm[:2]
            if warm is not None and self.solver != "qp":
                # the ladder's first rung solved here: a success needs nothing more (the common step);
                # a failure climbs the other rungs, the first one's plan reused
                plan = self._nlp.solve(x, W, P, *warm, solver=self._nlp.solvers[0], theta=self.theta)
                if plan.success:
                    self._ladder.succeeded(obs.t, plan)
                else:
                    first, *rest = self._rungs(x, W, P, warm)
                    plan = self._ladder.step(obs.t, [(first[0], lambda: plan), *rest])
            else:
                plan = self._ladder.step(obs.t, self._rungs(x, W, P, warm))
        return Decision(u=plan.inputs[0].copy(), value=plan.value, success=plan.success,
                        status=plan.status, iterations=plan.iterations, solve_time=plan.solve_time,
                        fallback=plan.fallback, solver=plan.solver)

    def values_batch(self, X, W_windows):
        """V_M(x_t, W_t) of the steps the exact LQ path deferred (the simulator's fast path,
        :attr:`fast_input`, with a time-invariant cost): one matrix product over the whole run
        (:meth:`orrc.solvers.lq.LQPreviewLaw.values`).

        X : (k, n) states; W_windows : (k, preview_w, n) their preview windows. Returns (k,).
        """
        if self.solver != "lq":
            raise OrrcValueError(f"values_batch is the exact LQ path's (this controller uses solver={self.solver!r}, "
                                 "which reports V_M at each step)")
        n, k = self.system.n, self.preview_w
        X = as_array("X", X, (None, n))
        W_windows = as_array("W_windows", W_windows, (len(X), k, n))
        if self.preview_w < self.M:  # the unseen w_{t+k..t+M-1} are zero in the plan
            full = np.zeros((len(X), self.M, self.system.n))
            full[:, :self.preview_w] = W_windows
            W_windows = full
        return self.law.values(X, W_windows)

    def __repr__(self):
        k = "" if self.preview_w == self.M else f", preview_w={self.preview_w}"
        return f"PreviewRHC(M={self.M}{k}, solver={self.solver!r}, system={self.system!r})"
