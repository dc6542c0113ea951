"""Figures of the comparison chapter.

* :func:`metric_bars` -- one metric (total cost, attenuation ratio, R^p_T(γ), dynamic regret, worst
  cases) for every controller, as horizontal bars (a rows list of :func:`orrc.comparison.compare`);
* :func:`preview_decay` -- the dynamic regret of preview RHC against k, with its exponential fit and
  the rate λ_K² of the literature, λ_K the spectral radius of A − BK (:func:`orrc.comparison.preview_value`);
* :func:`running_cost` -- Σ_{s<=t} c_s of several trajectories against t (an explorer frame).
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .._validate import OrrcValueError
from .figures import legend_below
from .style import _figure, _nonempty_dict, _trajs, controller_color

__all__ = ["metric_bars", "preview_decay", "running_cost"]

_METRICS = {"cost": "total cost Σ c_t", "ratio": "attenuation ratio Σc / Σ‖w‖²",
            "regret_p": "R^p_T(γ)", "dynamic_regret": "dynamic regret",
            "worst_attenuation": "worst-case level γ*_T", "worst_regret": "worst-case regret (‖w‖ ≤ 1)"}


def metric_bars(rows, metric: str, title: str | None = None, log: bool | None = None) -> Figure:
    """Horizontal bars of one field of :class:`orrc.comparison.ComparisonRow` per controller, values printed.

    Parameters
    ----------
    rows : list of ComparisonRow
        From :func:`orrc.comparison.compare`; rows whose value is None (not a linear loop) are left out.
    metric : str
        "cost", "ratio", "regret_p", "dynamic_regret", "worst_attenuation" or "worst_regret".
    title : str, optional
        The axes' title.
    log : bool, optional
        A logarithmic axis. Default (None): logarithmic when every value is >= 0 and the positive ones
        span more than two decades, so that the smallest bars stay visible. On a logarithmic axis a
        value <= 0 (the clairvoyant optimum's zero regret) has no bar; its value is still printed.

    Returns
    -------
    Figure
        One bar per kept row, each with its value (3 significant digits) printed beside it.

    Examples
    --------
    >>> import orrc
    >>> from orrc.comparison import compare
    >>> ex = orrc.examples.scalar_unstable()
    >>> w = orrc.disturbances.uniform_ball(12, 1, 1.0, seed=0)
    >>> rows = compare(ex.system, ex.cost, {"LQR": orrc.LQR(ex.system, ex.cost)}, w,
    ...                10, 1.0)
    >>> fig = metric_bars(rows, "cost")
    """
    from ..comparison import ComparisonRow

    if metric not in _METRICS:
        raise OrrcValueError(f"metric must be one of {sorted(_METRICS)}; got {metric!r}")
    if not isinstance(rows, (list, tuple)) or not rows or not all(isinstance(r, ComparisonRow) for r in rows):
        raise OrrcValueError("rows must be a non-empty list of orrc.comparison.ComparisonRow (from compare)")
    kept = [r for r in rows if getattr(r, metric) is not None]
    if not kept:
        raise OrrcValueError(f"no row has a value for {metric!r}")
    vals = np.array([float(getattr(r, metric)) for r in kept])
    positive = vals[vals > 0]
    if log is None:
        log = bool(np.all(vals >= 0) and positive.size and positive.max() > 100 * positive.min())
    fig, axes = _figure(width=7.0, height=0.45 * len(kept) + 1.2)
    ax = axes[0, 0]
    y = np.arange(len(kept))[::-1]
    if log and positive.size:
        ax.set_xscale("log")
        floor = positive.min() / 10   # bars start here; a value <= 0 gets no bar, only its label
        bars = ax.barh(y, np.where(vals > 0, vals - floor, 0.0), left=floor,
                       color=[controller_color(r.name, i) for i, r in enumerate(kept)])
        ax.set_xlim(floor, positive.max() * 30)
    else:
        bars = ax.barh(y, vals, color=[controller_color(r.name, i) for i, r in enumerate(kept)])
        ax.axvline(0.0, color="0.3", linewidth=0.8)
        span = max(np.abs(vals).max(), 1e-300)
        ax.set_xlim(min(0.0, vals.min() * 1.3), max(0.0, vals.max()) + 0.3 * span)
    ax.bar_label(bars, labels=[f"{v:.3g}" for v in vals], padding=3, fontsize=9)
    ax.set_yticks(y, [r.name for r in kept], fontsize=9)
    # flush right: under the bars, never past the figure's edge when the names take most of a
    # phone's width
    ax.set_xlabel(_METRICS[metric] + (" (log scale)" if log and positive.size else ""), loc="right")
    if title:
        ax.set_title(title, fontsize=10)
    return fig


def preview_decay(pv, title: str | None = None) -> Figure:
    """The value of preview: the excess dynamic regret of preview RHC with k previewed disturbances
    over full preview, regret(k) − regret(M), against k on a log scale (dots), with the fitted
    C r^k (line) and the rate λ_K^{2k} of the literature, λ_K the spectral radius of A − BK
    (dashed, through the first point).

    Parameters
    ----------
    pv : :class:`orrc.comparison.PreviewValue`
        From :func:`orrc.comparison.preview_value`.
    title : str, optional
        The axes' title.

    Returns
    -------
    Figure
        One panel on a log scale, its legend below it.

    Examples
    --------
    >>> import orrc
    >>> from orrc import comparison
    >>> from orrc.viz import comparison_plots
    >>> ex = orrc.examples.scalar_unstable()
    >>> w = orrc.disturbances.uniform_ball(30, 1, 1.0, seed=0)
    >>> pv = comparison.preview_value(ex.system, ex.cost, 6, [0, 1, 2, 3, 6], w, T=20)
    >>> fig = comparison_plots.preview_decay(pv, title="scalar system")
    >>> fig.axes[0].get_yscale(), fig.axes[0].get_xlabel()
    ('log', 'previewed disturbances k')
    """
    from ..comparison import PreviewValue

    if not isinstance(pv, PreviewValue):
        raise OrrcValueError(f"pv must be an orrc.comparison.PreviewValue; got {type(pv).__name__}")
    fig, axes = _figure(width=6.5, height=3.4)
    ax = axes[0, 0]
    ok = pv.excess > 0
    ax.semilogy(pv.ks[ok], pv.excess[ok], "o", color="tab:blue", label="dynamic regret, minus its value at k = M")
    k0 = pv.ks[ok][0]
    c0 = pv.excess[ok][0]
    ax.semilogy(pv.ks, c0 * pv.rate ** (pv.ks - k0), "-", color="tab:blue",
                label=f"fit C·r^k, r = {pv.rate:.3g} (R² = {pv.r2:.3f})")
    ax.semilogy(pv.ks, c0 * pv.lambda_K_sq ** (pv.ks - k0), "--", color="black",
                label=f"$\\lambda_K^{{2k}}$, $\\lambda_K^2$ = {pv.lambda_K_sq:.3g}")
    ax.set_xlabel("previewed disturbances k")
    ax.set_ylabel("excess dynamic regret")
    legend_below(ax, fontsize=9)   # clear of the data
    if title:
        ax.set_title(title, fontsize=10)
    return fig


def running_cost(trajs: dict, title: str | None = None, fast: bool = False) -> Figure:
    """The running cost Σ_{s<=t} c_s against t, one curve per trajectory (the clairvoyant optimum
    dashed): the quantity whose final value the comparisons rank.

    Parameters
    ----------
    trajs : dict
        Label -> :class:`orrc.Trajectory`; a label's colour follows
        :func:`orrc.viz.plots.controller_color`.
    title : str, optional
        The axes' title.
    fast : bool
        A fixed layout instead of the constrained one (for explorer frames drawn many times).

    Returns
    -------
    Figure
        One panel, the legend under it.

    Examples
    --------
    >>> import orrc
    >>> from orrc.viz import comparison_plots
    >>> ex = orrc.examples.scalar_unstable()
    >>> w = orrc.disturbances.uniform_ball(20, 1, 1.0, seed=0)
    >>> runs = {"LQR": orrc.simulate(ex.system, orrc.LQR(ex.system, ex.cost), ex.x0, w,
    ...                              T=20),
    ...         "clairvoyant optimum": orrc.simulate(ex.system,
    ...                                              orrc.Clairvoyant(ex.system, ex.cost,
    ...                                                               T=20), ex.x0,
    ...                                              w, T=20)}
    >>> fig = comparison_plots.running_cost(runs, title="i.i.d.")
    >>> [line.get_linestyle() for line in fig.axes[0].get_lines()]
    ['-', '--']
    """
    trajs = _trajs(_nonempty_dict("trajs", trajs, "Trajectory"))
    fig, axes = _figure(width=6.5, height=3.4, fast=fast, margins={"left": 0.12, "bottom": 0.15})
    ax = axes[0, 0]
    for i, (label, tr) in enumerate(trajs.items()):
        ax.plot(np.arange(1, tr.T + 1), np.cumsum(tr.costs), color=controller_color(label, i), label=label,
                linestyle="--" if "clairvoyant" in label.lower() else "-")
    ax.set_xlabel("$t$")
    ax.set_ylabel(r"$\sum_{s \leq t} c_s$")
    # under the axes: inside, it covers the curves that rise fastest (a phone's narrow figure most)
    legend_below(ax, fontsize=9, ncol=min(len(trajs), 3))
    if title:
        ax.set_title(title, fontsize=10)
    return fig
