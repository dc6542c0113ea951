"""The result of one receding-horizon solve, and how a failed solve is reported.

* :class:`Plan` -- inputs, states and value of one M-step solve, with the solver's report;
* :class:`SolverWarning` -- a solve failed and a fallback was applied (one per :func:`orrc.simulate`
  run, or one per failed direct ``plan()`` call);
* :class:`SolverError` -- a controller stopped because its solves kept failing
  (:mod:`orrc.controllers.failures`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


class SolverWarning(UserWarning):
    """A numerical solver did not report success; the message says what was applied instead.

    Inside :func:`orrc.simulate` the failed steps are collected and ONE warning is issued at the end
    of the run (the count of failed steps and the fallbacks applied); a direct
    ``PreviewRHC.plan(...)`` call that fails warns once.

    Examples
    --------
    Every solver limited to one iteration, and the run told to go on (``max_failures=None``):

    >>> import warnings
    >>> import orrc
    >>> ex = orrc.examples.inverted_pendulum()
    >>> rhc = orrc.PreviewRHC(ex.system, ex.cost, M=10, input_bounds=ex.input_bounds,
    ...                       max_failures=None,
    ...                       solver_options={"sqpmethod.max_iter": 1, "ipopt.max_iter": 1})
    >>> w = orrc.disturbances.zero(15, 2)
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     traj = orrc.simulate(ex.system, rhc, ex.x0, w, T=5)
    >>> [w.category.__name__ for w in caught], bool(traj.success.any())
    (['SolverWarning'], False)
    """


class SolverError(RuntimeError):
    """A receding-horizon controller stopped: its M-step solve failed at too many consecutive steps.

    Attributes: ``step`` (the step t at which it stopped), ``statuses`` (the solver statuses of the
    consecutive failed steps, oldest first), ``trajectory`` (set by :func:`orrc.simulate`: the run up to
    the step before, an :class:`orrc.Trajectory` whose failed steps are marked; else None).

    Parameters
    ----------
    message : what failed and what to try.
    step : the step t at which the controller stopped.
    statuses : the solver statuses of the consecutive failed steps, oldest first.
    trajectory : the run up to the step before (set by :func:`orrc.simulate`).

    Examples
    --------
    >>> import orrc
    >>> ex = orrc.examples.inverted_pendulum()
    >>> rhc = orrc.PreviewRHC(ex.system, ex.cost, M=10, input_bounds=ex.input_bounds,
    ...                       solver_options={"sqpmethod.max_iter": 1, "ipopt.max_iter": 1})
    >>> try:
    ...     orrc.simulate(ex.system, rhc, ex.x0, orrc.disturbances.zero(30, 2), T=20)
    ... except orrc.SolverError as err:
    ...     print(err.step, len(err.statuses), err.trajectory.x.shape)
    2 3 (3, 2)
    """

    def __init__(self, message: str, step: int | None = None, statuses=(), trajectory=None):
        super().__init__(message)
        self.step = step
        self.statuses = list(statuses)
        self.trajectory = trajectory


@dataclass
class Plan:
    """An M-step plan: ``inputs`` (M, m), ``states`` (M+1, n) and its value V_M.

    ``value`` is the optimal cost Σ_{j<M} c_j(x̃_j, ũ_j) (+ terminal cost, if any) of
    the problem that was solved. ``success`` and ``status`` report the solver's
    outcome; when ``success`` is False, ``value`` is the objective of the solver's last
    iterate (not V_M) and ``fallback`` says what the inputs are. ``solver`` names the solver that
    produced the plan ("lq", "sqp" or "ipopt"); ``extra["attempts"]`` lists (what was tried, status)
    when a solve needed a retry. On the NLP path ``extra`` also holds the solver's multipliers
    (``"lam_x"`` of the bounds on [vec U; x̃_1..x̃_M], ``"lam_g"`` of the dynamics) and, for SQP, the
    acceptance checks' quantities (``"complementarity"``, ``"guess_cost"``; :mod:`orrc.solvers.nlp`).

    Attributes
    ----------
    inputs : (M, m) the planned inputs ũ_0..ũ_{M-1}.
    states : (M + 1, n) the predicted states x̃_0..x̃_M.
    value : V_M, the optimal value of Eq. (3) (the last iterate's objective when the solve failed).
    success, status, iterations, solve_time, fallback, solver : the solver's report.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> ex = orrc.examples.inverted_pendulum()
    >>> rhc = orrc.PreviewRHC(ex.system, ex.cost, M=10, input_bounds=ex.input_bounds)
    >>> plan = rhc.plan(ex.x0, np.zeros((10, 2)))
    >>> plan.inputs.shape, plan.states.shape, plan.solver, plan.success
    ((10, 1), (11, 2), 'sqp', True)
    >>> print(f"{plan.value:.4f}")
    37.2523
    """

    inputs: np.ndarray
    states: np.ndarray
    value: float
    success: bool = True
    status: str = "optimal"
    iterations: int = 0
    solve_time: float = 0.0
    fallback: str | None = None
    solver: str = "lq"
    extra: dict = field(default_factory=dict)
