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

from .._validate import OrrcValueError, as_array, as_float, as_int
from ..metrics import attenuation_ratio, attenuation_regret
from .figures import legend_below
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


def preview_gains(laws: dict, K_ref=None) -> Figure:
    """The preview gains of the exact LQ law of Algorithm 1, u_t = −K x_t − Σ_j L_j w_{t+j}: the
    spectral norm ‖L_j‖ against the preview index j for each law, on a log scale.

    Parameters
    ----------
    laws : dict label -> ``LQPreviewLaw``, or a :class:`orrc.PreviewRHC` on the exact LQ path
        (linear system, quadratic cost, no bounds).
    K_ref : optional reference feedback gain (e.g. the infinite-horizon LQR gain); when given, a
        second panel shows ‖K_M − K_ref‖ against each law's horizon M.

    Returns
    -------
    matplotlib.figure.Figure
        One panel, or two with ``K_ref``.

    Examples
    --------
    >>> import orrc
    >>> from orrc.viz import plots
    >>> ex = orrc.examples.scalar_unstable()
    >>> laws = {f"M = {M}": orrc.PreviewRHC(ex.system, ex.cost, M=M) for M in (3, 6)}
    >>> fig = plots.preview_gains(laws)
    >>> fig.axes[0].get_xlabel()
    'preview index $j$ (gain on $w_{t+j}$)'
    """
    laws = _nonempty_dict("laws", laws, "LQPreviewLaw (or PreviewRHC)")
    items = []
    for label, law in laws.items():
        law = getattr(law, "law", law)
        if law is None or not hasattr(law, "L") or not hasattr(law, "K"):
            raise OrrcValueError(
                f"laws[{label!r}] must be an LQPreviewLaw or a PreviewRHC on the exact LQ path "
                "(linear system, quadratic cost, no bounds)")
        L = np.asarray(law.L).reshape(law.m, law.M, law.n).transpose(1, 0, 2)  # (M, m, n): L_j
        items.append((label, law, np.linalg.norm(L, ord=2, axis=(1, 2))))
    ncols = 2 if K_ref is not None else 1
    fig, axes = _figure(1, ncols, width=WIDTH if ncols > 1 else 5.0, height=3.4)
    ax = axes[0, 0]
    for i, (label, law, norms) in enumerate(items):
        j = np.arange(law.M)
        keep = norms > 0
        ax.semilogy(j[keep], norms[keep], marker=".", color=f"C{i}", label=label)
    ax.set_xlabel("preview index $j$ (gain on $w_{t+j}$)")
    ax.set_ylabel(r"$\|L_j\|$")
    ax.legend(fontsize=FONT)
    if K_ref is not None:
        K_ref = np.atleast_2d(as_array("K_ref", K_ref))
        ax2 = axes[0, 1]
        Ms = [law.M for _, law, _ in items]
        d = [np.linalg.norm(np.asarray(law.K) - K_ref, 2) for _, law, _ in items]
        ax2.semilogy(Ms, np.maximum(d, 1e-16), marker="o", color="tab:blue")
        ax2.set_xlabel("horizon $M$")
        ax2.set_ylabel(r"$\|K_M - K_{\mathrm{LQR}}\|$")
    return fig


