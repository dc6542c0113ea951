"""The M-step problem of Algorithm 1 for general systems and costs, with CasADi + IPOPT.

    min_{ũ_0..ũ_{M-1} ∈ U}  Σ_{j=0}^{M-1} c(x̃_j, ũ_j; p_j)  (+ terminal(x̃_M), an extension)
    s.t.  x̃_{j+1} = f(x̃_j, ũ_j, w_j),  x̃_0 = x,   (x̃_j ∈ X, an extension)

is transcribed once per (system, cost family, M) by multiple shooting into a
``casadi.nlpsol`` whose parameters are (x, vec W, vec P): the previewed state,
disturbances and cost parameters. Each call is warm-started from the given guess
(the receding-horizon controller passes its shifted previous plan).

A model with parameters θ (an :class:`orrc.ParametricSystem`, ``n_params > 0``) appends θ to
the parameter vector, (x, vec W, vec P, θ): Algorithm 2 solves on f(·; θ̂) and a new estimate
θ̂ is a new parameter value, not a new solver.

The solver only reports: a failed solve returns a :class:`~orrc.solvers.Plan` with
``success=False`` and the solver's status, holding the last iterate. What is then applied
(a cold retry, the shifted previous plan, stopping) is the controller's escalation policy
(:mod:`orrc.controllers.failures`), the same whichever solver failed.
"""
from __future__ import annotations

import time

import casadi as ca
import numpy as np

from .._validate import check_size
from ..systems import System
from ..costs import StageCost
from .plan import Plan, SolverWarning  # noqa: F401  (SolverWarning: importable here, as before)

#: operations per node of the transcribed expression graph (build and IPOPT set-up), measured
#: on the pendulum: about 1 ms per shooting interval of about 25 nodes
_OPS_PER_NODE = 4e4


DEFAULT_IPOPT = {
    "ipopt.print_level": 0,
    "ipopt.sb": "yes",
    "print_time": False,
    "ipopt.tol": 1e-9,
    "ipopt.acceptable_tol": 1e-6,
    "ipopt.max_iter": 500,
}


