"""The fast paths of :func:`orrc.simulate`: the same closed loop and information pattern, without an
Observation and a Decision per step (:mod:`orrc.controllers.base`, "Inputs without the per-step
records" and "Affine laws").

The rule that chooses them (:func:`fast_path`): a controller that offers ``fast_input`` on a problem
without a cost preview runs :func:`fast_input_loop`; if it also offers ``fast_affine`` (an affine law
u_t = −K x_t + f(W_t)), :func:`affine_loop`; a controller that offers ``fast_nlp`` (a warm SQP step,
:class:`~orrc.solvers.warm_sqp.WarmSQP`) on such a problem runs :func:`nlp_loop`. Every other run takes
the loop of the paper's information pattern in :mod:`orrc.simulate`.
"""
from __future__ import annotations

import numpy as np

from ._casadi import Buffered
from ._validate import OrrcValueError
from .solvers.nlp import SQP, SQP_SOLVED
from .systems import NonlinearSystem
from .trajectory import Record, windows


def fast_path(controller, rec: Record):
    """The loop that runs ``controller`` (:func:`affine_loop`, :func:`fast_input_loop`, :func:`nlp_loop`), or None for
    the loop of the information pattern: a controller's ``fast_input`` serves a problem whose costs
    it does not preview (a time-invariant cost, or a controller with preview_c = 0); ``fast_nlp`` serves
    every problem (the previewed costs c_{t:t+M-1} are parameters of its NLP)."""
    if controller.fast_input is None or (rec.cparams is not None and rec.Mc):
        offer = getattr(controller, "fast_nlp", None)   # (a cost preview is a parameter of its NLP)
        return nlp_loop if offer is not None and offer() is not None else None
    return affine_loop if getattr(controller, "fast_affine", None) is not None else fast_input_loop


def affine_loop(controller, rec: Record, step, A, B) -> None:
    """The closed loop of a controller that offers ``fast_affine``: u_t = −K x_t + f_t, with the
    feed-forward f_t of every step's own preview window from one batch call before the loop. On a
    linear system (``step`` None) the loop steps the closed loop x_{t+1} = (A − BK) x_t + B f_t + w_t
    (one product per step) and the inputs u_t = −K x_t + f_t follow in one product; otherwise each step
    computes u_t and calls the dynamics."""
    T, Mw, X, X_read, U, wpad = rec.T, rec.Mw, rec.X, rec.X_read, rec.U, rec.wpad
    m = U.shape[1]
    K, feedforward = controller.fast_affine
    F = np.asarray(feedforward(windows(wpad, Mw, T)), dtype=float)
    if F.shape != (T, m) or np.shape(K) != (m, X.shape[1]):
        raise OrrcValueError(f"controller {controller.name!r}: fast_affine must give K of shape ({m}, {X.shape[1]}) "
                             f"and a feed-forward of shape ({T}, {m}); got {np.shape(K)} and {F.shape}")
    negK = -np.asarray(K, dtype=float)
    if step is None:   # linear: x_{t+1} = (A − BK) x_t + (B f_t + w_t), the inputs after the loop in one product
        Acl, E = A + B @ negK, F @ B.T + wpad[:T]
        for t in range(T):
            X[t + 1] = Acl @ X_read[t] + E[t]
        U[:] = X[:T] @ negK.T + F
        return
    for t in range(T):
        xt = X_read[t]
        u = negK @ xt + F[t]
        U[t] = u
        X[t + 1] = step(xt, u, wpad[t])


def fast_input_loop(controller, rec: Record, step, A, B) -> None:
    """The closed loop of a controller that offers ``fast_input``: the same information (x_t read-only,
    the preview w_{t:t+M_w-1}), no Observation or Decision per step."""
    T, Mw, X, X_read, U, wpad = rec.T, rec.Mw, rec.X, rec.X_read, rec.U, rec.wpad
    m = U.shape[1]
    fast = controller.fast_input
    m_shape = (m,)
    empty_w = wpad[:0]
    for t in range(T):
        xt = X_read[t]
        u = fast(xt, wpad[t:t + Mw] if Mw else empty_w)
        if type(u) is not np.ndarray or u.shape != m_shape or u.dtype != float:
            try:
                u = np.asarray(u, dtype=float).reshape(m)
            except (TypeError, ValueError) as exc:
                raise OrrcValueError(f"controller {controller.name!r}: fast_input must return u with m={m} entries; "
                                     f"at t={t} it returned shape {np.shape(u)}") from exc
        U[t] = u
        X[t + 1] = A @ xt + B @ u + wpad[t] if step is None else step(xt, u, wpad[t])


