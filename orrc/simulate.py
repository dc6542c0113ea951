"""The closed loop: x_{t+1} = f(x_t, u_t, w_t) with u_t from a controller that sees
only its preview (the information pattern of Eq. 2 of the paper).

Time runs t = 0..T-1 (the paper's t = 1..T). At step t the controller receives an
:class:`~orrc.controllers.Observation` with x_t, w_{t-1}, the previewed
disturbances w_{t:t+M_w-1} and cost parameters c_{t:t+M_c-1}, where M_w, M_c are
the controller's declared ``preview_w`` and ``preview_c``, and nothing else.

Preview past the data: ``w`` needs at least T rows; rows T, T+1, ... are the preview
tail (give T+M-1 rows for a full preview up to the end). Where the given rows run
out, the controller sees w = 0 (the future beyond the supplied sequence is taken as
zero). A cost sequence shorter than needed repeats its last cost.

What can go wrong, and what :func:`simulate` does:

* bad arguments (shapes, NaN, a controller built for other dimensions or another T): an
  :class:`~orrc.OrrcValueError` before the first step;
* a solver failure at some steps: the controller's fallback is applied and the steps are
  marked (``Trajectory.success``, ``status``, ``fallback``; V_M is NaN there and
  ``Trajectory.value_valid`` False); the run ends with exactly ONE :class:`~orrc.SolverWarning`
  naming the count of failed steps and the fallbacks applied (the controllers do not warn per
  step). A controller that gives up (:class:`~orrc.SolverError`, after ``max_failures``
  consecutive failed steps of :class:`~orrc.PreviewRHC`) stops the run: the error propagates
  with ``error.trajectory``, the run up to the step before;
* the state or the input becomes inf or NaN (the loop diverged): ``FloatingPointError``
  naming the step;
* the state stays finite but a stage cost, σ or V_M overflows (a huge weight or state, a long
  unstable run): one :class:`~orrc.NonFiniteWarning` naming the quantities and the first step;
  a non-finite V_M is also marked invalid in ``value_valid``.
"""
from __future__ import annotations

import time
import warnings
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from ._validate import NonFiniteWarning, OrrcValueError, as_array, as_int, check_size
from .controllers.base import Controller, Observation
from .costs import CostSequence, QuadraticCost, StageCost
from .solvers.plan import SolverError, SolverWarning
from .systems import LinearSystem, NonlinearSystem, System


@dataclass
class Trajectory:
    """The result of :func:`simulate`.

    x : (T+1, n) states x_0..x_T
    u : (T, m) inputs
    w : (T, n) the disturbances that acted
    costs : (T,) c_t(x_t, u_t)
    w_all : (T + max(M_w, 1), n) the disturbance record the controller previewed
        (w plus the preview tail, zeros where the given data ran out)
    sigma : (T+1,) σ(x_t)
    values : (T,) V_M at each step when the controller reports it at every step, else None;
        NaN at the steps whose solve failed (a failed solve has no optimal value)
    value_valid : (T,) bool, True where ``values`` holds the V_M of a successful solve (None with
        ``values``); the checks of :mod:`orrc.checks` refuse a trajectory where it is not all True
    success : (T,) False at the steps whose solve failed (True where the controller solved
        nothing, e.g. the clairvoyant's steps after t = 0)
    status : list of solver statuses (a step rescued by a retry reads e.g. "SQP cold start:
        Solve_Succeeded (after SQP warm start: ...)")
    solver : list, per step, the solver that produced the step ("lq", "sqp", "ipopt"; for a
        failed step the last one tried; None where nothing was solved); :attr:`solver_counts`
        counts them (e.g. how often SQP fell back to IPOPT)
    fallback : list, per step, None or what was applied instead of the failed solve's optimum
        (e.g. "the previous successful plan, shifted", "the solver's last iterate")
    iterations, solve_times : (T,) solver iterations and seconds per step
    wall_time : seconds for the whole simulation
    info : what the controller recorded during the run (``Controller.record()``; empty by default)
    """

    x: np.ndarray
    u: np.ndarray
    w: np.ndarray
    w_all: np.ndarray
    costs: np.ndarray
    sigma: np.ndarray
    values: np.ndarray | None
    success: np.ndarray
    status: list
    iterations: np.ndarray
    solve_times: np.ndarray
    controller: str
    preview_w: int
    preview_c: int
    alpha_lo: float | None = None
    wall_time: float = 0.0
    info: dict = field(default_factory=dict)
    value_valid: np.ndarray | None = None
    fallback: list = field(default_factory=list)
    solver: list = field(default_factory=list)

    @property
    def T(self) -> int:
        return len(self.u)

    @property
    def n_failures(self) -> int:
        """The number of steps whose solve failed."""
        return int(np.count_nonzero(~self.success))

    @property
    def failed_steps(self) -> np.ndarray:
        """The steps t whose solve failed."""
        return np.flatnonzero(~self.success)

    @property
    def solver_counts(self) -> dict:
        """{solver: number of steps it produced} (``solver`` per step; None: nothing solved)."""
        return dict(Counter(self.solver))

    def __repr__(self):
        return (f"Trajectory(controller={self.controller!r}, T={self.T}, total cost={self.costs.sum():.4g}, "
                f"solver failures={self.n_failures})")


