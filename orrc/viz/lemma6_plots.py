"""Figures of Lemma 6 (the min-max value as a Lyapunov function) and Theorem 3 (the attenuation of
Algorithm 3 against the largest possible disturbance), along trajectories of Algorithm 3.
Gathered with the other min-max figures in :mod:`orrc.viz.minmax_plots`.
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .._validate import OrrcValueError, as_float
from ..checks import Lemma1Margins, Margins
from ..simulate import Trajectory
from .style import _figure, _nonempty_dict
from .theory_plots import lemma1_check

__all__ = ["lemma6_check", "theorem3_growth"]


def _legend_below(ax, ncol: int = 2, offset: float = -0.2, **kw) -> None:
    """A frameless legend with 9 pt text centred under the axes (``offset``: its top, in axes fractions)."""
    ax.legend(fontsize=9, loc="upper center", bbox_to_anchor=(0.5, offset), ncol=ncol, frameon=False, **kw)


def lemma6_check(lemma6, value_bound=None, title: str | None = None, fast: bool = False) -> Figure:
    """Lemma 6 along a trajectory of Algorithm 3: the min-max value V^t_{W,M}(x_t) between its
    bounds, and its increments under Lemma 6's bound.

    Top: V^t_{W,M}(x_t) with its lower bound α_lo σ(x_t) and, when ``value_bound`` is given, the
    upper bound ᾱ_W σ(x_t) + γ̄_W max‖w‖² (log scale). Bottom: the increments V^{t+1} − V^t and
    the bound Γ_{W,V} σ(x_t) + Γ^γ_{W,V} max‖w‖² (symmetric log scale). The title gives the
    smallest margin. The figure of Lemma 1 (:func:`orrc.viz.theory_plots.lemma1_check`) with
    Lemma 6's labels, stacked.

    Parameters
    ----------
    lemma6 : the margins of :func:`orrc.checks.lemma6_margins`.
    value_bound : optional margins of :func:`orrc.checks.minmax_value_bound_margins`.
    title : optional title above the panels.
    fast : fixed margins instead of the constrained layout (for explorer frames).

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
    >>> lemma6 = checks.lemma6_margins(traj, 6, W, k.alpha_lo, k.alpha_hi_W, k.gamma_bar_W)
    >>> bound = checks.minmax_value_bound_margins(traj, 6, W, k.alpha_hi_W, k.gamma_bar_W)
    >>> fig = minmax_plots.lemma6_check(lemma6, bound, title="scalar system, M = 6")
    >>> len(fig.axes)
    2
    """
    if not isinstance(lemma6, Lemma1Margins):
        raise OrrcValueError(f"lemma6 must be the result of orrc.checks.lemma6_margins; got {type(lemma6).__name__}")
    return lemma1_check(lemma6, value_bound, title=title, fast=fast, stacked=True, labels={
        "value": r"$V^t_{W,M}(x_t)$",
        "upper": r"$\overline{\alpha}_W\sigma(x_t) + \overline{\gamma}_W\max\|w\|^2$",
        "bound": r"bound $\Gamma_{W,V}\sigma(x_t) + \Gamma^\gamma_{W,V}\max\|w\|^2$",
        "increment": r"$V^{t+1}_{W,M} - V^t_{W,M}$",
        "Gamma": r"\Gamma_{W,V}",
        "Gamma_gamma": r"\Gamma^\gamma_{W,V}"})


def theorem3_growth(runs: dict, gamma: float, w_max_sq: float, title: str | None = None) -> Figure:
    """Theorem 3 along trajectories of Algorithm 3: the cumulative cost against what the theorem
    allows.

    For each run, one colour: the cumulative cost Σ_{t<T} c_t (solid), Theorem 3's bound on it,
    C_T + γ T max‖w‖² (dashed), and γ Σ_{t<T} ‖w_t‖², the same level applied to the realised
    disturbance energy (dotted: what a guarantee in terms of the realised energy would allow;
    Theorem 3 does not give one). Log scale.

    Parameters
    ----------
    runs : dict label -> (:class:`~orrc.Trajectory`, :class:`~orrc.checks.Margins` of
        :func:`orrc.checks.theorem3_margin` at the level ``gamma``).
    gamma : the level γ of the margins (e.g. γ_{c,W}).
    w_max_sq : max‖w‖² over W.
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
    >>> w = orrc.disturbances.uniform_box(40, 1, -0.5, 0.5, seed=0)
    >>> minmax = orrc.MinMaxRHC(ex.system, ex.cost, 6, W)
    >>> traj = orrc.simulate(ex.system, minmax, ex.x0, w, 30)
    >>> m = checks.theorem3_margin(traj, 6, W, k.a, k.alpha_lo, k.alpha_hi_W, k.gamma_bar_W,
    ...                            k.gamma_c_W)
    >>> fig = minmax_plots.theorem3_growth({"uniform in W": (traj, m)}, k.gamma_c_W,
    ...                                    W.max_norm_sq)
    >>> fig.axes[0].get_yscale()
    'log'
    """
    runs = _nonempty_dict("runs", runs, "(Trajectory, Margins)")
    gamma = as_float("gamma", gamma, minimum=0.0)
    w_max_sq = as_float("w_max_sq", w_max_sq, minimum=0.0)
    from matplotlib.lines import Line2D

    fig, ax = _figure(width=7.0, height=4.4)
    ax = ax[0, 0]
    handles = []
    for i, (label, run) in enumerate(runs.items()):
        if not (isinstance(run, tuple) and len(run) == 2 and isinstance(run[0], Trajectory)
                and isinstance(run[1], Margins)):
            raise OrrcValueError(f"runs[{label!r}] must be a pair (Trajectory, Margins of theorem3_margin)")
        tr, m = run
        if len(m.t) != tr.T:
            raise OrrcValueError(f"runs[{label!r}]: the margins have {len(m.t)} steps, the trajectory {tr.T}")
        col = f"C{i}"
        T = m.t.astype(float)
        positive = lambda v: np.where(v > 0, v, np.nan)  # noqa: E731  (log scale: zeros left out)
        ax.plot(T, positive(np.cumsum(tr.costs)), color=col, linewidth=1.8)
        ax.plot(T, positive(m.bound + gamma * T * w_max_sq), color=col, linestyle="--", linewidth=1.2)
        ax.plot(T, positive(gamma * np.cumsum(np.einsum("ij,ij->i", tr.w, tr.w))), color=col, linestyle=":",
                linewidth=1.4)
        handles.append(Line2D([], [], color=col, linewidth=1.8, label=label))
    handles += [Line2D([], [], color="k", linewidth=1.8, label=r"$\sum_{t<T} c_t$"),
                Line2D([], [], color="k", linestyle="--", linewidth=1.2,
                       label=r"Theorem 3: $C_T + \gamma\, T \max\|w\|^2$"),
                Line2D([], [], color="k", linestyle=":", linewidth=1.4,
                       label=r"$\gamma \sum_{t<T}\|w_t\|^2$ (not a bound)")]
    ax.set_yscale("log")
    ax.set_xlabel("$T$")
    _legend_below(ax, ncol=2, offset=-0.16, handles=handles)
    ax.set_title(title or f"Theorem 3 at $\\gamma = \\gamma_{{c,W}} = {gamma:.4g}$", fontsize=10)
    return fig
