"""The worst-case dynamic regret of a linear closed loop over a finite horizon.

* :func:`worst_case_regret` -- for a linear controller (Algorithm 1 on the LQ path with any
  preview k, HInfinity, LQR, zero input, a frozen GPC, RegretOptimal) over T steps from x_0 = 0:
  the largest dynamic regret against the clairvoyant optimum over disturbances of unit energy,
  max_{‖w‖ <= 1} Σ_{t<T} c_t − Σ_{t<T} c*_t, and the disturbance attaining it.

Both the controller's inputs and the clairvoyant optimum's are linear in W = (w_0, ..., w_{T-1})
(:func:`orrc.certify.worst_case_attenuation`'s operators; :mod:`orrc.solvers.condensed`), and the
cost is quadratic with Hessian S in the inputs, so the regret of one disturbance is exactly
‖S^½(Φ − Φ*) vec W‖²: the worst case is the top singular value of the regret operator
S^½(Φ − Φ*), squared, and its top right singular vector is the worst disturbance.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._validate import as_int
from ..controllers.baselines import LQR
from ..solvers.condensed import Condensed, condensed
from ._loop import _linear_loop, _operators, _top_singular

__all__ = ["Regret", "worst_case_regret"]


@dataclass
class Regret:
    """The worst-case dynamic regret of a linear closed loop over T steps from x_0 = 0.

    Attributes
    ----------
    regret : max over Σ‖w_t‖² <= 1 of Σ c_t − Σ c*_t (the clairvoyant optimum's cost, same w): a
        squared gain, like the attenuation level.
    w : (T, n) the disturbance that attains it (unit energy).
    T : the horizon.
    operator : (T m, T n) the regret operator S^½(Φ − Φ*).
    condensed : the condensed problem (:class:`orrc.solvers.condensed.Condensed`).

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> di = orrc.examples.double_integrator()
    >>> lqr = orrc.LQR(di.system, di.cost)
    >>> worst = certify.worst_case_regret(di.system, lqr, T=20)
    >>> worst.w.shape, worst.operator.shape
    ((20, 2), (20, 40))
    """

    regret: float
    w: np.ndarray
    T: int
    operator: np.ndarray = field(repr=False)
    condensed: Condensed = field(repr=False)


def worst_case_regret(system, controller, T: int, cost=None) -> Regret:
    """The worst-case dynamic regret over ‖w‖ <= 1 of a linear closed loop, T steps from x_0 = 0.

    The comparator is the clairvoyant optimum of :class:`orrc.Clairvoyant` (the T-step optimum
    with all of w known, no terminal cost). The regret operator's top singular pair gives the
    value and the worst disturbance; ``orrc.simulate`` of the controller and of
    ``orrc.Clairvoyant(system, cost, T)`` on ``result.w`` reproduces it.
    Controllers with preview see zeros past T, as in :func:`orrc.certify.worst_case_attenuation`.
    ``cost`` defaults to the controller's own cost.

    Parameters
    ----------
    system : a :class:`~orrc.LinearSystem`.
    controller : a linear controller.
    T : the horizon.
    cost : the quadratic cost (default: the controller's).

    Returns
    -------
    Regret
        the worst-case ``regret``, the disturbance ``w`` (T, n) that attains it, the ``operator``.

    Raises
    ------
    orrc.OrrcValueError
        When the system is not linear or the cost not quadratic, an argument is out of range, or the
        computation exceeds the size limits of ``orrc.config``.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> di = orrc.examples.double_integrator()
    >>> lqr = orrc.LQR(di.system, di.cost)
    >>> print(round(certify.worst_case_regret(di.system, lqr, T=20).regret, 3))
    50.553
    """
    loop = _linear_loop(system, controller, cost, "worst_case_regret")
    T = as_int("T", T, minimum=1)
    from ..costs import QuadraticCost

    K = LQR(system, QuadraticCost(loop.Q, loop.R)).K         # pre-stabilisation (well-conditioned S)
    c = condensed(system.A, system.B, loop.Q, loop.R, T, K=K, who="worst_case_regret")
    X, U = _operators(system, loop, T)
    op = c.regret_operator(c.v_operator(U, X))
    value, v = _top_singular(op)
    w = v.reshape(T, system.n)
    j = int(np.argmax(np.abs(w.ravel())))
    if w.ravel()[j] < 0:
        w = -w
    return Regret(regret=value, w=w, T=T, operator=op, condensed=c)
