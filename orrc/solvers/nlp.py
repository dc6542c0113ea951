"""The M-step problem of Algorithm 1 for general systems and costs, with CasADi: SQP, and IPOPT.

    min_{ũ_0..ũ_{M-1} ∈ U}  Σ_{j=0}^{M-1} c(x̃_j, ũ_j; p_j)  (+ terminal(x̃_M), an extension)
    s.t.  x̃_{j+1} = f(x̃_j, ũ_j, w_j),  x̃_0 = x,   (x̃_j ∈ X, an extension)

is transcribed once per (system, cost family, M) by multiple shooting; the parameters of the
compiled problem are (x, vec W, vec P): the previewed state, disturbances and cost parameters.
Each call starts from the given guess (the receding-horizon controller passes its shifted
previous plan) or from a cold start. A model with parameters θ (an :class:`orrc.ParametricSystem`,
``n_params > 0``) appends θ to the parameters, (x, vec W, vec P, θ): Algorithm 2 solves on
f(·; θ̂), and a new estimate θ̂ is a new parameter value, not a new solver. Two CasADi solvers can be built on the same transcription:

* ``"sqp"`` -- CasADi's ``sqpmethod`` with its QP solver ``qrqp`` (both ship with the casadi
  wheel): a sequential-quadratic-programming method with the exact Hessian of the Lagrangian,
  convexified block by block (``eigen-clip``: negative eigenvalues of a non-convex cost or of
  the dynamics' curvature are clipped, so each QP is convex and its step a descent direction),
  a backtracking line search on an l1 merit function, and stopping tolerances of 1e-8 on the
  stationarity and feasibility residuals. Each iteration is one small sparse QP, and a warm
  start near the optimum converges in one or two iterations (0.1-0.3 ms for the pendulum at
  M = 20, against 2-5 ms for IPOPT, whose fixed cost per call is most of its time).
* ``"ipopt"`` -- the interior-point solver IPOPT (tolerance 1e-9): slower per call, but it
  globalises with a filter line search and a restoration phase. Used as the fallback when SQP
  fails, and alone with ``PreviewRHC(..., solver="ipopt")``.

**Accepting an SQP answer.** ``sqpmethod`` stops when the gradient of the Lagrangian and the
constraint violation are below its tolerances. It checks neither the signs of the bound
multipliers nor whether the point it reached is any better than where it started, and its line
search accepts a step after ``max_iter_ls`` trials even without sufficient decrease. So an SQP
solve is accepted only if, in addition,

1. the bound multipliers are complementary: Σ_i λ⁺_i (ub_i − z_i) + λ⁻_i (z_i − lb_i) ≤ 1e-8 |J|
   + 1e-12 (a multiplier pushes only against an active bound; the sum is the most the objective
   can be off because of it), and
2. its objective J is not above the cost J_g of a known feasible point, the initial guess's
   inputs rolled out through the dynamics: J ≤ J_g + 1e-8 |J_g| + ‖λ_g‖₁ ‖g‖_∞ (the last term:
   how much lower than the optimum an SQP point that violates the dynamics by ‖g‖_∞ can be).

A solve that fails either check is reported failed (status ``"rejected: ..."``), like one that
did not converge; the controller's failure ladder then tries its next rung (IPOPT). Both checks are
one compiled CasADi function of the answer where the solver left it (:mod:`orrc.solvers.acceptance`).

The solver only reports: a failed solve returns a :class:`~orrc.solvers.Plan` with
``success=False`` and the solver's status, holding the last iterate. What is then applied
(a cold retry, IPOPT, the shifted previous plan, stopping) is the controller's escalation policy
(:mod:`orrc.controllers.failures`), the same whichever solver failed.

**Options.** ``solver_options`` keys that start with ``"sqpmethod."`` go to the SQP solver (the
prefix removed; e.g. ``{"sqpmethod.max_iter": 20}``, ``{"sqpmethod.qpsol": "osqp"}``), keys that
start with ``"ipopt."`` to IPOPT (CasADi's own syntax, e.g. ``{"ipopt.max_iter": 100}``), and other
keys (options of every CasADi ``nlpsol``, e.g. ``"print_time"``) to each solver that is built.
Two of SQP's defaults serve the closed loop's speed and change no answer: ``error_on_fail`` (an
unsuccessful solve raises, so a successful one is known without reading the solver's statistics;
:meth:`ShootingNLP.solve` reads an unsuccessful one as before) and no multipliers of the parameters
(``calc_lam_p`` off: nothing here uses them, and each solve saves a gradient evaluation).
"""
from __future__ import annotations

