"""Figures of Algorithm 1 (preview receding-horizon control): the preview gains of the exact LQ law,
the closed-loop cost against the horizon M, the frames of the M-and-γ explorer, and the solver's
effort per step. Every function takes the data it draws and returns a
:class:`matplotlib.figure.Figure` built without pyplot; :mod:`orrc.viz.plots` gathers them with
the figures of the problem's chapter, as the chapters use them.
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .._validate import OrrcValueError, as_array, as_float, as_int
from ..metrics import attenuation_regret
from .figures import legend_below
from .style import FONT, WIDTH, _figure, _nonempty_dict, _trajs

__all__ = ["preview_gains", "cost_vs_horizon", "rhc_frame", "solver_effort"]


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
