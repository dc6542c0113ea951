"""The problem of Section 2 as a controller or certificate receives it: a system and a stage cost.

:func:`check_problem` sits above :mod:`orrc.systems` and :mod:`orrc.costs` (it checks their types),
so that the validation layer below them (:mod:`orrc._validate`) imports neither.
"""
from __future__ import annotations

from ._validate import OrrcValueError
from .costs import QuadraticCost, StageCost
from .systems import LinearSystem, System


def check_problem(system, cost, *, linear: bool = False, quadratic: bool = False, who: str = "",
                  why_linear: str = "", why_quadratic: str = "") -> None:
    """The (system, cost) pair a controller or certificate starts from (the problem of Section 2).

    ``system`` must be an orrc system (a :class:`~orrc.LinearSystem` when ``linear``; None is
    refused like any other non-system: a caller without a system checks the cost alone with
    :func:`check_cost`), ``cost`` an orrc stage cost (a :class:`~orrc.QuadraticCost` when ``quadratic``)
    whose dimensions match the system's (n, m). ``who`` names the caller that needs the
    narrower type and ``why_*`` says why, e.g. ``who="GPC", why_linear=": it recovers w_t ..."``.
    Raises :class:`OrrcValueError` naming the argument, the type given and the type allowed.
    """
    def needs(arg: str, kind: str) -> str:
        return f"{arg}: {who} needs a {kind}" if who else f"{arg} must be an orrc {kind}"

    if linear and not isinstance(system, LinearSystem):
        raise OrrcValueError(f"{needs('system', 'LinearSystem')}{why_linear}; got {type(system).__name__}")
    if not isinstance(system, System):
        raise OrrcValueError(f"system must be an orrc LinearSystem or NonlinearSystem; got {type(system).__name__}")
    if quadratic and not isinstance(cost, QuadraticCost):
        raise OrrcValueError(f"{needs('cost', 'QuadraticCost')}{why_quadratic}; got {type(cost).__name__}")
    check_cost(cost)
    cost.check_dims(system.n, system.m)


def check_cost(cost) -> None:
    """``cost`` an orrc stage cost (for a caller whose model is not a System, e.g. Algorithm 2's
    ParametricSystem or an EDMD dictionary, which checks the dimensions itself)."""
    if not isinstance(cost, StageCost):
        raise OrrcValueError(f"cost must be an orrc stage cost (QuadraticCost, L1Cost, Cost); got "
                             f"{type(cost).__name__}")