def cost_vs_horizon(Ms, costs: dict, optimum: dict | None = None, baseline: dict | None = None) -> Figure:
    """Total closed-loop cost J_M of Algorithm 1 against the horizon M, and its relative excess
    over the clairvoyant optimum J*.

    Parameters
    ----------
    Ms : the horizons M >= 1.
    costs : dict label (e.g. a disturbance kind) -> the totals J_M, one per M in ``Ms``.
    optimum : optional dict label -> the clairvoyant optimum J* of the same problem; adds a
        second panel with the relative excess (J_M − J*)/J* on a log scale (a symmetric-log scale
        when some excess is <= 0, e.g. against a local NLP optimum).
    baseline : optional dict label -> another controller's total (e.g. LQR), its excess dashed.

    Returns
    -------
    matplotlib.figure.Figure
        The totals on a log scale with J* dotted; with ``optimum``, the excess beside them.

    Examples
    --------
    >>> from orrc.viz import plots
    >>> fig = plots.cost_vs_horizon([1, 2, 4], {"i.i.d.": [3.0, 2.2, 2.05]},
    ...                             optimum={"i.i.d.": 2.0}, baseline={"i.i.d.": 2.5})
    >>> len(fig.axes), fig.axes[1].get_yscale()
    (2, 'log')
    """
    Ms = [as_int("M", m, minimum=1) for m in Ms]
    costs = _nonempty_dict("costs", costs, "totals per M")
    ncols = 2 if optimum else 1
    fig, axes = _figure(1, ncols, width=WIDTH if ncols > 1 else 5.0, height=3.4)
    ax = axes[0, 0]
    excess = []
    for i, (label, c) in enumerate(costs.items()):
        c = as_array(f"costs[{label!r}]", c, (len(Ms),))
        col = f"C{i}"
        ax.plot(Ms, c, marker="o", markersize=4, color=col, label=label)
        if optimum and label in optimum:
            ax.axhline(optimum[label], color=col, linestyle=":", linewidth=1.0)
            J = float(optimum[label])
            axr = axes[0, 1]
            axr.plot(Ms, (c - J) / J, marker="o", markersize=4, color=col, label=label)
            excess.extend((c - J) / J)
            if baseline and label in baseline:
                axr.axhline((float(baseline[label]) - J) / J, color=col, linestyle="--", linewidth=1.0)
                excess.append((float(baseline[label]) - J) / J)
    ax.set_yscale("log")
    ax.set_xlabel("horizon $M$")
    ax.set_ylabel(r"total cost $J_M$ (dotted: $J^*$)")
    ax.legend(fontsize=FONT)
    if optimum:
        axr = axes[0, 1]
        if excess and min(excess) > 0:
            axr.set_yscale("log")
        else:  # an excess <= 0 (a local NLP optimum as reference, or rounding): symmetric log
            axr.set_yscale("symlog", linthresh=1e-4)
            axr.axhline(0.0, color="k", linewidth=0.8)
        axr.set_xlabel("horizon $M$")
        axr.set_ylabel(r"$(J_M - J^*)/J^*$" + ("  (dashed: LQR)" if baseline else ""))
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


def rhc_frame(traj, reference, gamma: float, state_labels=("$x_t[0]$",), input_bounds=None,
              title: str | None = None, ylim_R=None) -> Figure:
    """One frame of the horizon-and-level explorer of Algorithm 1: the first state and the input of
    a run against the clairvoyant reference (dashed), and the running regret R^p_t(γ) of Eq. (2)
    of both.

    Parameters
    ----------
    traj : the :class:`orrc.Trajectory` of the controller (e.g. preview RHC).
    reference : the clairvoyant run on the same disturbances, drawn dashed.
    gamma : the attenuation level γ >= 0 of the regret panel.
    state_labels : the axis label of the state panel (its first entry).
    input_bounds : optional (lo, hi), drawn as dotted grey lines on the input panel.
    title : optional title above the panels.
    ylim_R : optional fixed limits of the regret panel, so frames for different M and γ compare
        at a glance.

    Returns
    -------
    matplotlib.figure.Figure
        Three panels: the state, the input, and R^p_t(γ).

    Examples
    --------
    >>> import orrc
    >>> from orrc.viz import plots
    >>> ex = orrc.examples.scalar_unstable()
    >>> w = orrc.disturbances.uniform_ball(25, 1, 0.5, seed=0)
    >>> rhc = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, M=5), ex.x0,
    ...                     w, T=20)
    >>> best = orrc.simulate(ex.system, orrc.Clairvoyant(ex.system, ex.cost, T=20),
    ...                      ex.x0, w, T=20)
    >>> fig = plots.rhc_frame(rhc, best, gamma=10.0, title="M = 5")
    >>> len(fig.axes), fig.axes[1].get_ylabel()
    (3, 'input $u_t$')
    """
    trajs = _trajs({"traj": traj, "reference": reference})
    traj, reference = trajs["traj"], trajs["reference"]
    gamma = as_float("gamma", gamma, minimum=0.0)
    fig, axes = _figure(1, 3, height=3.0)
    ax_x, ax_u, ax_r = axes[0]
    t = np.arange(traj.T + 1)
    ax_x.plot(t, reference.x[:, 0], color="black", linestyle="--", linewidth=1.2, label="clairvoyant")
    ax_x.plot(t, traj.x[:, 0], color="tab:blue", linewidth=1.5, label="preview RHC")
    ax_x.axhline(0.0, color="0.8", linewidth=0.8, zorder=0)
    ax_x.set_ylabel(state_labels[0])
    ax_x.legend(fontsize=FONT)
    ax_u.step(t[:-1], reference.u[:, 0], where="post", color="black", linestyle="--", linewidth=1.0)
    ax_u.step(t[:-1], traj.u[:, 0], where="post", color="tab:blue", linewidth=1.3)
    if input_bounds is not None:
        for b in input_bounds:
            ax_u.axhline(float(np.ravel(b)[0]), color="0.6", linewidth=0.9, linestyle=":")
    ax_u.set_ylabel("input $u_t$")
    ax_r.plot(t[1:], attenuation_regret(reference, gamma, cumulative=True), color="black", linestyle="--",
              linewidth=1.2)
    ax_r.plot(t[1:], attenuation_regret(traj, gamma, cumulative=True), color="tab:blue", linewidth=1.5)
    ax_r.axhline(0.0, color="k", linewidth=0.8)
    if ylim_R is not None:
        ax_r.set_ylim(*ylim_R)
    ax_r.set_ylabel(rf"$R^p_t(\gamma)$, $\gamma={gamma:g}$")
    for ax in axes[0]:
        ax.set_xlabel("$t$")
    if title:
        fig.suptitle(title, fontsize=11)
    return fig


