"""Figures of the min-max chapter (Algorithm 3, Lemma 6, Theorem 3; Appendix D of the paper).

Every function takes the data it draws (plans of :class:`~orrc.MinMaxRHC`, constants of
:func:`orrc.certify.minmax_constants`, margins of :mod:`orrc.checks.nopreview`, trajectories) and
returns a :class:`matplotlib.figure.Figure`, built without pyplot; none of them solves anything.

* :func:`bounds_history` -- the lower and upper bounds of scenario exchange, iteration by iteration;
* :func:`minmax_pareto` -- the certified pairs (ᾱ_W, γ̄_W), the lower curve of exact samples, the
  chosen pair and the paper's γ̄_W = γ̄ M;
* :func:`lemma6_check` -- V_{W,M} between its bounds and its increments under Lemma 6's bound;
* :func:`theorem3_growth` -- the cumulative cost under Theorem 3's bound γ T max‖w‖² + C_T, beside γ Σ‖w_t‖²;
* :func:`controller_costs` -- total costs of several controllers under several disturbances (bars);
* :func:`minmax_frame` -- an explorer frame over (M, size of W): the closed-loop costs of the
  controllers and the per-step value with its certified upper bound.

The figures of Lemma 6 and Theorem 3 live in :mod:`orrc.viz.lemma6_plots`; this module gathers them.
"""
from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from .._validate import OrrcValueError, as_array, as_float, as_int
from ..certify import Constants, MinMaxConstants
from ..solvers.minmax import MinMaxPlan
from .lemma6_plots import _legend_below, lemma6_check, theorem3_growth  # noqa: F401 (Lemma 6, Theorem 3)
from .style import _figure, _nonempty_dict, _trajs, controller_color
from .theory_plots import _message

__all__ = ["bounds_history", "minmax_pareto", "lemma6_check", "theorem3_growth", "controller_costs", "minmax_frame"]


def _plans(plans) -> dict:
    plans = _nonempty_dict("plans", plans, "MinMaxPlan")
    for k, p in plans.items():
        if not isinstance(p, MinMaxPlan):
            raise OrrcValueError(f"plans[{k!r}] must be a MinMaxPlan (MinMaxRHC.plan); got {type(p).__name__}")
        if p.history is None or len(p.history) == 0:
            raise OrrcValueError(f"plans[{k!r}] has no bound history (method {p.method!r}); use method='exchange' "
                                 "or 'exact'")
    return plans


def bounds_history(plans: dict, title: str | None = None) -> Figure:
    """The bounds on the min-max value V_{W,M}(x) of Algorithm 3 after each iteration of its solve
    (``plan.history``).

    Top: lower (dots) and upper (squares) bounds divided by the final value, one colour per plan.
    Bottom: the relative gap (upper − lower)/upper on a log scale (a gap of exactly 0 is drawn at
    1e-16). The panels are stacked (readable on a phone).

    Parameters
    ----------
    plans : dict label -> :class:`~orrc.solvers.minmax.MinMaxPlan` (from
        :meth:`orrc.MinMaxRHC.plan`).
    title : optional title above the panels.

    Returns
    -------
    matplotlib.figure.Figure
        Two panels, one above the other.

    Examples
    --------
    >>> import orrc
    >>> from orrc.viz import minmax_plots
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> W = orrc.Box(-0.5, 0.5, n=1)
    >>> plan = orrc.MinMaxRHC(ex.system, ex.cost, 6, W).plan([1.0])
    >>> fig = minmax_plots.bounds_history({"box ±0.5": plan})
    >>> len(fig.axes), fig.axes[1].get_yscale()
    (2, 'log')
    """
    plans = _plans(plans)
    fig, axes = _figure(2, 1, width=6.4, height=7.6)
    ax, ax2 = axes[:, 0]
    for i, (label, p) in enumerate(plans.items()):
        h = np.asarray(p.history, float)
        it = np.arange(1, len(h) + 1)
        col = f"C{i}"
        ax.plot(it, h[:, 0] / p.value, color=col, marker="o", linestyle="-", label=f"{label}: lower")
        ax.plot(it, h[:, 1] / p.value, color=col, marker="s", linestyle="--", label=f"{label}: upper")
        gap = np.maximum((h[:, 1] - h[:, 0]) / np.abs(h[:, 1]), 1e-16)
        ax2.semilogy(it, gap, color=col, marker="o", label=label)
    ax.axhline(1.0, color="k", linewidth=0.7)
    ax.set_xlabel("iteration")
    ax.set_ylabel("bound / final value")
    ax.set_title("lower and upper bounds on $V_{W,M}(x)$", fontsize=10)
    _legend_below(ax, ncol=2, offset=-0.22)
    ax2.set_xlabel("iteration")
    ax2.set_ylabel("(upper - lower) / upper")
    ax2.set_title("relative gap", fontsize=10)
    _legend_below(ax2, ncol=2, offset=-0.22)
    for a in (ax, ax2):
        a.xaxis.get_major_locator().set_params(integer=True)
    if title:
        fig.suptitle(title, fontsize=11)
    return fig


