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
"""
from __future__ import annotations

import math
import time

import numpy as np

from .nlp import SQP, ShootingNLP, rejection
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
        self.nu, self.nw = M * m, n + M * n
        # the cost's parameters and θ: the same at every step of a time-invariant cost (as every solve writes them)
        self.p[self.nw:] = np.concatenate([np.asarray(P, float).reshape(-1), [] if theta is None else
                                           np.asarray(theta, float)])
        self.good = np.empty_like(self.z)   # the last accepted answer, z = [vec U; x̃_1..x̃_M]

    def set_guess(self, inputs, states) -> None:
        """The guess of the next solve: ``inputs`` (M, m) and states x̃_0..x̃_M (M+1, n; x̃_0 is replaced by the
        state), as :meth:`ShootingNLP.solve` writes them."""
        self.z0[: self.nu], self.z0[self.nu:] = inputs.reshape(-1), states[1:].reshape(-1)

    def step(self, x, w, P=None):
        """Solve from state x with preview w = vec(w_t..w_{t+M-1}) (M n,) and, for a cost sequence, the
        parameters P = vec(p_t..p_{t+M-1}) of the previewed costs (else the cost's own), from the guess in
        the buffer: (V_M, status, iterations, seconds) of an accepted answer, whose first input is
        ``z[:m]`` and which becomes the next guess shifted by one step; None when the answer is not
        accepted (the buffer's guess is then unchanged)."""
        p = self.p
        p[: self.n], p[self.n:self.nw] = x, w
        if P is not None:
            p[self.nw:self.nw + len(P)] = P
        t0 = time.perf_counter()
        try:
            self._evaluate()
        except RuntimeError:
            return None
        elapsed = time.perf_counter() - t0
        if self._buffer.ret():
            return None
        stats = self._buffer.stats()
        if not stats["success"]:
            return None
        z, value = self.z, float(self.f[0])
        self.check.evaluate()
        quantities = self.check.res[0].tolist()   # (the last: z is finite)
        if not (math.isfinite(value) and quantities[5] == 1.0) or rejection(quantities, value) is not None:
            return None
        # accepted: kept for the failure ladder, and shifted by one step into the next guess
        nu, m, n, z0 = self.nu, self.m, self.n, self.z0
        self.good[:] = z
        z0[: nu - m], z0[nu - m:nu] = z[m:nu], z[nu - m:nu]
        z0[nu:-n], z0[-n:] = z[nu + n:], z[-n:]
        return value, stats["return_status"], stats["iter_count"], elapsed

    def plan(self, x, value: float) -> Plan:
        """The :class:`~orrc.solvers.Plan` of the last accepted answer, solved from state x (what the failure
        ladder keeps to shift from)."""
        M, n, m, z = self.M, self.n, self.m, self.good
        states = np.empty((M + 1, n))
        states[0], states[1:] = x, z[self.nu:].reshape(M, n)
        return Plan(inputs=z[: self.nu].reshape(M, m).copy(), states=states, value=value, solver=SQP)
