"""What a controller sees (Observation) and returns (Decision).

The simulator builds one :class:`Observation` per step with exactly the preview a
controller declares (``preview_w`` future disturbances, ``preview_c`` future
costs), which is how the paper's information pattern
u_t = π_t(x_{1:t}, u_{1:t-1}, w_{1:t+M_w-1}, c_{1:t+M_c-1}) is enforced.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import OrrcValueError


@dataclass(slots=True)
class Observation:
    """The information available at step t.

    t : int
    x : (n,) the current state x_t (read-only)
    w_past : (n,) or None, the disturbance w_{t-1} that has just acted (None at t=0)
    w_preview : (preview_w, n) the disturbances w_t..w_{t+M_w-1} (read-only)
    cost_params : (preview_c, n_params) parameters of c_t..c_{t+M_c-1}, or None when
        the problem's cost is time-invariant (the controller's own cost applies)
    """

    t: int
    x: np.ndarray
    w_past: np.ndarray | None
    w_preview: np.ndarray
    cost_params: np.ndarray | None


@dataclass(slots=True)
class Decision:
    """A controller's output at one step: the input u_t and, when it has them, the
    optimal value V_M of the problem it solved and the solver's report.

    ``success`` is False when the step's solve failed; ``status`` then gives the solver's
    statuses, ``fallback`` what u_t is instead (e.g. "the previous successful plan, shifted"),
    and ``value`` is NaN (or is ignored: a failed solve has no optimal value). A step at which
    the controller solves nothing keeps ``success=True``. :func:`orrc.simulate` records all of
    it in the :class:`~orrc.Trajectory` and warns once per run when some step failed.
    """

    u: np.ndarray
    value: float | None = None
    success: bool = True
    status: str = "optimal"
    iterations: int = 0
    solve_time: float = 0.0
    fallback: str | None = None


class Controller:
    """Base class. Subclasses set ``preview_w``, ``preview_c`` (and ``cost`` when they
    optimise one, ``system`` when they hold a model) and implement :meth:`control`."""

    preview_w: int = 0
    preview_c: int = 0
    cost = None
    name = "controller"

    def check_run(self, system, T: int) -> None:
        """Refuse a run this controller cannot serve (called by ``simulate`` before the first step).

        Default: a controller that holds a model (``self.system``) or an input dimension
        (``self.m``) must match the simulated system's dimensions. Subclasses extend it (e.g.
        :class:`~orrc.Clairvoyant` needs the T it planned for).
        """
        own = getattr(self, "system", None)
        if own is not None and (getattr(own, "n", None), getattr(own, "m", None)) != (system.n, system.m):
            raise OrrcValueError(
                f"controller {self.name!r} was built for a system with n={own.n} states and m={own.m} inputs; "
                f"the simulated system has n={system.n}, m={system.m}")
        m = getattr(self, "m", None)
        if isinstance(m, int) and m != system.m:
            raise OrrcValueError(f"controller {self.name!r} gives m={m} inputs; the simulated system has "
                                 f"m={system.m}")

    def reset(self) -> None:
        """Forget any state kept from a previous run (called by ``simulate``)."""

    def record(self) -> dict:
        """What the controller learned or decided during the run, beyond u_t (called by ``simulate``
        once, after the last step; the result becomes ``Trajectory.info``).

        Default: nothing. Controllers with internal state report it here, e.g. the phase of each
        step and the estimate θ̂ (Algorithm 2), or per-step bounds of a min-max solve (Algorithm 3).
        Values are numpy arrays with time along axis 0 where they are per step.
        """
        return {}

    def control(self, obs: Observation) -> Decision:  # pragma: no cover - abstract
        raise NotImplementedError