def _problem_cost(controller: Controller, costs):
    if costs is None:
        if not isinstance(getattr(controller, "cost", None), StageCost):
            raise OrrcValueError(
                f"simulate needs the problem's costs: pass costs=... (a StageCost or CostSequence); "
                f"the controller {controller.name!r} has no cost of its own")
        return controller.cost, None
    if isinstance(costs, StageCost):
        return costs, None
    if isinstance(costs, CostSequence):
        own = getattr(controller, "cost", None)
        if controller.preview_c > 0 and own is not None and own.n_params != costs.stage.n_params:
            raise OrrcValueError(
                f"the cost sequence's family ({costs.stage.name}, {costs.stage.n_params} params) does not "
                f"match the controller's cost ({own.name}, {own.n_params} params)")
        return costs.stage, costs
    raise OrrcValueError(f"costs must be a StageCost, a CostSequence or None; got {type(costs).__name__}")


def _steps_text(steps, most: int = 12) -> str:
    """"0-4, 17, 20" for [0, 1, 2, 3, 4, 17, 20] (the first ``most`` runs, then "...")."""
    runs, start = [], None
    for i, t in enumerate(steps):
        if start is None:
            start = t
        if i + 1 == len(steps) or steps[i + 1] != t + 1:
            runs.append(f"{start}" if start == t else f"{start}-{t}")
            start = None
    return ", ".join(runs[:most]) + (", ..." if len(runs) > most else "")


def _failure_summary(name: str, T: int, ok, status, fallback) -> str:
    steps = np.flatnonzero(~ok)
    applied = Counter(fallback[t] or "not stated by the controller" for t in steps)
    statuses = sorted({status[t] for t in steps})
    what = ", ".join(f"{label} ({k} step{'s' if k > 1 else ''})" for label, k in applied.most_common())
    return (f"{name}: the solve failed at {len(steps)} of {T} steps (t = {_steps_text(steps)}; statuses: "
            f"{statuses}); applied instead: {what}. Trajectory.success marks these steps, Trajectory.fallback "
            "says what was applied, and their V_M are NaN (Trajectory.value_valid); orrc.checks refuses such a "
            "trajectory.")


def _nonfinite_report(name, C, sig, V, valid_value):
    """The NonFiniteWarning text for overflowed costs, σ or V_M (x, u finite), or None."""
    parts = []
    for label, arr in (("stage costs c_t", C), ("σ(x_t)", sig)):
        bad = np.flatnonzero(~np.isfinite(arr))
        if bad.size:
            parts.append(f"{label} at {bad.size} steps from t={bad[0]}")
    if V is not None and valid_value is not None:
        bad = np.flatnonzero(~np.isfinite(V) & valid_value)
        if bad.size:
            parts.append(f"the controller's V_M at {bad.size} steps from t={bad[0]} (marked in value_valid)")
    if not parts:
        return None
    return (f"{name}: the state stayed finite but " + "; ".join(parts) + " overflowed (inf or NaN): the "
            "weights, the state or T are too large for floating point; the metrics refuse these values")


