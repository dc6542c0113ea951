"""What a controller sees (Observation) and returns (Decision), and the interface it offers the simulator.

The simulator builds one :class:`Observation` per step with exactly the preview a
controller declares (``preview_w`` future disturbances, ``preview_c`` future
costs), which is how the paper's information pattern
u_t = π_t(x_{1:t}, u_{1:t-1}, w_{1:t+M_w-1}, c_{1:t+M_c-1}) is enforced.

**Values in a batch.** V_M does not feed back into the loop, so a controller that can compute it
for many steps at once may leave it out of the step: it returns ``Decision(value_deferred=True)``
(and no ``value``), and :func:`orrc.simulate` calls :meth:`Controller.values_batch` once after the
last step, with the states and preview windows of every deferred step (a step of the fast path below
counts as deferred when its ``fast_decision`` says so). The exact LQ path of :class:`~orrc.PreviewRHC`
does this through its fast path: V_M(x_t, W_t) = z_tᵀ ℋ z_t for the whole run is one matrix product,
where one product per step with the (n + Mn)² matrix ℋ was most of the step's time. (Its
:meth:`~orrc.PreviewRHC.control`, called directly or by a controller that wraps it, still reports V_M.)

**Inputs without the per-step records.** A controller whose steps, on a problem without a cost
preview, produce nothing but u_t (no solve to report, V_M deferred) may also offer ``fast_input``, a
callable ``fast_input(x_t, w_preview) -> u_t`` given exactly what an :class:`Observation` would hold
(the read-only state and the M_w-step preview), and ``fast_decision``, the :class:`Decision` that
describes every such step (its ``status``, ``solver``, ``value_deferred``; its ``u`` is ignored).
:func:`orrc.simulate` then calls ``fast_input`` instead of :meth:`Controller.control` and builds no
Observation or Decision per step (two small objects were a third of the exact LQ path's step). The
information pattern is the same. A controller offers it only when its own :meth:`~Controller.control` would
return that Decision at every such step (:class:`~orrc.PreviewRHC` on its exact LQ path, and not in a
subclass that overrides ``control``).

**Affine laws.** A fast-path controller whose input is affine, u_t = −K x_t + f(W_t) with W_t its own
preview window, may also offer ``fast_affine = (K, feedforward)``, ``feedforward`` mapping a stack of
windows (k, M_w, n) to their f(W_t) (k, m), each row from its own window only. The simulator then
computes the feed-forward of all steps in one call before the loop and steps u_t = −K x_t + f_t and
the dynamics: the window of step t still enters only u_t, as in the paper's information pattern.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import OrrcValueError


@dataclass(slots=True)
class Observation:
    """The information available at step t: what the paper's information pattern allows a controller.

    Attributes
    ----------
    t : int
    x : (n,) the current state x_t (read-only)
    w_past : (n,) or None, the disturbance w_{t-1} that has just acted (None at t=0)
    w_preview : (preview_w, n) the disturbances w_t..w_{t+M_w-1} (read-only)
    cost_params : (preview_c, n_params) parameters of c_t..c_{t+M_c-1}, or None when
        the problem's cost is time-invariant (the controller's own cost applies)

    Examples
    --------
    What the simulator hands a controller at t = 0 of a run with one step of preview:

    >>> import numpy as np
    >>> import orrc
    >>> obs = orrc.Observation(t=0, x=np.array([1.0, 0.0]), w_past=None,
    ...                        w_preview=np.array([[0.1, 0.0]]), cost_params=None)
    >>> obs.w_preview.shape
    (1, 2)

    A controller reads it in :meth:`Controller.control`:

    >>> import numpy as np
    >>> import orrc
    >>> class Proportional(orrc.Controller):
    ...     # u_t = -k x_t[0]: no preview of w or of the costs
    ...     preview_w = preview_c = 0
    ...     def __init__(self, k):
    ...         self.k = k
    ...     def control(self, obs):
    ...         return orrc.Decision(u=np.array([-self.k * obs.x[0]]))
    >>> ex = orrc.examples.scalar_unstable(A=2.0, B=1.0)
    >>> traj = orrc.simulate(ex.system, Proportional(1.5), ex.x0, np.zeros((10, 1)), T=10,
    ...                      costs=ex.cost)
    >>> traj.x[:4, 0]   # x+ = (2 - 1.5) x
    array([1.   , 0.5  , 0.25 , 0.125])
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
    the controller solves nothing keeps ``success=True``. ``solver`` names the solver that
    produced the step ("lq", "sqp", "ipopt"; for a failed step the last one tried; None when
    nothing was solved). ``value_deferred=True`` says that this step's V_M will come from
    :meth:`Controller.values_batch` after the run (``value`` is then None). :func:`orrc.simulate`
    records all of it in the :class:`~orrc.Trajectory` and warns once per run when some step failed.

    Parameters
    ----------
    u : (m,) the input u_t.
    value : V_M of the problem solved at this step, or None.
    success, status, iterations, solve_time, fallback, solver : the solver's report (see above).
    value_deferred : True when V_M comes from :meth:`Controller.values_batch` after the run.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> d = orrc.Decision(u=np.array([0.5]))
    >>> d.u, d.success, d.value
    (array([0.5]), True, None)
    """

    u: np.ndarray
    value: float | None = None
    success: bool = True
    status: str = "optimal"
    iterations: int = 0
    solve_time: float = 0.0
    fallback: str | None = None
    solver: str | None = None
    value_deferred: bool = False


class Controller:
    """Base class. Subclasses set ``preview_w``, ``preview_c`` (and ``cost`` when they
    optimise one, ``system`` when they hold a model) and implement :meth:`control`.

    Examples
    --------
    A controller of one's own: declare the preview, return a :class:`Decision`.

    >>> import numpy as np
    >>> import orrc
    >>> class Proportional(orrc.Controller):
    ...     # u_t = -k x_t[0]: no preview of w or of the costs
    ...     preview_w = preview_c = 0
    ...     def __init__(self, k):
    ...         self.k = k
    ...     def control(self, obs):
    ...         return orrc.Decision(u=np.array([-self.k * obs.x[0]]))
    >>> ex = orrc.examples.scalar_unstable(A=2.0, B=1.0)
    >>> traj = orrc.simulate(ex.system, Proportional(1.5), ex.x0, np.zeros((10, 1)), T=10,
    ...                      costs=ex.cost)
    >>> traj.x[:4, 0]   # x+ = (2 - 1.5) x
    array([1.   , 0.5  , 0.25 , 0.125])
    """

    preview_w: int = 0
    preview_c: int = 0
    cost = None
    name = "controller"
    #: optional: ``fast_input(x, w_preview) -> u`` and the Decision of every such step (module docstring)
    fast_input = None
    fast_decision: "Decision | None" = None
    #: optional, with ``fast_input``: ``(K, feedforward)`` of an affine law (module docstring)
    fast_affine = None

    def check_run(self, system, T: int) -> None:
        """Refuse a run this controller cannot serve (called by ``simulate`` before the first step).

        Default: a controller that holds a model (``self.system``), a state dimension (``self.n``) or an
        input dimension (``self.m``) must match the simulated system's dimensions. Subclasses extend it (e.g.
        :class:`~orrc.Clairvoyant` needs the T it planned for).
        """
        own = getattr(self, "system", None)
        if own is not None and (getattr(own, "n", None), getattr(own, "m", None)) != (system.n, system.m):
            raise OrrcValueError(
                f"controller {self.name!r} was built for a system with n={own.n} states and m={own.m} inputs; "
                f"the simulated system has n={system.n}, m={system.m}")
        n = getattr(self, "n", None)
        if isinstance(n, int) and n != system.n:
            raise OrrcValueError(f"controller {self.name!r} was built for n={n} states; the simulated system has "
                                 f"n={system.n}")
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

    def values_batch(self, X: np.ndarray, W_windows: np.ndarray) -> np.ndarray:
        """V_M of many steps at once, for the steps whose :class:`Decision` had ``value_deferred=True``
        (called by :func:`orrc.simulate` once, after the last step).

        X : (k, n) the states x_t of those steps, in time order.
        W_windows : (k, preview_w, n) their preview windows w_{t:t+M_w-1} (read-only).
        Returns (k,) the values V_M(x_t, W_t), each equal to what the step would have reported.
        A controller that defers values must implement it; the default refuses.
        """
        raise OrrcValueError(f"controller {self.name!r} returned Decision(value_deferred=True) but does not implement "
                             "values_batch(X, W_windows), which must then give those steps' V_M")

    def control(self, obs: Observation) -> Decision:  # pragma: no cover - abstract
        raise NotImplementedError
