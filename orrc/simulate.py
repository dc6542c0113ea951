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
  a non-finite V_M is also marked invalid in ``value_valid``;
* a controller reports V_M = NaN or inf at a successful step: one :class:`~orrc.NonFiniteWarning`
  naming the steps (marked invalid in ``value_valid``).

How the loop runs: :func:`simulate` checks the arguments, then runs
:func:`information_pattern_loop` (the loop of Eq. 2, one Observation and one Decision per step), or,
for a controller that offers a fast path on this problem, one of the loops of
:mod:`orrc._fast_loops` (the rule: :func:`orrc._fast_loops.fast_path`); the record of the run and
its checks are :mod:`orrc.trajectory`'s.
"""
from __future__ import annotations

import math
import time
import warnings

import numpy as np

from ._fast_loops import fast_path, nlp_loop, record_fast_steps
from ._validate import OrrcValueError, as_array, as_int, check_size
from .controllers.base import Controller, Observation
from .costs import CostSequence, StageCost
from .forecasts import Forecast
from .solvers.plan import SolverError, SolverWarning
from .systems import LinearSystem, NonlinearSystem, System
from .trajectory import Record, Trajectory, failure_summary

__all__ = ["simulate", "Trajectory"]


def simulate(system: System, controller: Controller, x0, w, T: int, costs=None, forecast=None) -> Trajectory:
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
    forecast : an :class:`orrc.forecasts.Forecast`, or None for the exact preview. With a
        forecast the controller's preview at step t is the model's ŵ_{t:t+M_w-1|t}, never the
        true window; the truth w_{t-1} is revealed at step t as before. The forecasts are
        recorded in ``Trajectory.forecasts`` (T, M_w, n).

    Failures (see the module docstring): bad arguments raise :class:`~orrc.OrrcValueError`;
    failed solves are marked in the trajectory and summarised in ONE :class:`~orrc.SolverWarning`;
    :class:`~orrc.SolverError` from the controller propagates with ``.trajectory`` (the run so
    far); a diverging state raises ``FloatingPointError``; overflowed costs, σ or V_M warn
    (:class:`~orrc.NonFiniteWarning`).

    Returns
    -------
    Trajectory
        the run: states ``x`` (T+1, n), inputs ``u`` (T, m), disturbances ``w`` (T, n), stage costs
        ``costs`` (T,), σ(x_t) ``sigma`` (T+1,), V_M ``values`` (T,) or None, and each step's solver
        report.

    Raises
    ------
    orrc.OrrcValueError
        When an argument does not match the system (x0's length, w's shape or length, the
        controller's dimensions) or T is out of range.
    orrc.SolverError
        When the controller stops after repeated solver failures.
    FloatingPointError
        When the state or the input becomes inf or NaN.

    Examples
    --------
    Algorithm 1 on the double integrator, the disturbance previewed 10 steps ahead:

    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(L=60, n=2, radius=0.1, seed=0)
    >>> traj = orrc.simulate(di.system, orrc.PreviewRHC(di.system, di.cost, M=10), di.x0,
    ...                      w, T=50)
    >>> print(f"{traj.costs.sum():.4f}")
    9.9116
    """
    rec = _prepare(system, controller, x0, w, T, costs)
    forecasts = _prepare_forecast(forecast, controller, rec)
    linear = isinstance(system, LinearSystem)
    A, B = (system.A, system.B) if linear else (None, None)
    step = None if linear else (system._step if type(system).step is NonlinearSystem.step else system.step)
    controller.reset()
    # the rule: orrc._fast_loops.fast_path (the fast loops read the true windows: not with a forecast)
    loop = fast_path(controller, rec) if forecast is None else None
    start = time.perf_counter()
    with np.errstate(over="ignore", invalid="ignore"):  # divergence is checked (and raised) below
        if loop is None:
            information_pattern_loop(controller, rec, step, A, B, start, forecast=forecast, forecasts=forecasts)
        elif loop is nlp_loop:   # the steps it does not take itself: the controller's own, one at a time
            nlp_loop(controller, rec, step, A, B,
                     lambda t: information_pattern_loop(controller, rec, step, A, B, start, (t,)))
        else:
            loop(controller, rec, step, A, B)
            record_fast_steps(controller, rec)
        wall = time.perf_counter() - start
        _check_divergence(controller, rec)
    traj = rec.trajectory(rec.T, wall)
    traj.forecasts = forecasts
    if not rec.ok.all():
        warnings.warn(failure_summary(controller.name, rec.T, rec.ok, rec.status, rec.fallback), SolverWarning,
                      stacklevel=2)
    return traj


