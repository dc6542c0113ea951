"""Figures of Theorem 2 (Algorithm 2's regret): the bound's parts against T, the cost of not
knowing θ, and the exploration trade-off Δ(N, T) with the best estimation length N against T.
Gathered with the other unknown-system figures in :mod:`orrc.viz.unknown_plots`.
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .._validate import OrrcValueError, as_array
from ..tradeoff import Tradeoff
from ._unknown_common import _COLORS, _decade, _dict, _fig, _style


__all__ = ["theorem2_parts", "excess_vs_T", "tradeoff_curves", "best_N"]


def _check_tradeoff(tradeoff) -> None:
    """An OrrcValueError unless ``tradeoff`` is what :func:`orrc.tradeoff.exploration_tradeoff` returns."""
    if not isinstance(tradeoff, Tradeoff):
        raise OrrcValueError(f"tradeoff must be an orrc.tradeoff.Tradeoff; got {type(tradeoff).__name__}")


def theorem2_parts(Ts, parts: dict, actual, title: str | None = None) -> Figure:
    """Theorem 2's bound on R^p_T(γ) split into its parts (estimation, known system, model error),
    their sum, and the actual R^p_T(γ), against T on a symmetric log axis.

    Parameters
    ----------
    Ts : (k,) the lengths T.
    parts : dict label -> (k,) one part of the bound against ``Ts``.
    actual : (k,) the measured R^p_T(γ).
    title : optional title.

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.viz import unknown_plots
    >>> T = np.arange(10, 60, 10)
    >>> parts = {"estimation (O(N))": np.full(5, 40.0), "model error": 0.5 * T}
    >>> fig = unknown_plots.theorem2_parts(T, parts, actual=0.1 * T)
    >>> fig.axes[0].get_xlabel()
    'T'
    """
    Ts = as_array("Ts", Ts, ndim=1)
    parts = _dict("parts", parts)
    actual = as_array("actual", actual, (Ts.size,))
    fig, (ax,) = _fig(1, 4.6)
    total = np.zeros(Ts.size)
    for i, (label, y) in enumerate(parts.items()):
        y = as_array(f"parts[{label!r}]", y, (Ts.size,))
        total = total + y
        ax.plot(Ts, y, color=_COLORS[i % 8], lw=1.2, ls="--", label=label)
    ax.plot(Ts, total, color="tab:red", lw=1.6, label="bound (sum)")
    ax.plot(Ts, actual, color="black", lw=1.4, label=r"$R^p_T(\gamma)$")
    ax.set_yscale("symlog", linthresh=_decade(np.concatenate([total, actual]), 0.05), linscale=1.5)
    _style(ax, "T", None, title, loc="below")
    return fig


def excess_vs_T(curves: dict, T: int | None = None, title: str | None = None, fast: bool = False) -> Figure:
    """The cost of not knowing θ, Σ_{t<T} (c_t − c_t^known), against T for several runs (e.g. one
    per estimation length N of Algorithm 2).

    Parameters
    ----------
    curves : dict label -> (L,) cumulative excess cost.
    T : optional last T drawn (the whole curves by default).
    title : optional title.
    fast : fixed margins instead of the constrained layout (for explorer frames).

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.viz import unknown_plots
    >>> t = np.arange(100)
    >>> fig = unknown_plots.excess_vs_T({"N = 10": 0.5 * t, "N = 40": 10 + 0.1 * t}, T=80)
    >>> len(fig.axes[0].get_lines()) >= 2
    True
    """
    curves = _dict("curves", curves)
    fig, (ax,) = _fig(1, 3.6, fast)
    for i, (label, y) in enumerate(curves.items()):
        y = as_array(f"curves[{label!r}]", y, ndim=1)
        L = y.size if T is None else min(int(T), y.size)
        ax.plot(np.arange(1, L + 1), y[:L], color=_COLORS[i % 8], lw=1.4, label=label)
    _style(ax, "T", r"$\sum_{t<T}\,(c_t - c_t^{\rm known})$", title, loc="upper left")
    return fig


def tradeoff_curves(tradeoff, Ts, title: str | None = None) -> Figure:
    """The exploration trade-off Δ(N, T) of Theorem 2 against the estimation length N, on log-log
    axes, for each T: the measured seed means (dots), the fitted curve (line) and its minimiser
    (star); the raw minimiser is the lowest dot.

    Parameters
    ----------
    tradeoff : the :class:`orrc.tradeoff.Tradeoff` of :func:`orrc.tradeoff.exploration_tradeoff`.
    Ts : the lengths T, one curve each.
    title : optional title.

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> import orrc
    >>> from orrc import tradeoff
    >>> from orrc.viz import unknown_plots
    >>> di = orrc.examples.double_integrator()
    >>> study = tradeoff.exploration_tradeoff(di.system, orrc.ParametricSystem.linear(2, 1),
    ...                                       di.cost, M=5, Ns=[3, 6, 12], seeds=2,
    ...                                       window=30, backend="serial")
    >>> fig = unknown_plots.tradeoff_curves(study, [100, 1000])
    >>> fig.axes[0].get_xscale(), fig.axes[0].get_yscale()
    ('log', 'log')
    """
    _check_tradeoff(tradeoff)
    Ts = as_array("Ts", Ts, ndim=1)
    fig, (ax,) = _fig(1, 4.8)   # the legend below the axes
    grid = np.geomspace(tradeoff.Ns[0], tradeoff.Ns[-1], 300)
    best = tradeoff.best_N(Ts)
    for i, (T, b) in enumerate(zip(Ts, best)):
        c = _COLORS[i % 8]
        ax.loglog(tradeoff.Ns, tradeoff.excess(T), "o", ms=4, color=c)
        ax.loglog(grid, tradeoff.fitted_excess(grid, T), color=c, lw=1.2, label=f"T = {T:,.0f}")
        ax.loglog([b], tradeoff.fitted_excess(np.array([b]), T), "*", ms=12, color=c, mec="black")
    _style(ax, "N (exciting steps)", r"$\Delta(N, T)$", title, loc="below")
    return fig


def best_N(tradeoff, Ts, title: str | None = None) -> Figure:
    """The best estimation length N against T, on log-log axes: the fitted curve's minimisers with
    their fitted slope, the raw minimisers over the grid of N, and a line of the slope 2/3 of the
    remark after Theorem 2 through the first point.

    Parameters
    ----------
    tradeoff : the :class:`orrc.tradeoff.Tradeoff` of :func:`orrc.tradeoff.exploration_tradeoff`.
    Ts : the lengths T.
    title : optional title.

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> import orrc
    >>> from orrc import tradeoff
    >>> from orrc.viz import unknown_plots
    >>> di = orrc.examples.double_integrator()
    >>> study = tradeoff.exploration_tradeoff(di.system, orrc.ParametricSystem.linear(2, 1),
    ...                                       di.cost, M=5, Ns=[3, 6, 12], seeds=2,
    ...                                       window=30, backend="serial")
    >>> fig = unknown_plots.best_N(study, [100, 300, 1000])
    >>> fig.axes[0].get_xlabel()
    'T'
    """
    _check_tradeoff(tradeoff)
    Ts = as_array("Ts", Ts, ndim=1)
    b = tradeoff.best_N(Ts)
    raw = tradeoff.best_N(Ts, fitted=False)
    slope = tradeoff.slope(Ts)
    fig, (ax,) = _fig(1, 4.4)   # the legend below the axes
    ax.loglog(Ts, b, "o-", color="tab:blue", ms=5, label=f"best N (fitted curve), slope {slope:.2f}")
    ax.loglog(Ts, raw, "s", color="tab:orange", ms=5, mfc="none", label="best N on the grid (raw)")
    ax.loglog(Ts, b[0] * (Ts / Ts[0]) ** (2 / 3), color="0.3", ls="--", label="slope 2/3")
    _style(ax, "T", "best N", title, loc="below")
    return fig