import math
import re
import time
import warnings

import casadi as ca
import numpy as np

from .._casadi import Buffered, DropsBuffers, buffered
from .._validate import OrrcValueError, check_size
from ..systems import System
from ..costs import StageCost
from .acceptance import ACCEPT_ATOL, ACCEPT_RTOL, acceptance_function, rejection  # noqa: F401  (importable here)
from .plan import Plan, SolverWarning  # noqa: F401  (SolverWarning: importable here, as before)

#: operations per node of the transcribed expression graph (build and IPOPT set-up), measured
#: on the pendulum: about 1 ms per shooting interval of about 25 nodes
_OPS_PER_NODE = 4e4

SQP, IPOPT = "sqp", "ipopt"
#: the NLP solvers, in the order of the default failure ladder (SQP first, IPOPT as the fallback)
NLP_SOLVERS = (SQP, IPOPT)
#: how the solvers are named in statuses and messages
SOLVER_LABELS = {SQP: "SQP", IPOPT: "IPOPT"}
#: the prefix of a solver's own keys in ``solver_options``
OPTION_PREFIX = {SQP: "sqpmethod.", IPOPT: "ipopt."}
_PLUGIN = {SQP: "sqpmethod", IPOPT: "ipopt"}

DEFAULT_IPOPT = {
    "ipopt.print_level": 0,
    "ipopt.sb": "yes",
    "print_time": False,
    "ipopt.tol": 1e-9,
    "ipopt.acceptable_tol": 1e-6,
    "ipopt.max_iter": 500,
}

_QRQP_QUIET = {"print_iter": False, "print_header": False, "print_info": False}

DEFAULT_SQP = {
    "qpsol": "qrqp",
    "qpsol_options": dict(_QRQP_QUIET, error_on_fail=False),
    "hessian_approximation": "exact",
    "convexify_strategy": "eigen-clip",
    "tol_pr": 1e-8,
    "tol_du": 1e-8,
    "max_iter": 50,
    "print_header": False,
    "print_iteration": False,
    "print_status": False,
    "print_time": False,
    # an unsuccessful solve raises (CasADi's error text: UNSUCCESSFUL), so that a successful one is known
    # without reading its statistics; its answer and statistics are there as without the option
    "error_on_fail": True,
    # no multipliers of the parameters (nothing here uses them): no gradient evaluation after each solve
    "calc_lam_p": False,
    "no_nlp_grad": True,
}
#: what CasADi raises for an unsuccessful solve with ``error_on_fail`` (the solve itself ran as without it)
UNSUCCESSFUL = "nlpsol process failed"
#: the status of every successful ``sqpmethod`` solve (the only one with ``success``)
SQP_SOLVED = "Solve_Succeeded"
_NEEDS_NLP_GRAD = ("calc_lam_p", "calc_lam_x", "calc_f", "calc_g")



def _split_options(solver_options: dict | None, solvers) -> tuple[dict, list]:
    """``{solver: options}`` for the ``solvers`` to build, from the user's ``solver_options`` merged
    into the defaults (module docstring: ``"sqpmethod."`` keys for SQP, ``"ipopt."`` keys for
    IPOPT, other keys for each), and the keys that none of ``solvers`` takes (to warn about)."""
    given = dict(solver_options or {})
    out, unused = {}, []
    for key in given:
        owner = [s for s, pre in OPTION_PREFIX.items() if key.startswith(pre)]
        if owner and owner[0] not in solvers:
            unused.append(key)
    for s in solvers:
        opts = dict(DEFAULT_SQP if s == SQP else DEFAULT_IPOPT)
        if s == SQP:
            opts["qpsol_options"] = dict(opts["qpsol_options"])
        for key, value in given.items():
            own = [t for t, pre in OPTION_PREFIX.items() if key.startswith(pre)]
            if own and own[0] != s:
                continue
            if s == SQP and own:
                key = key[len(OPTION_PREFIX[SQP]):]
            if s == SQP and key == "qpsol" and value != opts["qpsol"]:
                opts["qpsol_options"] = {"error_on_fail": False}  # qrqp's print options are qrqp's own
            if s == SQP and key == "qpsol_options" and isinstance(value, dict):
                opts["qpsol_options"].update(value)
            else:
                opts[key] = value
        if s == SQP and any(opts.get(key) for key in _NEEDS_NLP_GRAD):
            opts["no_nlp_grad"] = False   # the user asked for what the gradient function computes
        out[s] = opts
    return out, unused


