"""Algorithm 1: preview receding-horizon control (known system)."""
from __future__ import annotations

import functools

import numpy as np

from .._validate import OrrcValueError, as_array, as_int
from ..costs import L1Cost, QuadraticCost, StageCost
from ..systems import LinearSystem, System
from ..solvers import lq
from ..solvers.nlp import ShootingNLP
from ..solvers.qp import L1QP
from ..solvers.plan import Plan
from .base import Controller, Decision, Observation


def _bounds(name, bounds, dim):
    if bounds is None:
        return None
    if not isinstance(bounds, (tuple, list)) or len(bounds) != 2:
        raise OrrcValueError(f"{name} must be a pair (lo, hi) of scalars or length-{dim} arrays; got {bounds!r}")
    lo = np.broadcast_to(as_array(f"{name}[0]", bounds[0], allow_nonfinite=True), (dim,)).astype(float)
    hi = np.broadcast_to(as_array(f"{name}[1]", bounds[1], allow_nonfinite=True), (dim,)).astype(float)
    if np.any(np.isnan(lo)) or np.any(np.isnan(hi)) or np.any(lo > hi):
        raise OrrcValueError(f"{name} needs lo <= hi (no NaN) in every coordinate; got lo={lo}, hi={hi}")
    return lo, hi


class PreviewRHC(Controller):
    """Algorithm 1 of the paper: at each t solve Eq. (3),

        min_{ũ_t..ũ_{t+M-1} ∈ U} Σ_{j=t}^{t+M-1} c_j(x̃_j, ũ_j)  s.t.  x̃_{j+1} = f(x̃_j, ũ_j, w_j), x̃_t = x_t,

    with the previewed costs c_{t:t+M-1} and disturbances w_{t:t+M-1}, and apply
    the first input u_t = κ_M(x_t). V^t_M(x_t, w_{t:t+M-1}) is the optimal value.

    Solvers: a :class:`~orrc.LinearSystem` with a :class:`~orrc.QuadraticCost` and
    no bounds is solved exactly by the Riccati recursion with disturbance
    feed-forward (``orrc.solvers.lq``); a LinearSystem with an :class:`~orrc.L1Cost` exactly as
    one quadratic program (``orrc.solvers.qp``, input bounds allowed); everything else by CasADi + IPOPT
    (``orrc.solvers.nlp``), built once and warm-started from the shifted previous plan.

    Parameters
    ----------
    system, cost : the model and the stage-cost family.
    M : preview/prediction horizon (M >= 1); the controller sees w and c M steps ahead.
    input_bounds : (lo, hi), the set U (scalars or length-m arrays).
    terminal_cost : extension beyond the paper -- a (n, n) PSD matrix Pf (cost x̃ᵀPf x̃
        on x̃_{t+M}) or a callable in CasADi operations. The paper has none.
    state_bounds : extension beyond the paper -- (lo, hi) box on x̃_{t+1..t+M} (CasADi path).
    solver : "auto" (default), "lq", "qp" or "nlp".
    solver_options : extra options for ``casadi.nlpsol`` (e.g. {"ipopt.max_iter": 100}).
    theta : for a :class:`~orrc.ParametricSystem` model f(·; θ), the parameter value to plan
        with (Algorithm 2 plans with its estimate θ̂). It is a parameter of the CasADi NLP:
        :meth:`set_theta` changes it without rebuilding the solver.

    On an NLP failure the step reports ``success=False`` with the solver status,
    warns (:class:`~orrc.SolverWarning`), and applies the first input of the shifted
    previous plan when there is one (else the solver's last iterate).
    """

    name = "preview RHC"

    def __init__(self, system: System, cost: StageCost, M: int, input_bounds=None,
                 terminal_cost=None, state_bounds=None, solver: str = "auto", solver_options=None,
                 theta=None):
        if not isinstance(system, System):
            raise OrrcValueError(f"system must be an orrc LinearSystem or NonlinearSystem; got {type(system).__name__}")
        if not isinstance(cost, StageCost):
            raise OrrcValueError(f"cost must be an orrc stage cost (QuadraticCost, Cost); got {type(cost).__name__}")
        cost.check_dims(system.n, system.m)
        self.M = as_int("M", M, minimum=1)
        self.system, self.cost = system, cost
        self.preview_w = self.preview_c = self.M
        self.input_bounds = _bounds("input_bounds", input_bounds, system.m)
        self.state_bounds = _bounds("state_bounds", state_bounds, system.n)
        if solver not in ("auto", "lq", "nlp", "qp"):
            raise OrrcValueError(f"solver must be 'auto', 'lq', 'qp' or 'nlp'; got {solver!r}")
        if solver_options is not None and not isinstance(solver_options, dict):
            raise OrrcValueError(f"solver_options must be a dict; got {type(solver_options).__name__}")
        Pf, term_fn = None, None
        if terminal_cost is not None:
            if callable(terminal_cost):
                term_fn = terminal_cost
            else:
                from .._validate import as_square, check_psd
                Pf = as_square("terminal_cost", terminal_cost, system.n)
                check_psd("terminal_cost", Pf)
                term_fn = lambda x, Pf=Pf: (x.T @ Pf @ x)  # noqa: E731
        lq_ok = (isinstance(system, LinearSystem) and isinstance(cost, QuadraticCost)
                 and self.input_bounds is None and self.state_bounds is None
                 and (terminal_cost is None or Pf is not None))
        if solver == "lq" and not lq_ok:
            raise OrrcValueError(
                "solver='lq' needs a LinearSystem, a QuadraticCost, no input/state bounds and a "
                "quadratic (matrix) terminal cost or none; use solver='nlp' or 'auto'")
        self.solver = "lq" if (solver == "lq" or (solver == "auto" and lq_ok)) else "nlp"
        # an ℓ1 state cost on a linear system: one exact QP per step (orrc.solvers.qp)
        qp_ok = (isinstance(system, LinearSystem) and isinstance(cost, L1Cost) and self.state_bounds is None
                 and terminal_cost is None)
        if solver == "qp" and not qp_ok:
            raise OrrcValueError("solver='qp' needs a LinearSystem, an L1Cost, no state bounds and no terminal cost")
        if solver in ("auto", "qp") and qp_ok:
            self.solver = "qp"
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
        elif self.solver == "qp":
            self._nlp = L1QP(system.A, system.B, cost.q, cost.R, self.M, self.input_bounds)
        else:
            self._nlp = ShootingNLP(system, cost, self.M, self.input_bounds, self.state_bounds,
                                    term_fn, solver_options=solver_options)
        self._prev: Plan | None = None

    @functools.cached_property
    def law(self) -> lq.LQPreviewLaw | None:
        """The exact affine law u = -K x - L vec W and V_M = zᵀHz of the LQ path (None on the NLP path).

        Built on first use (by :meth:`control`, ``orrc.certify`` or the reader), not in the
        constructor: it costs O(M³n³) and an (n+Mn)² matrix, which :meth:`plan` does not
        need (e.g. :class:`~orrc.Clairvoyant` runs this class with M = T and only plans).
        """
        if self.solver != "lq":
            return None
        return lq.LQPreviewLaw(self.system.A, self.system.B, self.cost.Q, self.cost.R, self.M, self._Pf)

    # -- the M-step problem -------------------------------------------------------
    def _check_preview(self, x, w_preview, cost_params):
        n = self.system.n
        x = as_array("x", x, (n,))
        w_preview = as_array("w_preview", w_preview)
        if w_preview.ndim == 1 and n == 1:
            w_preview = w_preview[:, None]
        if w_preview.ndim != 2 or w_preview.shape[1] != n or w_preview.shape[0] < self.M:
            raise OrrcValueError(
                f"w_preview must have shape (M, n) = ({self.M}, {n}) (at least M rows); got shape "
                f"{w_preview.shape}")
        w_preview = w_preview[: self.M]
        if cost_params is None:
            P = np.broadcast_to(self.cost.default_params, (self.M, self.cost.n_params))
        else:
            P = self.cost.check_params(cost_params)
            if P.shape[0] < self.M:
                raise OrrcValueError(
                    f"cost_params must have at least M={self.M} rows; got shape {P.shape}")
            P = P[: self.M]
        return x, w_preview, P

    def plan(self, x, w_preview, cost_params=None, warm_start: Plan | None = None) -> Plan:
        """Solve Eq. (3) from state ``x`` with preview ``w_preview`` (M, n).

        ``cost_params`` (M, n_params): parameters of c_t..c_{t+M-1} (default: the
        cost's own, time-invariant). Returns a :class:`~orrc.solvers.Plan` with
        ``.inputs`` (M, m), ``.states`` (M+1, n) and ``.value`` = V_M.
        """
        x, W, P = self._check_preview(x, w_preview, cost_params)
        return self._solve(x, W, P, cost_params is None, warm_start)

    def _solve(self, x, W, P, invariant, warm_start):
        if self.solver == "lq":
            if invariant:
                Qs = np.broadcast_to(self.cost.Q, (self.M,) + self.cost.Q.shape)
                Rs = np.broadcast_to(self.cost.R, (self.M,) + self.cost.R.shape)
            else:
                pairs = [self.cost.unpack(p) for p in P]
                Qs = np.array([q for q, _ in pairs])
                Rs = np.array([r for _, r in pairs])
            U, X, value = lq.solve(self.system.A, self.system.B, Qs, Rs, x, W, self._Pf)
            return Plan(inputs=U, states=X, value=value)
        if self.solver == "qp":
            plan = self._nlp.solve(x, W)
            if not plan.success and warm_start is not None:
                plan.inputs = np.vstack([warm_start.inputs[1:], warm_start.inputs[-1:]])
                plan.fallback = "shifted previous plan"
            return plan
        guess_U = guess_X = None
        if warm_start is not None:
            guess_U = np.vstack([warm_start.inputs[1:], warm_start.inputs[-1:]])
            guess_X = np.vstack([x, warm_start.states[2:], warm_start.states[-1:]])
        plan = self._nlp.solve(x, W, P, guess_U, guess_X, theta=self.theta)
        if not plan.success and warm_start is not None:
            plan.inputs = guess_U
            plan.states = guess_X
            plan.fallback = "shifted previous plan"
        return plan

    def set_theta(self, theta) -> None:
        """Plan with the model parameters θ from now on (a ParametricSystem model; no solver rebuild)."""
        if self.theta is None:
            raise OrrcValueError(f"set_theta needs a ParametricSystem model; {self.system.name} has no parameters")
        self.theta = self.system.check_theta(theta)
        self._prev = None

    # -- the controller -----------------------------------------------------------
    def reset(self) -> None:
        self._prev = None

    def control(self, obs: Observation) -> Decision:
        if self.solver == "lq" and obs.cost_params is None:
            u, value = self.law.input_and_value(obs.x, obs.w_preview)
            return Decision(u=u, value=value)
        P = (np.broadcast_to(self.cost.default_params, (self.M, self.cost.n_params))
             if obs.cost_params is None else obs.cost_params)
        plan = self._solve(obs.x, obs.w_preview, P, obs.cost_params is None, self._prev)
        self._prev = plan
        return Decision(u=plan.inputs[0].copy(), value=plan.value, success=plan.success,
                        status=plan.status, iterations=plan.iterations, solve_time=plan.solve_time)

    def __repr__(self):
        return f"PreviewRHC(M={self.M}, solver={self.solver!r}, system={self.system!r})"