def solver_effort(iterations: dict, solve_times: dict | None = None) -> Figure:
    """How the solver's effort in Algorithm 1's receding-horizon steps is distributed over a run,
    per label (e.g. warm and cold starts): the share of the steps that took 1, 2, 3, ...
    iterations, and, when given, the distribution of the time per step with its median.

    Distributions rather than means: one slow step (a busy machine) moves a mean, not a median.

    Parameters
    ----------
    iterations : dict label -> (T,) integer iteration counts, one per step.
    solve_times : optional dict label -> (T,) solve times in seconds, drawn as the empirical
        distribution of the milliseconds per step (a log axis when they are positive), the median
        dashed.

    Returns
    -------
    matplotlib.figure.Figure
        One panel of bars side by side, two with ``solve_times``.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.viz import plots
    >>> its = {"warm start": np.array([3, 1, 1, 2, 1]),
    ...        "cold start": np.array([5, 4, 4, 5, 4])}
    >>> times = {k: 1e-3 * v for k, v in its.items()}
    >>> fig = plots.solver_effort(its, times)
    >>> fig.axes[1].get_xlabel()
    'solve time per step [ms]'
    """
    from matplotlib.ticker import MaxNLocator

    iterations = _nonempty_dict("iterations", iterations, "per-step iteration counts")
    ncols = 2 if solve_times else 1
    fig, axes = _figure(1, ncols, width=WIDTH if ncols > 1 else 5.0, height=3.0)
    counts = {label: as_array(f"iterations[{label!r}]", it, ndim=1) for label, it in iterations.items()}
    width = 0.8 / len(counts)
    for i, (label, it) in enumerate(counts.items()):
        values, n = np.unique(it.astype(int), return_counts=True)
        axes[0, 0].bar(values + (i - (len(counts) - 1) / 2) * width, n / len(it), width=width,
                       color=f"C{i}", label=label)
    axes[0, 0].xaxis.set_major_locator(MaxNLocator(integer=True))
    axes[0, 0].set_xlabel("solver iterations at a step")
    axes[0, 0].set_ylabel("share of the steps")
    legend_below(axes[0, 0], ncol=1)
    if solve_times:
        every = []
        for i, (label, st) in enumerate(solve_times.items()):
            ms = np.sort(1e3 * as_array(f"solve_times[{label!r}]", st, ndim=1))
            every.append(ms)
            axes[0, 1].step(ms, np.arange(1, len(ms) + 1) / len(ms), where="post",
                            color=f"C{i}", label=label, linewidth=1.2)
            axes[0, 1].axvline(np.median(ms), color=f"C{i}", linestyle="--", linewidth=1.0)
        every = np.concatenate(every)
        if every.size and every.min() > 0:   # a log axis: the times span decades
            axes[0, 1].set_xlim(every.min() / 1.5, every.max() * 1.5)
            axes[0, 1].set_xscale("log")
        axes[0, 1].set_xlabel("solve time per step [ms]")
        axes[0, 1].set_ylabel("share of the steps at most")
    return fig
