"""Algorithm 2: estimation then control, for a system with unknown parameters θ (Section 4.2)."""
from __future__ import annotations

import numpy as np

from .._validate import OrrcValueError, as_array, as_bool, as_int
from .._problem import check_cost
from ..costs import L1Cost, QuadraticCost, StageCost
from ..parametric import LinearParametricSystem, ParametricSystem
from ..solvers.lq import lq_law_size
from .base import Controller, Decision, Observation
from .lifted import LiftedRHC
from ._preview_setup import _bounds
from .preview import PreviewRHC

PHASES = ("estimate", "control")


class Excitation(Controller):
    """The estimation phase of Algorithm 2 on its own: u_t = e_t - K₀ x_t, clipped to U.

    ``excitation`` (T, m): the exciting inputs e_t (e.g. :func:`orrc.estimation.prbs`); ``gain`` K₀ (m, n)
    an optional prior stabilising feedback; ``input_bounds`` (lo, hi). No preview: it needs none. Run it in
    :func:`orrc.simulate` for at most T steps to collect the data of an estimation phase.

    Parameters
    ----------
    excitation : (T, m) the exciting inputs e_t.
    gain : (m, n) K₀, an optional prior stabilising feedback.
    input_bounds : (lo, hi), the set U.
    n : the state dimension (needed when ``gain`` is None and no system is known yet).
    cost : the stage cost to record along the run.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> from orrc.controllers import Excitation
    >>> from orrc.estimation import prbs
    >>> di = orrc.examples.double_integrator()
    >>> traj = orrc.simulate(di.system, Excitation(prbs(30, 1, seed=0), cost=di.cost),
    ...                      di.x0, np.zeros((30, 2)), T=30)
    >>> traj.u[:4, 0]
    array([ 1.,  1., -1., -1.])
    """

    name = "excitation"

    def __init__(self, excitation, gain=None, input_bounds=None, n: int | None = None, cost=None):
        excitation = as_array("excitation", excitation)
        if excitation.ndim == 1:
            excitation = excitation[:, None]
        if excitation.ndim != 2 or excitation.shape[0] < 1:
            raise OrrcValueError(f"excitation must have shape (T, m); got shape {excitation.shape}")
        self.excitation = excitation
        self.m = excitation.shape[1]
        self.gain = None if gain is None else as_array("gain", gain, (self.m, n))
        self.n = None if self.gain is None else self.gain.shape[1]     # checked against the system by simulate
        self.input_bounds = _bounds("input_bounds", input_bounds, self.m)
        self.cost = cost

    def control(self, obs: Observation) -> Decision:
        if obs.t >= len(self.excitation):
            raise OrrcValueError(f"the excitation has {len(self.excitation)} steps; step t = {obs.t} has none")
        u = self.excitation[obs.t].copy()
        if self.gain is not None:
            u -= self.gain @ obs.x
        if self.input_bounds is not None:
            u = np.clip(u, *self.input_bounds)
        return Decision(u=u)