def _nlpsol(solver: str, problem: dict, opts: dict, given: dict | None):
    try:
        return ca.nlpsol(f"rhc_{solver}", _PLUGIN[solver], problem, opts)
    except RuntimeError as exc:  # CasADi rejects unknown options at construction
        first = _last_line(exc)
        hint = (" (options of one solver take its prefix: 'sqpmethod.max_iter', 'ipopt.max_iter'; "
                "unprefixed keys go to every solver)") if given else ""
        raise OrrcValueError(
            f"CasADi rejected the NLP solver {SOLVER_LABELS[solver]} ({_PLUGIN[solver]}) with solver_options "
            f"{sorted(given or {})}: {first}{hint}") from exc


def _last_line(exc: Exception) -> str:
    """The informative line of a CasADi error (its source location dropped): the one naming the unknown
    option or missing plugin when there is one, else the last."""
    lines = [ln.strip() for ln in str(exc).strip().splitlines() if ln.strip()]
    if not lines:
        return type(exc).__name__
    keys = ("Unknown option", "No such", "not found", "Invalid", "failed")
    line = next((ln for ln in lines if any(k in ln for k in keys)), lines[-1])
    return re.sub(r"^(\.\.\./)?\S+\.(cpp|hpp):\d+: ", "", line)[:200]