def minmax_pareto(constants, preview=None, title: str | None = None) -> Figure:
    """The pairs (γ̄_W, ᾱ_W) of the class of Lemma 6, V_{W,M}(x) <= ᾱ_W σ(x) + γ̄_W max‖w‖², on log
    axes.

    Drawn: the curve of ``constants`` (certified, or sampled for an estimate), the lower curve of
    exact samples (``info["lower_pareto"]``, when present: the true curve lies between), the
    chosen pair (star), the horizon threshold ᾱ_W < α_lo √(M−1) (dotted) and, when ``preview``
    is given, the paper's pair (γ̄ M, ᾱ) (a cross) and the smallest admissible γ̄_W,
    V_{W,M}(0)/max‖w‖² (dashed vertical line).

    Parameters
    ----------
    constants : the :class:`~orrc.certify.MinMaxConstants` of
        :func:`orrc.certify.minmax_constants`.
    preview : optional :class:`~orrc.certify.Constants` of the preview problem at the same M
        (:func:`orrc.certify.lq_constants`).
    title : optional title.

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks
    >>> from orrc.viz import minmax_plots
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> W = orrc.Box(-0.5, 0.5, n=1)
    >>> k = certify.minmax_constants(ex.system, ex.cost, 6, W)
    >>> fig = minmax_plots.minmax_pareto(k,
    ...                                  preview=certify.lq_constants(ex.system,
    ...                                                               ex.cost, 6))
    >>> fig.axes[0].get_xscale(), fig.axes[0].get_yscale()
    ('log', 'log')
    """
    if not isinstance(constants, MinMaxConstants):
        raise OrrcValueError(f"constants must be orrc.certify.MinMaxConstants (minmax_constants); got "
                             f"{type(constants).__name__}")
    if preview is not None and not isinstance(preview, Constants):
        raise OrrcValueError(f"preview must be orrc.certify.Constants (lq_constants); got {type(preview).__name__}")
    c = constants
    fig, ax = _figure(width=7.0, height=4.2)
    ax = ax[0, 0]
    gb, ah = c.pareto[:, 0], c.pareto[:, 1]
    kind = "estimated (sampled)" if c.estimate else "certified"
    ax.loglog(gb, ah, color="tab:blue", linewidth=1.8, label=f"{kind}: admissible on or above")
    low = c.info.get("lower_pareto")
    if low is not None:
        ok = np.isfinite(low[:, 1])
        ax.loglog(low[ok, 0], low[ok, 1], color="tab:orange", linestyle="--", linewidth=1.4,
                  label="lower curve from exact $V_{W,M}$ at sampled $x$")
    thr = c.alpha_lo * math.sqrt(c.M - 1)
    ax.axhline(thr, color="tab:green", linestyle=":", linewidth=1.2,
               label=r"threshold $\underline{\alpha}\sqrt{M-1}$")
    ax.plot([c.gamma_bar], [c.alpha_hi], marker="*", markersize=13, color="tab:blue", markeredgecolor="k",
            linestyle="none", label=r"chosen pair (smallest $\gamma_{c,W}$)" if c.admissible else "knee")
    if "gamma_bar_W_min" in c.info:
        ax.axvline(c.info["gamma_bar_W_min"], color="0.4", linestyle="--", linewidth=1.0,
                   label=r"$V_{W,M}(0)/\max\|w\|^2$")
    if preview is not None:
        ax.plot([preview.gamma_bar * preview.M], [preview.alpha_hi], marker="X", markersize=10, color="tab:red",
                linestyle="none", label=r"the paper's $(\overline{\gamma} M, \overline{\alpha})$")
    from matplotlib.ticker import LogLocator, NullFormatter, ScalarFormatter

    ax.set_xlabel(r"$\overline{\gamma}_W$")
    ax.set_ylabel(r"$\overline{\alpha}_W$")
    ax.set_ylim(min(ah.min(), thr) / 1.3, 4.0 * max(ah.min(), thr))
    ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(ScalarFormatter())
    ax.yaxis.set_minor_formatter(NullFormatter())
    lo_x = min(gb.min(), preview.gamma_bar * preview.M if preview is not None else gb.min()) / 2.0
    ax.set_xlim(lo_x, min(gb.max(), 1e3 * max(c.gamma_bar, gb.min())))
    _legend_below(ax, ncol=2, offset=-0.18)
    ax.set_title(title or f"M = {c.M}: the pairs of the class of Lemma 6 ({kind})", fontsize=10)
    return fig


