"""What a receding-horizon controller does when its M-step solve fails: the escalation policy.

One policy for every receding-horizon controller (``PreviewRHC`` and what is built on it), and
independent of the solver that failed: the controller hands :class:`FailureLadder` a list of
*rungs*, each a way of solving the same M-step problem, and the ladder climbs them.

At each step t (``FailureLadder.step``):

1. **Solve** from the warm start: the last *successful* plan shifted to t (never a failed
   iterate, so one failure cannot compound into an open-loop replay of a bad plan).
2. **Retry from a cold start** if that fails (a bad warm start is the commonest cause). More rungs
   can follow: on the default NLP path of ``PreviewRHC``, IPOPT after SQP (warm and cold). The
   first rung that succeeds gives the step's plan (and names its solver, ``Plan.solver``).
3. **Fall back** if every rung failed: apply the next input of the last successful plan, shifted
   by the steps since it was computed, while that plan lasts (fewer than M steps old): the
   standard receding-horizon fallback, a plan that was optimal a few steps ago. With no such
   plan (the very first step, or a plan used up) the last rung's final iterate is applied
   (within the input bounds, not optimal). The step is marked failed (``success=False``, the
   statuses, ``fallback`` naming what was applied; its V_M is NaN).
4. **Stop** when ``max_failures`` consecutive steps have failed (default 3): raise
   :class:`~orrc.SolverError` naming the step, the statuses and what to try.

Why stop, and why after 3: a control engineer expects an isolated failure to be ridden out on
the shifted plan (it stays valid for up to M-1 steps) but not a run that goes on open loop: when
three steps in a row fail the failure is systematic (a solver option, infeasible bounds, a state
far outside the region the horizon can handle), the inputs applied are no longer Algorithm 1's,
and the paper's claims say nothing about the run. ``max_failures=None`` never stops (to study the
failures themselves); ``max_failures=1`` stops at the first one.

A direct ``plan()`` call climbs the same rungs (``FailureLadder.attempt``) but has no time: it
returns the failed plan with its fallback and warns once (:class:`~orrc.SolverWarning`).
"""
from __future__ import annotations

import math
from typing import Callable, Sequence

import numpy as np

from .._validate import as_int
from ..solvers.plan import Plan, SolverError

__all__ = ["FailureLadder", "SHIFTED", "LAST_ITERATE", "DEFAULT_MAX_FAILURES"]

#: consecutive failed steps after which a controller stops (see the module docstring)
DEFAULT_MAX_FAILURES = 3

#: the fallback labels (``Decision.fallback``, ``Trajectory.fallback``, the summary warning)
SHIFTED = "the previous successful plan, shifted"
LAST_ITERATE = "the solver's last iterate"

Rung = tuple[str, Callable[[], Plan]]


def max_failures_arg(max_failures) -> int | None:
    """``max_failures`` checked: None (never stop) or an integer >= 1."""
    return None if max_failures is None else as_int("max_failures", max_failures, minimum=1)


def _shift(rows: np.ndarray, k: int) -> np.ndarray:
    """rows[k:] followed by k copies of the last row (same length)."""
    out = np.empty_like(rows)
    out[:len(rows) - k] = rows[k:]
    out[len(rows) - k:] = rows[-1]
    return out


