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
  M = 20, against 2-5 ms for IPOPT, whose fixed cost per call is most of its time). From the horizon
  :data:`~orrc.solvers.nlp_solvers.HPIPM_FROM` on, the QP solver is HPIPM instead, a Riccati recursion whose
  work grows linearly with M (the variables are then in stage order, ũ_0, x̃_1, ũ_1, ...; the checks below
  read them in either order).
  **The Hessian** (``hessian``, :func:`~orrc.solvers.nlp_solvers.sqp_hessian`): the exact Hessian of the
  Lagrangian above, or the Gauss-Newton Hessian, the objective's alone (the dynamics' curvature dropped, as
  acados does for a least-squares cost): for a :class:`~orrc.QuadraticCost` it is the stage cost's own
  Hessian, positive semi-definite and free to evaluate, not convexified. Both stop at the same KKT point
  (SQP's stopping test reads the gradient of the Lagrangian and the constraint violation, not the Hessian),
  and both answers pass the same acceptance checks below; the Gauss-Newton steps avoid the second derivatives
  of the dynamics through the horizon and their convexification, at the price of linear convergence.
  ``hessian="auto"`` takes Gauss-Newton for a quadratic stage cost from
  :data:`~orrc.solvers.nlp_solvers.GAUSS_NEWTON_FROM` variables per stage (n + m) on, where the exact Hessian's
  eigenvalue convexification was measured to give non-finite steps (the quadrotor, the chain of 12 masses),
  the exact Hessian otherwise; ``hessian="exact"`` or ``"gauss-newton"`` (or
  ``solver_options={"sqpmethod.hessian_approximation": ...}``, which :class:`~orrc.PreviewRHC` passes on)
  forces it.
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

An answer of SQP with HPIPM that fails only the first check (HPIPM's interior-point multipliers are
complementary to its own tolerance, about 1e-10 per bound, which is more than 1e-8 |J| where the optimal cost
is small) is first *polished*: SQP with the active-set QP solver ``qrqp`` (exactly complementary) is started
from it, on the same NLP with the same Hessian, and its answer is accepted if it passes both checks; the
plan's ``extra["polished"]`` says so. A solve that fails either check is reported failed (status
``"rejected: ..."``), like one that did not converge; the controller's failure ladder then tries its next rung (IPOPT). Both checks are
one compiled CasADi function of the answer where the solver left it (:mod:`orrc.solvers.acceptance`).

The solver only reports: a failed solve returns a :class:`~orrc.solvers.Plan` with
``success=False`` and the solver's status, holding the last iterate. What is then applied
(a cold retry, IPOPT, the shifted previous plan, stopping) is the controller's escalation policy
(:mod:`orrc.controllers.failures`), the same whichever solver failed.

**Options** (:mod:`orrc.solvers.nlp_solvers`): ``solver_options`` keys ``"sqpmethod.*"`` go to SQP,
``"ipopt.*"`` to IPOPT, other keys to each solver that is built.
"""
from __future__ import annotations

import math
import time
import warnings

import casadi as ca
import numpy as np

from .._casadi import Buffered, DropsBuffers, buffered
from .._jit import COMPILE_AFTER, COUNTER_CHECKS, Compiled, compiled_function, compiled_nlpsol
from .._validate import OrrcValueError, check_size
from .nlp_solvers import (DEFAULT_IPOPT, DEFAULT_SQP, GAUSS_NEWTON, IPOPT, NLP_SOLVERS, OPTION_PREFIX,  # noqa: F401
                          SOLVER_LABELS, SQP, SQP_SOLVED, UNSUCCESSFUL, _PLUGIN, _last_line, _nlpsol, _qrqp_sqp,
                          _solve_once, _split_options, _stats, sqp_hessian, structured_qpsol)
from ..systems import System
from ..costs import QuadraticCost, StageCost
from .acceptance import ACCEPT_ATOL, ACCEPT_RTOL, acceptance_function, rejection  # noqa: F401  (importable here)
from .plan import Plan, SolverWarning  # noqa: F401  (SolverWarning: importable here, as before)

#: how the acceptance checks' reason for multipliers that are not complementary begins
#: (:func:`~orrc.solvers.acceptance.rejection`)
NOT_COMPLEMENTARY = "bound multipliers not complementary"

#: operations per node of the transcribed expression graph (build and IPOPT set-up), measured
#: on the pendulum: about 1 ms per shooting interval of about 25 nodes
_OPS_PER_NODE = 4e4

def _reordered(acceptance: ca.Function, order, iu) -> ca.Function:
    """The acceptance checks (written for z = [vec U; x̃_1..x̃_M]) on a solver whose variables are z[order]:
    the answer and its bound multipliers permuted back, the guess's inputs read at ``iu`` of the guess's z, and
    the shifted answer given in the solver's order (the same operations on the same numbers)."""
    ins = [ca.SX.sym(acceptance.name_in(i), acceptance.size_in(i)) for i in range(acceptance.n_in())]
    inverse = np.argsort(order)
    zs, gs, lam_x, lam_g, ps, z_guess, J = ins
    z_guess = ca.SX.sym("z_guess", zs.numel())
    out, shifted = acceptance(zs[inverse.tolist()], gs, lam_x[inverse.tolist()], lam_g, ps, z_guess[np.asarray(iu).tolist()], J)
    return ca.Function("acceptance", [zs, gs, lam_x, lam_g, ps, z_guess, J], [out, shifted[order.tolist()]])