def controller_costs(costs: dict, title: str | None = None, ylabel: str = r"total cost $\sum_t c_t$") -> Figure:
    """Grouped bars of total costs, as in the comparisons of Algorithm 3 with the other controllers:
    one group per disturbance, one colour per controller, each bar with its value (3 significant
    digits) above it; on a log scale when the values span more than a decade, else on a linear
    one from zero.

    Parameters
    ----------
    costs : dict disturbance label -> {controller label: total cost >= 0}.
    title : optional title.
    ylabel : the value axis' label.

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> from orrc.viz import minmax_plots
    >>> costs = {"uniform in W": {"min-max RHC": 0.4, "LQR": 2.6},
    ...          "worst vertex sequence": {"min-max RHC": 9.0, "LQR": 11.0}}
    >>> fig = minmax_plots.controller_costs(costs, title="T = 30")
    >>> fig.axes[0].get_yscale(), sorted(t.get_text() for t in fig.axes[0].texts)
    ('log', ['0.4', '11', '2.6', '9'])
    """
    costs = _nonempty_dict("costs", costs, "dict of controller -> total cost")
    controllers = []
    for k, d in costs.items():
        d = _nonempty_dict(f"costs[{k!r}]", d, "total cost")
        for c, v in d.items():
            as_float(f"costs[{k!r}][{c!r}]", v, minimum=0.0)
            if c not in controllers:
                controllers.append(c)
    fig, ax = _figure(width=7.0, height=4.0)
    ax = ax[0, 0]
    width = 0.8 / len(controllers)
    top = 0.0
    for i, c in enumerate(controllers):
        xs = [j + (i - (len(controllers) - 1) / 2) * width for j in range(len(costs))]
        vals = [float(costs[k].get(c, np.nan)) for k in costs]
        bars = ax.bar(xs, vals, width=width * 0.95, color=controller_color(c, i), label=c)
        # each bar shows its value above it
        ax.bar_label(bars, labels=["" if np.isnan(v) else f"{v:.3g}" for v in vals], padding=2, fontsize=9)
        top = max([top] + [v for v in vals if np.isfinite(v)])
    ax.set_xticks(range(len(costs)))
    ax.set_xticklabels(list(costs), fontsize=9)
    positive = [v for d in costs.values() for v in map(float, d.values()) if v > 0]
    if positive and max(positive) > 10 * min(positive):
        # values over more than a decade: a log axis whose bottom lies below the smallest bar, so
        # that every bar shows (from an automatic bottom the smallest one could be a sliver)
        ax.set_yscale("log")
        ax.set_ylim(min(positive) / 3, top * 3)   # room for the values above the tallest bars
    else:
        # values of one order: bars from zero, whose heights compare at a glance
        ax.set_ylim(0.0, 1.15 * top if top > 0 else 1.0)
    ax.set_ylabel(ylabel)
    _legend_below(ax, ncol=2, offset=-0.14)
    if title:
        ax.set_title(title, fontsize=10)
    return fig


