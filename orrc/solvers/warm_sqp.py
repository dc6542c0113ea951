"""The warm-started SQP step of the receding-horizon loop, on the solver's own buffers.

At each step of a closed loop on the NLP path (:class:`~orrc.PreviewRHC`, the SQP solver first), the
common case is one SQP solve from the previous plan shifted by one step, which converges and passes the
acceptance checks of :mod:`orrc.solvers.acceptance`. :class:`WarmSQP` runs exactly that solve without
building a :class:`~orrc.solvers.Plan`: the state and preview are written into the solver's parameters,
and one compiled CasADi function reads the answer where the solver left it and gives the checks'
verdict and the next guess (the answer shifted by one step), copied into the solver's input buffer
when the answer is accepted. What it decides is what
:meth:`ShootingNLP.solve <orrc.solvers.nlp.ShootingNLP.solve>` decides on the same guess: a step it
does not accept (no convergence, an error, a non-finite answer, a rejected answer) is left to the
controller's failure ladder, which solves it again from the same guess and climbs its rungs.
:meth:`WarmSQP.run` takes consecutive warm steps in one loop, writing each step's record into the
closed loop's arrays, until a step is not accepted (the simulator then records the run's statuses in
one assignment: every step of it has the same).

**Compiled after a while.** Once :data:`~orrc._jit.COMPILE_AFTER` SQP solves have been made on an NLP (or
after :meth:`ShootingNLP.compile <orrc.solvers.nlp.ShootingNLP.compile>`), compiled copies of the SQP
solver (the NLP's functions and derivatives as machine code instead of CasADi's interpreter: about a fifth
of a step) and of the acceptance checks (about 3 µs a step) are built in the background by the system's
C compiler and cached (:mod:`orrc._jit`); the warm step uses each from the first run after it is ready.
They give the interpreted ones' answers and verdicts bit for bit, so a run's record does not depend on
when they arrive; without a C compiler the interpreted ones stay. The compiled solver also counts its
SQP iterations (one Hessian of the Lagrangian each, :func:`orrc._jit.compiled_nlpsol`): its count is read
in 0.1 µs at every step, checked against the statistics on its first
:data:`~orrc._jit.COUNTER_CHECKS` solves in a thread, and no statistics are read after that.

**The per-step record without a statistics read per step.** Each accepted step is recorded with the
solver's status and iteration count, as :meth:`ShootingNLP.solve` records them. CasADi's Python API
gives the iteration count only inside the solver's statistics (``FunctionBuffer.stats()``: a
dictionary of 28 entries, about 7 µs to convert, a tenth of the step), so the step reads it at every
second accepted step and both counts come out of that one read, exactly:

* whether the solve succeeded is known without the statistics: orrc's SQP solver is built with
  ``error_on_fail`` (:data:`~orrc.solvers.nlp.DEFAULT_SQP`), so an unsuccessful solve raises, and a
  successful one has the status :data:`~orrc.solvers.nlp.SQP_SOLVED` (``sqpmethod``'s only status of
  success);
* ``sqpmethod`` solves one QP per iteration (``n_call_QP``, counted over every solve of the buffer's
  memory; not so with its ``elastic_mode`` or ``so_corr`` options, which then get a read per step): the
  statistics after solves a and b give b's count (``iter_count``) and a's as the growth of ``n_call_QP``
  since the read before a, less b's count. A step whose count is not read yet is *pending*; the next
  solve of the buffer (accepted or not) or the end of the run reads it. The counters accumulate over
  a buffer's solves because ``FunctionBuffer`` evaluates without resetting them (a ``Function`` call
  resets them): a buffer's first two reads in a row check that (and that ``n_call_nlp_jac_fg`` grew by
  the count + 1) before any count is deferred (``Buffered.counts_accumulate``; else a read per step),
  and every read that splits two counts checks that the Jacobians add up (iterations + 1 per solve).
"""
from __future__ import annotations

import time

import numpy as np

from .._casadi import Buffered
from .._jit import COUNTER_CHECKS
from .nlp import SQP, ShootingNLP
from .plan import Plan


