"""What a controller sees (Observation) and returns (Decision).

The simulator builds one :class:`Observation` per step with exactly the preview a
controller declares (``preview_w`` future disturbances, ``preview_c`` future
costs), which is how the paper's information pattern
u_t = π_t(x_{1:t}, u_{1:t-1}, w_{1:t+M_w-1}, c_{1:t+M_c-1}) is enforced.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


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
    optimal value V_M of the problem it solved and the solver's report."""

    u: np.ndarray
    value: float | None = None
    success: bool = True
    status: str = "optimal"
    iterations: int = 0
    solve_time: float = 0.0


class Controller:
    """Base class. Subclasses set ``preview_w``, ``preview_c`` (and ``cost`` when they
    optimise one) and implement :meth:`control`."""

    preview_w: int = 0
    preview_c: int = 0
    cost = None
    name = "controller"

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