class FailureLadder:
    """The escalation policy of one receding-horizon controller (see the module docstring).

    Parameters
    ----------
    M : the horizon (a successful plan can be shifted for up to M-1 steps).
    max_failures : consecutive failed steps tolerated before :class:`~orrc.SolverError`; None: never stop.
    name : the controller's name, for the messages.

    Examples
    --------
    Every receding-horizon controller holds one; ``PreviewRHC(..., max_failures=5)`` sets its limit:

    >>> from orrc.controllers import FailureLadder
    >>> ladder = FailureLadder(M=10, max_failures=5, name="preview RHC")
    >>> ladder.M, ladder.max_failures
    (10, 5)
    """

    def __init__(self, M: int, max_failures: int | None = DEFAULT_MAX_FAILURES, name: str = "controller"):
        self.M = M
        self.max_failures = max_failures_arg(max_failures)
        self.name = name
        self.reset()

    def reset(self) -> None:
        """Forget the last successful plan and the failure streak (a new run)."""
        self._good: Plan | None = None
        self._good_t = 0
        self._streak: list[tuple[int, str]] = []
        self._tried: list[str] = []  # the rungs of the last failed step, for the stop message

    # -- stateless: one problem, several ways of solving it --------------------------------------
    @staticmethod
    def attempt(rungs: Sequence[Rung]) -> Plan:
        """Try the rungs in order; the first successful plan, else the last failed one.

        When more than one rung was tried, the plan's ``extra["attempts"]`` lists (rung, status),
        its iterations and solve time are the sums over the rungs, and its ``status`` names them:
        "cold start: Solve_Succeeded (after warm start: ...)" for a step rescued by a retry,
        "warm start: ...; cold start: ..." for a failed one.
        """
        tried = []
        plan = None
        iterations, seconds = 0, 0.0
        for label, solve in rungs:
            plan = solve()
            tried.append((label, plan.status))
            iterations, seconds = iterations + plan.iterations, seconds + plan.solve_time
            if plan.success:
                break
        if len(tried) > 1:  # the step's effort is that of every rung tried, and its status says so
            plan.extra["attempts"] = tried
            plan.iterations, plan.solve_time = iterations, seconds
            earlier = "; ".join(f"{label}: {status}" for label, status in tried[:-1])
            plan.status = (f"{tried[-1][0]}: {plan.status} (after {earlier})" if plan.success
                           else f"{earlier}; {tried[-1][0]}: {plan.status}")
        return plan

    # -- stateful: one step of a run -------------------------------------------------------------
    def warm_start(self, t: int) -> tuple[np.ndarray, np.ndarray, int] | None:
        """(inputs, states, k): the last successful plan shifted by k = t - (its step), or None
        when there is none or it is used up (k >= M). States hold x̃_k..x̃_M padded (x̃_0 is
        replaced by the current state by the caller)."""
        if self._good is None:
            return None
        k = t - self._good_t
        if not 1 <= k < self.M:
            return None
        return _shift(self._good.inputs, k), _shift(self._good.states, k), k

    def step(self, t: int, rungs: Sequence[Rung]) -> Plan:
        """The plan to apply at step t: climb the rungs, fall back, or stop (module docstring)."""
        plan = self.attempt(rungs)
        self._tried = [label for label, _ in rungs]
        if plan.success:
            return self.succeeded(t, plan)
        self._streak.append((t, plan.status))
        shifted = self.warm_start(t)
        if shifted is not None:
            plan.inputs, plan.states, k = shifted
            plan.fallback = SHIFTED
            plan.extra["shifted_by"] = k
        else:
            plan.fallback = LAST_ITERATE
        plan.value = math.nan  # a failed solve has no optimal value V_M
        if self.max_failures is not None and len(self._streak) >= self.max_failures:
            raise SolverError(self._stop_message(t), step=t, statuses=[s for _, s in self._streak])
        return plan

    def succeeded(self, t: int, plan: Plan) -> Plan:
        """Record ``plan``, solved successfully at step t, as the plan to shift from (what :meth:`step`
        does when a rung succeeds; a controller that solved its first rung itself calls it directly)."""
        self._good, self._good_t = plan, t
        self._streak = []
        return plan

    def _stop_message(self, t: int) -> str:
        first = self._streak[0][0]
        statuses = sorted({s for _, s in self._streak})
        tried = ", then ".join(self._tried) if len(self._tried) > 1 else "one solve"
        return (f"{self.name} stopped at step t={t}: the M-step solve failed at {len(self._streak)} consecutive "
                f"steps (t={first}..{t}; max_failures={self.max_failures}; each step tried {tried}); "
                f"solver statuses: {statuses}. What to try: raise the solvers' iteration limits "
                "(solver_options={'sqpmethod.max_iter': ..., 'ipopt.max_iter': ...}) or loosen their tolerances; "
                "check that the input and "
                "state bounds leave the M-step problem feasible from these states; a shorter horizon M or a "
                "rescaled cost; or pass max_failures=None to run on through the fallbacks (the run is then not "
                "Algorithm 1 at the failed steps, which orrc.Trajectory.success marks)")
