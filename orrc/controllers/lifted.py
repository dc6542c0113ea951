"""Algorithm 1 on a lifted linear model (EDMD): the controller sees x, plans on z = ψ(x)."""
from __future__ import annotations

import numpy as np

from .._validate import OrrcValueError, as_array
from .._problem import check_cost
from ..costs import Cost, QuadraticCost, StageCost
from .base import Controller, Decision, Observation
from .preview import PreviewRHC


def lifted_cost(cost: StageCost, C: np.ndarray) -> StageCost:
    """The stage cost on the lifted state: c_z(z, u) = c(C z, u).

    A :class:`~orrc.QuadraticCost` (Q, R) becomes QuadraticCost(CᵀQC, R) (so a lifted linear model
    keeps the exact LQ path); any other cost is wrapped as a CasADi :class:`~orrc.Cost`.

    Parameters
    ----------
    cost : the stage cost c(x, u).
    C : (n, K) the projection x = C z.

    Returns
    -------
    StageCost
        c_z; a :class:`~orrc.QuadraticCost` when ``cost`` is one.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> from orrc.controllers import lifted
    >>> di = orrc.examples.double_integrator()
    >>> type(lifted.lifted_cost(di.cost, np.eye(2))).__name__
    'QuadraticCost'
    """
    n, K = C.shape
    if isinstance(cost, QuadraticCost):
        Qz = C.T @ cost.Q @ C
        return QuadraticCost(0.5 * (Qz + Qz.T), cost.R, alpha_lo=0.0, name=f"{cost.name} on the lifted state")
    import casadi as ca

    Cd = ca.DM(C)

    def fun(z, u, p=None):
        return cost.expr(ca.mtimes(Cd, z), u, cost.default_params if p is None else p)

    return Cost(fun, K, cost.m, n_params=cost.n_params, default_params=cost.default_params,
                name=f"{cost.name} on the lifted state")


class LiftedRHC(Controller):
    """Algorithm 1 (preview RHC) on a lifted linear model z+ = A z + B u + E w, z = ψ(x), x = C z.

    At step t it lifts the observed state, z_t = ψ(x_t), maps the previewed disturbances through
    E, and runs :class:`~orrc.PreviewRHC` on ``model.system`` (a :class:`~orrc.LinearSystem` on z)
    with the cost c(C z, u): the exact LQ path for a quadratic cost without bounds, CasADi +
    IPOPT otherwise. ``model``: an :class:`orrc.estimation.EDMDModel` (anything with ``system``,
    ``lift``, ``C`` and ``E``). The cost is time invariant (the paper's Section 5.2 assumes it).

    Parameters
    ----------
    model : an :class:`orrc.estimation.EDMDModel` (from :func:`orrc.estimation.edmd`).
    cost : the stage cost c(x, u) on the original state.
    M : the preview horizon.
    input_bounds : (lo, hi), the set U.
    solver_options : options for the CasADi path.

    Examples
    --------
    A linear dictionary fitted on 40 steps of the double integrator:

    >>> import numpy as np
    >>> from orrc.estimation import edmd, polynomial_dictionary
    >>> import orrc
    >>> di = orrc.examples.double_integrator()
    >>> w = orrc.disturbances.uniform_ball(L=60, n=2, radius=0.1, seed=0)
    >>> rng = np.random.default_rng(0)
    >>> U, W = rng.standard_normal((40, 1)), 0.1 * rng.standard_normal((40, 2))
    >>> X = np.zeros((41, 2))
    >>> for k in range(40):
    ...     X[k + 1] = di.system.step(X[k], U[k], W[k])
    >>> model = edmd(X, U, polynomial_dictionary(2, 1), W=W)
    >>> traj = orrc.simulate(di.system, orrc.LiftedRHC(model, di.cost, M=10), di.x0,
    ...                      w, T=50)
    >>> traj.x.shape
    (51, 2)
    """

    name = "preview RHC on the lifted model"

    def __init__(self, model, cost: StageCost, M: int, input_bounds=None, solver_options=None):
        for attr in ("system", "lift", "C", "E"):
            if not hasattr(model, attr):
                raise OrrcValueError(f"model must be a lifted linear model (orrc.estimation.EDMDModel); it has no "
                                     f"{attr!r}")
        check_cost(cost)
        n = model.C.shape[0]
        cost.check_dims(n, model.B.shape[1])
        self.model, self.cost = model, cost
        self.inner = PreviewRHC(model.system, lifted_cost(cost, model.C), M, input_bounds=input_bounds,
                                solver_options=solver_options)
        self.M = self.inner.M
        self.preview_w = self.preview_c = self.M
        self.solver = self.inner.solver

    def reset(self) -> None:
        self.inner.reset()

    def lift_observation(self, obs: Observation) -> Observation:
        """The observation on the lifted model: z_t = ψ(x_t) and the previewed E w_t..E w_{t+M-1}."""
        if obs.cost_params is not None:
            raise OrrcValueError("LiftedRHC plans with a time-invariant cost (Section 5.2); got a cost preview")
        z = self.model.lift(obs.x)
        Wz = obs.w_preview @ self.model.E.T
        return Observation(obs.t, z, None if obs.w_past is None else self.model.E @ obs.w_past, Wz, None)

    def plan(self, x, w_preview):
        """The M-step plan on the lifted model from state x with previewed disturbances (M, n)."""
        n = self.model.C.shape[0]
        x = as_array("x", x, (n,))
        w_preview = as_array("w_preview", w_preview, (self.M, n))
        return self.inner.plan(self.model.lift(x), w_preview @ self.model.E.T)

    def control(self, obs: Observation) -> Decision:
        return self.inner.control(self.lift_observation(obs))

    def __repr__(self):
        return f"LiftedRHC(M={self.M}, K={self.model.K}, solver={self.solver!r})"