class WarmSQP:
    """The warm SQP step of Algorithm 1: Eq. (3) solved from the previous plan shifted by one step, on
    the solver's own buffers (see the module).

    Parameters
    ----------
    nlp : ShootingNLP
        The transcription of Eq. (3) (:class:`~orrc.solvers.nlp.ShootingNLP`) whose first solver is SQP.
    P : array_like
        The cost's own parameters, (M, n_params); a step may give the previewed ones instead.
    theta : array_like, optional
        The model parameters θ of a :class:`~orrc.ParametricSystem`; None for a model without them.

    Examples
    --------
    Five warm steps of the inverted pendulum's closed loop, without disturbances; the first step's V_M
    is the plan's value from a cold start:

    >>> import numpy as np
    >>> import orrc
    >>> from orrc.solvers.warm_sqp import WarmSQP
    >>> ex = orrc.examples.inverted_pendulum()
    >>> rhc = orrc.PreviewRHC(ex.system, ex.cost, M=10, input_bounds=ex.input_bounds)
    >>> warm = WarmSQP(rhc.nlp,
    ...                np.broadcast_to(ex.cost.default_params, (10, ex.cost.n_params)))
    >>> T = 5
    >>> X, U = np.zeros((T + 1, 2)), np.zeros((T, 1))
    >>> V, times, iters = np.zeros(T), np.zeros(T), np.zeros(T, dtype=int)
    >>> w = np.zeros((T + 10) * 2)                         # the flat disturbances
    >>> X[0] = ex.x0
    >>> def advance(s):
    ...     X[s + 1] = ex.system.step(X[s], U[s], w[2 * s:2 * s + 2])
    >>> warm.set_guess(None, None, X[0])                   # a cold start
    >>> warm.run(0, T, X, U, V, times, iters, w, advance=advance)    # every step accepted
    5
    >>> bool(abs(V[0] - rhc.plan(ex.x0, np.zeros((10, 2))).value) < 1e-6 * V[0])
    True
    >>> bool(np.all(np.diff(V) < 0))   # the value decreases along the loop
    True
    >>> plan = warm.plan(X[T - 1], V[T - 1])               # the last accepted answer
    >>> plan.inputs.shape, plan.states.shape, plan.solver
    ((10, 1), (11, 2), 'sqp')
    """

    def __init__(self, nlp: ShootingNLP, P, theta=None):
        self.nlp = nlp
        M, n, m = self.M, self.n, self.m = nlp.M, nlp.n, nlp.m
        self._use_solver(nlp._call(SQP))
        call = self.call
        self.z0, self.p, self.z, self.f = call.args[0], call.args[1], call.res[0], call.res[1]
        self._use_check(nlp._call("acceptance"))
        #: the solver and the checks are the compiled copies (:meth:`ShootingNLP.compiled`)
        self.compiled = False
        #: what :func:`orrc._fast_loops.nlp_loop` makes once per warm step, not per run: {"plant": (the plant's
        #: Function, its step on this step's buffers)}
        self.made = {}
        self.nu, self.nw = M * m, n + M * n
        # the cost's parameters and θ: the same at every step of a time-invariant cost (as every solve writes them)
        self.p[self.nw:] = np.concatenate([np.asarray(P, float).reshape(-1), [] if theta is None else
                                           np.asarray(theta, float)])
        self.good = np.empty_like(self.z)   # the last accepted answer, z = [vec U; x̃_1..x̃_M]
        opts = nlp.solver_options[SQP]
        #: success known from error_on_fail, and one QP per iteration: a statistics read every second step
        self.every_other = bool(opts.get("error_on_fail")) and not opts.get("elastic_mode") and not opts.get("so_corr")

    def _use_solver(self, call: Buffered) -> None:
        """Solve with ``call`` (the SQP solver on the arrays every other part reads)."""
        self.call, self._evaluate, self._buffer = call, call._evaluate, call.buffer

    def _use_check(self, check: Buffered) -> None:
        """Evaluate the acceptance checks with ``check`` (on the solver's own arrays)."""
        self.check, self._check = check, check._evaluate
        self.verdict, self.shifted = check.res   # the checks (entry 6: 1 if accepted), z shifted by a step

    def _use_compiled(self) -> None:
        """The solver and the checks compiled to machine code, where ready (:meth:`ShootingNLP.compile`: the
        same answers and verdicts, bit for bit; each used from the first run after it is ready)."""
        solver, check = self.nlp.compiled(SQP), self.nlp.compiled("acceptance")
        if solver is not None and solver is not self.call:
            self._use_solver(solver)
        if check is not None and check is not self.check:
            self._use_check(check)
        self.compiled = solver is not None and check is not None

    def set_guess(self, inputs, states, x=None) -> None:
        """Write the guess of the next solve of Eq. (3) into the solver's buffer.

        The guess is ``inputs`` and ``states``, or with both None the cold start from state ``x``, as
        :meth:`ShootingNLP.solve` writes them
        (:meth:`ShootingNLP.write_guess <orrc.solvers.nlp.ShootingNLP.write_guess>`).

        Parameters
        ----------
        inputs : ndarray or None
            The guessed inputs, (M, m).
        states : ndarray or None
            The guessed states x̃_0..x̃_M, (M+1, n); x̃_0 is replaced by the state.
        x : ndarray, optional
            The state of a cold start (n,).

        Returns
        -------
        None

        Examples
        --------
        See :class:`WarmSQP`.
        """
        self.nlp.write_guess(self.z0, x, inputs, states)

    def run(self, t: int, stop: int, X, U, V, times, iters, w, P=None, k: int = 0, advance=None) -> int:
        """Warm steps t, t+1, ... of one closed loop, while each is accepted, up to ``stop``: returns the
        first step not taken (``stop`` when all were). Step s solves from state ``X[s]`` with the preview
        vec(w_s..w_{s+M-1}) = ``w[s n:(s+M) n]`` (``w`` the flat disturbances) and, for a cost sequence,
        the previewed costs' parameters ``P[s k:(s+M) k]`` (``P`` flat, k per step; None: the cost's own),
        from the guess in the buffer. An accepted step records its input ``U[s]`` (the answer's first),
        V_M ``V[s]``, the seconds of its solve ``times[s]`` and its iteration count ``iters[s]`` (its status
        is :data:`~orrc.solvers.nlp.SQP_SOLVED`), makes its answer the next guess shifted by one step, and
        moves the plant: ``advance(s)`` writes ``X[s + 1]``, or, with ``advance`` a
        :class:`~orrc._casadi.Buffered` (the plant's step evaluated on this buffer's own arrays: x_s and
        w_s in the parameters, u_s in the answer), its result is ``X[s + 1]``. A step not accepted (no convergence, an error, a
        non-finite or rejected answer) leaves the buffer's guess unchanged for the failure ladder. Every
        count is written before it returns (the module docstring: a pending count is read with the next
        solve's statistics, or at the end).

        Parameters
        ----------
        t, stop : int
            The first step to take and the step to stop before.
        X, U, V, times, iters : ndarray
            The closed loop's states (T+1, n), inputs (T, m), V_M, solve seconds and iteration counts (T,),
            written in place.
        w : ndarray
            The flat disturbances, at least (stop + M - 1) n entries.
        P : ndarray, optional
            The previewed costs' parameters, flat, k per step; None: the cost's own.
        k : int
            The cost's parameters per step (with ``P``).
        advance : callable or Buffered
            The plant's step: ``advance(s)`` writes ``X[s + 1]``, or a Buffered step whose result is.

        Returns
        -------
        int
            The first step not taken (``stop`` when every step was accepted).

        Examples
        --------
        See :class:`WarmSQP`.
        """
        if not self.compiled:
            self._use_compiled()
        first = t
        p, n, nw, M, m, call = self.p, self.n, self.nw, self.M, self.m, self.call
        solve, check, verdict, shifted = self._evaluate, self._check, self.verdict, self.shifted
        z, z0, good, read, ret, value = self.z, self.z0, self.good, call.read_stats, self._buffer.ret, self.f
        every_other, clock = self.every_other, time.perf_counter
        px, pw, zu = p[:n], p[n:nw], z[:m]   # x_s and the preview in the parameters; u_s in the answer
        pc = p[nw:nw + M * k] if P is not None else None
        plant = advance if isinstance(advance, Buffered) else None
        if plant is not None:
            feval, fout = plant._evaluate, plant.res[0]
        pending, base = -1, None   # the step whose count is not read yet; (n_call_QP, n_call_nlp_jac_fg) then
        counter = call.counter if every_other else None   # a compiled solver's own count of its iterations
        calls = counter.value if counter is not None else 0
        while t < stop:
            px[:] = X[t]
            pw[:] = w[t * n:(t + M) * n]
            if pc is not None:
                pc[:] = P[t * k:(t + M) * k]
            t0 = clock()
            try:
                solve()
            except RuntimeError:   # not successful (error_on_fail), or an error inside the solver
                break
            elapsed = clock() - t0
            check()
            if verdict[6] != 1.0:
                break
            if counter is not None:   # one Hessian per iteration, counted by the compiled solver
                c = counter.value - calls
                calls += c
                if call.counter_checks < COUNTER_CHECKS:   # the buffer's first solves: the statistics agree?
                    read_c = read()["iter_count"]
                    if read_c == c:
                        call.counter_checks += 1
                    else:   # not one Hessian per iteration (e.g. a quasi-Newton option): the statistics from now on
                        call.counter = counter = None
                        c = read_c
                iters[t] = c
            elif pending < 0 and base is not None and call.counts_accumulate:
                pending = t   # counted with the next solve's statistics
            else:
                stats = read()
                if not every_other and (ret() or not stats["success"]):
                    break
                qp, jac, c = stats["n_call_QP"], stats["n_call_nlp_jac_fg"], stats["iter_count"]
                if pending >= 0:   # two converged solves: c + 1 and the pending count + 1 Jacobians
                    if (jac - base[1]) - (qp - base[0]) != 2:
                        raise RuntimeError(f"WarmSQP: the solver's counters at step {t} do not add up "
                                           "(n_call_nlp_jac_fg against n_call_QP over two solves)")
                    _count(iters, pending, qp - base[0] - c)
                    pending = -1
                elif base is not None and call.counts_accumulate is None:   # the first two reads in a row
                    call.counts_accumulate = qp - base[0] == c and jac - base[1] == c + 1
                iters[t] = c
                base = (qp, jac) if every_other else None
            # accepted: kept for the failure ladder, and shifted by one step into the next guess
            good[:] = z
            z0[:] = shifted
            V[t], times[t], U[t] = value[0], elapsed, zu
            if plant is None:
                advance(t)
            else:
                feval()
                X[t + 1] = fout
            t += 1
        if pending >= 0:
            stats = read()
            if t < stop:   # the solve not taken counts the pending step too (iter_count -1: no iteration)
                _count(iters, pending, stats["n_call_QP"] - base[0] - max(stats["iter_count"], 0))
            else:          # the pending step was the last solve of the run
                iters[pending] = stats["iter_count"]
        self.nlp.sqp_solves += t - first
        return t

    def plan(self, x, value: float) -> Plan:
        """The plan of Eq. (3) of the last accepted answer, solved from state x (what the failure ladder
        keeps to shift from).

        Parameters
        ----------
        x : ndarray
            The state (n,) the last accepted answer was solved from.
        value : float
            Its V_M (as :meth:`run` recorded it).

        Returns
        -------
        Plan
            The :class:`~orrc.solvers.Plan` of that answer (solver "sqp").

        Examples
        --------
        See :class:`WarmSQP` (its last lines: the plan of the fifth step).
        """
        M, n, m, z = self.M, self.n, self.m, self.good
        states = np.empty((M + 1, n))
        states[0], states[1:] = x, z[self.nlp.ix].reshape(M, n)
        return Plan(inputs=z[self.nlp.iu].reshape(M, m).copy(), states=states, value=value, solver=SQP)


def _count(iters, t: int, c: int) -> None:
    """Record step t's iteration count c, split from n_call_QP (module docstring)."""
    if c < 0:   # cannot happen with one QP per iteration: a CasADi whose sqpmethod counts otherwise
        raise RuntimeError(f"WarmSQP: step {t}'s iteration count from n_call_QP is {c} < 0; "
                           "the solver does not solve one QP per iteration")
    iters[t] = c
