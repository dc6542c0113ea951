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
  solve of the buffer (accepted or not) or the end of the loop reads it. The counters accumulate over
  a buffer's solves because ``FunctionBuffer`` evaluates without resetting them (a ``Function`` call
  resets them): a buffer's first two reads in a row check that (and that ``n_call_nlp_jac_fg`` grew by
  the count + 1) before any count is deferred (``Buffered.counts_accumulate``; else a read per step),
  and every read that splits two counts checks that the Jacobians add up (iterations + 1 per solve).
"""
from __future__ import annotations

import time

import numpy as np

from .nlp import SQP, ShootingNLP
from .plan import Plan


class WarmSQP:
    """The warm SQP step of ``nlp`` (a :class:`ShootingNLP` whose first solver is SQP) with the cost's own
    parameters ``P`` (M, n_params; a step may give the previewed ones instead) and model parameters
    ``theta`` (or None)."""

    def __init__(self, nlp: ShootingNLP, P, theta=None):
        self.nlp = nlp
        M, n, m = self.M, self.n, self.m = nlp.M, nlp.n, nlp.m
        self.call = call = nlp._call(SQP)
        self.check = nlp._call("acceptance")
        self._evaluate, self._buffer = call._evaluate, call.buffer
        self.z0, self.p, self.z, self.f = call.args[0], call.args[1], call.res[0], call.res[1]
        self.verdict, self.shifted = self.check.res   # the checks (entry 6: 1 if accepted), z shifted by a step
        self._check = self.check._evaluate
        self.nu, self.nw = M * m, n + M * n
        # the cost's parameters and θ: the same at every step of a time-invariant cost (as every solve writes them)
        self.p[self.nw:] = np.concatenate([np.asarray(P, float).reshape(-1), [] if theta is None else
                                           np.asarray(theta, float)])
        self.good = np.empty_like(self.z)   # the last accepted answer, z = [vec U; x̃_1..x̃_M]
        opts = nlp.solver_options[SQP]
        #: success known from error_on_fail, and one QP per iteration: a statistics read every second step
        self.every_other = bool(opts.get("error_on_fail")) and not opts.get("elastic_mode") and not opts.get("so_corr")

    def set_guess(self, inputs, states) -> None:
        """The guess of the next solve: ``inputs`` (M, m) and states x̃_0..x̃_M (M+1, n; x̃_0 is replaced by the
        state), as :meth:`ShootingNLP.solve` writes them."""
        self.z0[: self.nu], self.z0[self.nu:] = inputs.reshape(-1), states[1:].reshape(-1)

    def stepper(self, iters):
        """The warm step of one closed loop, ``(step, finish)``, recording the iteration counts of the
        accepted steps into ``iters`` (indexed by step; a pending count, module docstring, is written
        by the next call of either).

        ``step(t, x, w, P=None)`` solves step t from state x with preview w = vec(w_t..w_{t+M-1}) (M n,)
        and, for a cost sequence, the parameters P = vec(p_t..p_{t+M-1}) of the previewed costs (None: the
        cost's own), from the guess in the buffer. It returns the seconds the solve took if its answer is
        accepted (V_M is ``f[0]``, the first input ``z[:m]``, the status
        :data:`~orrc.solvers.nlp.SQP_SOLVED`; the answer becomes the next guess shifted by one step), else
        None (the buffer's guess is then unchanged; the failure ladder's solves follow). ``finish()``: the
        end of the loop."""
        p, n, nw, call = self.p, self.n, self.nw, self.call
        solve, check, verdict, shifted = self._evaluate, self._check, self.verdict, self.shifted
        z, z0, good, read, ret = self.z, self.z0, self.good, call.read_stats, self._buffer.ret
        every_other, clock = self.every_other, time.perf_counter
        pending, base = -1, None   # the step whose count is not read yet; (n_call_QP, n_call_nlp_jac_fg) then

        def count(t: int, c: int) -> None:
            if c < 0:   # cannot happen with one QP per iteration: a CasADi whose sqpmethod counts otherwise
                raise RuntimeError(f"WarmSQP: step {t}'s iteration count from n_call_QP is {c} < 0; "
                                   "the solver does not solve one QP per iteration")
            iters[t] = c

        def not_taken():
            nonlocal pending, base
            if pending >= 0:   # this solve's statistics count the pending step too (iter_count -1: no iteration)
                stats = read()
                count(pending, stats["n_call_QP"] - base[0] - max(stats["iter_count"], 0))
                pending = -1
            base = None
            return None

        def step(t: int, x, w, P=None):
            nonlocal pending, base
            p[:n], p[n:nw] = x, w
            if P is not None:
                p[nw:nw + len(P)] = P
            t0 = clock()
            try:
                solve()
            except RuntimeError:   # not successful (error_on_fail), or an error inside the solver
                return not_taken()
            elapsed = clock() - t0
            check()
            if verdict[6] != 1.0:
                return not_taken()
            if pending < 0 and base is not None and call.counts_accumulate:
                pending = t   # counted with the next solve's statistics
            else:
                stats = read()
                if not every_other and (ret() or not stats["success"]):
                    return not_taken()
                qp, jac, c = stats["n_call_QP"], stats["n_call_nlp_jac_fg"], stats["iter_count"]
                if pending >= 0:   # two converged solves: c + 1 and the pending count + 1 Jacobians
                    if (jac - base[1]) - (qp - base[0]) != 2:
                        raise RuntimeError(f"WarmSQP: the solver's counters at step {t} do not add up "
                                           "(n_call_nlp_jac_fg against n_call_QP over two solves)")
                    count(pending, qp - base[0] - c)
                    pending = -1
                elif base is not None and call.counts_accumulate is None:   # the first two reads in a row
                    call.counts_accumulate = qp - base[0] == c and jac - base[1] == c + 1
                iters[t] = c
                base = (qp, jac) if every_other else None
            # accepted: kept for the failure ladder, and shifted by one step into the next guess
            good[:] = z
            z0[:] = shifted
            return elapsed

        def finish() -> None:
            nonlocal pending, base
            if pending >= 0:   # the last solve of the buffer
                count(pending, read()["iter_count"])
                pending = -1
            base = None

        return step, finish

    def plan(self, x, value: float) -> Plan:
        """The :class:`~orrc.solvers.Plan` of the last accepted answer, solved from state x (what the failure
        ladder keeps to shift from)."""
        M, n, m, z = self.M, self.n, self.m, self.good
        states = np.empty((M + 1, n))
        states[0], states[1:] = x, z[self.nu:].reshape(M, n)
        return Plan(inputs=z[: self.nu].reshape(M, m).copy(), states=states, value=value, solver=SQP)
