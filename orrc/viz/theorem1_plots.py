"""Figures of Theorem 1: γ_c against a and M, the certified level beside the exact worst case,
R^p_t(γ) and the explicit ceiling, the adversary made explicit.

* :func:`gamma_c_map` -- γ_c of Theorem 1 against a (several M) and against M;
* :func:`attenuation_levels` -- certified γ_c beside the attenuation actually achieved, against M;
* :func:`regret_growth` -- R^p_t(γ) against t, with Theorem 1's explicit ceiling;
* :func:`adversary` -- worst-case disturbances and the stage costs they cause;
* :func:`theorem1_frame` -- an explorer frame: γ_c(a) and the ceiling on R^p_t for one (M, a);
* :func:`attenuation_vs_T` -- the exact finite-T worst case against T, with its cold and stationary limits.
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .._validate import OrrcValueError, as_array, as_float, as_int
from ._theory_common import _finish, _margins
from .figures import legend_below
from .lemma2_plots import _admissible_frame
from .style import FONT, _axes, _figure, _nonempty_dict

__all__ = ["gamma_c_map", "attenuation_levels", "regret_growth", "adversary", "theorem1_frame",
           "attenuation_vs_T"]


def gamma_c_map(curves: dict, a_min: dict, Ms, gamma_c_best, floor=None, title: str | None = None) -> Figure:
    """Theorem 1's level γ_c = b((M−1)(1−a) + 1)/(1−a)² as a function of the decay rate a and of
    the horizon M.

    Left: γ_c against a for each label, with the smallest admissible a marked. Right: the best
    γ_c (at a = a_min) against M, and, when given, the floor 2γ̄ of the remark after Theorem 1.

    Parameters
    ----------
    curves : dict label -> (a values, γ_c values), one curve each.
    a_min : dict label -> (a_min, γ_c(a_min)), the point marked on each curve.
    Ms : the horizons of the right panel.
    gamma_c_best : the best γ_c at each horizon, aligned with ``Ms``.
    floor : optional floor 2γ̄ of the remark after Theorem 1, aligned with ``Ms``.
    title : optional title above the panels.

    Returns
    -------
    matplotlib.figure.Figure
        Two panels.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc import theory
    >>> from orrc.viz import theory_plots
    >>> a_min = theory.min_decay_rate(8, 1.0, 2.0)
    >>> a = np.linspace(a_min, 0.99, 20)
    >>> gc = [theory.gamma_c(8, x, 1.0, 2.0, 1.0) for x in a]
    >>> fig = theory_plots.gamma_c_map({"M = 8": (a, gc)}, {"M = 8": (a[0], gc[0])},
    ...                                [8], [gc[0]])
    >>> len(fig.axes)
    2
    """
    curves = _nonempty_dict("curves", curves)
    if not isinstance(a_min, dict):
        raise OrrcValueError(f"a_min must be a dict label -> (a_min, gamma_c); got {type(a_min).__name__}")
    Ms = np.array([as_int("M", m, minimum=2) for m in Ms])
    gcb = as_array("gamma_c_best", gamma_c_best, (len(Ms),))
    fig, axes = _figure(1, 2, height=3.6)
    ax, ax2 = axes[0]
    for i, (label, (a, g)) in enumerate(curves.items()):
        a = as_array(f"curves[{label!r}] a", a, ndim=1)
        g = as_array(f"curves[{label!r}] gamma_c", g, (len(a),))
        ax.semilogy(a, g, color=f"C{i}", label=label)
        if label in a_min:
            am, gm = a_min[label]
            ax.plot([am], [gm], marker="o", color=f"C{i}", markeredgecolor="k")
    ax.set_xlabel("decay rate $a$ (dot: smallest admissible)")
    ax.set_ylabel(r"$\gamma_c$")
    ax.legend(fontsize=FONT)
    ax2.semilogy(Ms, gcb, color="tab:blue", marker=".", label=r"$\gamma_c$ at $a = a_{\min}(M)$")
    if floor is not None:
        floor = as_array("floor", floor, (len(Ms),))
        ax2.semilogy(Ms, floor, color="k", linestyle="--", label=r"$2\overline{\gamma}$")
    ax2.set_xlabel("horizon $M$")
    ax2.set_ylabel(r"$\gamma_c$")
    ax2.legend(fontsize=FONT)
    if title:
        fig.suptitle(title, fontsize=11)
    return fig


def attenuation_levels(Ms, levels: dict, threshold_M: int | None = None, title: str | None = None) -> Figure:
    """Attenuation levels against the horizon M on a log scale: Theorem 1's certified γ_c beside the
    exact worst-case levels of :func:`orrc.certify.worst_case_attenuation_limit`.

    A label containing "LQR" with a single number is drawn as a horizontal line (it does not
    depend on M). Labels containing "certified", "floor", "stationary", "cold" or "LQR" get fixed
    styles.

    Parameters
    ----------
    Ms : the horizons M.
    levels : dict label -> values aligned with ``Ms`` (inf or nan where a level does not exist),
        or a single number for a label containing "LQR".
    threshold_M : optional smallest M certified by Theorem 1; the horizons below it are shaded.
    title : optional title.

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> import math
    >>> from orrc.viz import theory_plots
    >>> fig = theory_plots.attenuation_levels([2, 4, 8],
    ...                                       {"certified γ_c": [math.inf, 40.0, 12.0],
    ...                                        "exact, stationary": [3.0, 2.5, 2.4],
    ...                                        "LQR": 2.6}, threshold_M=4)
    >>> fig.axes[0].get_yscale()
    'log'
    """
    Ms = np.array([as_int("M", m, minimum=1) for m in Ms])
    levels = _nonempty_dict("levels", levels)
    fig, ax = _figure(width=7.0, height=4.2)
    ax = ax[0, 0]
    styles = {"lqr": ("tab:orange", "-", None), "certified": ("tab:red", "-", "o"), "floor": ("tab:red", ":", None),
              "stationary": ("tab:blue", "-", "s"), "cold": ("tab:blue", "--", "^")}
    for i, (label, v) in enumerate(levels.items()):
        v = as_array(f"levels[{label!r}]", v, allow_nonfinite=True)
        if v.ndim > 1 or (v.ndim == 1 and len(v) != len(Ms)):
            raise OrrcValueError(f"levels[{label!r}] must be one number or {len(Ms)} values aligned with Ms; "
                                 f"got shape {v.shape}")
        low = label.lower()
        col, ls, mk = next((s for k, s in styles.items() if k in low), (f"C{i}", "-", "."))
        if "lqr" in low and v.ndim == 0:
            ax.axhline(float(v), color=col, linestyle=ls, linewidth=1.4, label=label)
            continue
        v = np.broadcast_to(v, Ms.shape).astype(float)
        fin = np.isfinite(v)
        ax.plot(Ms[fin], v[fin], color=col, linestyle=ls, marker=mk, markersize=4, label=label)
    ax.set_yscale("log")
    if threshold_M is not None:
        threshold_M = as_int("threshold_M", threshold_M, minimum=1)
        ax.axvspan(Ms.min() - 0.5, threshold_M - 0.5, color="0.85", alpha=0.5, linewidth=0)
        ax.text(0.5 * (Ms.min() + threshold_M - 1), 0.97, "Theorem 1\nsilent", transform=ax.get_xaxis_transform(),
                ha="center", va="top", fontsize=FONT, color="0.3")
    _finish(ax, "horizon $M$", r"attenuation level $\gamma$", title, legend="below", offset=-0.16)
    return fig


def regret_growth(t, R: dict, ceiling=None, title: str | None = None, ylim=None, ax=None) -> Figure:
    """The running attenuation regret R^p_t(γ) = Σ_{s<t} c_s − γ Σ_{s<t} ‖w_s‖² of Eq. (2) against
    t, one curve per label, under Theorem 1's explicit ceiling C_t when given.

    Parameters
    ----------
    t : the steps.
    R : dict label -> R^p_t(γ), aligned with ``t``.
    ceiling : optional Theorem 1 ceiling C_t aligned with ``t`` (the ``bound`` of
        :func:`orrc.checks.theorem1_margin`).
    title : optional title.
    ylim : optional fixed limits of the value axis.
    ax : optional matplotlib axes to draw in (a new figure when None).

    Returns
    -------
    matplotlib.figure.Figure
        The figure of ``ax``, or a new one-panel figure.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks
    >>> from orrc.viz import theory_plots
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)
    >>> w = orrc.disturbances.uniform_ball(60, 1, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 8), ex.x0,
    ...                      w, 50)
    >>> m = checks.theorem1_margin(traj, 8, k.a, k.alpha_lo, k.alpha_hi,
    ...                            k.gamma_bar, k.gamma_c)
    >>> fig = theory_plots.regret_growth(m.t, {"preview RHC": m.actual}, ceiling=m.bound)
    >>> len(fig.axes)
    1
    """
    t = as_array("t", t, ndim=1)
    R = _nonempty_dict("R", R)
    fig, ax = _axes(ax, 6.4, 3.4)
    if ceiling is not None:
        ceiling = as_array("ceiling", ceiling, (len(t),))
        ax.plot(t, ceiling, color="tab:red", linestyle="--", linewidth=1.3, label="Theorem 1 ceiling $C_t$")
    for i, (label, r) in enumerate(R.items()):
        r = as_array(f"R[{label!r}]", r, (len(t),))
        ax.plot(t, r, color=f"C{i}", linewidth=1.5, label=label)
    ax.axhline(0.0, color="k", linewidth=0.7)
    if ylim is not None:
        ax.set_ylim(*ylim)
    _finish(ax, "$t$", r"$R^p_t(\gamma)$", title)
    return fig


def adversary(ws: dict, costs: dict, title: str | None = None) -> Figure:
    """The adversary of R^p_T(γ) (Eq. 2) made explicit: worst-case disturbances (their norm ‖w_t‖
    when n > 1) and the stage costs they cause.

    Parameters
    ----------
    ws : dict label -> (T, n) disturbance array, e.g. the ``w`` of
        :func:`orrc.certify.worst_case_attenuation`.
    costs : dict label -> (T,) stage costs, the same labels.
    title : optional title above the panels.

    Returns
    -------
    matplotlib.figure.Figure
        Two panels: the disturbances and the stage costs, one legend under the second.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> from orrc.viz import theory_plots
    >>> di = orrc.examples.double_integrator()
    >>> lqr = orrc.LQR(di.system, di.cost)
    >>> worst = certify.worst_case_attenuation(di.system, lqr, T=30)
    >>> traj = orrc.simulate(di.system, lqr, [0.0, 0.0], worst.w, T=30)
    >>> fig = theory_plots.adversary({"LQR": worst.w}, {"LQR": traj.costs})
    >>> len(fig.axes)
    2
    """
    ws = _nonempty_dict("ws", ws)
    costs = _nonempty_dict("costs", costs)
    fig, axes = _figure(1, 2, height=3.3)
    ax, ax2 = axes[0]
    for i, (label, w) in enumerate(ws.items()):
        w = as_array(f"ws[{label!r}]", w, ndim=2)
        col = "tab:orange" if "lqr" in label.lower() else ("tab:blue" if "rhc" in label.lower() else f"C{i}")
        t = np.arange(len(w))
        if w.shape[1] == 1:
            ax.plot(t, w[:, 0], color=col, marker=".", markersize=3, label=label)
        else:
            ax.plot(t, np.linalg.norm(w, axis=1), color=col, marker=".", markersize=3, label=label)
        if label not in costs:
            raise OrrcValueError(f"costs has no entry for {label!r}; give the stage costs of every disturbance")
        c = as_array(f"costs[{label!r}]", costs[label], (len(w),))
        ax2.plot(t, c, color=col, marker=".", markersize=3, label=label)
    ax.axhline(0.0, color="0.8", linewidth=0.8, zorder=0)
    ax.set_xlabel("$t$")
    ax.set_ylabel("$w_t$" if all(np.asarray(w).shape[1] == 1 for w in ws.values()) else r"$\|w_t\|$")
    ax.set_title(r"worst-case disturbance, $\sum_t\|w_t\|^2 = 1$", fontsize=10)
    ax2.set_xlabel("$t$")
    ax2.set_ylabel("stage cost $c_t$")
    ax2.set_title("the cost it causes (from $x_0 = 0$)", fontsize=10)
    # one legend for both panels (the same controllers, the same colours), under the cost panel:
    # inside either panel it covered the humps of the curves
    legend_below(ax2, fontsize=FONT, ncol=2)
    if title:
        fig.suptitle(title, fontsize=11)
    return fig


def theorem1_frame(M: int, a: float, a_min: float, a_grid=None, gamma_c_grid=None, margin=None,
                   ylim=None, gamma_c=None) -> Figure:
    """One frame of the Theorem 1 explorer for the horizon M and the decay rate a.

    When a >= ``a_min``: left, γ_c = b((M−1)(1−a)+1)/(1−a)² against a with the chosen a marked;
    right, R^p_t(γ_c) along a trajectory under Theorem 1's explicit ceiling C_t. When a < a_min
    the theorem does not apply and the frame says so.

    Parameters
    ----------
    M : the horizon.
    a : the decay rate of the frame.
    a_min : the smallest admissible decay rate (:func:`orrc.theory.min_decay_rate`).
    a_grid, gamma_c_grid : the admissible range of a at this M and γ_c along it.
    margin : the margins of :func:`orrc.checks.theorem1_margin` at γ = γ_c(a) (``actual`` is
        R^p_t, ``bound`` is C_t, against ``margin.t``). ``a_grid``, ``gamma_c_grid`` and
        ``margin`` are needed when a >= a_min.
    ylim : optional fixed limits of the right panel.
    gamma_c : the exact γ_c at a (:func:`orrc.theory.gamma_c`, the γ of ``margin``), for the
        dot on the left and the legend on the right; without it, γ_c is interpolated in the grid,
        which is off between grid points.

    Returns
    -------
    matplotlib.figure.Figure
        Two panels, or one that says the theorem does not apply.

    Examples
    --------
    >>> import numpy as np
    >>> import orrc
    >>> from orrc import certify, checks, theory
    >>> from orrc.viz import theory_plots
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)
    >>> w = orrc.disturbances.uniform_ball(60, 1, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 8), ex.x0,
    ...                      w, 50)
    >>> a_grid = np.linspace(k.a, 0.99, 10)
    >>> grid = [theory.gamma_c(8, a, k.alpha_lo, k.alpha_hi, k.gamma_bar) for a in a_grid]
    >>> m = checks.theorem1_margin(traj, 8, k.a, k.alpha_lo, k.alpha_hi,
    ...                            k.gamma_bar, k.gamma_c)
    >>> fig = theory_plots.theorem1_frame(8, k.a, k.a, a_grid, grid, m, gamma_c=k.gamma_c)
    >>> len(fig.axes)
    2
    """
    M, a, a_min, fig, (ax, ax2) = _admissible_frame(M, a, a_min, "Theorem 1", "no guarantee")
    if ax is None:
        return fig
    if a_grid is None or gamma_c_grid is None or margin is None:
        raise OrrcValueError("for an admissible a, theorem1_frame needs a_grid, gamma_c_grid and margin")
    a_grid = as_array("a_grid", a_grid, ndim=1)
    gcg = as_array("gamma_c_grid", gamma_c_grid, (len(a_grid),))
    margin = _margins("margin", margin)
    if gamma_c is None:
        gc = float(np.interp(a, a_grid, gcg))
    else:
        gc = as_float("gamma_c", gamma_c, minimum=0.0, strict_min=True)
    ax.semilogy(a_grid, gcg, color="tab:red", linewidth=1.4)
    ax.plot([a], [gc], marker="o", color="tab:red", markeredgecolor="k", markersize=8)
    ax.axvline(a_min, color="0.5", linestyle=":", linewidth=1.0)
    ax.set_xlabel(r"decay rate $a$ (dotted: $a_{\min}$)")
    ax.set_ylabel(r"$\gamma_c$")
    ax.set_title(rf"$\gamma_c(a)$ at $M = {M}$", fontsize=10)
    regret_growth(margin.t, {rf"$R^p_t(\gamma_c)$, $\gamma_c = {gc:.4g}$": margin.actual}, ceiling=margin.bound,
                  ax=ax2, ylim=ylim)
    ax2.set_title("the guarantee along one run", fontsize=10)
    # symbols as math, as in the text: a_min is $a_{\min}$, the margin is C_t − R^p_t
    fig.suptitle(rf"$M = {M}$, $a = {a:g}$ ($a_{{\min}} = {a_min:.4f}$): smallest margin "
                 rf"$C_t - R^p_t = {margin.margin.min():.4g}$", fontsize=11)
    return fig


def attenuation_vs_T(Ts, levels: dict, limits: dict | None = None, title: str | None = None) -> Figure:
    """The exact finite-T worst-case attenuation level (:func:`orrc.certify.worst_case_attenuation`)
    against the length T of the run, with its T → ∞ limits as horizontal lines, on a log-scale T
    axis.

    Parameters
    ----------
    Ts : the lengths T.
    levels : dict label -> levels aligned with ``Ts``.
    limits : optional dict label -> the limit level, from
        :func:`orrc.certify.worst_case_attenuation_limit` with ``start="cold"`` or
        ``"stationary"`` (dashed when the label contains "stationary").
    title : optional title.

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> from orrc.viz import theory_plots
    >>> fig = theory_plots.attenuation_vs_T([10, 30, 100], {"LQR": [2.1, 2.4, 2.5]},
    ...                                     limits={"LQR, stationary": 2.52})
    >>> fig.axes[0].get_xscale()
    'log'
    """
    Ts = np.array([as_int("T", T, minimum=1) for T in Ts])
    levels = _nonempty_dict("levels", levels)
    limits = {} if limits is None else limits
    if not isinstance(limits, dict):
        raise OrrcValueError(f"limits must be a dict label -> number; got {type(limits).__name__}")
    fig, axes = _figure(width=7.0, height=3.6)
    ax = axes[0, 0]
    for i, (label, v) in enumerate(levels.items()):
        v = as_array(f"levels[{label!r}]", v, (len(Ts),))
        ax.plot(Ts, v, color=f"C{i}", marker="o", markersize=4, label=label)
    for i, (label, v) in enumerate(limits.items()):
        v = as_float(f"limits[{label!r}]", v, minimum=0.0)
        ls = "--" if "stationary" in label.lower() else ":"
        ax.axhline(v, color=f"C{i}" if i < len(levels) else "k", linestyle=ls, linewidth=1.2, label=label)
    ax.set_xscale("log")
    _finish(ax, "horizon $T$ of the sum", r"worst-case $\gamma^*_T$", title)
    return fig