class ShootingNLP(DropsBuffers):
    """Multiple-shooting transcription of the M-step problem, built once, with its solvers.

    ``input_bounds``/``state_bounds``: (lo, hi) arrays of length m / n (±inf allowed).
    ``terminal``: a callable ``terminal(x)`` in CasADi operations, or None.
    ``solvers``: the CasADi solvers to build, in the order a controller tries them
    (:data:`NLP_SOLVERS`: SQP, then IPOPT). ``solver_options``: see the module docstring.
    """

    def __init__(self, system: System, cost: StageCost, M: int, input_bounds=None,
                 state_bounds=None, terminal=None, solvers=NLP_SOLVERS, solver_options=None):
        n, m, npar = system.n, system.m, cost.n_params
        self.M, self.n, self.m = M, n, m
        self.n_theta = int(getattr(system, "n_params", 0) or 0)   # model parameters θ (ParametricSystem)
        theta = ca.SX.sym("theta", self.n_theta)
        model = (lambda x, u, w: system.symbolic(x, u, w, theta)) if self.n_theta else system.symbolic
        self.solvers = tuple(solvers)
        if not self.solvers or any(s not in NLP_SOLVERS for s in self.solvers):
            raise OrrcValueError(f"solvers must be a non-empty sequence of {NLP_SOLVERS}; got {solvers!r}")
        x1, u1, w1, p1 = ca.SX.sym("x", n), ca.SX.sym("u", m), ca.SX.sym("w", n), ca.SX.sym("p", npar)
        stage_nodes = ca.Function("stage", [x1, u1, w1, p1, theta],
                                  [model(x1, u1, w1), cost.expr(x1, u1, p1)]).n_nodes()
        per_interval = stage_nodes + 4 * (n + m + npar)
        check_size(f"the CasADi transcription of the M-step problem at the horizon M={M} (n={n}, m={m})",
                   nbytes=M * per_interval * 400.0 * len(self.solvers),
                   ops=M * per_interval * _OPS_PER_NODE * len(self.solvers),
                   hint="lower M (the NLP has M (n + m) variables; the solvers' work per iteration grows with it)")
        X = ca.SX.sym("X", n, M)        # x̃_1 .. x̃_M
        U = ca.SX.sym("U", m, M)
        x0 = ca.SX.sym("x0", n)
        W = ca.SX.sym("W", n, M)
        Pp = ca.SX.sym("P", npar, M)
        J = 0
        g = []
        xj = x0
        J_roll, xr, X_roll = 0, x0, []  # the same cost along a rollout of U (single shooting)
        for j in range(M):
            J += cost.expr(xj, U[:, j], Pp[:, j])
            g.append(X[:, j] - model(xj, U[:, j], W[:, j]))
            xj = X[:, j]
            J_roll += cost.expr(xr, U[:, j], Pp[:, j])
            xr = model(xr, U[:, j], W[:, j])
            X_roll.append(xr)
        if terminal is not None:
            J += terminal(xj)
            J_roll += terminal(xr)
        z = ca.vertcat(ca.vec(U), ca.vec(X))
        p = ca.vertcat(x0, ca.vec(W), ca.vec(Pp), theta)
        problem = {"x": z, "f": J, "g": ca.vertcat(*g), "p": p}
        self.problem = problem  # the transcription: z = [vec U; x̃_1..x̃_M], p = [x; vec W; vec P; θ], g = 0
        opts, unused = _split_options(solver_options, self.solvers)
        if unused:
            warnings.warn(f"solver_options {sorted(unused)} are ignored: they are for a solver this controller does "
                          f"not use (it uses {', '.join(SOLVER_LABELS[s] for s in self.solvers)})",
                          UserWarning, stacklevel=3)
        self._nlpsol = {s: _nlpsol(s, problem, opts[s], solver_options) for s in self.solvers}
        self.solver_options = opts
        ulo, uhi = (np.full(m, -np.inf), np.full(m, np.inf)) if input_bounds is None else input_bounds
        xlo, xhi = (np.full(n, -np.inf), np.full(n, np.inf)) if state_bounds is None else state_bounds
        self.lbz = np.concatenate([np.tile(ulo, M), np.tile(xlo, M)])
        self.ubz = np.concatenate([np.tile(uhi, M), np.tile(xhi, M)])
        if SQP in self.solvers:
            self._rollout = ca.Function("rollout", [p, ca.vec(U)], [J_roll, ca.vertcat(*X_roll)])
            nu = M * m   # the guess of the next step: z shifted by one step (its last input and state kept)
            shift = [*range(m, nu), *range(nu - m, nu), *range(nu + n, nu + M * n),
                     *range(nu + (M - 1) * n, nu + M * n)]
            self._acceptance = acceptance_function(z, problem["g"], p, ca.vec(U), J_roll, ca.vertcat(*X_roll),
                                                    self.lbz, self.ubz, state_bounds is not None, shift)
        self.input_bounds = (np.asarray(ulo, float), np.asarray(uhi, float))
        self._cold_U = np.clip(np.zeros((M, m)), *self.input_bounds)
        self._cold_U.flags.writeable = False
        self.state_bounds = None if state_bounds is None else (np.asarray(xlo, float), np.asarray(xhi, float))

    def _call(self, name: str) -> Buffered:
        """The solver (or the rollout, or the acceptance checks) ``name`` on numpy buffers
        (:mod:`orrc._casadi`); the solvers' bounds never change (the x̃ and ũ boxes, g = 0 for the
        dynamics, zero initial multipliers)."""
        if name == "rollout":
            return buffered(self, name, lambda: self._rollout)
        if name == "acceptance":   # its inputs are the SQP buffer's own arrays: nothing is copied
            return buffered(self, name, lambda: Buffered(self._acceptance, args=self._acceptance_inputs()))
        if name == "acceptance-copy":   # on arrays of its own (an answer given from elsewhere)
            return buffered(self, name, lambda: self._acceptance)
        return buffered(self, name, lambda: self._nlpsol[name], None, None, self.lbz, self.ubz, 0.0, 0.0, 0.0, 0.0)

    def _acceptance_inputs(self) -> list:
        """The inputs of the acceptance function (:func:`acceptance_function`: z, g, λ_x, λ_g, p, the guess's
        inputs, J) as views of this thread's SQP buffer: the solver's results, its parameters and the inputs of
        its initial guess, where the solver left them."""
        sqp = self._call(SQP)
        return [sqp.res[0], sqp.res[2], sqp.res[3], sqp.res[4], sqp.args[1], sqp.args[0][: self.M * self.m],
                sqp.res[1]]

    @property
    def solver_name(self) -> str:
        """The first solver a controller tries."""
        return self.solvers[0]

    @property
    def solver(self) -> ca.Function:
        """The CasADi ``nlpsol`` of the first solver (built once: a new θ̂ or preview is a new parameter
        value, not a new solver; the unknown-systems chapter checks this)."""
        return self._nlpsol[self.solvers[0]]

    def cold_start(self, x) -> tuple[np.ndarray, np.ndarray]:
        """The cold-start guess (inputs (M, m), states x̃_1..x̃_M (M, n)): zero inputs clipped to the
        bounds, the state held at x over the horizon. (A rollout of the guessed inputs falls away
        from the origin on open-loop unstable systems, and on long horizons IPOPT then stops in a
        poor local optimum: e.g. the clairvoyant pendulum with |u| <= 8 over T = 150 steps, cost
        ~3500 vs ~205.)"""
        return self._cold_U.copy(), np.tile(x, (self.M, 1))

    def solve(self, x, W, P, guess_U=None, guess_X=None, solver: str | None = None, theta=None) -> Plan:
        """Solve from state x (n,) with preview W (M, n) and cost parameters P (M, n_params);
        ``theta`` (n_theta,): the model parameters, for a ParametricSystem (else None).

        ``solver``: one of :attr:`solvers` (default the first). No guess: a cold start
        (:meth:`cold_start`). On failure (no convergence, a CasADi error inside the solver, a
        non-finite result, or an SQP answer rejected by the checks of the module docstring) the plan
        has ``success=False``, the solver's ``status`` and its last iterate (or the guess, where the
        iterate is not finite); nothing is warned here: the caller's escalation policy decides what
        to apply and says so.
        """
        solver = self.solvers[0] if solver is None else solver
        if solver not in self._nlpsol:
            raise OrrcValueError(f"solver must be one of {self.solvers} (built for this problem); got {solver!r}")
        M, n, m = self.M, self.n, self.m
        if guess_U is None:
            guess_U = self._cold_U
        guess_next = np.tile(x, (M, 1)) if guess_X is None else guess_X[1:]  # guess_X: x̃_0..x̃_M (cold_start)
        call = self._call(solver)
        z0, p = call.args[0], call.args[1]  # written in place: the guess [vec U; x̃_1..x̃_M], the parameters
        z0[: M * m], z0[M * m:] = guess_U.reshape(-1), guess_next.reshape(-1)
        k = n + M * n + P.size
        p[:n], p[n:n + M * n], p[n + M * n:k] = x, W.reshape(-1), P.reshape(-1)
        if self.n_theta:
            p[k:] = theta
        t0 = time.perf_counter()
        try:
            error = call()
        except RuntimeError as exc:  # e.g. the QP solver of SQP fails inside CasADi: a failed solve
            error = None if UNSUCCESSFUL in str(exc) else exc   # (not converged: read below, as any answer)
        elapsed = time.perf_counter() - t0
        stats = call.stats()
        iterations = int(stats.get("iter_count", 0) or 0)
        if error:
            text = _last_line(error) if isinstance(error, Exception) else f"CasADi return code {error}"
            return Plan(inputs=guess_U.copy(), states=np.vstack([x, guess_next]), value=float("nan"), success=False,
                        status=f"error: {text}", iterations=iterations, solve_time=elapsed,
                        fallback="the initial guess (the solver raised an error)", solver=solver)
        status = str(stats.get("return_status", "unknown"))
        success = bool(stats.get("success", False))
        zopt, value = call.res[0].copy(), float(call.res[1][0])
        U = zopt[: M * m].reshape(M, m)
        X = np.empty((M + 1, n))
        X[0], X[1:] = x, zopt[M * m:].reshape(M, n)
        extra = {"lam_x": call.res[3].copy(), "lam_g": call.res[4].copy()}  # the multipliers (bounds, dynamics)
        fallback = None
        finite = math.isfinite(value) and math.isfinite(zopt.sum())  # (the sum is inf or NaN if an entry is)
        if success and finite and solver == SQP:
            reason = self._rejection(call.res, zopt, value, p, guess_U, extra, in_place=True)
            if reason:
                success, status = False, f"rejected: {reason}"
        if not success or not finite:
            success = False
            fallback = "the solver's last iterate"
            if not (np.isfinite(U).all() and np.isfinite(X).all()):
                U, X = guess_U.copy(), np.vstack([x, guess_next])
                fallback = "the initial guess (the solver's iterate is not finite)"
            if status == "Solve_Succeeded":
                status = "non-finite result"
        return Plan(inputs=U, states=X, value=value, success=success, status=status, iterations=iterations,
                    solve_time=elapsed, fallback=fallback, solver=solver, extra=extra)

    def _rejection(self, res, z, value, p, guess_U, extra, in_place: bool = False) -> str | None:
        """Why a converged SQP answer is not accepted (the checks of the module docstring), or None.
        ``res``: the solver's outputs (x, f, g, lam_x, lam_g, lam_p). The quantities of both checks come
        from one compiled CasADi function (:func:`acceptance_function`); ``in_place``: the answer is in
        the SQP buffer (:meth:`solve`), whose arrays the function reads without a copy."""
        if in_place:   # the solver's own buffers: the checks read its answer, p and the guess where they are
            check = self._call("acceptance")
            check.evaluate()
        else:
            check = self._call("acceptance-copy")
            check.evaluate(z, res[2], res[3], res[4], p, guess_U.reshape(-1), value)
        quantities = check.res[0].tolist()
        extra["complementarity"], extra["guess_cost"] = quantities[0], quantities[1]
        return rejection(quantities, value)