def nlp_loop(controller, rec: Record, step, A, B, general_step) -> None:
    """The closed loop of a receding-horizon controller on the NLP path (``controller.fast_nlp()``, a
    :class:`~orrc.solvers.warm_sqp.WarmSQP`): each run of steps solved by SQP and accepted by its checks is
    taken by :meth:`WarmSQP.run <orrc.solvers.warm_sqp.WarmSQP.run>`, which records u_t, V_M, the seconds and
    iterations in place, with no Observation, Decision or Plan; its statuses and solver, and the stage costs
    of a non-quadratic cost, are recorded after the run. A run starts from the guess of the failure ladder's
    first rung: at t = 0 the SQP cold start (the ladder has no plan to shift yet: the NLP's
    :meth:`~orrc.solvers.nlp.ShootingNLP.cold_start`), after a step of the controller's own the previous plan
    shifted. Every other step (one the warm solve does not accept, the steps after a failed one) is
    ``general_step(t)``, the controller's own :meth:`~orrc.Controller.control` in the loop of the information
    pattern, after its failure ladder (``controller.failures``) is handed the last plan accepted in a run; a
    step not accepted leaves the guess as it was, and the ladder solves it again from the same guess (the
    same answer) before it climbs its rungs. The same inputs, values and record as :func:`orrc.simulate`'s
    loop of the information pattern."""
    T, X, X_read, U, wpad = rec.T, rec.X, rec.X_read, rec.U, rec.wpad
    warm, ladder = controller.fast_nlp(), controller.failures
    m, z = U.shape[1], warm.z
    n = X.shape[1]
    made = warm.made   # what this loop makes once per warm step, not per run
    wflat = wpad.reshape(-1)   # the preview of step t: its rows t..t+M-1, vec(w_t..w_{t+M-1})
    cp = rec.cparams if rec.Mc else None   # a cost sequence: the parameters of c_t..c_{t+M-1} at step t
    cflat, k = (np.ascontiguousarray(cp).reshape(-1), cp.shape[1]) if cp is not None else (None, 0)
    if step is not None and getattr(step, "__func__", None) is NonlinearSystem._step:
        # the plant on the solver's buffers (as a NonlinearSystem's _step evaluates): f(x_t, u_t, w_t) read
        # where an accepted warm step leaves them, x_t and w_t (the preview's first row) in the solver's
        # parameters, u_t in its answer (no copies); made once per warm step and plant
        fn = step.__self__.function
        plant = made.get("plant")
        if plant is None or plant[0] is not fn:
            plant = made["plant"] = (fn, Buffered(fn, args=[warm.p[:n], z[:m], warm.p[n:2 * n]]))
        advance = plant[1]
    elif step is None:
        def advance(t):
            X[t + 1] = A @ X_read[t] + B @ U[t] + wpad[t]
    else:
        def advance(t):
            X[t + 1] = step(X_read[t], U[t], wpad[t])
    status, solver, has_value = rec.status, rec.solver, rec.has_value
    t, guess = 0, ladder.warm_start(0) is None
    if guess:   # the first rung of step 0: SQP from the cold start (its inputs; the state held at x_0)
        warm.set_guess(None, None, X[0])
    while t < T:
        if guess:
            start = t
            t = warm.run(t, T, X, U, rec.V, rec.times, rec.iters, wflat, cflat, k, advance)
            if t > start:   # steps start..t-1 taken by the warm loop: SQP solved them
                status[start:t], solver[start:t], has_value[start:t] = \
                    [SQP_SOLVED] * (t - start), [SQP] * (t - start), True
                if not rec.quadratic:
                    for s in range(start, t):
                        rec.C[s] = rec.stage_cost(X_read[s], U[s], None if cp is None else cp[s])
                ladder.succeeded(t - 1, warm.plan(X_read[t - 1], float(rec.V[t - 1])))
            if t == T:
                break
        general_step(t)   # the controller's own step (its failure ladder)
        t += 1
        shifted = ladder.warm_start(t) if t < T and rec.ok[t - 1] else None
        guess = shifted is not None and shifted[2] == 1
        if guess:
            warm.set_guess(shifted[0], shifted[1])


def record_fast_steps(controller, rec: Record) -> None:
    """The per-step record of a fast run: every step is described by ``controller.fast_decision``
    (its status, solver, V_M or that V_M is deferred); the stage costs of a non-quadratic cost."""
    tmpl, T = controller.fast_decision, rec.T
    rec.status[:], rec.solver[:] = [tmpl.status] * T, [tmpl.solver] * T
    rec.deferred[:] = tmpl.value_deferred
    if tmpl.value is not None:
        rec.V[:], rec.has_value[:] = tmpl.value, True
    if not rec.quadratic:
        rec.costs_in_loop()
