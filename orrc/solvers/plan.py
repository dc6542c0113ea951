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
    """


class SolverError(RuntimeError):
    """A receding-horizon controller stopped: its M-step solve failed at too many consecutive steps.

    Attributes: ``step`` (the step t at which it stopped), ``statuses`` (the solver statuses of the
    consecutive failed steps, oldest first), ``trajectory`` (set by :func:`orrc.simulate`: the run up to
    the step before, an :class:`orrc.Trajectory` whose failed steps are marked; else None).
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
