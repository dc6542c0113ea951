"""The record of a closed-loop run (:class:`Trajectory`) and how :func:`orrc.simulate` fills it.

:class:`Record` holds the arrays a run writes step by step (x_t, u_t, c_t, V_M and the solver's
report of each step); :meth:`Record.trajectory` assembles the :class:`Trajectory` of the first
``steps`` steps: the deferred V_M in one ``values_batch`` call, the stage costs of a quadratic cost
in one product, σ(x_t), and the checks of what the run produced (a non-finite cost, σ or V_M warns
with :class:`~orrc.NonFiniteWarning`; a negative σ is refused). The texts of the run's warnings are
here too (:func:`failure_summary`).
"""
from __future__ import annotations

import math
import warnings
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from ._validate import NonFiniteWarning, OrrcValueError
from .costs import QuadraticCost, StageCost


@dataclass
class Trajectory:
    """The result of :func:`simulate`: the closed loop of Eq. (1) and what the controller reported.

    Attributes
    ----------
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
    forecasts : (T, M_w, n) the forecasts ŵ_{t:t+M_w-1|t} the controller previewed, in a run with a
        forecast model (:func:`simulate`'s ``forecast``); None with the exact preview
    iterations, solve_times : (T,) solver iterations and seconds per step
    wall_time : seconds for the whole simulation
    info : what the controller recorded during the run (``Controller.record()``; empty by default)

    Examples
    --------
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(L=60, n=2, radius=0.1, seed=0)
    >>> traj = orrc.simulate(di.system, orrc.PreviewRHC(di.system, di.cost, M=10), di.x0,
    ...                      w, T=50)
    >>> traj.x.shape, traj.u.shape, traj.costs.shape, traj.values.shape
    ((51, 2), (50, 1), (50,), (50,))
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
    forecasts: np.ndarray | None = None

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


def steps_text(steps, most: int = 12) -> str:
    """"0-4, 17, 20" for [0, 1, 2, 3, 4, 17, 20] (the first ``most`` runs, then "...").

    Parameters
    ----------
    steps : increasing step indices.
    most : the number of runs written before "...".

    Returns
    -------
    str
        the runs of consecutive steps.

    Examples
    --------
    >>> from orrc.trajectory import steps_text
    >>> steps_text([0, 1, 2, 3, 4, 17, 20])
    '0-4, 17, 20'
    """
    runs, start = [], None
    for i, t in enumerate(steps):
        if start is None:
            start = t
        if i + 1 == len(steps) or steps[i + 1] != t + 1:
            runs.append(f"{start}" if start == t else f"{start}-{t}")
            start = None
    return ", ".join(runs[:most]) + (", ..." if len(runs) > most else "")


def failure_summary(name: str, T: int, ok, status, fallback) -> str:
    """The message of the one :class:`~orrc.SolverWarning` of a run with failed steps.

    Parameters
    ----------
    name : the controller's name.
    T : the number of steps.
    ok : (T,) bool, False at the failed steps.
    status : (T,) the steps' solver statuses.
    fallback : (T,) what each failed step applied instead (None where nothing is stated).

    Returns
    -------
    str
        the failed steps, their statuses and what was applied instead.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.trajectory import failure_summary
    >>> text = failure_summary("preview RHC", 4, np.array([True, False, False, True]),
    ...                        ["ok", "failed", "failed", "ok"],
    ...                        [None, "the shifted plan", "the shifted plan", None])
    >>> text[:58]
    'preview RHC: the solve failed at 2 of 4 steps (t = 1-2; st'
    """
    steps = np.flatnonzero(~ok)
    applied = Counter(fallback[t] or "not stated by the controller" for t in steps)
    statuses = sorted({status[t] for t in steps})
    what = ", ".join(f"{label} ({k} step{'s' if k > 1 else ''})" for label, k in applied.most_common())
    return (f"{name}: the solve failed at {len(steps)} of {T} steps (t = {steps_text(steps)}; statuses: "
            f"{statuses}); applied instead: {what}. Trajectory.success marks these steps, Trajectory.fallback "
            "says what was applied, and their V_M are NaN (Trajectory.value_valid); orrc.checks refuses such a "
            "trajectory.")


def _nonfinite_report(name, C, sig, V, valid_value, reported=None):
    """The NonFiniteWarning text for overflowed costs, σ or V_M (x, u finite), or None."""
    parts = []
    for label, arr in (("stage costs c_t", C), ("σ(x_t)", sig)):
        bad = np.flatnonzero(~np.isfinite(arr))
        if bad.size:
            parts.append(f"{label} at {bad.size} steps from t={bad[0]}")
    if V is not None and valid_value is not None:
        bad = np.flatnonzero(~np.isfinite(V) & valid_value & ~reported)
        if bad.size:
            parts.append(f"the controller's V_M at {bad.size} steps from t={bad[0]} (marked in value_valid)")
    text = None
    if parts:
        text = (f"{name}: the state stayed finite but " + "; ".join(parts) + " overflowed (inf or NaN): the "
                "weights, the state or T are too large for floating point; the metrics refuse these values")
    if reported is not None and reported.any():
        steps = np.flatnonzero(reported)
        where = ("marked invalid in Trajectory.value_valid" if V is not None else
                 "Trajectory.values is None: the controller did not report V_M at every step")
        said = (f"{name}: the controller reported a non-finite V_M (value=NaN or inf) at {steps.size} successful "
                f"step{'s' if steps.size > 1 else ''} (t = {steps_text(steps)}); {where}; the metrics and "
                "orrc.checks refuse these values")
        text = said if text is None else text + "; " + said
    return text




def windows(wpad, Mw: int, k: int):
    """The preview windows w_{t:t+M_w-1} of the steps t < k, a read-only (k, M_w, n) view of the
    disturbance record (no copy).

    Parameters
    ----------
    wpad : (L, n) the disturbance record, L >= k + M_w - 1.
    Mw : the preview length M_w.
    k : the number of steps.

    Returns
    -------
    numpy.ndarray
        (k, M_w, n), read-only, row t = w_t..w_{t+M_w-1}.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.trajectory import windows
    >>> W = windows(np.arange(12.0).reshape(6, 2), 3, 4)
    >>> W.shape, W.flags.writeable, W[1, 0]
    ((4, 3, 2), False, array([2., 3.]))
    """
    n = wpad.shape[1]
    s0, s1 = wpad.strides
    return np.lib.stride_tricks.as_strided(wpad, shape=(k, Mw, n), strides=(s0, s0, s1), writeable=False)


def _batch_values(controller, X, wpad, Mw: int, deferred, V, has_value) -> None:
    """V[t] for the deferred steps t, from one ``controller.values_batch`` call (see
    :mod:`orrc.controllers.base`): the states x_t and the preview windows w_{t:t+M_w-1} (read-only
    views of the disturbance record, not copies)."""
    idx = np.flatnonzero(deferred)
    wins = windows(wpad, Mw, len(V))
    if len(idx) < len(V):
        wins = wins[idx]
    vals = np.asarray(controller.values_batch(X[idx], wins), dtype=float)
    if vals.shape != (len(idx),):
        raise OrrcValueError(f"controller {controller.name!r}: values_batch must return one value per deferred step, "
                             f"shape ({len(idx)},); it returned shape {vals.shape}")
    V[idx] = vals
    has_value[idx] = True


class Record:
    """What a run of T steps writes, step by step: x_t (``X``, row 0 = x_0), u_t (``U``), c_t (``C``,
    filled after the loop for a time-invariant quadratic cost), V_M (``V``; ``has_value`` where the
    controller reported it, ``deferred`` where it comes from ``values_batch`` after the loop,
    ``reported_nonfinite`` where it reported NaN or inf at a successful step: the rows of ``flags``), and
    the solver's report of each step (``ok``, ``status``, ``solver``, ``fallback``, ``iters``, ``times``).

    ``X_read`` is a read-only view of ``X``: its rows are what a controller is handed as x_t.
    ``wpad`` is the read-only disturbance record (w plus the preview tail, zeros past the data);
    ``cparams`` the cost parameters of a cost sequence (read-only; None for a time-invariant cost).

    Parameters
    ----------
    controller : the :class:`~orrc.Controller` of the run.
    stage : the stage-cost family of the run.
    seq : the :class:`~orrc.CostSequence` of a time-varying cost, or None.
    x0 : (n,) the initial state.
    wpad, cparams : the disturbance record and the cost parameters (see above).
    T, n, m : the number of steps and the dimensions.

    Examples
    --------
    :func:`orrc.simulate` fills one and turns it into the :class:`~orrc.Trajectory`:

    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> traj = orrc.simulate(di.system, orrc.LQR(di.system, di.cost), di.x0,
    ...                      orrc.disturbances.zero(5, 2), T=5)
    >>> traj.x.shape
    (6, 2)
    """

    def __init__(self, controller, stage: StageCost, seq, x0, wpad, cparams, T: int, n: int, m: int):
        self.controller, self.stage, self.seq, self.wpad, self.cparams = controller, stage, seq, wpad, cparams
        self.T, self.Mw, self.Mc = T, controller.preview_w, controller.preview_c
        self.X = np.empty((T + 1, n))
        self.U = np.empty((T, m))
        self.C = np.empty(T)
        self.V = np.empty(T)
        self.V.fill(np.nan)
        # (the flags the trajectory does not hand on: rows of one array)
        self.flags = np.zeros((3, T), dtype=bool)
        self.has_value, self.deferred, self.reported_nonfinite = self.flags
        self.ok = np.empty(T, dtype=bool)
        self.ok.fill(True)
        self.status, self.solver, self.fallback = [""] * T, [None] * T, [None] * T
        self.iters = np.zeros(T, dtype=int)
        self.times = np.zeros(T)
        self.X[0] = x0
        self.X_read = self.X.view()
        self.X_read.flags.writeable = False
        #: c_t = x_tᵀQx_t + u_tᵀRu_t for all t at once after the loop (the costs do not feed back)
        self.quadratic = isinstance(stage, QuadraticCost) and seq is None
        # the stage cost for checked x, u (the loop's hot path)
        self.stage_cost = stage._value if type(stage).value is StageCost.value else stage.value

    def costs_in_loop(self) -> None:
        """c_t of every step from the recorded x_t, u_t (a cost the loop did not compute)."""
        cp = self.cparams
        for t in range(self.T):
            self.C[t] = self.stage_cost(self.X[t], self.U[t], None if cp is None else cp[t])

    def trajectory(self, steps: int, wall: float, stacklevel: int = 3):
        """The :class:`Trajectory` of the first ``steps`` steps (all T, or the steps before a SolverError).

        Every check runs on every run, in as few passes as it takes: one sum over the stage costs, σ(x_t) and
        V_M tells that they are all finite (a sum of finite numbers is finite unless it overflows, and one
        inf or NaN entry makes it inf or NaN), and only a run where it is not looks for the steps. Of a
        whole run (``steps`` = T) the trajectory takes over the arrays no controller was handed (u_t, c_t,
        V_M and the solver's report; the record is not used after it) instead of copying them."""
        controller, stage, seq, Mw = self.controller, self.stage, self.seq, self.Mw
        whole = steps == len(self.U)
        if whole:
            Xs, Us, Cs, Vs, oks, has_value = self.X, self.U, self.C, self.V, self.ok, self.has_value
        else:
            Xs, Us, Cs, Vs, oks = self.X[:steps + 1], self.U[:steps], self.C[:steps], self.V[:steps], self.ok[:steps]
            has_value = self.has_value[:steps]
        with np.errstate(over="ignore", invalid="ignore"):  # an overflowed cost, σ or V_M is reported below
            n_value, n_deferred, n_reported = self.flags[:, :steps].sum(axis=1).tolist()
            if n_deferred:  # V_M of the deferred steps: one call for the whole run
                _batch_values(controller, Xs, self.wpad, Mw, self.deferred[:steps], Vs, has_value)
                n_value = int(np.count_nonzero(has_value))
            if self.quadratic:
                Q, R = stage.Q, stage.R
                Xt = Xs[:-1]
                Cs[:] = np.einsum("ti,ti->t", Xt @ Q, Xt) + np.einsum("ti,ti->t", Us @ R, Us)
            if type(stage).sigma is StageCost.sigma:   # Σ_i x_i², never negative (NaN is not < 0)
                sig = np.einsum("ij,ij->i", Xs, Xs)
            else:
                sig = np.array([stage.sigma(x) for x in Xs])
                if np.any(sig < 0):
                    raise OrrcValueError(f"the cost's sigma(x) must be >= 0 (Assumption 2); it is {sig.min():.3g} "
                                         f"at t={int(np.argmin(sig))}")
            values = valid = None
            all_ok = bool(oks.all())
            if steps and n_value == steps:
                if not all_ok:
                    Vs[~oks] = np.nan  # a failed solve has no optimal value, whatever the controller reported
                values = Vs if whole else Vs.copy()
            add = np.add.reduce
            finite = math.isfinite(add(Cs) + add(sig) + (0.0 if values is None else add(values)))
        if values is not None:
            valid = oks.copy() if finite else oks & np.isfinite(values)
        if not finite or n_reported:
            report = _nonfinite_report(controller.name, Cs, sig, values, oks if values is not None else None,
                                       self.reported_nonfinite[:steps] & oks)
            if report:
                warnings.warn(report, NonFiniteWarning, stacklevel=stacklevel)
        alpha_lo = seq.alpha_lo if seq is not None else stage.alpha_lo
        wpad = self.wpad
        own = (lambda a: a) if whole else np.copy
        return Trajectory(x=Xs.copy(), u=own(Us), w=np.array(wpad[:steps]), w_all=np.array(wpad[:steps + max(Mw, 1)]),
                          costs=own(Cs), sigma=sig, values=values, success=own(oks), status=self.status[:steps],
                          iterations=own(self.iters[:steps]), solve_times=own(self.times[:steps]),
                          controller=controller.name, preview_w=Mw, preview_c=self.Mc, alpha_lo=alpha_lo,
                          wall_time=wall, info=dict(controller.record()), value_valid=valid,
                          fallback=self.fallback[:steps], solver=self.solver[:steps])