def _windows(wpad, Mw: int, k: int):
    """The preview windows w_{t:t+M_w-1} of the steps t < k, a read-only (k, M_w, n) view of the
    disturbance record (no copy)."""
    n = wpad.shape[1]
    s0, s1 = wpad.strides
    return np.lib.stride_tricks.as_strided(wpad, shape=(k, Mw, n), strides=(s0, s0, s1), writeable=False)


def _affine_loop(controller, T, m, X, X_read, U, wpad, Mw, step, A, B) -> None:
    """The closed loop of a controller that offers ``fast_affine`` (:mod:`orrc.controllers.base`):
    u_t = −K x_t + f_t, with the feed-forward f_t of every step's own preview window from one
    batch call before the loop. On a linear system the loop steps the closed loop
    x_{t+1} = (A − BK) x_t + B f_t + w_t (one product per step) and the inputs u_t = −K x_t + f_t
    follow in one product; otherwise each step computes u_t and calls the dynamics."""
    K, feedforward = controller.fast_affine
    F = np.asarray(feedforward(_windows(wpad, Mw, T)), dtype=float)
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


def _fast_loop(fast, controller, T, m, X, X_read, U, wpad, Mw, step, A, B) -> None:
    """The closed loop of a controller that offers ``fast_input`` (:mod:`orrc.controllers.base`): the
    same information (x_t read-only, the preview w_{t:t+M_w-1}), no Observation or Decision per step."""
    if getattr(controller, "fast_affine", None) is not None:
        return _affine_loop(controller, T, m, X, X_read, U, wpad, Mw, step, A, B)
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


def _batch_values(controller, X, wpad, Mw: int, deferred, V, has_value) -> None:
    """V[t] for the deferred steps t, from one ``controller.values_batch`` call (see
    :mod:`orrc.controllers.base`): the states x_t and the preview windows w_{t:t+M_w-1} (read-only
    views of the disturbance record, not copies)."""
    idx = np.flatnonzero(deferred)
    windows = _windows(wpad, Mw, len(V))
    if len(idx) < len(V):
        windows = windows[idx]
    vals = np.asarray(controller.values_batch(X[idx], windows), dtype=float)
    if vals.shape != (len(idx),):
        raise OrrcValueError(f"controller {controller.name!r}: values_batch must return one value per deferred step, "
                             f"shape ({len(idx)},); it returned shape {vals.shape}")
    V[idx] = vals
    has_value[idx] = True


