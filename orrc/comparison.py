"""Comparisons of controllers on one problem (the computations of the comparison chapter).

* :func:`compare` -- every controller on the same disturbance: total cost, attenuation ratio,
  R^p_T(γ), dynamic regret against :class:`~orrc.Clairvoyant`, and for linear loops the exact
  worst-case attenuation and worst-case regret over T steps (:mod:`orrc.certify`);
* :func:`preview_value` -- the dynamic regret of ``PreviewRHC(M, preview_w=k)`` against k, with the
  exponential fit regret(k) − regret(M) ≈ C r^k and the rate λ_K² (λ_K the spectral radius of A − BK_LQR) that the literature
  predicts (Yu, Shi, Chung, Yue and Wierman 2020; Zhang, Li and Li 2021).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._validate import OrrcValueError, as_array, as_bool, as_float, as_int
from ._problem import check_problem
from ._progress import progress

__all__ = ["ComparisonRow", "compare", "PreviewValue", "preview_value"]


@dataclass
class ComparisonRow:
    """One controller on one disturbance (see :func:`compare`); worst-case fields are None for a
    controller that is not a linear loop (nonlinear system, input bounds, a learning GPC).

    Attributes
    ----------
    name : the controller's label.
    cost : Σ_{t<T} c_t.
    ratio : Σ c_t / Σ ‖w_t‖².
    regret_p : R^p_T(γ) of Eq. (2).
    dynamic_regret : the cost above the clairvoyant optimum.
    worst_attenuation, worst_regret : the worst cases over ‖w‖ <= 1 for a linear loop, else None.

    Examples
    --------
    >>> import orrc
    >>> from orrc import comparison
    >>> ex = orrc.examples.scalar_unstable()
    >>> w = orrc.disturbances.uniform_ball(30, 1, 1.0, seed=0)
    >>> rows = comparison.compare(ex.system, ex.cost, {"LQR": orrc.LQR(ex.system, ex.cost)},
    ...                           w, T=20, gamma=5.0)
    >>> [row.name for row in rows]
    ['LQR', 'clairvoyant optimum']
    """

    name: str
    cost: float
    ratio: float
    regret_p: float
    dynamic_regret: float
    worst_attenuation: float | None
    worst_regret: float | None


def compare(system, cost, controllers: dict, w, T: int, gamma: float, x0=None, worst_case: bool = True,
            clairvoyant_kwargs=None) -> list[ComparisonRow]:
    """Run every controller of ``controllers`` (label -> Controller) on ``w`` for T steps from ``x0``
    (default 0) and return one :class:`ComparisonRow` each, plus the clairvoyant optimum's row.

    The worst-case attenuation (:func:`orrc.certify.worst_case_attenuation`) and regret
    (:func:`orrc.certify.worst_case_regret`) over the same T are added for linear loops.

    Parameters
    ----------
    system, cost : the problem.
    controllers : label -> :class:`~orrc.Controller`.
    w : (L, n) the disturbances, L >= T + the longest preview.
    T : the number of steps.
    gamma : the level γ of R^p_T(γ).
    x0 : the initial state (default 0).
    worst_case : add the worst cases of linear loops.
    clairvoyant_kwargs : options of the :class:`~orrc.Clairvoyant` reference.

    Returns
    -------
    list of ComparisonRow
        one row per controller, then the clairvoyant optimum's.

    Raises
    ------
    orrc.OrrcValueError
        When a controller does not fit the problem or an argument is malformed.

    Examples
    --------
    >>> import orrc
    >>> from orrc import comparison
    >>> ex = orrc.examples.scalar_unstable()
    >>> w = orrc.disturbances.uniform_ball(30, 1, 1.0, seed=0)
    >>> rows = comparison.compare(ex.system, ex.cost,
    ...                           {"LQR": orrc.LQR(ex.system, ex.cost),
    ...                            "preview RHC": orrc.PreviewRHC(ex.system, ex.cost, 5)},
    ...                           w, T=20, gamma=5.0)
    >>> [(row.name, round(row.dynamic_regret, 2)) for row in rows]
    [('LQR', 25.3), ('preview RHC', 0.05), ('clairvoyant optimum', 0.0)]
    """
    from . import certify
    from .controllers import Clairvoyant, Controller
    from .metrics import attenuation_ratio, attenuation_regret, dynamic_regret
    from .simulate import simulate
    from .systems import LinearSystem

    if not isinstance(controllers, dict) or not controllers:
        raise OrrcValueError("controllers must be a non-empty dict label -> orrc Controller")
    for k, c in controllers.items():
        if not isinstance(c, Controller):
            raise OrrcValueError(f"controllers[{k!r}] must be an orrc Controller; got {type(c).__name__}")
    T = as_int("T", T, minimum=1)
    gamma = as_float("gamma", gamma, minimum=0.0)
    check_problem(system, cost)
    worst_case = as_bool("worst_case", worst_case)
    x0 = np.zeros(system.n) if x0 is None else as_array("x0", x0, (system.n,))
    clair = simulate(system, Clairvoyant(system, cost, T, **(clairvoyant_kwargs or {})), x0, w, T)
    rows = []
    runs = {**controllers, "clairvoyant optimum": None}
    for label, ctrl in progress(runs.items(), desc="controllers compared", total=len(runs)):
        tr = clair if ctrl is None else simulate(system, ctrl, x0, w, T)
        wa = wr = None
        if worst_case and ctrl is not None and isinstance(system, LinearSystem):
            try:
                wa = certify.worst_case_attenuation(system, ctrl, T, cost=cost).gamma
                wr = certify.worst_case_regret(system, ctrl, T, cost=cost).regret
            except OrrcValueError:
                pass
        rows.append(ComparisonRow(label, float(tr.costs.sum()), attenuation_ratio(tr), attenuation_regret(tr, gamma),
                                  dynamic_regret(tr, clair), wa, wr))
    return rows


@dataclass
class PreviewValue:
    """The value of preview: the dynamic regret of Algorithm 1 against the number k of previewed disturbances.

    Attributes
    ----------
    ks : (k,) the numbers of previewed disturbances.
    regret : (k,) the dynamic regret of ``PreviewRHC(M, preview_w=k)``.
    excess : (k,) regret − regret at k = M.
    rate : the fitted r of excess ≈ C r^k.
    r2 : the R² of the log-linear fit.
    lambda_K_sq : λ_K², λ_K the spectral radius of A − BK_LQR: the rate the theory predicts.
    M : the horizon.

    Examples
    --------
    >>> import orrc
    >>> from orrc import comparison
    >>> ex = orrc.examples.scalar_unstable()
    >>> w = orrc.disturbances.uniform_ball(30, 1, 1.0, seed=0)
    >>> value = comparison.preview_value(ex.system, ex.cost, 6, [0, 1, 2, 3, 6], w, T=20)
    >>> bool(value.regret[0] > value.regret[-1])
    True
    """

    ks: np.ndarray
    regret: np.ndarray
    excess: np.ndarray
    rate: float
    r2: float
    lambda_K_sq: float
    M: int


def preview_value(system, cost, M: int, ks, w, T: int, x0=None, fit_above: float = 1e-8) -> PreviewValue:
    """The dynamic regret of preview RHC against the number k of previewed disturbances (see the module doc).

    The fit uses the points whose excess is above ``fit_above`` times the largest (below it the excess
    is rounding).

    Parameters
    ----------
    system, cost : a linear-quadratic problem.
    M : the horizon of Algorithm 1.
    ks : the numbers of previewed disturbances, 0 <= k <= M.
    w : (L, n) the disturbances.
    T : the number of steps.
    x0 : the initial state (default 0).
    fit_above : the relative excess below which points are left out of the fit.

    Returns
    -------
    PreviewValue
        the regrets and excesses per k, the fitted rate and ρ(A − BK_LQR)².

    Raises
    ------
    orrc.OrrcValueError
        When ks are out of range or the problem is not linear-quadratic.

    Examples
    --------
    >>> import orrc
    >>> from orrc import comparison
    >>> ex = orrc.examples.scalar_unstable()
    >>> w = orrc.disturbances.uniform_ball(30, 1, 1.0, seed=0)
    >>> value = comparison.preview_value(ex.system, ex.cost, 6, [0, 1, 2, 3, 6], w, T=20)
    >>> value.regret.round(2)
    array([25.3 ,  3.87,  0.61,  0.13,  0.04])
    """
    from .controllers import LQR, Clairvoyant, PreviewRHC
    from .simulate import simulate

    M = as_int("M", M, minimum=1)
    if isinstance(ks, (str, bytes)) or not hasattr(ks, "__iter__"):
        raise OrrcValueError(f"ks must be a list of preview lengths (integers); got {ks!r}")
    ks = np.array([as_int(f"ks[{i}]", k, minimum=0) for i, k in enumerate(ks)], dtype=int)
    if ks.size < 3 or ks.max() > M:
        raise OrrcValueError(f"ks must hold at least 3 preview lengths between 0 and M = {M}; got {list(ks)}")
    check_problem(system, cost)
    x0 = np.zeros(system.n) if x0 is None else as_array("x0", x0, (system.n,))
    fit_above = as_float("fit_above", fit_above, minimum=0.0)
    clair = simulate(system, Clairvoyant(system, cost, T), x0, w, T).costs.sum()

    def regret(k):
        return simulate(system, PreviewRHC(system, cost, M, preview_w=int(k)), x0, w, T).costs.sum() - clair

    reg = np.array([regret(k) for k in ks])
    excess = reg - regret(M)
    use = excess > fit_above * excess.max()
    slope, icpt = np.polyfit(ks[use], np.log(excess[use]), 1)
    resid = np.log(excess[use]) - (slope * ks[use] + icpt)
    tot = np.sum((np.log(excess[use]) - np.log(excess[use]).mean()) ** 2)
    lqr = LQR(system, cost)
    A, B = (system.A, system.B) if hasattr(system, "A") else system.linearize()
    lambda_K = float(np.max(np.abs(np.linalg.eigvals(A - B @ lqr.K))))
    return PreviewValue(ks, reg, excess, float(np.exp(slope)), float(1 - resid @ resid / tot), lambda_K ** 2, M)