class ShootingNLP(DropsBuffers):
    """Multiple-shooting transcription of the M-step problem, built once, with its solvers.

    ``input_bounds``/``state_bounds``: (lo, hi) arrays of length m / n (±inf allowed).
    ``terminal``: a callable ``terminal(x)`` in CasADi operations, or None.
    ``solvers``: the CasADi solvers to build, in the order a controller tries them
    (:data:`NLP_SOLVERS`: SQP, then IPOPT). ``solver_options``: see the module docstring.
    ``hessian``: SQP's Hessian, ``"auto"`` (by the cost and the state dimension), ``"exact"`` or
    ``"gauss-newton"`` (module docstring); the one chosen is :attr:`hessian`.
    """

    def __init__(self, system: System, cost: StageCost, M: int, input_bounds=None,
                 state_bounds=None, terminal=None, solvers=NLP_SOLVERS, solver_options=None, hessian="auto"):
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
        opts, unused = _split_options(solver_options, self.solvers)
        if unused:
            warnings.warn(f"solver_options {sorted(unused)} are ignored: they are for a solver this controller does "
                          f"not use (it uses {', '.join(SOLVER_LABELS[s] for s in self.solvers)})",
                          UserWarning, stacklevel=3)
        #: the variables in stage order (ũ_0, x̃_1, ũ_1, x̃_2, ...), where SQP's QP solver needs it (HPIPM,
        #: :func:`~orrc.solvers.nlp_solvers.structured_qpsol`); else z = [vec U; x̃_1..x̃_M]
        self.stage_order = structured_qpsol(opts, solver_options, M, n, m)
        #: SQP's Hessian: "exact" or "gauss-newton" (None: no SQP solver, or CasADi's limited-memory one)
        self.hessian = sqp_hessian(hessian, opts, solver_options, n + m,
                                   isinstance(cost, QuadraticCost) and terminal is None)
        nu = M * m
        z = ca.vertcat(ca.vec(U), ca.vec(X))   # the variables in the order the checks and the shift are written in
        if self.stage_order:
            #: z_solver = z[order]; the inputs and states are at ``iu`` and ``ix`` of the solver's z
            self.order = np.concatenate([np.r_[j * m:(j + 1) * m, nu + j * n:nu + (j + 1) * n] for j in range(M)])
            inverse = np.argsort(self.order)
            self.iu, self.ix = inverse[:nu], inverse[nu:]
            zs = ca.vertcat(*[ca.vertcat(U[:, j], X[:, j]) for j in range(M)])
        else:
            self.order, self.iu, self.ix, zs = None, slice(0, nu), slice(nu, None), z
        p = ca.vertcat(x0, ca.vec(W), ca.vec(Pp), theta)
        problem = {"x": zs, "f": J, "g": ca.vertcat(*g), "p": p}
        if self.hessian == GAUSS_NEWTON:   # the objective's Hessian as SQP's Hessian of the Lagrangian
            lam_f, lam_g = ca.SX.sym("lam_f"), ca.SX.sym("lam_g", M * n)
            opts[SQP]["hess_lag"] = ca.Function("nlp_hess_l", [zs, p, lam_f, lam_g], [lam_f * ca.hessian(J, zs)[0]],
                                                ["x", "p", "lam_f", "lam_g"], ["hess_gamma_x_x"])
        self.problem = problem  # the transcription: z (above), p = [x; vec W; vec P; θ], g = 0
        self._nlpsol = {s: _nlpsol(s, problem, opts[s], solver_options) for s in self.solvers}
        self.solver_options = opts
        ulo, uhi = (np.full(m, -np.inf), np.full(m, np.inf)) if input_bounds is None else input_bounds
        xlo, xhi = (np.full(n, -np.inf), np.full(n, np.inf)) if state_bounds is None else state_bounds
        lbz = np.concatenate([np.tile(ulo, M), np.tile(xlo, M)])
        ubz = np.concatenate([np.tile(uhi, M), np.tile(xhi, M)])
        self.lbz, self.ubz = (lbz, ubz) if self.order is None else (lbz[self.order], ubz[self.order])
        if SQP in self.solvers:
            self._rollout = ca.Function("rollout", [p, ca.vec(U)], [J_roll, ca.vertcat(*X_roll)])
            # the guess of the next step: z shifted by one step (its last input and state kept)
            shift = [*range(m, nu), *range(nu - m, nu), *range(nu + n, nu + M * n),
                     *range(nu + (M - 1) * n, nu + M * n)]
            self._acceptance = acceptance_function(z, problem["g"], p, ca.vec(U), J_roll, ca.vertcat(*X_roll),
                                                    lbz, ubz, state_bounds is not None, shift)
            if self.order is not None:   # the same checks on the solver's order (its answer, its guess)
                self._acceptance = _reordered(self._acceptance, self.order, self.iu)
        #: SQP solves on this NLP (here and in :class:`~orrc.solvers.warm_sqp.WarmSQP`), and the compiled copies
        #: (:mod:`orrc._jit`) of the SQP solver and the acceptance checks, asked for after
        #: :data:`orrc._jit.COMPILE_AFTER` of them or by :meth:`compile`
        self.sqp_solves, self._jit = 0, {}
        self._polisher = None   # SQP with qrqp, built on first use (:meth:`_polish`)
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
        if name == "acceptance-compiled":   # the compiled copies (orrc._jit), on the SQP buffer's arrays too
            return buffered(self, name, lambda: Buffered(self._jit[name].function(), args=self._acceptance_inputs()))
        if name == "sqp-compiled":
            return buffered(self, name, self._compiled_sqp)
        return buffered(self, name, lambda: self._nlpsol[name], None, None, self.lbz, self.ubz, 0.0, 0.0, 0.0, 0.0)

    def compile(self, wait: bool = False) -> bool:
        """Compile the SQP solver (the NLP's functions and derivatives as machine code: about a fifth less time
        per solve) and the acceptance checks (about 3 µs per solve) with the system's C compiler, in the
        background (:mod:`orrc._jit`; done by itself after :data:`~orrc._jit.COMPILE_AFTER` SQP solves). Both
        give the interpreted ones' answers bit for bit and are used once ready. ``wait``: until both are ready
        or failed. Returns whether both are ready (:meth:`compile_error` says why not)."""
        if SQP not in self._nlpsol:
            return False
        for name in ("acceptance", SQP):
            key = f"{name}-compiled"
            if key not in self._jit:
                try:
                    self._jit[key] = (compiled_function(self._acceptance) if name == "acceptance" else
                                      compiled_nlpsol(self._nlpsol[SQP], _PLUGIN[SQP],   # (the library holds hess_lag)
                                                      {k: v for k, v in self.solver_options[SQP].items()
                                                       if k != "hess_lag"}))
                except RuntimeError as exc:   # no C code for it (e.g. a user's callback among the options)
                    self._jit[key] = Compiled(name, None, None, error=f"no C code for it: {_last_line(exc)}")
        if wait:
            for job in self._jit.values():
                job.wait()
        return all(self.compiled(name) is not None for name in ("acceptance", SQP))

    def compiled(self, name: str) -> Buffered | None:
        """The compiled copy (:meth:`compile`) of the acceptance checks (``"acceptance"``) or of the SQP solver
        (``"sqp"``) on this thread's SQP buffer's own arrays, once it is ready, else None. After
        :data:`~orrc._jit.COMPILE_AFTER` SQP solves the first call asks for them (:meth:`compile`)."""
        key = f"{name}-compiled"
        job = self._jit.get(key)
        if job is None:
            if self.sqp_solves < COMPILE_AFTER or SQP not in self._nlpsol:
                return None
            self.compile()
            job = self._jit[key]
        return self._call(key) if job.function() is not None else None

    def _compiled_sqp(self) -> Buffered:
        """The compiled SQP solver on this thread's SQP buffer's own arrays, with its iteration counter."""
        sqp, job = self._call(SQP), self._jit["sqp-compiled"]
        call = Buffered(job.function(), args=sqp.args, res=sqp.res)
        call.counter = job.counter()
        return call

    def compile_error(self, name: str) -> str | None:
        """Why the compiled copy ``name`` (:meth:`compiled`) is not used (None: used, building, or not asked
        for yet)."""
        job = self._jit.get(f"{name}-compiled")
        return None if job is None else job.error

    def __getstate__(self):
        state = super().__getstate__()
        state["_jit"] = {}   # threads and loaded libraries: made again (from the cache) on demand
        state["_polisher"] = None
        return state

    def _acceptance_inputs(self) -> list:
        """The inputs of the acceptance function (:func:`acceptance_function`: z, g, λ_x, λ_g, p, the guess's
        inputs, J) as views of this thread's SQP buffer: the solver's results, its parameters and the inputs of
        its initial guess, where the solver left them."""
        sqp = self._call(SQP)
        guess = sqp.args[0] if self.stage_order else sqp.args[0][: self.M * self.m]   # (all of z: the checks pick)
        return [sqp.res[0], sqp.res[2], sqp.res[3], sqp.res[4], sqp.args[1], guess, sqp.res[1]]

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
        call = self._call(solver)
        if solver == SQP:   # the compiled copy, once ready (the same answer, sooner)
            self.sqp_solves += 1
            call = self.compiled(SQP) or call
        z0, p = call.args[0], call.args[1]  # written in place: the guess [vec U; x̃_1..x̃_M], the parameters
        self.write_guess(z0, x, guess_U, guess_X)
        k = n + M * n + P.size
        p[:n], p[n:n + M * n], p[n + M * n:k] = x, W.reshape(-1), P.reshape(-1)
        if self.n_theta:
            p[k:] = theta
        # the compiled solver's own count of its iterations, where an unsuccessful solve raises (orrc._jit)
        counter = call.counter if solver == SQP and self.solver_options[SQP].get("error_on_fail") else None
        before = counter.value if counter is not None else 0
        t0 = time.perf_counter()
        try:
            error, converged = call(), True
        except RuntimeError as exc:  # e.g. the QP solver of SQP fails inside CasADi: a failed solve
            converged = False
            error = None if UNSUCCESSFUL in str(exc) else exc   # (not converged: read below, as any answer)
        elapsed = time.perf_counter() - t0
        if error:
            text = _last_line(error) if isinstance(error, Exception) else f"CasADi return code {error}"
            return Plan(inputs=guess_U.copy(), states=np.vstack([x, self._guess_states(x, guess_X)]), value=float("nan"),
                        success=False, status=f"error: {text}", iterations=int(_stats(call).get("iter_count", 0) or 0),
                        solve_time=elapsed, fallback="the initial guess (the solver raised an error)", solver=solver)
        if counter is not None and converged and call.counter_checks >= COUNTER_CHECKS:
            iterations, status, success = counter.value - before, SQP_SOLVED, True   # no statistics to read
        else:
            stats = _stats(call)
            iterations = int(stats.get("iter_count", 0) or 0)
            status = str(stats.get("return_status", "unknown"))
            success = bool(stats.get("success", False))
            if counter is not None and converged:   # the count checked against the statistics, or dropped
                call.counter_checks, call.counter = ((call.counter_checks + 1, counter)
                                                     if counter.value - before == iterations else (0, None))
        zopt, value = call.res[0].copy(), float(call.res[1][0])
        U = zopt[self.iu].reshape(M, m)
        X = np.empty((M + 1, n))
        X[0], X[1:] = x, zopt[self.ix].reshape(M, n)
        extra = {"lam_x": call.res[3].copy(), "lam_g": call.res[4].copy()}  # the multipliers (bounds, dynamics)
        fallback = None
        finite = math.isfinite(value) and math.isfinite(zopt.sum())  # (the sum is inf or NaN if an entry is)
        if success and finite and solver == SQP:
            reason = self._rejection(call.res, zopt, value, p, guess_U, extra, in_place=True)
            if reason and self.stage_order and reason.startswith(NOT_COMPLEMENTARY):
                polished = self._polish(zopt, p, guess_U, extra)
                if polished is not None:   # the same KKT point, its multipliers exactly complementary
                    zopt, value, more = polished
                    iterations, reason = iterations + more, None
                    U, X[1:] = zopt[self.iu].reshape(M, m), zopt[self.ix].reshape(M, n)
            if reason:
                success, status = False, f"rejected: {reason}"
        if not success or not finite:
            success = False
            fallback = "the solver's last iterate"
            if not (np.isfinite(U).all() and np.isfinite(X).all()):
                U, X = guess_U.copy(), np.vstack([x, self._guess_states(x, guess_X)])
                fallback = "the initial guess (the solver's iterate is not finite)"
            if status == "Solve_Succeeded":
                status = "non-finite result"
        return Plan(inputs=U, states=X, value=value, success=success, status=status, iterations=iterations,
                    solve_time=elapsed, fallback=fallback, solver=solver, extra=extra)

    def _polish(self, z, p, guess_U, extra) -> tuple[np.ndarray, float, int] | None:
        """SQP with ``qrqp`` (module docstring: "Accepting an SQP answer") from the answer z of SQP with HPIPM that
        failed only the complementarity check: (its answer, J, its iterations) if that answer is accepted, else
        None. Its multipliers and the checks' quantities replace those in ``extra``; ``extra["polished"]`` says so.
        The polishing solver is built on first use (the same NLP and options, the QP solver ``qrqp``)."""
        if self._polisher is None:
            self._polisher = _qrqp_sqp(self.problem, self.solver_options[SQP])
        out = _solve_once(self._polisher, z, p, self.lbz, self.ubz)
        if out is None:
            return None
        res, value, iterations = out
        zp = res[0]
        quantities = {}
        if self._rejection(res, zp, value, p, guess_U, quantities) is not None:
            return None
        extra.update(quantities, lam_x=res[3], lam_g=res[4],
                     polished=f"by SQP with qrqp ({iterations} iterations): HPIPM's answer was not complementary")
        return zp, value, iterations

    def write_guess(self, z0, x, guess_U=None, guess_X=None) -> None:
        """Write a solve's guess z0 = [vec U; x̃_1..x̃_M] in place: the inputs ``guess_U`` (M, m; None: the cold
        start's) and the states ``guess_X[1:]`` (x̃_0..x̃_M given; None: x held over the horizon, the cold
        start's, :meth:`cold_start`)."""
        z0[self.iu] = (self._cold_U if guess_U is None else guess_U).reshape(-1)
        z0[self.ix] = np.tile(x, self.M) if guess_X is None else guess_X[1:].reshape(-1)

    def _guess_states(self, x, guess_X) -> np.ndarray:
        """The guess's states x̃_1..x̃_M (M, n): ``guess_X[1:]``, or x held (the cold start)."""
        return np.tile(x, (self.M, 1)) if guess_X is None else guess_X[1:]

    def _rejection(self, res, z, value, p, guess_U, extra, in_place: bool = False) -> str | None:
        """Why a converged SQP answer is not accepted (the checks of the module docstring), or None.
        ``res``: the solver's outputs (x, f, g, lam_x, lam_g, lam_p). The quantities of both checks come
        from one compiled CasADi function (:func:`acceptance_function`); ``in_place``: the answer is in
        the SQP buffer (:meth:`solve`), whose arrays the function reads without a copy."""
        if in_place:   # the solver's own buffers: the checks read its answer, p and the guess where they are
            check = self.compiled("acceptance") or self._call("acceptance")
            check.evaluate()
        else:
            check = self._call("acceptance-copy")
            guess = guess_U.reshape(-1)
            if self.stage_order:   # the checks read the guess's inputs out of a whole z
                guess = np.zeros(len(z))
                guess[self.iu] = guess_U.reshape(-1)
            check.evaluate(z, res[2], res[3], res[4], p, guess, value)
        quantities = check.res[0].tolist()
        extra["complementarity"], extra["guess_cost"] = quantities[0], quantities[1]
        return rejection(quantities, value)