class ShootingNLP:
    """Multiple-shooting transcription of the M-step problem, built once.

    ``input_bounds``/``state_bounds``: (lo, hi) arrays of length m / n (±inf allowed).
    ``terminal``: a callable ``terminal(x)`` in CasADi operations, or None.
    ``solver_options``: extra options passed to ``casadi.nlpsol`` (IPOPT by default).
    """

    def __init__(self, system: System, cost: StageCost, M: int, input_bounds=None,
                 state_bounds=None, terminal=None, solver: str = "ipopt", solver_options=None):
        n, m, npar = system.n, system.m, cost.n_params
        self.M, self.n, self.m = M, n, m
        self.n_theta = int(getattr(system, "n_params", 0) or 0)   # model parameters θ (ParametricSystem)
        theta = ca.SX.sym("theta", self.n_theta)
        model = (lambda x, u, w: system.symbolic(x, u, w, theta)) if self.n_theta else system.symbolic
        x1, u1, w1, p1 = ca.SX.sym("x", n), ca.SX.sym("u", m), ca.SX.sym("w", n), ca.SX.sym("p", npar)
        stage_nodes = ca.Function("stage", [x1, u1, w1, p1, theta],
                                  [model(x1, u1, w1), cost.expr(x1, u1, p1)]).n_nodes()
        per_interval = stage_nodes + 4 * (n + m + npar)
        check_size(f"the CasADi transcription of the M-step problem at the horizon M={M} (n={n}, m={m})",
                   nbytes=M * per_interval * 400.0, ops=M * per_interval * _OPS_PER_NODE,
                   hint="lower M (the NLP has M (n + m) variables; IPOPT's work per iteration grows with it)")
        X = ca.SX.sym("X", n, M)        # x̃_1 .. x̃_M
        U = ca.SX.sym("U", m, M)
        x0 = ca.SX.sym("x0", n)
        W = ca.SX.sym("W", n, M)
        Pp = ca.SX.sym("P", npar, M)
        J = 0
        g = []
        xj = x0
        for j in range(M):
            J += cost.expr(xj, U[:, j], Pp[:, j])
            g.append(X[:, j] - model(xj, U[:, j], W[:, j]))
            xj = X[:, j]
        if terminal is not None:
            J += terminal(xj)
        z = ca.vertcat(ca.vec(U), ca.vec(X))
        p = ca.vertcat(x0, ca.vec(W), ca.vec(Pp), theta)
        opts = dict(DEFAULT_IPOPT) if solver == "ipopt" else {}
        opts.update(solver_options or {})
        try:
            self.solver = ca.nlpsol("rhc", solver, {"x": z, "f": J, "g": ca.vertcat(*g), "p": p}, opts)
        except RuntimeError as exc:  # CasADi rejects unknown solvers/options at construction
            from .._validate import OrrcValueError

            first = str(exc).strip().splitlines()[-1] if str(exc).strip() else repr(exc)
            raise OrrcValueError(
                f"CasADi rejected the NLP solver {solver!r} with options {sorted(solver_options or {})}: "
                f"{first}") from exc
        self.solver_name = solver
        ulo, uhi = (np.full(m, -np.inf), np.full(m, np.inf)) if input_bounds is None else input_bounds
        xlo, xhi = (np.full(n, -np.inf), np.full(n, np.inf)) if state_bounds is None else state_bounds
        self.lbz = np.concatenate([np.tile(ulo, M), np.tile(xlo, M)])
        self.ubz = np.concatenate([np.tile(uhi, M), np.tile(xhi, M)])
        self.input_bounds = (np.asarray(ulo, float), np.asarray(uhi, float))

    def solve(self, x, W, P, guess_U=None, guess_X=None, theta=None) -> Plan:
        """Solve from state x (n,) with preview W (M, n) and cost parameters P (M, n_params);
        ``theta`` (n_theta,): the model parameters, for a ParametricSystem (else None).

        No guess: a cold start (zero inputs clipped to the bounds, the state held at x). On
        failure the plan has ``success=False``, the solver's ``status`` and its last iterate
        (or the guess, where the iterate is not finite); nothing is warned here: the caller's
        escalation policy decides what to apply and says so.
        """
        M, n, m = self.M, self.n, self.m
        if guess_U is None:
            guess_U = np.clip(np.zeros((M, m)), *self.input_bounds)
        if guess_X is None:
            # cold start: hold the current state over the horizon (x̃_1..x̃_M = x). (A rollout
            # of the guessed inputs falls away from the origin on open-loop unstable systems,
            # and on long horizons IPOPT then stops in a poor local optimum: e.g. the
            # clairvoyant pendulum with |u| <= 8 over T = 150 steps, cost ~3500 vs ~205.)
            guess_next = np.tile(x, (M, 1))
        else:
            guess_next = guess_X[1:]  # guess_X holds x̃_0..x̃_M; the NLP's variables are x̃_1..x̃_M
        z0 = np.concatenate([guess_U.reshape(-1), guess_next.reshape(-1)])
        p = np.concatenate([x, W.reshape(-1), P.reshape(-1), np.zeros(0) if theta is None else theta])
        t0 = time.perf_counter()
        sol = self.solver(x0=z0, p=p, lbx=self.lbz, ubx=self.ubz, lbg=0.0, ubg=0.0)
        elapsed = time.perf_counter() - t0
        stats = self.solver.stats()
        status = str(stats.get("return_status", "unknown"))
        success = bool(stats.get("success", False))
        zopt = np.asarray(sol["x"]).ravel()
        U = zopt[: M * m].reshape(M, m)
        X = np.vstack([x, zopt[M * m:].reshape(M, n)])
        value = float(sol["f"])
        fallback = None
        if not success or not np.all(np.isfinite(zopt)) or not np.isfinite(value):
            success = False
            fallback = "the solver's last iterate"
            if not (np.all(np.isfinite(U)) and np.all(np.isfinite(X))):
                U, X = guess_U.copy(), np.vstack([x, guess_next])
                fallback = "the initial guess (the solver's iterate is not finite)"
            if status == "Solve_Succeeded":
                status = "non-finite result"
        return Plan(inputs=U, states=X, value=value, success=success, status=status,
                    iterations=int(stats.get("iter_count", 0)), solve_time=elapsed, fallback=fallback,
                    solver=self.solver_name)
