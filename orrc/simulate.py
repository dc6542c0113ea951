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
"""
from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from ._validate import OrrcValueError, as_array, as_int
from .controllers.base import Controller, Observation
from .costs import CostSequence, QuadraticCost, StageCost
from .systems import LinearSystem, System


@dataclass
class Trajectory:
    """The result of :func:`simulate`.

    x : (T+1, n) states x_0..x_T          u : (T, m) inputs
    w : (T, n) the disturbances that acted  costs : (T,) c_t(x_t, u_t)
    w_all : (T + max(M_w, 1), n) the disturbance record the controller previewed
        (w plus the preview tail, zeros where the given data ran out)
    sigma : (T+1,) σ(x_t)
    values : (T,) V_M at each step when the controller reports it at every step, else None
    success : (T,) solver success per step; status : list of solver statuses
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

    @property
    def T(self) -> int:
        return len(self.u)

    @property
    def n_failures(self) -> int:
        return int(np.count_nonzero(~self.success))

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
    """
    if not isinstance(system, System):
        raise OrrcValueError(f"system must be an orrc LinearSystem or NonlinearSystem; got {type(system).__name__}")
    if not isinstance(controller, Controller):
        raise OrrcValueError(f"controller must be an orrc Controller; got {type(controller).__name__}")
    T = as_int("T", T, minimum=1)
    n, m = system.n, system.m
    x0 = as_array("x0", x0, (n,))
    w = as_array("w", w)
    if w.ndim == 1 and n == 1:
        w = w[:, None]
    if w.ndim != 2 or w.shape[1] != n or w.shape[0] < T:
        raise OrrcValueError(f"w must have shape (L, {n}) with L >= T = {T}; got shape {w.shape}")
    stage, seq = _problem_cost(controller, costs)
    stage.check_dims(n, m)
    Mw, Mc = controller.preview_w, controller.preview_c
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
    V = np.empty(T)
    has_value = np.zeros(T, dtype=bool)
    ok = np.ones(T, dtype=bool)
    status = [""] * T
    iters = np.zeros(T, dtype=int)
    times = np.zeros(T)
    X[0] = x0
    linear = isinstance(system, LinearSystem)
    A, B = (system.A, system.B) if linear else (None, None)
    quad = isinstance(stage, QuadraticCost) and seq is None
    Q, R = (stage.Q, stage.R) if quad else (None, None)
    empty_w = wpad[:0]
    controller.reset()
    start = time.perf_counter()
    with np.errstate(over="ignore", invalid="ignore"):  # divergence is checked (and raised) below
        for t in range(T):
            xt = X[t].copy()
            xt.flags.writeable = False
            obs = Observation(t, xt, wpad[t - 1] if t > 0 else None,
                              wpad[t:t + Mw] if Mw else empty_w,
                              cparams[t:t + Mc] if (cparams is not None and Mc) else None)
            d = controller.control(obs)
            u = np.asarray(d.u, dtype=float).reshape(m)
            U[t] = u
            if d.value is not None:
                V[t] = d.value
                has_value[t] = True
            ok[t], status[t], iters[t], times[t] = d.success, d.status, d.iterations, d.solve_time
            if not quad:
                C[t] = stage.value(xt, u, None if seq is None else cparams[t])
            if linear:
                X[t + 1] = A @ xt + B @ u + wpad[t]
            else:
                X[t + 1] = system.step(xt, u, wpad[t])
        if quad:  # c_t = x_tᵀQx_t + u_tᵀRu_t for all t at once (the costs do not feed back)
            C[:] = np.einsum("ti,ti->t", X[:-1] @ Q, X[:-1]) + np.einsum("ti,ti->t", U @ R, U)
    wall = time.perf_counter() - start
    if not np.all(np.isfinite(X)) or not np.all(np.isfinite(U)):
        bad = int(np.argmax(~np.all(np.isfinite(X), axis=1)))
        raise FloatingPointError(
            f"the closed loop diverged: the state is not finite at t={bad} "
            f"(controller {controller.name!r}); shorten T or check the controller")
    if not ok.all():
        warnings.warn(f"{(~ok).sum()} of {T} solves did not succeed (statuses: "
                      f"{sorted(set(s for s, good in zip(status, ok) if not good))}); "
                      "see Trajectory.success/status", RuntimeWarning, stacklevel=2)
    sig = np.einsum("ij,ij->i", X, X) if type(stage).sigma is StageCost.sigma else \
        np.array([stage.sigma(x) for x in X])
    values = V if has_value.all() else None
    alpha_lo = seq.alpha_lo if seq is not None else stage.alpha_lo
    return Trajectory(x=X, u=U, w=np.array(wpad[:T]), w_all=np.array(wpad), costs=C, sigma=sig, values=values, success=ok,
                      status=status, iterations=iters, solve_times=times, controller=controller.name,
                      preview_w=Mw, preview_c=Mc, alpha_lo=alpha_lo, wall_time=wall,
                      info=dict(controller.record()))
