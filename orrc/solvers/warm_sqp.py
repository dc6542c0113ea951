"""The warm-started SQP step of the receding-horizon loop, on the solver's own buffers.

At each step of a closed loop on the NLP path (:class:`~orrc.PreviewRHC`, the SQP solver first), the
common case is one SQP solve from the previous plan shifted by one step, which converges and passes the
acceptance checks of :mod:`orrc.solvers.nlp`. :class:`WarmSQP` runs exactly that solve without
building a :class:`~orrc.solvers.Plan`: the shifted guess is written into the solver's input buffer
straight from its output buffer, the state and preview into its parameters, and the acceptance checks
read the answer where the solver left it (one compiled CasADi function). What it decides is what
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
  solve of the buffer (accepted or not) or the end of the loop reads it.
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
        call, self.check = nlp._call(SQP), nlp._call("acceptance")
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
        self.start(np.zeros(0, dtype=int))

    def start(self, iters) -> None:
        """Record the iteration counts of the accepted steps into ``iters`` (indexed by step)."""
        self.iters, self.pending, self.base = iters, -1, None   # base: n_call_QP after the last counted solve

    def set_guess(self, inputs, states) -> None:
        """The guess of the next solve: ``inputs`` (M, m) and states x̃_0..x̃_M (M+1, n; x̃_0 is replaced by the
        state), as :meth:`ShootingNLP.solve` writes them."""
        self.z0[: self.nu], self.z0[self.nu:] = inputs.reshape(-1), states[1:].reshape(-1)

    def step(self, x, w, P, t: int):
        """Solve step t from state x with preview w = vec(w_t..w_{t+M-1}) (M n,) and, for a cost sequence,
        the parameters P = vec(p_t..p_{t+M-1}) of the previewed costs (None: the cost's own), from the guess
        in the buffer: the seconds the solve took if its answer is accepted (V_M is ``f[0]``, the first input
        ``z[:m]``, the iteration count in ``iters[t]`` now or, pending, after the next solve or
        :meth:`finish`, the status :data:`~orrc.solvers.nlp.SQP_SOLVED`; the answer becomes the next guess
        shifted by one step), else None (the buffer's guess is then unchanged)."""
        p = self.p
        p[: self.n], p[self.n:self.nw] = x, w
        if P is not None:
            p[self.nw:self.nw + len(P)] = P
        t0 = time.perf_counter()
        try:
            self._evaluate()
        except RuntimeError:   # not successful (error_on_fail), or an error inside the solver
            return self._not_taken()
        elapsed = time.perf_counter() - t0
        self._check()
        if self.verdict[6] != 1.0:
            return self._not_taken()
        if self.pending < 0 and self.base is not None:
            self.pending = t   # counted with the next solve's statistics
        else:
            stats = self._buffer.stats()
            if not self.every_other and (self._buffer.ret() or not stats["success"]):
                return self._not_taken()
            qp, count = stats["n_call_QP"], stats["iter_count"]
            if self.pending >= 0:
                self._count(self.pending, qp - self.base - count)
            self.iters[t] = count
            self.base = qp if self.every_other else None
        # accepted: kept for the failure ladder, and shifted by one step into the next guess
        self.good[:] = self.z
        self.z0[:] = self.shifted
        return elapsed

    def _count(self, t: int, count: int) -> None:
        if count < 0:   # cannot happen with one QP per iteration: a CasADi whose sqpmethod counts otherwise
            raise RuntimeError(f"WarmSQP: step {t}'s iteration count from n_call_QP is {count} < 0; "
                               "the solver does not solve one QP per iteration")
        self.iters[t], self.pending = count, -1

    def _not_taken(self):
        """None, for a solve not accepted (the failure ladder solves the step again): a pending count read
        from this solve's statistics first, and from then on none known (the ladder's solves follow)."""
        if self.pending >= 0:
            stats = self._buffer.stats()
            self._count(self.pending, stats["n_call_QP"] - self.base - stats["iter_count"])
        self.base = None
        return None

    def finish(self) -> None:
        """Read the count of a pending step (the last solve of the buffer) at the end of the loop."""
        if self.pending >= 0:
            self._count(self.pending, self._buffer.stats()["iter_count"])
        self.base = None

    def plan(self, x, value: float) -> Plan:
        """The :class:`~orrc.solvers.Plan` of the last accepted answer, solved from state x (what the failure
        ladder keeps to shift from)."""
        M, n, m, z = self.M, self.n, self.m, self.good
        states = np.empty((M + 1, n))
        states[0], states[1:] = x, z[self.nu:].reshape(M, n)
        return Plan(inputs=z[: self.nu].reshape(M, m).copy(), states=states, value=value, solver=SQP)