def information_pattern_loop(controller: Controller, rec: Record, step, A, B, start: float, steps=None,
                             forecast=None, forecasts=None) -> None:
    """The closed loop of Eq. (2): at each step t the controller is handed x_t (read-only), w_{t-1},
    the previewed w_{t:t+M_w-1} and c_{t:t+M_c-1}, and nothing else; it returns u_t (with V_M and its
    solver's report, recorded), and the system moves to x_{t+1} = f(x_t, u_t, w_t) (``step``; None:
    A x_t + B u_t + w_t). A :class:`~orrc.SolverError` propagates with the run so far. ``steps``: the
    steps to take (default all T, in order). With a ``forecast`` model the previewed window is the
    model's (:func:`_forecast_window`, recorded in ``forecasts``), never the true one."""
    T, Mw, Mc, wpad, cparams, X_read = rec.T, rec.Mw, rec.Mc, rec.wpad, rec.cparams, rec.X_read
    m = rec.U.shape[1]
    m_shape, empty_w = (m,), wpad[:0]
    per_step_cost = not rec.quadratic
    for t in range(T) if steps is None else steps:
        xt = X_read[t]  # a read-only view of x_t (X[t] is not written again)
        window = wpad[t:t + Mw] if Mw else empty_w
        if forecast is not None:
            window = forecasts[t] = _forecast_window(forecast, t, wpad, Mw)
        obs = Observation(t, xt, wpad[t - 1] if t > 0 else None, window,
                          cparams[t:t + Mc] if (cparams is not None and Mc) else None)
        try:
            d = controller.control(obs)
        except SolverError as exc:  # the controller gave up: hand back the run so far
            exc.trajectory = rec.trajectory(t, time.perf_counter() - start, stacklevel=4)
            raise
        u = getattr(d, "u", None)
        if type(u) is not np.ndarray or u.shape != m_shape or u.dtype != float:  # (the fast path: an (m,) array)
            u = _as_input(controller, d, u, m, t)
        rec.U[t] = u
        _record_decision(rec, t, d)
        if per_step_cost:
            rec.C[t] = rec.stage_cost(xt, u, None if cparams is None else cparams[t])
        rec.X[t + 1] = A @ xt + B @ u + wpad[t] if step is None else step(xt, u, wpad[t])


def _record_decision(rec: Record, t: int, d) -> None:
    """Step t's V_M (or that it is deferred) and the solver's report, from the controller's Decision."""
    if d.value is not None:
        rec.V[t] = d.value
        rec.has_value[t] = True
        if d.value != d.value or d.value in (np.inf, -np.inf):  # NaN or ±inf reported by the controller
            rec.reported_nonfinite[t] = True
    elif d.value_deferred:
        rec.deferred[t] = True
    rec.status[t], rec.solver[t] = d.status, d.solver
    if d.iterations or d.solve_time:
        rec.iters[t], rec.times[t] = d.iterations, d.solve_time
    if not d.success:
        rec.ok[t], rec.fallback[t] = False, d.fallback


def _as_input(controller, d, u, m: int, t: int) -> np.ndarray:
    try:
        return np.asarray(u, dtype=float).reshape(m)
    except (TypeError, ValueError) as exc:
        raise OrrcValueError(
            f"controller {controller.name!r} must return a Decision whose u has m={m} entries; at t={t} "
            f"it returned {type(d).__name__} with u of shape {np.shape(u)}") from exc


def _prepare(system, controller, x0, w, T, costs) -> Record:
    """The arguments checked (an :class:`~orrc.OrrcValueError` before the first step) and the run's
    :class:`~orrc.trajectory.Record`: the padded, read-only disturbance record and cost parameters."""
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
    return Record(controller, stage, seq, x0, wpad, cparams, T, n, m)


def _prepare_forecast(forecast, controller, rec: Record):
    """The (T, M_w, n) record of the forecasts, the model reset; None without a forecast."""
    if forecast is None:
        return None
    if not isinstance(forecast, Forecast):
        raise OrrcValueError(f"forecast must be an orrc.forecasts.Forecast (e.g. Noisy(0.1)) or None; "
                             f"got {type(forecast).__name__}")
    if rec.Mw == 0:
        raise OrrcValueError(f"forecast={forecast!r} was given, but controller {controller.name!r} previews no "
                             "disturbance (preview_w = 0): a forecast would never be used")
    n = rec.wpad.shape[1]
    check_size(f"the forecasts of T={rec.T} steps (M_w={rec.Mw}, n={n})", nbytes=8.0 * rec.T * rec.Mw * n,
               ops=rec.T * rec.Mw * n, hint="lower T or the horizon")
    forecast.reset(n)
    return np.zeros((rec.T, rec.Mw, n))


def _forecast_window(forecast, t: int, wpad: np.ndarray, Mw: int) -> np.ndarray:
    """The model's ŵ_{t:t+M_w-1|t} from the revealed w_{0:t-1} and, for a model of an error, the true
    window; checked (shape, finite) and handed out read-only, a copy that shares nothing with the truth."""
    window = np.array(forecast.window(t, wpad[:t], wpad[t:t + Mw]), dtype=float)
    if window.shape != (Mw, wpad.shape[1]) or not np.all(np.isfinite(window)):
        raise OrrcValueError(f"forecast {forecast!r} must return a finite ({Mw}, {wpad.shape[1]}) window at t={t}; "
                             f"got shape {window.shape}" + ("" if window.shape != (Mw, wpad.shape[1]) else
                                                             " with non-finite entries"))
    window.flags.writeable = False
    return window


def _check_divergence(controller, rec: Record) -> None:
    """``FloatingPointError`` naming the first step where the state or the input is not finite. One sum
    tells that every entry is finite (one inf or NaN makes it inf or NaN; a finite sum has none); only
    where it is not (or it overflowed: called with overflow warnings off) are the entries looked at."""
    X, U, T = rec.X, rec.U, rec.T
    if math.isfinite(np.add.reduce(X, axis=None) + np.add.reduce(U, axis=None)) or \
            (np.isfinite(X).all() and np.isfinite(U).all()):
        return
    bad_x = int(np.argmax(~np.all(np.isfinite(X), axis=1)))
    bad_u = int(np.argmax(~np.all(np.isfinite(U), axis=1))) if not np.all(np.isfinite(U)) else T + 1
    if bad_u < bad_x:
        raise FloatingPointError(
            f"controller {controller.name!r} returned a non-finite input u at t={bad_u} (from a finite state); "
            "check the controller")
    raise FloatingPointError(
        f"the closed loop diverged: the state is not finite at t={bad_x} "
        f"(controller {controller.name!r}); shorten T or check the controller")


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