def simulate(system: System, controller: Controller, x0, w, T: int, costs=None) -> Trajectory:
    """Run ``controller`` on ``system`` for T steps from x0 under disturbances ``w``.

    Parameters
    ----------
    system : the true system (a controller may hold a different model of it).
    controller : any :class:`~orrc.controllers.Controller` (Algorithm 1, baselines, ...).
    x0 : (n,) initial state.
    w : (L, n) disturbances with L >= T; rows past T are the preview tail.
    T : number of steps.
    costs : the problem's costs c_t: a StageCost (time-invariant), a CostSequence
        (time-varying, previewed to the controller M_c steps ahead), or None for the
        controller's own cost.

    Failures (see the module docstring): bad arguments raise :class:`~orrc.OrrcValueError`;
    failed solves are marked in the trajectory and summarised in ONE :class:`~orrc.SolverWarning`;
    :class:`~orrc.SolverError` from the controller propagates with ``.trajectory`` (the run so
    far); a diverging state raises ``FloatingPointError``; overflowed costs, σ or V_M warn
    (:class:`~orrc.NonFiniteWarning`).
    """
    if not isinstance(system, System):
        raise OrrcValueError(f"system must be an orrc LinearSystem or NonlinearSystem; got {type(system).__name__}")
    if not isinstance(controller, Controller):
        raise OrrcValueError(f"controller must be an orrc Controller; got {type(controller).__name__}")
    T = as_int("T", T, minimum=1)
    n, m = system.n, system.m
    Mw, Mc = controller.preview_w, controller.preview_c
    check_size(f"simulate over T={T} steps (n={n}, m={m}, preview M_w={Mw})",
               nbytes=8.0 * (T * (3 * n + m + 12) + (T + Mw) * n), ops=2e3 * T, hint="lower T")
    controller.check_run(system, T)
    x0 = as_array("x0", x0, (n,))
    w = as_array("w", w)
    if w.ndim == 1 and n == 1:
        w = w[:, None]
    if w.ndim != 2 or w.shape[1] != n or w.shape[0] < T:
        raise OrrcValueError(f"w must have shape (L, {n}) with L >= T = {T}; got shape {w.shape}")
    stage, seq = _problem_cost(controller, costs)
    stage.check_dims(n, m)
    # padded, read-only disturbance record: the controller gets slices of it
    wpad = np.zeros((T + max(Mw, 1), n))
    L = min(len(w), len(wpad))
    wpad[:L] = w[:L]
    wpad.flags.writeable = False
    cparams = None
    if seq is not None:
        cparams = seq.window(0, T + max(Mc, 1))
        cparams.flags.writeable = False

    X = np.empty((T + 1, n))
    U = np.empty((T, m))
    C = np.empty(T)
    V = np.full(T, np.nan)
    has_value = np.zeros(T, dtype=bool)
    deferred = np.zeros(T, dtype=bool)  # V_M to come from controller.values_batch after the loop
    solver = [None] * T
    ok = np.ones(T, dtype=bool)
    status = [""] * T
    fallback = [None] * T
    iters = np.zeros(T, dtype=int)
    times = np.zeros(T)
    X[0] = x0
    linear = isinstance(system, LinearSystem)
    A, B = (system.A, system.B) if linear else (None, None)
    quad = isinstance(stage, QuadraticCost) and seq is None
    Q, R = (stage.Q, stage.R) if quad else (None, None)
    stage_cost = stage._value if type(stage).value is StageCost.value else stage.value  # x, u checked here
    step = system._step if type(system).step is NonlinearSystem.step else system.step  # finiteness checked below
    empty_w = wpad[:0]

    def trajectory(steps: int, wall: float) -> Trajectory:
        """The record of the first ``steps`` steps (all T, or the steps before a SolverError)."""
        Xs, Us, Cs, Vs, oks = X[:steps + 1], U[:steps], C[:steps], V[:steps], ok[:steps]
        if deferred[:steps].any():  # V_M of the deferred steps: one call for the whole run
            with np.errstate(over="ignore", invalid="ignore"):  # an overflowed V_M is reported below
                _batch_values(controller, Xs, wpad, Mw, deferred[:steps], Vs, has_value[:steps])
        if quad:  # c_t = x_tᵀQx_t + u_tᵀRu_t for all t at once (the costs do not feed back)
            with np.errstate(over="ignore", invalid="ignore"):
                Cs[:] = np.einsum("ti,ti->t", Xs[:-1] @ Q, Xs[:-1]) + np.einsum("ti,ti->t", Us @ R, Us)
        with np.errstate(over="ignore", invalid="ignore"):
            sig = np.einsum("ij,ij->i", Xs, Xs) if type(stage).sigma is StageCost.sigma else \
                np.array([stage.sigma(x) for x in Xs])
        if np.any(sig < 0):
            raise OrrcValueError(f"the cost's sigma(x) must be >= 0 (Assumption 2); it is {sig.min():.3g} at "
                                 f"t={int(np.argmin(sig))}")
        values = valid = None
        if steps and has_value[:steps].all():
            Vs[~oks] = np.nan  # a failed solve has no optimal value, whatever the controller reported
            values, valid = Vs.copy(), oks & np.isfinite(Vs)
        report = _nonfinite_report(controller.name, Cs, sig, values, oks if values is not None else None)
        if report:
            warnings.warn(report, NonFiniteWarning, stacklevel=3)
        alpha_lo = seq.alpha_lo if seq is not None else stage.alpha_lo
        return Trajectory(x=Xs.copy(), u=Us.copy(), w=np.array(wpad[:steps]), w_all=np.array(wpad[:steps + max(Mw, 1)]),
                          costs=Cs.copy(), sigma=sig, values=values, success=oks.copy(), status=status[:steps],
                          iterations=iters[:steps].copy(), solve_times=times[:steps].copy(),
                          controller=controller.name, preview_w=Mw, preview_c=Mc, alpha_lo=alpha_lo,
                          wall_time=wall, info=dict(controller.record()), value_valid=valid,
                          fallback=fallback[:steps], solver=solver[:steps])

    X_read = X.view()  # its rows are read-only views: what the controller is handed as x_t
    X_read.flags.writeable = False
    m_shape = (m,)
    controller.reset()
    fast = controller.fast_input if (cparams is None or not Mc) else None  # (orrc.controllers.base)
    start = time.perf_counter()
    with np.errstate(over="ignore", invalid="ignore"):  # divergence is checked (and raised) below
        if fast is not None:
            _fast_loop(fast, controller, T, m, X, X_read, U, wpad, Mw, step if not linear else None, A, B)
            tmpl = controller.fast_decision
            status[:], solver[:] = [tmpl.status] * T, [tmpl.solver] * T
            deferred[:] = tmpl.value_deferred
            if tmpl.value is not None:
                V[:], has_value[:] = tmpl.value, True
            if not quad:
                for t in range(T):
                    C[t] = stage_cost(X[t], U[t], None if seq is None else cparams[t])
        for t in range(T if fast is None else 0):
            xt = X_read[t]  # a read-only view of x_t (X[t] is not written again)
            obs = Observation(t, xt, wpad[t - 1] if t > 0 else None,
                              wpad[t:t + Mw] if Mw else empty_w,
                              cparams[t:t + Mc] if (cparams is not None and Mc) else None)
            try:
                d = controller.control(obs)
            except SolverError as exc:  # the controller gave up: hand back the run so far
                exc.trajectory = trajectory(t, time.perf_counter() - start)
                raise
            u = getattr(d, "u", None)
            if type(u) is not np.ndarray or u.shape != m_shape or u.dtype != float:  # (the fast path: an (m,) array)
                try:
                    u = np.asarray(u, dtype=float).reshape(m)
                except (TypeError, ValueError) as exc:
                    raise OrrcValueError(
                        f"controller {controller.name!r} must return a Decision whose u has m={m} entries; at t={t} "
                        f"it returned {type(d).__name__} with u of shape {np.shape(u)}") from exc
            U[t] = u
            if d.value is not None:
                V[t] = d.value
                has_value[t] = True
            elif d.value_deferred:
                deferred[t] = True
            status[t], solver[t] = d.status, d.solver
            if d.iterations or d.solve_time:
                iters[t], times[t] = d.iterations, d.solve_time
            if not d.success:
                ok[t], fallback[t] = False, d.fallback
            if not quad:
                C[t] = stage_cost(xt, u, None if seq is None else cparams[t])
            if linear:
                X[t + 1] = A @ xt + B @ u + wpad[t]
            else:
                X[t + 1] = step(xt, u, wpad[t])
    wall = time.perf_counter() - start
    if not np.all(np.isfinite(X)) or not np.all(np.isfinite(U)):
        bad_x = int(np.argmax(~np.all(np.isfinite(X), axis=1)))
        bad_u = int(np.argmax(~np.all(np.isfinite(U), axis=1))) if not np.all(np.isfinite(U)) else T + 1
        if bad_u < bad_x:
            raise FloatingPointError(
                f"controller {controller.name!r} returned a non-finite input u at t={bad_u} (from a finite state); "
                "check the controller")
        raise FloatingPointError(
            f"the closed loop diverged: the state is not finite at t={bad_x} "
            f"(controller {controller.name!r}); shorten T or check the controller")
    traj = trajectory(T, wall)
    if not ok.all():
        warnings.warn(_failure_summary(controller.name, T, ok, status, fallback), SolverWarning, stacklevel=2)
    return traj
