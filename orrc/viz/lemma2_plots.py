"""Figures of Lemma 2: its coefficients M_{w,j}, the stage costs under its bound, and the explorer
frame over the horizon M and the decay rate a.

* :func:`lemma2_coefficients` -- the coefficients M_{w,j} of Lemma 2 against j;
* :func:`bounds_vs_actual` -- a measured sequence under one or more bounds (Lemma 2's cost bound);
* :func:`lemma2_frame` -- an explorer frame: coefficients and the cost bound for one (M, a).
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .._validate import OrrcValueError, as_array, as_float, as_int
from ._theory_common import _finish, _margins, _message
from .figures import legend_below
from .style import FONT, _axes, _figure, _nonempty_dict

__all__ = ["lemma2_coefficients", "bounds_vs_actual", "lemma2_frame"]


def lemma2_coefficients(coefs: dict, M: int, H: int, ax=None) -> Figure:
    """The coefficients M_{w,j} of Lemma 2's bound on the stage cost c_{t+H}
    (:func:`orrc.theory.lemma2_coefficients`) against j − t = 0, ..., H + M − 2, one curve per
    label, on a log scale. Shaded: the window w_t..w_{t+M-1} previewed at the anchor t, the
    decaying middle, and the disturbances previewed at t + H.

    Parameters
    ----------
    coefs : dict label -> array of length H + M − 1, the coefficients.
    M : the horizon M >= 1.
    H : the look-ahead H >= 1 of the bound.
    ax : optional matplotlib axes to draw in (a new figure when None).

    Returns
    -------
    matplotlib.figure.Figure
        The figure of ``ax`` (its legend in the lower right corner), or a new one-panel figure
        (its legend under the axes).

    Examples
    --------
    >>> from orrc import theory
    >>> from orrc.viz import theory_plots
    >>> c = theory.lemma2_coefficients(M=6, H=6, a=0.9, alpha_hi=2.0, gamma_bar=1.0, b=1.5)
    >>> fig = theory_plots.lemma2_coefficients({"a = 0.9": c}, M=6, H=6)
    >>> fig.axes[0].get_yscale()
    'log'
    """
    coefs = _nonempty_dict("coefs", coefs)
    M = as_int("M", M, minimum=2)
    H = as_int("H", H, minimum=M)
    alone = ax is None
    fig, ax = _axes(ax, 6.4, 3.4)
    j = np.arange(H + M - 1)
    for i, (label, c) in enumerate(coefs.items()):
        c = as_array(f"coefs[{label!r}]", c, (H + M - 1,))
        ax.semilogy(j, c, color=f"C{i}", marker=".", markersize=3, label=label)
    span = H + M - 1
    for lo, hi, text, col in ((0, M - 1, "window at $t$", "tab:purple"), (M, H - 1, "decaying", "0.6"),
                              (H, H + M - 2, "window at $t+H$", "tab:orange")):
        if hi >= lo:
            ax.axvspan(lo - 0.5, hi + 0.5, color=col, alpha=0.08, linewidth=0)
            if hi - lo + 1 >= 0.25 * span:   # a band too narrow for its name stays unnamed (no overprint)
                ax.text(0.5 * (lo + hi), 1.0, text, transform=ax.get_xaxis_transform(), ha="center",
                        va="bottom", fontsize=FONT, color="0.3")
    ax.set_xlabel("$j - t$")
    ax.set_ylabel(r"$M_{w,j}$")
    if alone:   # a figure of its own: the legend under the axes, where it covers no curve
        legend_below(ax, fontsize=FONT, ncol=min(len(coefs), 3))
    else:       # a panel of an explorer frame (one curve): its corner, kept for the frame's layout
        ax.legend(fontsize=FONT, loc="lower right")
    return fig


def bounds_vs_actual(x, actual, bounds: dict, xlabel: str = "$t$", ylabel: str = "", log: bool = True,
                     title: str | None = None, actual_label: str = "actual", ax=None,
                     legend: str = "best") -> Figure:
    """A measured sequence under one or more bounds, on a log scale by default: Lemma 2's bound on
    the stage cost c_{t+H} and its parts, or any other inequality of the paper checked along a
    run.

    On a log scale, points where ``actual`` is not positive are left out (a stage cost of
    exactly 0).

    Parameters
    ----------
    x : the points (e.g. the steps t) of ``actual``.
    actual : the measured values, aligned with ``x``.
    bounds : dict label -> array like ``actual``, one curve each.
    xlabel, ylabel : the axis labels.
    log : a logarithmic value axis.
    title : optional title.
    actual_label : the legend's label of ``actual``.
    ax : optional matplotlib axes to draw in (a new figure when None).
    legend : "best" (inside the axes) or "below" (under the axes, clear of the data; for figures
        with several curves).

    Returns
    -------
    matplotlib.figure.Figure
        The figure of ``ax``, or a new one-panel figure.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.viz import theory_plots
    >>> t = np.arange(10)
    >>> fig = theory_plots.bounds_vs_actual(t, 0.5 ** t, {"bound": 2.0 * 0.6 ** t},
    ...                                     ylabel="$c_{t+H}$")
    >>> [line.get_label() for line in fig.axes[0].get_lines()]
    ['bound', 'actual']
    """
    if legend not in ("best", "below"):
        raise OrrcValueError(f'legend must be "best" or "below"; got {legend!r}')
    x = as_array("x", x, ndim=1)
    actual = as_array("actual", actual, (len(x),))
    bounds = _nonempty_dict("bounds", bounds)
    fig, ax = _axes(ax, 6.4, 4.2 if legend == "below" else 3.4)
    styles = ["-", "--", ":", "-."]
    colours = ["tab:red", "tab:green", "tab:purple", "tab:orange", "tab:brown", "tab:gray"]  # never the actual's blue
    for i, (label, b) in enumerate(bounds.items()):
        b = as_array(f"bounds[{label!r}]", b, (len(x),))
        ax.plot(x, b, color=colours[i % len(colours)], linestyle=styles[i % 4], linewidth=1.2, label=label)
    pos = actual > 0 if log else np.ones(len(x), bool)
    ax.plot(x[pos], actual[pos], color="tab:blue", linewidth=1.4, marker=".", markersize=3, label=actual_label)
    if log:
        ax.set_yscale("log")
    _finish(ax, xlabel, ylabel, title, legend)
    return fig


def _admissible_frame(M: int, a: float, a_min: float, result: str, right_message: str):
    """A two-panel explorer frame; when a < a_min it only says that ``result`` does not apply.

    Checks M >= 2 and 0 < a < 1, 0 <= a_min < 1. Returns ``(M, a, a_min, fig, (ax, ax2))``,
    with ``(None, None)`` for the axes when the frame is already complete.
    """
    M = as_int("M", M, minimum=2)
    a = as_float("a", a, minimum=0.0, maximum=1.0, strict_min=True, strict_max=True)
    a_min = as_float("a_min", a_min, minimum=0.0, maximum=1.0, strict_max=True)
    fig, axes = _figure(1, 2, height=3.3)
    ax, ax2 = axes[0]
    if a >= a_min:
        return M, a, a_min, fig, (ax, ax2)
    _message(ax, f"a = {a:g} is below the smallest admissible\ndecay rate at M = {M}: "
                 f"a_min = {a_min:.4f}.\n{result} does not apply.")
    _message(ax2, right_message)
    fig.suptitle(f"M = {M}, a = {a:g}: not admissible", fontsize=11)
    return M, a, a_min, fig, (None, None)


def lemma2_frame(M: int, a: float, a_min: float, coef=None, margins=None, H: int | None = None,
                 ylim=None, coef_ylim=None) -> Figure:
    """One frame of the Lemma 2 explorer for the horizon M and the decay rate a.

    When a >= ``a_min``: left, the coefficients M_{w,j}; right, the stage costs c_{t+H} under
    Lemma 2's bound along a trajectory, against the time t + H. When a < a_min the lemma does not
    apply and the frame says so.

    Parameters
    ----------
    M : the horizon.
    a : the decay rate of the frame.
    a_min : the smallest admissible decay rate (:func:`orrc.theory.min_decay_rate`).
    coef : the coefficients M_{w,j} at (M, a), length H + M − 1.
    margins : the margins of :func:`orrc.checks.lemma2_margins` at (M, a).
    H : the look-ahead H >= M. ``coef``, ``margins`` and ``H`` are needed when a >= a_min.
    ylim, coef_ylim : optional fixed limits of the right and left panels, so that frames compare
        at a glance.

    Returns
    -------
    matplotlib.figure.Figure
        Two panels, or one that says the lemma does not apply.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)
    >>> w = orrc.disturbances.uniform_ball(60, 1, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 8), ex.x0,
    ...                      w, 50)
    >>> from orrc import theory
    >>> from orrc.viz import theory_plots
    >>> coef = theory.lemma2_coefficients(8, 8, k.a, k.alpha_hi, k.gamma_bar, k.b)
    >>> lemma2 = checks.lemma2_margins(traj, 8, 8, k.a, k.alpha_lo, k.alpha_hi, k.gamma_bar)
    >>> fig = theory_plots.lemma2_frame(8, k.a, k.a, coef=coef, margins=lemma2, H=8)
    >>> len(fig.axes)
    2
    """
    M, a, a_min, fig, (ax, ax2) = _admissible_frame(M, a, a_min, "Lemma 2", "no bound")
    if ax is None:
        return fig
    if coef is None or margins is None or H is None:
        raise OrrcValueError("for an admissible a, lemma2_frame needs coef, margins and H")
    H = as_int("H", H, minimum=M)
    margins = _margins("margins", margins)
    lemma2_coefficients({f"a = {a:g}": coef}, M, H, ax=ax)
    bounds_vs_actual(margins.t + H, margins.actual, {"Lemma 2 bound": margins.bound}, xlabel="time $t + H$",
                     ylabel="stage cost", actual_label=r"$c_{t+H}$", ax=ax2)
    for axis, lim, name in ((ax2, ylim, "ylim"), (ax, coef_ylim, "coef_ylim")):
        if lim is not None:
            lim = as_array(name, lim, (2,))
            if not 0 < lim[0] < lim[1]:
                raise OrrcValueError(f"{name} must be (low, high) with 0 < low < high (log scale); got {tuple(lim)}")
            axis.set_ylim(*lim)
    ratio = float(np.median(margins.bound / np.maximum(margins.actual, 1e-300)))
    # symbols as math, as in the text: a_min is $a_{\min}$
    fig.suptitle(rf"$M = {M}$, $a = {a:g}$ ($a_{{\min}} = {a_min:.4f}$), $H = {H}$: median bound / cost = {ratio:.3g}",
                 fontsize=11)
    return fig
