"""Figures of the first chapters (the problem, Algorithm 1).

Every function takes the data it draws (trajectories from :func:`orrc.simulate`,
arrays of totals, LQ preview laws) and returns a :class:`matplotlib.figure.Figure`.
The computations behind the curves are ``orrc``'s own (:func:`orrc.attenuation_regret`,
:func:`orrc.attenuation_ratio`, ...), so a figure cannot disagree with the package.

The figures are created without ``pyplot`` (no global figure state): a figure is
shown in a notebook when it is the value of a cell (with ``%matplotlib inline``),
and it can be handed to :func:`orrc.viz.explore` as a frame.
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .._validate import OrrcValueError, as_array, as_int
from ..metrics import attenuation_ratio, attenuation_regret
from .figures import legend_below
from .rhc_plots import cost_vs_horizon, preview_gains, rhc_frame, solver_effort  # noqa: F401 (Algorithm 1)
from .style import (FONT, WIDTH, _axes, _figure, _gammas, _nonempty_dict, _style, _trajs,  # noqa: F401
                    controller_color)
from .tables import Table, table  # noqa: F401 (the table of the first chapters, kept here)

__all__ = [
    "controller_color", "information_pattern", "cost_overview", "running_regret", "cost_vs_energy",
    "preview_gains", "cost_vs_horizon", "disturbance_panel", "rhc_frame", "solver_effort",
    "table", "Table",
]


def information_pattern(t: int, M_w: int, M_c: int, T: int) -> Figure:
    """What a controller knows at step t, the information pattern of Eq. (2): x_{1:t}, u_{1:t-1},
    w_{1:t+M_w-1} and c_{1:t+M_c-1}, drawn as filled cells on a time line 1..T.

    Parameters
    ----------
    t : the current step, 1 <= t <= T.
    M_w : how many disturbances ahead the controller sees (its preview of w), >= 0.
    M_c : how many stage costs ahead it sees, >= 0.
    T : the length of the time line, >= 2.

    Returns
    -------
    matplotlib.figure.Figure
        One panel: a row of cells per kind of information (states, inputs, disturbances, costs),
        filled where known at t, and a dotted line at t.

    Examples
    --------
    >>> from orrc.viz import plots
    >>> fig = plots.information_pattern(t=4, M_w=3, M_c=3, T=10)
    >>> len(fig.axes), fig.axes[0].get_xlabel()
    (1, 'time step')
    """
    T = as_int("T", T, minimum=2)
    t = as_int("t", t, minimum=1)
    if t > T:
        raise OrrcValueError(f"t must be between 1 and T={T}; got {t}")
    M_w = as_int("M_w", M_w, minimum=0)
    M_c = as_int("M_c", M_c, minimum=0)
    rows = [("states $x$", t, "tab:blue"), ("inputs $u$", t - 1, "tab:orange"),
            ("disturbances $w$", t + M_w - 1, "tab:red"), ("costs $c$", t + M_c - 1, "tab:green")]
    fig, ax = _figure(width=WIDTH, height=2.4)
    ax = ax[0, 0]
    for i, (name, last, colour) in enumerate(rows):
        y = len(rows) - 1 - i
        last = min(last, T)
        for s in range(1, T + 1):
            known = s <= last
            ax.add_patch(_rect(s - 0.45, y - 0.3, 0.9, 0.6, colour if known else "white", colour, 0.85 if known else 1.0))
        ax.text(0.2, y, name, ha="right", va="center", fontsize=10)
    ax.axvline(t, color="k", linewidth=1.0, linestyle=":")
    ax.text(t, len(rows) - 0.45, f"now: $t={t}$", ha="center", va="bottom", fontsize=9)
    ax.set_xlim(-3.2, T + 0.8)
    ax.set_ylim(-0.7, len(rows) + 0.1)
    ax.set_yticks([])
    ax.set_xticks(range(1, T + 1))
    if T > 8:  # every other label (and t's), so that they stay apart on a phone's width
        ax.set_xticklabels([str(s) if s % 2 == 1 or s == t else "" for s in range(1, T + 1)])
    ax.set_xlabel("time step")
    for side in ("left", "right", "top"):
        ax.spines[side].set_visible(False)
    ax.set_title(f"known at time $t={t}$ with preview $M_w={M_w}$, $M_c={M_c}$ (filled = known)", fontsize=10)
    return fig


def _rect(x, y, w, h, face, edge, alpha):
    from matplotlib.patches import Rectangle

    return Rectangle((x, y), w, h, facecolor=face, edgecolor=edge, alpha=alpha, linewidth=1.0)


def cost_overview(trajs: dict, state: int = 0, state_label: str | None = None, off_scale=(),
                  stacked: bool = False) -> Figure:
    """A closed loop at a glance: one state coordinate x_t[state] against t, and the cumulative cost
    Σ_{s<=t} c_s(x_s, u_s) of Eq. (2) against t, one curve per trajectory.

    Parameters
    ----------
    trajs : dict label -> :class:`orrc.Trajectory` (a label's colour follows
        :func:`controller_color`).
    state : the state coordinate drawn in the first panel.
    state_label : the first panel's axis label (default ``state $x_t[state]$``).
    off_scale : labels of trajectories (e.g. an unstable open loop) that are drawn but ignored
        when the axis limits are chosen, so they leave the picture instead of flattening the others.
    stacked : the panels one above the other (narrow: for phones) instead of side by side.

    Returns
    -------
    matplotlib.figure.Figure
        Two panels: the state, and the cumulative cost with the legend below it.

    Examples
    --------
    >>> import orrc
    >>> from orrc.viz import plots
    >>> ex = orrc.examples.scalar_unstable()
    >>> w = orrc.disturbances.uniform_ball(20, 1, 0.5, seed=0)
    >>> runs = {"LQR": orrc.simulate(ex.system, orrc.LQR(ex.system, ex.cost), ex.x0, w,
    ...                              T=20),
    ...         "preview RHC": orrc.simulate(ex.system,
    ...                                      orrc.PreviewRHC(ex.system, ex.cost, M=5),
    ...                                      ex.x0, w, T=20)}
    >>> fig = plots.cost_overview(runs)
    >>> [ax.get_xlabel() for ax in fig.axes[:2]]
    ['time step $t$', 'time step $t$']
    """
    trajs = _trajs(trajs)
    first = next(iter(trajs.values()))
    state = as_int("state", state, minimum=0)
    if state >= first.x.shape[1]:
        raise OrrcValueError(f"state must index a state coordinate (0..{first.x.shape[1] - 1}); got {state}")
    off_scale = tuple(off_scale)
    for k in off_scale:
        if k not in trajs:
            raise OrrcValueError(f"off_scale label {k!r} is not among the trajectories {list(trajs)}")
    if len(off_scale) == len(trajs):
        raise OrrcValueError("off_scale cannot list every trajectory: at least one must set the axis limits")
    fig, axes = _figure(2, 1, width=6.4, height=6.0) if stacked else _figure(1, 2)
    ax_x, ax_c = axes[:, 0] if stacked else axes[0]
    x_rng, c_rng = [np.inf, -np.inf], [np.inf, -np.inf]
    for i, (label, tr) in enumerate(trajs.items()):
        c = controller_color(label, i)
        cum = np.cumsum(tr.costs)
        name = label + (" (leaves the plot)" if label in off_scale else "")
        ax_x.plot(np.arange(tr.T + 1), tr.x[:, state], color=c, label=name, **_style(label))
        ax_c.plot(np.arange(1, tr.T + 1), cum, color=c, label=name, **_style(label))
        if label not in off_scale:
            x_rng = [min(x_rng[0], tr.x[:, state].min()), max(x_rng[1], tr.x[:, state].max())]
            c_rng = [min(c_rng[0], cum[cum > 0].min(initial=np.inf)), max(c_rng[1], cum.max())]
    if off_scale:
        pad = 0.08 * (x_rng[1] - x_rng[0] or 1.0)
        ax_x.set_ylim(x_rng[0] - pad, x_rng[1] + pad)
        ax_c.set_ylim(0.0, 1.1 * c_rng[1])
    ax_x.axhline(0.0, color="0.8", linewidth=0.8, zorder=0)
    ax_x.set_xlabel("time step $t$")
    ax_x.set_ylabel(state_label or f"state $x_t[{state}]$")
    ax_c.set_xlabel("time step $t$")
    ax_c.set_ylabel(r"cumulative cost $\sum_{s\leq t} c_s$")
    legend_below(ax_c, fontsize=FONT)   # long controller names: clear of the curves
    return fig


def running_regret(trajs: dict, gammas) -> Figure:
    """The running attenuation regret R^p_t(γ) = Σ_{s<=t} c_s − γ Σ_{s<=t} ‖w_s‖² of Eq. (2) (signed
    form) against t: one panel per trajectory, one curve per level γ.

    Each panel's title gives the trajectory's attenuation ratio Σ c_t / Σ ‖w_t‖²: the curves for a
    γ above it end below zero.

    Parameters
    ----------
    trajs : dict label -> :class:`orrc.Trajectory`, one panel each.
    gammas : the attenuation levels γ > 0, one curve each.

    Returns
    -------
    matplotlib.figure.Figure
        ``len(trajs)`` panels side by side, sharing the time axis.

    Examples
    --------
    >>> import orrc
    >>> from orrc.viz import plots
    >>> ex = orrc.examples.scalar_unstable()
    >>> w = orrc.disturbances.uniform_ball(20, 1, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, orrc.LQR(ex.system, ex.cost), ex.x0, w, T=20)
    >>> fig = plots.running_regret({"LQR": traj}, gammas=[1.0, 10.0])
    >>> len(fig.axes), len(fig.axes[0].get_lines())   # two curves and the zero line
    (1, 3)
    """
    trajs = _trajs(trajs)
    gammas = _gammas(gammas)
    fig, axes = _figure(1, len(trajs), height=3.3, sharex=True)
    colours = [f"C{k}" for k in range(len(gammas))]
    for ax, (label, tr) in zip(axes[0], trajs.items()):
        t = np.arange(1, tr.T + 1)
        for g, c in zip(gammas, colours):
            ax.plot(t, attenuation_regret(tr, g, cumulative=True), color=c, label=rf"$\gamma={g:g}$")
        ax.axhline(0.0, color="k", linewidth=0.8)
        ax.set_title(f"{label}\nratio $\\sum c/\\sum\\|w\\|^2$ = {attenuation_ratio(tr):.3g}", fontsize=10)
        ax.set_xlabel("$t$")
    axes[0, 0].set_ylabel(r"$R^p_t(\gamma)$")
    axes[0, -1].legend(fontsize=FONT, loc="best")
    return fig


def cost_vs_energy(energies, costs: dict, gammas=()) -> Figure:
    """Total cost Σ_t c_t against the disturbance energy Σ_t ‖w_t‖² on log-log axes (the two sides
    of the attenuation inequality of Eq. 2), one curve per controller, with the lines
    cost = γ · energy as reference.

    Parameters
    ----------
    energies : (k,) the disturbance energies, > 0.
    costs : dict label -> (k,) the controller's total costs, aligned with ``energies``.
    gammas : levels γ whose lines cost = γ · energy are drawn dotted (none by default).

    Returns
    -------
    matplotlib.figure.Figure
        One panel, logarithmic on both axes.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.viz import plots
    >>> energy = np.array([1.0, 10.0, 100.0])
    >>> fig = plots.cost_vs_energy(energy, {"LQR": 3 * energy}, gammas=[1.0, 10.0])
    >>> fig.axes[0].get_xscale(), fig.axes[0].get_yscale()
    ('log', 'log')
    """
    energies = as_array("energies", energies, ndim=1)
    if np.any(energies <= 0):
        raise OrrcValueError("energies must be positive (log axis); got a value <= 0")
    costs = _nonempty_dict("costs", costs, "array of totals")
    fig, ax = _figure(width=6.0, height=3.8)
    ax = ax[0, 0]
    for i, (label, c) in enumerate(costs.items()):
        c = as_array(f"costs[{label!r}]", c, (len(energies),))
        ax.plot(energies, c, marker="o", markersize=4, color=controller_color(label, i), label=label, **_style(label))
    e = np.array([energies.min(), energies.max()])
    for g in _gammas(gammas) if len(gammas) else []:
        ax.plot(e, g * e, color="0.6", linewidth=0.9, linestyle=":")
        ax.text(e[-1], g * e[-1], rf" $\gamma={g:g}$", fontsize=FONT, color="0.4", va="center")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(r"disturbance energy $\sum_t \|w_t\|^2$")
    ax.set_ylabel(r"total cost $\sum_t c_t$")
    ax.legend(fontsize=FONT, loc="upper left")
    return fig


def disturbance_panel(ws: dict, scales=None, T: int | None = None) -> Figure:
    """The disturbance sequences w_t of Eq. (1) side by side: the first coordinate w_t[0] and the
    norm ‖w_t‖ for each kind, and, when given, the scales s_t of a time-varying cost
    c_t = s_t xᵀQx + uᵀRu.

    Parameters
    ----------
    ws : dict label -> (L, n) disturbance array, one panel each.
    scales : optional (L,) cost scales s_t, drawn in a last panel on a log scale.
    T : optional number of steps to draw (all by default).

    Returns
    -------
    matplotlib.figure.Figure
        ``len(ws)`` panels, one more with ``scales``.

    Examples
    --------
    >>> import orrc
    >>> from orrc.viz import plots
    >>> ws = {"i.i.d.": orrc.disturbances.uniform_ball(30, 1, 1.0, seed=0),
    ...       "sinusoid": orrc.disturbances.sinusoid(30, 1, amplitude=1.0, period=10)}
    >>> fig = plots.disturbance_panel(ws, T=20)
    >>> [ax.get_title() for ax in fig.axes]
    ['i.i.d.', 'sinusoid']
    """
    ws = _nonempty_dict("ws", ws, "(L, n) disturbance array")
    k = len(ws) + (scales is not None)
    fig, axes = _figure(1, k, width=3.0 * k + 0.5, height=2.6)
    for ax, (label, w) in zip(axes[0], ws.items()):
        w = as_array(f"ws[{label!r}]", w, ndim=2)
        w = w[:T] if T else w
        t = np.arange(len(w))
        ax.plot(t, w[:, 0], color="tab:red", linewidth=1.0, label="$w_t[0]$")
        ax.plot(t, np.linalg.norm(w, axis=1), color="0.3", linewidth=0.8, label=r"$\|w_t\|$")
        ax.set_title(label, fontsize=10)
        ax.set_xlabel("$t$")
    axes[0, 0].legend(fontsize=FONT)
    if scales is not None:
        s = as_array("scales", scales, ndim=1)
        s = s[:T] if T else s
        ax = axes[0, -1]
        ax.step(np.arange(len(s)), s, where="post", color="tab:green")
        ax.set_yscale("log")
        ax.set_title("cost scale $s_t$", fontsize=10)
        ax.set_xlabel("$t$")
    return fig