def minmax_frame(M: int, w_max: float, trajs: dict, bound=None, w_max_sq: float | None = None) -> Figure:
    """One frame of the min-max explorer for the horizon M and the size w_max of the box
    W = [−w_max, w_max]^n of Algorithm 3.

    Top: the cumulative cost of each closed loop, all under the same disturbance. Bottom: the
    min-max controller's value V^t_{W,M}(x_t) (the trajectory labelled with "min-max") with
    ``bound`` when given, else a message that no certified pair exists.

    Parameters
    ----------
    M : the horizon, >= 1.
    w_max : the half-width of the box W, >= 0.
    trajs : dict label -> :class:`~orrc.Trajectory`, all under the same disturbance.
    bound : optional (T,) upper bound on the value along the min-max run, e.g.
        ᾱ_W σ(x_t) + γ̄_W max‖w‖² (the ``bound`` of
        :func:`orrc.checks.minmax_value_bound_margins`).
    w_max_sq : optional max‖w‖² over W, named in the title.

    Returns
    -------
    matplotlib.figure.Figure
        Two panels, one above the other.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks
    >>> from orrc.viz import minmax_plots
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> W = orrc.Box(-0.5, 0.5, n=1)
    >>> k = certify.minmax_constants(ex.system, ex.cost, 6, W)
    >>> w = orrc.disturbances.uniform_box(40, 1, -0.5, 0.5, seed=0)
    >>> minmax = orrc.MinMaxRHC(ex.system, ex.cost, 6, W)
    >>> traj = orrc.simulate(ex.system, minmax, ex.x0, w, 30)
    >>> bound = checks.minmax_value_bound_margins(traj, 6, W, k.alpha_hi_W,
    ...                                           k.gamma_bar_W).bound
    >>> fig = minmax_plots.minmax_frame(6, 0.5, {"min-max RHC": traj}, bound=bound,
    ...                                 w_max_sq=0.25)
    >>> fig.texts[0].get_text()
    'M = 6, W = [-0.5, 0.5], max‖w‖² = 0.25'
    """
    M = as_int("M", M, minimum=1)
    w_max = as_float("w_max", w_max, minimum=0.0)
    trajs = _trajs(trajs)
    fig, axes = _figure(2, 1, width=6.4, height=7.4, fast=True,
                        margins={"bottom": 0.14, "top": 0.92, "hspace": 0.75, "left": 0.13, "right": 0.97})
    ax, ax2 = axes[:, 0]
    for i, (label, tr) in enumerate(trajs.items()):
        ax.plot(np.arange(1, tr.T + 1), np.cumsum(tr.costs), color=controller_color(label, i), linewidth=1.5,
                label=f"{label}: {tr.costs.sum():.3g}")
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel("$t$")
    ax.set_ylabel(r"$\sum_{s \leq t} c_s$")
    ax.set_title("cumulative cost (total in the legend)", fontsize=10)
    _legend_below(ax, ncol=2, offset=-0.22)
    mm = [tr for label, tr in trajs.items() if "min-max" in label.lower() and tr.values is not None]
    if not mm:
        _message(ax2, "no min-max trajectory with values")
    else:
        tr = mm[0]
        t = np.arange(tr.T)
        ax2.plot(t, tr.values, color="tab:blue", linewidth=1.6, label=r"$V^t_{W,M}(x_t)$")
        if bound is not None:
            bound = as_array("bound", bound, (tr.T,))
            ax2.plot(t, bound, color="tab:red", linewidth=1.2,
                     label=r"$\overline{\alpha}_W\sigma(x_t) + \overline{\gamma}_W\max\|w\|^2$")
        else:
            ax2.text(0.5, 0.9, "no certified pair at this M (below the threshold)", transform=ax2.transAxes,
                     ha="center", fontsize=9, color="tab:red")
        ax2.set_ylim(bottom=0.0)
        ax2.set_xlabel("$t$")
        ax2.set_title("the min-max value and its certified bound", fontsize=10)
        _legend_below(ax2, ncol=1, offset=-0.22)
    w = "" if w_max_sq is None else f", max‖w‖² = {as_float('w_max_sq', w_max_sq, minimum=0.0):.3g}"
    fig.suptitle(f"M = {M}, W = [-{w_max:g}, {w_max:g}]" + w, fontsize=11)
    return fig