class EstimateThenControl(Controller):
    """Algorithm 2 of the paper: N steps of excitation, the estimate θ̂ from the data the controller
    observed, then preview RHC (Algorithm 1) on the estimated model f(·; θ̂).

    For t < N it applies the excitation (plus an optional exploration feedback), recording
    D = {(x_{k+1}, x_k, u_k, w_k)}: the states it observed, its own inputs and the past
    disturbances ``Observation.w_past``. At t = N it estimates θ̂ from the N transitions and from
    then on solves Eq. (4) on the model with θ̂. It never reads θ or the future beyond its preview
    M: everything it uses comes through the :class:`~orrc.Observation` of :func:`orrc.simulate`.

    Parameters
    ----------
    model : what the controller knows a priori:

        * a :class:`~orrc.ParametricSystem` (f known up to θ); ``ParametricSystem.linear(n, m)``
          for a linear system with (A, B) unknown. Default estimator: least squares
          (:func:`~orrc.estimation.least_squares_linear` or
          :func:`~orrc.estimation.least_squares_parametric`, which needs f affine in θ);
        * an :class:`orrc.estimation.EDMD` (a dictionary): the control phase runs
          :class:`~orrc.controllers.LiftedRHC` on the fitted lifted model.
    cost : the (time-invariant) stage cost c(x, u).
    M : preview/prediction horizon of the control phase.
    N : length of the estimation phase (N >= 1; >= n + m for the linear estimator).
    estimator : None (the default for the model) or a callable ``estimator(X, U, W) -> θ̂`` for a
        ParametricSystem (W is None when ``use_w`` is False).
    excitation : (N, m) inputs of the estimation phase; default a PRBS of amplitude 1
        (:func:`orrc.estimation.prbs`, seed 0).
    use_w : give the estimator the disturbance record (default True, as in the paper's data set);
        False: the estimator treats w as noise (the g(N) = Θ(1/√N) setting).
    exploration_gain : optional (m, n) gain K₀: u_t = e_t - K₀ x_t during the estimation phase (a
        prior stabilising feedback for an open-loop unstable system).
    input_bounds : (lo, hi), the set U, in both phases (the excitation is clipped to it).
    theta0 : the initial θ̂ (default 0, as in Algorithm 2) with which the control-phase NLP is
        built before the estimate exists (a ParametricSystem off the LQ path).
    theta_true : optional true θ, used ONLY to report ‖θ̂ - θ‖ in ``record()``; the inputs do not
        depend on it.
    solver_options : passed to the control phase's PreviewRHC.
    rank_deficient : "raise" or "warn": what the least-squares estimators do with data that are
        not persistently exciting.

    ``Trajectory.info`` (:meth:`record`) holds ``phase`` (T,) ("estimate" or "control"), ``theta_hat``,
    ``theta_error`` (None without ``theta_true``), ``values`` (T,) V_M(x_t; θ̂) (NaN in the
    estimation phase), ``N`` and ``estimate`` (the estimator's result).

    Raises
    ------
    orrc.OrrcValueError
        When N is too short for the estimator, the model and cost do not match, or an option is
        unknown.

    Examples
    --------
    The double integrator with (A, B) unknown: 10 exciting steps, then Algorithm 1 on the estimate.

    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(L=60, n=2, radius=0.1, seed=0)
    >>> model = orrc.ParametricSystem.linear(2, 1)
    >>> etc = orrc.EstimateThenControl(model, di.cost, M=10, N=10)
    >>> traj = orrc.simulate(di.system, etc, di.x0, w, T=50)
    >>> [str(p) for p in traj.info["phase"][[0, 9, 10]]]
    ['estimate', 'estimate', 'control']
    """

    name = "estimate then control"

    def __init__(self, model, cost: StageCost, M: int, N: int, estimator=None, excitation=None,
                 use_w: bool = True, exploration_gain=None, input_bounds=None, theta0=None, theta_true=None,
                 solver_options=None, rank_deficient: str = "raise"):
        from ..estimation import EDMD

        if not isinstance(model, (ParametricSystem, EDMD)):
            raise OrrcValueError(f"model must be an orrc.ParametricSystem (θ unknown) or an orrc.estimation.EDMD "
                                 f"(a dictionary); got {type(model).__name__}")
        check_cost(cost)
        self.model, self.cost = model, cost
        self.edmd = isinstance(model, EDMD)
        n = model.n
        if self.edmd:
            m = cost.m
            if m is None:
                raise OrrcValueError("with an EDMD model the cost must state its input dimension m")
        else:
            m = model.m
        cost.check_dims(n, m)
        self.n, self.m = n, m
        self.M = as_int("M", M, minimum=1)
        self.N = as_int("N", N, minimum=1)
        self.preview_w = self.preview_c = self.M
        if isinstance(model, LinearParametricSystem) and estimator is None and self.N < n + m:
            raise OrrcValueError(f"N = {self.N} is too short for the linear estimator: it needs N >= n + m = {n + m} "
                                 "exciting steps to determine [A B]")
        if estimator is not None and (self.edmd or not callable(estimator)):
            raise OrrcValueError("estimator must be None or a callable estimator(X, U, W) -> theta for a "
                                 "ParametricSystem model")
        if estimator is None and not self.edmd and not isinstance(model, LinearParametricSystem) \
                and not model.linear_in_theta:
            raise OrrcValueError(f"model ({model.name}) is not affine in theta, so least squares does not apply: pass "
                                 "estimator=..., or use an orrc.estimation.EDMD model")
        self.estimator = estimator
        self.use_w = as_bool("use_w", use_w)
        if rank_deficient not in ("raise", "warn"):
            raise OrrcValueError(f"rank_deficient must be 'raise' or 'warn'; got {rank_deficient!r}")
        self.rank_deficient = rank_deficient
        self.input_bounds = _bounds("input_bounds", input_bounds, m)
        if excitation is None:
            from ..estimation import prbs

            excitation = prbs(self.N, m, amplitude=1.0, seed=0)
        excitation = as_array("excitation", excitation)
        if excitation.ndim == 1 and m == 1:
            excitation = excitation[:, None]
        if excitation.ndim != 2 or excitation.shape[1] != m or excitation.shape[0] < self.N:
            raise OrrcValueError(f"excitation must have shape (N, m) = ({self.N}, {m}) (at least N rows); got shape "
                                 f"{excitation.shape}")
        self.excitation = excitation[:self.N]
        self.exploration_gain = None if exploration_gain is None else as_array("exploration_gain", exploration_gain,
                                                                               (m, n))
        self._explorer = Excitation(self.excitation, self.exploration_gain, input_bounds, n=n)
        self.theta_true = None
        if theta_true is not None:
            if self.edmd:
                raise OrrcValueError("theta_true is for a ParametricSystem model; an EDMD model has no true θ")
            self.theta_true = model.check_theta(theta_true, "theta_true")
        self.solver_options = solver_options
        # the control phase's solver, built now when it does not depend on the estimate's structure
        # a linear model with a quadratic (no bounds) or an l1 cost: the exact LQ or QP path of PreviewRHC on
        # the estimated LinearSystem, built at t = N; otherwise the NLP with θ as a parameter, built now
        self._lq = isinstance(model, LinearParametricSystem) and (
            (isinstance(cost, QuadraticCost) and self.input_bounds is None) or isinstance(cost, L1Cost))
        self._rhc = None
        if self._lq and isinstance(cost, QuadraticCost):   # the law is built at t = N: its size is checked now
            lq_law_size(self.M, n, m, who="EstimateThenControl's control phase (the exact LQ preview law)")
        if not self.edmd and not self._lq:
            theta0 = np.zeros(model.n_params) if theta0 is None else model.check_theta(theta0, "theta0")
            self._rhc = PreviewRHC(model, cost, self.M, input_bounds=input_bounds, solver_options=solver_options,
                                   theta=theta0)
        self.reset()

    @property
    def control_phase(self):
        """The controller of the control phase (Algorithm 1 on the estimated model), or None before it exists.

        A :class:`~orrc.PreviewRHC` on f(·; θ̂), or a :class:`~orrc.controllers.LiftedRHC` on the fitted
        EDMD model. On the CasADi path (a ParametricSystem off the exact LQ/QP path) it is built in the
        constructor with θ̂ = ``theta0`` and stays the same object: the estimate enters its NLP as a
        parameter value (:meth:`~orrc.PreviewRHC.set_theta`), so the solver is not rebuilt. On the exact
        LQ/QP path and with EDMD it is built at t = N from the estimate (None before).
        """
        return self._ctrl if self._ctrl is not None else self._rhc

    # -- the two phases ---------------------------------------------------------------------------------
    def reset(self) -> None:
        self._t = 0
        self._X, self._U, self._W = [], [], []
        self._phase, self._values = [], []
        self.estimate = None
        self.theta_hat = None
        self._ctrl = None
        if self._rhc is not None:
            self._rhc.reset()

    def _fit(self) -> None:
        from ..estimation import Estimate, least_squares_linear, least_squares_parametric

        X = np.array(self._X)
        U = np.array(self._U)
        W = np.array(self._W) if self.use_w else None
        if self.edmd:
            est = self.model.fit(X, U, W)
            self._ctrl = LiftedRHC(est, self.cost, self.M, input_bounds=self.input_bounds,
                                   solver_options=self.solver_options)
        else:
            if self.estimator is not None:
                theta = self.model.check_theta(self.estimator(X, U, W), "the estimator's θ̂")
                est = Estimate(theta=theta, N=len(U), rank=-1, rank_needed=self.model.n_params, residual=float("nan"),
                               condition=float("nan"), used_w=W is not None, method="user estimator")
            elif isinstance(self.model, LinearParametricSystem):
                est = least_squares_linear(X, U, W, rank_deficient=self.rank_deficient)
            else:
                est = least_squares_parametric(self.model, X, U, W, rank_deficient=self.rank_deficient)
            self.theta_hat = est.theta
            if self._lq:
                self._ctrl = PreviewRHC(self.model.at(est.theta), self.cost, self.M, input_bounds=self.input_bounds,
                                        solver_options=self.solver_options)
            else:
                self._rhc.set_theta(est.theta)
                self._ctrl = self._rhc
        self.estimate = est

    def control(self, obs: Observation) -> Decision:
        if obs.t != self._t:
            raise RuntimeError(f"EstimateThenControl must be run by orrc.simulate from t = 0, one step at a time; "
                               f"expected t = {self._t}, got t = {obs.t}")
        self._t += 1
        self._X.append(np.array(obs.x, dtype=float))
        if obs.t > 0 and len(self._W) < self.N:
            self._W.append(np.array(obs.w_past, dtype=float))
        if obs.t < self.N:
            u = self._explorer.control(obs).u
            self._U.append(u)
            self._phase.append(0)
            self._values.append(np.nan)
            return Decision(u=u)
        if obs.t == self.N:
            self._fit()
        d = self._ctrl.control(obs)
        self._phase.append(1)
        self._values.append(np.nan if d.value is None else d.value)
        return d

    def record(self) -> dict:
        """The phase of each step, θ̂, ‖θ̂ - θ‖ (with ``theta_true``), V_M(x_t; θ̂) and the estimate."""
        err = None
        if self.theta_true is not None and self.theta_hat is not None:
            err = float(np.linalg.norm(self.theta_hat - self.theta_true))
        return {"phase": np.array([PHASES[p] for p in self._phase]), "theta_hat": self.theta_hat,
                "theta_error": err, "values": np.array(self._values, dtype=float), "N": self.N,
                "estimate": self.estimate}

    def __repr__(self):
        kind = "EDMD" if self.edmd else self.model.name
        return f"EstimateThenControl(N={self.N}, M={self.M}, model={kind!r}, use_w={self.use_w})"
