"""Figures of the theory chapters (Lemma 1, Lemma 2, Theorem 1).

Every function takes the data it draws (the constants of :mod:`orrc.certify`, the
margins of :mod:`orrc.checks`, arrays of levels) and returns a
:class:`matplotlib.figure.Figure`; none of them computes a constant or a bound. A
figure is shown when it is the value of a notebook cell, and can be handed to
:func:`orrc.viz.explore` as a frame. ``fast=True`` uses fixed margins instead of the
constrained layout (quicker to render: for explorer frames).

Functions (the statement they illustrate):

* :func:`pareto_curves` -- the admissible pairs (ᾱ, γ̄) of V_M <= ᾱ σ + γ̄ Σ‖w‖² and Theorem 1's γ_c along them;
* :func:`horizon_threshold` -- M > ᾱ²/α_lo² + 1 when ᾱ itself depends on M (Lemma 1, Theorem 1);
* :func:`lemma1_check` -- V_M between its bounds, and its increments under Lemma 1's bound;
* :func:`lemma2_coefficients` -- the coefficients M_{w,j} of Lemma 2 against j;
* :func:`bounds_vs_actual` -- a measured sequence under one or more bounds (Lemma 2's cost bound);
* :func:`lemma2_frame` -- an explorer frame of Lemma 2: coefficients and the cost bound for one (M, a);
* :func:`gamma_c_map` -- γ_c of Theorem 1 against a (several M) and against M;
* :func:`attenuation_levels` -- certified γ_c beside the attenuation actually achieved, against M;
* :func:`regret_growth` -- R^p_t(γ) against t, with Theorem 1's explicit ceiling;
* :func:`adversary` -- worst-case disturbances and the stage costs they cause;
* :func:`theorem1_frame` -- an explorer frame of Theorem 1: γ_c(a) and the ceiling on R^p_t for one (M, a);
* :func:`attenuation_vs_T` -- the exact finite-T worst case against T, with its cold and stationary limits.
"""
from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from .. import theory
from .._validate import OrrcValueError, as_array, as_float, as_int
from .plots import _axes, _figure, _nonempty_dict

__all__ = ["pareto_curves", "horizon_threshold", "lemma1_check", "lemma2_coefficients", "bounds_vs_actual",
           "lemma2_frame", "gamma_c_map", "attenuation_levels", "regret_growth", "adversary", "theorem1_frame",
           "attenuation_vs_T"]


def _constants(name: str, c):
    from ..certify import Constants

    if not isinstance(c, Constants):
        raise OrrcValueError(f"{name} must be orrc.certify.Constants (lq_constants or sampled_constants); "
                             f"got {type(c).__name__}")
    return c


def _margins(name: str, m):
    from ..checks import Margins

    if not isinstance(m, Margins):
        raise OrrcValueError(f"{name} must be orrc.checks.Margins; got {type(m).__name__}")
    return m


def _message(ax, text: str) -> None:
    ax.text(0.5, 0.5, text, ha="center", va="center", fontsize=10, wrap=True, transform=ax.transAxes,
            bbox={"boxstyle": "round", "facecolor": "0.95", "edgecolor": "0.7"})
    ax.set_xticks([])
    ax.set_yticks([])


def _symlog(ax, *arrays) -> None:
    """A symmetric log scale whose linear part covers the small magnitudes (the smallest
    tenth of the non-zero values, and at least 1e-6 of the largest)."""
    v = np.concatenate([np.abs(np.ravel(a)) for a in arrays])
    v = v[v > 0]
    lin = max(float(np.quantile(v, 0.1)), 1e-6 * float(v.max())) if len(v) else 1.0
    ax.set_yscale("symlog", linthresh=lin, linscale=0.5)


def _legend_below(ax, ncol: int = 2, offset: float = -0.2) -> None:
    """A frameless legend centred under the axes, its top ``offset`` (axes fraction) below them."""
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, offset), ncol=ncol, frameon=False)


def _finish(ax, xlabel: str, ylabel: str, title: str | None = None, legend: str = "best", ncol: int = 2,
            offset: float = -0.2) -> None:
    """The common tail of a one-panel figure: the axis labels, the legend ("best": inside the
    axes; "below": :func:`_legend_below` with ``ncol`` and ``offset``) and the title when given."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if legend == "below":
        _legend_below(ax, ncol=ncol, offset=offset)
    else:
        ax.legend(fontsize=8, loc="best")
    if title:
        ax.set_title(title, fontsize=10)


# -- Lemma 1 ---------------------------------------------------------------------------------------
def pareto_curves(constants: dict, title: str | None = None) -> Figure:
    """The admissible pairs of the class condition V_M(x, W) <= ᾱ σ(x) + γ̄ Σ_k ‖w_k‖² (Section 5.1).

    ``constants``: label -> :class:`orrc.certify.Constants` (one per horizon M). Left: the
    Pareto curve ᾱ(γ̄) on log-log axes (every pair on or above it is admissible), the
    chosen pair (star: the one that minimises γ_c, or the knee when none is below the
    threshold) and the horizon threshold ᾱ < α_lo √(M-1) (dotted: Lemma 2 and Theorem 1
    need a pair below it). Right: Theorem 1's γ_c along each curve (with a = min_decay_rate),
    finite only where the pair is below the threshold.
    """
    from matplotlib.ticker import LogLocator, NullFormatter, ScalarFormatter

    constants = _nonempty_dict("constants", constants)
    cs = {label: _constants(f"constants[{label!r}]", c) for label, c in constants.items()}
    fig, axes = _figure(1, 2, width=10.0, height=3.6)
    ax, ax2 = axes[0]
    styles = ["-", "--", "-.", ":"]
    # x range: from the left end of the curves to a decade past the stars and the plateaus
    x_lo = min(c.pareto[0, 0] for c in cs.values())
    x_hi = x_lo
    for c in cs.values():
        gb, ah = c.pareto[:, 0], c.pareto[:, 1]
        flat = gb[ah <= 1.01 * ah.min()]
        x_hi = max(x_hi, c.gamma_bar, flat[0] if len(flat) else gb[-1])
    x_hi = min(10.0 * x_hi, max(c.pareto[-1, 0] for c in cs.values()))
    y_lo = min(min(c.pareto[:, 1].min(), c.alpha_lo * math.sqrt(c.M - 1)) for c in cs.values()) / 1.15
    y_hi = 4.0 * max(c.pareto[:, 1].min() for c in cs.values())
    any_gc = estimate = False
    for i, (label, c) in enumerate(cs.items()):
        estimate |= c.estimate
        col, ls = f"C{i}", styles[i % len(styles)]
        gb, ah = c.pareto[:, 0], c.pareto[:, 1]
        ax.plot(gb, ah, color=col, linestyle=ls, linewidth=1.6, label=label)
        ax.vlines(gb[0], ah[0], y_hi, color=col, linestyle=ls, linewidth=1.6)  # left end of a sampled curve
        thr = c.alpha_lo * math.sqrt(c.M - 1)
        ax.axhline(thr, color=col, linestyle=":", linewidth=1.0)
        ax.text(x_hi, thr, f" {label}", color=col, fontsize=7, va="center", ha="left", clip_on=False)
        ax.plot([c.gamma_bar], [c.alpha_hi], marker="*", markersize=11, color=col, markeredgecolor="k",
                linestyle="none")
        fin = np.isfinite(c.pareto_gamma_c)
        if fin.any():
            any_gc = True
            ax2.loglog(gb[fin], c.pareto_gamma_c[fin], color=col, linestyle=ls, label=label)
            ax2.plot([c.gamma_bar], [c.gamma_c], marker="*", markersize=11, color=col, markeredgecolor="k")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(x_lo / 1.3, x_hi)
    ax.set_ylim(y_lo, y_hi)
    ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    ax.yaxis.set_major_formatter(ScalarFormatter())
    ax.yaxis.set_minor_formatter(ScalarFormatter())
    for a in (ax, ax2):
        a.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel(r"$\overline{\gamma}$")
    ax.set_ylabel(r"$\overline{\alpha}$  (dotted: $\underline{\alpha}\sqrt{M-1}$)")
    ax.set_title("admissible pairs: on or above each curve", fontsize=10)
    ax.legend(fontsize=8, loc="upper right")
    if any_gc:
        ax2.set_xlim(x_lo / 1.3, x_hi)
        ax2.set_xlabel(r"$\overline{\gamma}$ (pair on the curve)")
        ax2.set_ylabel(r"$\gamma_c$ of Theorem 1")
        ax2.set_title(r"$\gamma_c$ along the curve (star: the best)", fontsize=10)
        ax2.legend(fontsize=8)
    else:
        _message(ax2, "no pair lies below the horizon threshold:\nTheorem 1 certifies nothing at these M")
    if title or estimate:
        fig.suptitle((title or "") + ("  [ESTIMATED constants: sampled, not certified]" if estimate else ""),
                     fontsize=11)
    return fig


def horizon_threshold(Ms, alpha_hi, alpha_lo, M_star: int | None = None) -> Figure:
    """The horizon condition M > ᾱ²/α_lo² + 1 (Lemma 1's Γ_V < 0; Lemma 2, Theorem 1) when ᾱ
    depends on M: ``alpha_hi[i]`` is the smallest admissible ᾱ at horizon ``Ms[i]``.

    Draws the required horizon ᾱ(M)²/α_lo² + 1 against M with the diagonal: M is certified
    where the curve is below the diagonal. ``M_star``: the smallest certified M, marked.
    """
    Ms = np.array([as_int("M", m, minimum=2) for m in Ms])
    alpha_hi = as_array("alpha_hi", alpha_hi, (len(Ms),))
    alpha_lo = as_float("alpha_lo", alpha_lo, minimum=0.0, strict_min=True)
    need = np.array([theory.horizon_threshold(alpha_lo, h) for h in alpha_hi])
    ok = np.array([theory.above_threshold(M, alpha_lo, h) for M, h in zip(Ms, alpha_hi)])
    fig, ax = _figure(width=6.4, height=3.6)
    ax = ax[0, 0]
    ax.plot(Ms, need, color="tab:blue", marker=".", label=r"required: $\overline{\alpha}(M)^2/\underline{\alpha}^2 + 1$")
    ax.plot(Ms, Ms, color="k", linewidth=1.0, label="the horizon $M$ itself")
    ax.fill_between(Ms, need, Ms, where=ok, color="tab:green", alpha=0.15, label="certified: $M$ above")
    ax.fill_between(Ms, need, Ms, where=~ok, color="tab:red", alpha=0.10, label="not certified")
    if M_star is not None:
        M_star = as_int("M_star", M_star, minimum=2)
        ax.axvline(M_star, color="tab:green", linestyle="--", linewidth=1.0)
        ax.text(M_star, ax.get_ylim()[1], f" first certified $M = {M_star}$", va="top", fontsize=9)
    ax.set_xlabel("horizon $M$")
    ax.set_ylabel("horizon")
    ax.legend(fontsize=8, loc="lower right")
    return fig


_LEMMA1_LABELS = {
    "value": r"$V^t_M(x_t)$",
    "upper": r"$\overline{\alpha}\sigma(x_t) + \overline{\gamma}\sum_k\|w_k\|^2$",
    "bound": r"bound $\Gamma_V\sigma(x_t) + \Gamma^\gamma_V\sum_{k=t}^{t+M-1}\|w_k\|^2$",
    "increment": r"$V^{t+1}_M - V^t_M$",
    "Gamma": r"\Gamma_V",
    "Gamma_gamma": r"\Gamma^\gamma_V",
}


def lemma1_check(lemma1, value_bound=None, title: str | None = None, fast: bool = False,
                 labels: dict | None = None, stacked: bool = False) -> Figure:
    """Lemma 1 along a trajectory, from :func:`orrc.checks.lemma1_margins` (``lemma1``).

    Left: V^t_M(x_t) with its lower bound α_lo σ(x_t) (Lemma 1, first part) and, when
    ``value_bound`` (:func:`orrc.checks.value_bound_margins`) is given, the upper bound
    ᾱ σ(x_t) + γ̄ Σ_k ‖w_k‖² of the class condition; log scale. Right: the increments
    V^{t+1}_M - V^t_M and the bound Γ_V σ(x_t) + Γ^γ_V Σ_{k=t}^{t+M-1} ‖w_k‖² (symmetric
    log scale: increments are often negative). The title gives Γ_V, Γ^γ_V and the
    smallest margin. ``labels`` replaces some of the legend's and title's labels (keys of
    ``_LEMMA1_LABELS``: value, upper, bound, increment, Gamma, Gamma_gamma), for the same check of
    another lemma (Lemma 6: :func:`orrc.viz.minmax_plots.lemma6_check`). ``stacked``: the two
    panels one above the other (narrow: for phones).
    """
    from ..checks import Lemma1Margins

    if not isinstance(lemma1, Lemma1Margins):
        raise OrrcValueError(f"lemma1 must be the result of orrc.checks.lemma1_margins; got {type(lemma1).__name__}")
    lab = dict(_LEMMA1_LABELS)
    if labels is not None:
        from .._validate import check_options

        check_options("labels", labels, _LEMMA1_LABELS)
        lab.update(labels)
    if value_bound is not None:
        value_bound = _margins("value_bound", value_bound)
    if stacked:
        fig, axes = _figure(2, 1, width=6.4, height=8.0, fast=fast,
                            margins={"top": 0.88 if title else 0.92, "bottom": 0.12, "hspace": 0.75, "left": 0.14})
        ax, ax2 = axes[:, 0]
    else:
        fig, axes = _figure(1, 2, width=10.0, height=4.0, fast=fast,
                            margins={"top": 0.80 if title else 0.86, "bottom": 0.27})
        ax, ax2 = axes[0]
    low = lemma1.lower
    floor = max(float(np.min(low.bound[low.bound > 0], initial=1.0)) * 1e-3, 1e-300)
    if value_bound is not None:
        ax.fill_between(value_bound.t, np.maximum(low.actual, floor), value_bound.bound, color="tab:blue",
                        alpha=0.08, linewidth=0)
        ax.plot(value_bound.t, value_bound.bound, color="tab:red", linewidth=1.2, label=lab["upper"])
    ax.plot(low.t, low.bound, color="tab:blue", linewidth=1.6, label=lab["value"])
    ax.plot(low.t, np.maximum(low.actual, floor), color="tab:green", linewidth=1.2,
            label=r"$\underline{\alpha}\,\sigma(x_t)$")
    ax.set_yscale("log")
    ax.set_xlabel("$t$")
    ax.set_title("the value between its bounds", fontsize=10)
    _legend_below(ax, ncol=2 if stacked else 3, offset=-0.25 if stacked else -0.2)
    inc = lemma1.increment
    ax2.plot(inc.t, inc.bound, color="tab:red", linewidth=1.2, label=lab["bound"])
    ax2.plot(inc.t, inc.actual, color="tab:blue", linewidth=1.4, marker=".", markersize=3, label=lab["increment"])
    ax2.axhline(0.0, color="k", linewidth=0.7)
    _symlog(ax2, inc.bound, inc.actual)
    ax2.set_xlabel("$t$")
    ax2.set_title(rf"increments: ${lab['Gamma']} = {lemma1.Gamma_V:.3g}$, "
                  rf"${lab['Gamma_gamma']} = {lemma1.Gamma_V_gamma:.3g}$", fontsize=10)
    _legend_below(ax2, offset=-0.25 if stacked else -0.2)
    m = min(float(inc.margin.min()), float(low.margin.min()))
    head = (title + "\n") if title else ""
    fig.suptitle(f"{head}smallest margin (bound minus actual): {m:.3g}", fontsize=10)
    return fig


# -- Lemma 2 ---------------------------------------------------------------------------------------
def lemma2_coefficients(coefs: dict, M: int, H: int, ax=None) -> Figure:
    """The coefficients M_{w,j} of Lemma 2 (:func:`orrc.theory.lemma2_coefficients`) against
    j - t = 0, ..., H + M - 2, one curve per label (``coefs``: label -> array of length
    H + M - 1), log scale. Shaded: the window w_t..w_{t+M-1} previewed at the anchor t,
    the decaying middle, and the disturbances previewed at t + H."""
    coefs = _nonempty_dict("coefs", coefs)
    M = as_int("M", M, minimum=2)
    H = as_int("H", H, minimum=M)
    fig, ax = _axes(ax, 6.4, 3.4)
    j = np.arange(H + M - 1)
    for i, (label, c) in enumerate(coefs.items()):
        c = as_array(f"coefs[{label!r}]", c, (H + M - 1,))
        ax.semilogy(j, c, color=f"C{i}", marker=".", markersize=3, label=label)
    for lo, hi, text, col in ((0, M - 1, "window at $t$", "tab:purple"), (M, H - 1, "decaying", "0.6"),
                              (H, H + M - 2, "window at $t+H$", "tab:orange")):
        if hi >= lo:
            ax.axvspan(lo - 0.5, hi + 0.5, color=col, alpha=0.08, linewidth=0)
            ax.text(0.5 * (lo + hi), 1.0, text, transform=ax.get_xaxis_transform(), ha="center", va="bottom",
                    fontsize=8, color="0.3")
    ax.set_xlabel("$j - t$")
    ax.set_ylabel(r"$M_{w,j}$")
    ax.legend(fontsize=8, loc="lower right")
    return fig


def bounds_vs_actual(x, actual, bounds: dict, xlabel: str = "$t$", ylabel: str = "", log: bool = True,
                     title: str | None = None, actual_label: str = "actual", ax=None,
                     legend: str = "best") -> Figure:
    """A measured sequence (``actual`` at the points ``x``) under one or more bounds
    (``bounds``: label -> array like ``actual``), on a log scale by default. Used for
    Lemma 2's bound on the stage cost c_{t+H} (Eq. of Lemma 2) and its parts.

    On a log scale, points where ``actual`` is not positive are left out (a stage cost
    of exactly 0). ``legend``: "best" (inside the axes) or "below" (under the axes,
    clear of the data; for figures with several curves).
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


def _admissible_frame(M: int, a: float, a_min: float, result: str, right_message: str,
                      margins: dict | None = None):
    """A two-panel explorer frame; when a < a_min it only says that ``result`` does not apply.

    Checks M >= 2 and 0 < a < 1, 0 <= a_min < 1. Returns ``(M, a, a_min, fig, (ax, ax2))``,
    with ``(None, None)`` for the axes when the frame is already complete. ``margins``
    (see :func:`orrc.viz.plots._figure`) apply to the frame of an admissible a only.
    """
    M = as_int("M", M, minimum=2)
    a = as_float("a", a, minimum=0.0, maximum=1.0, strict_min=True, strict_max=True)
    a_min = as_float("a_min", a_min, minimum=0.0, maximum=1.0, strict_max=True)
    fig, axes = _figure(1, 2, width=10.0, height=3.3, fast=True, margins=margins if a >= a_min else None)
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
    """One frame of the Lemma 2 explorer for the horizon M and decay rate a.

    When a >= ``a_min`` (:func:`orrc.theory.min_decay_rate`): left, the coefficients
    M_{w,j} (``coef``, length H + M - 1); right, the stage costs c_{t+H} under Lemma 2's
    bound along a trajectory (``margins`` from :func:`orrc.checks.lemma2_margins`),
    against the time t + H. When a < a_min the lemma does not apply and the frame says so.
    ``ylim``, ``coef_ylim``: fixed limits of the right and left panels, so that frames
    compare at a glance.
    """
    M, a, a_min, fig, (ax, ax2) = _admissible_frame(M, a, a_min, "Lemma 2", "no bound", margins={"top": 0.80})
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
    fig.suptitle(f"M = {M}, a = {a:g} (a_min = {a_min:.4f}), H = {H}: median bound / cost = {ratio:.3g}",
                 fontsize=11)
    return fig


# -- Theorem 1 -------------------------------------------------------------------------------------
def gamma_c_map(curves: dict, a_min: dict, Ms, gamma_c_best, floor=None, title: str | None = None) -> Figure:
    """γ_c = b((M-1)(1-a) + 1)/(1-a)² of Theorem 1 as a function of a and of M.

    Left: γ_c against a for each label of ``curves`` (label -> (a values, γ_c values)),
    with the smallest admissible a marked (``a_min``: label -> (a_min, γ_c(a_min))).
    Right: the best γ_c (at a = a_min) against M (``Ms``, ``gamma_c_best``), and,
    when given, the floor 2γ̄ of the remark after Theorem 1 (``floor``, aligned with Ms).
    """
    curves = _nonempty_dict("curves", curves)
    if not isinstance(a_min, dict):
        raise OrrcValueError(f"a_min must be a dict label -> (a_min, gamma_c); got {type(a_min).__name__}")
    Ms = np.array([as_int("M", m, minimum=2) for m in Ms])
    gcb = as_array("gamma_c_best", gamma_c_best, (len(Ms),))
    fig, axes = _figure(1, 2, width=10.0, height=3.6)
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
    ax.legend(fontsize=8)
    ax2.semilogy(Ms, gcb, color="tab:blue", marker=".", label=r"$\gamma_c$ at $a = a_{\min}(M)$")
    if floor is not None:
        floor = as_array("floor", floor, (len(Ms),))
        ax2.semilogy(Ms, floor, color="k", linestyle="--", label=r"$2\overline{\gamma}$")
    ax2.set_xlabel("horizon $M$")
    ax2.set_ylabel(r"$\gamma_c$")
    ax2.legend(fontsize=8)
    if title:
        fig.suptitle(title, fontsize=11)
    return fig


def attenuation_levels(Ms, levels: dict, threshold_M: int | None = None, title: str | None = None) -> Figure:
    """Attenuation levels against the horizon M on a log scale (``levels``: label -> values
    aligned with ``Ms``; inf or nan where a level does not exist): Theorem 1's certified
    γ_c beside the exact worst-case levels of :func:`orrc.certify.worst_case_attenuation_limit`.
    A label containing "LQR" with a single number is drawn as a horizontal line (it does
    not depend on M). Labels containing "certified", "floor", "stationary", "cold" or "LQR"
    get fixed styles. ``threshold_M``: the smallest M certified by Theorem 1; the horizons
    below it are shaded."""
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
        ax.text(0.5 * (Ms.min() + threshold_M), 1.0, "Theorem 1 silent", transform=ax.get_xaxis_transform(),
                ha="center", va="bottom", fontsize=8, color="0.3")
    _finish(ax, "horizon $M$", r"attenuation level $\gamma$", title, legend="below", offset=-0.16)
    return fig


def regret_growth(t, R: dict, ceiling=None, title: str | None = None, ylim=None, fast: bool = False, ax=None) -> Figure:
    """R^p_t(γ) = Σ_{s<t} c_s - γ Σ_{s<t} ‖w_s‖² against t (Eq. 2), one curve per label of
    ``R`` (label -> array aligned with ``t``), and, when given, Theorem 1's explicit
    ceiling C_t (``ceiling``: array aligned with t, from :func:`orrc.checks.theorem1_margin`)."""
    t = as_array("t", t, ndim=1)
    R = _nonempty_dict("R", R)
    fig, ax = _axes(ax, 6.4, 3.4, fast=fast)
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


def adversary(ws: dict, costs: dict, title: str | None = None, fast: bool = False) -> Figure:
    """Worst-case disturbances (``ws``: label -> (T, n) array, e.g. the ``w`` of
    :func:`orrc.certify.worst_case_attenuation`; the norm ‖w_t‖ is drawn when n > 1) and
    the stage costs they cause (``costs``: label -> (T,) array, same labels): the
    adversary of R^p_T(γ) (Eq. 2) made explicit."""
    ws = _nonempty_dict("ws", ws)
    costs = _nonempty_dict("costs", costs)
    fig, axes = _figure(1, 2, width=10.0, height=3.3, fast=fast, margins={"top": 0.80 if title else 0.88})
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
    ax.legend(fontsize=8)
    ax2.set_xlabel("$t$")
    ax2.set_ylabel("stage cost $c_t$")
    ax2.set_title("the cost it causes (from $x_0 = 0$)", fontsize=10)
    ax2.legend(fontsize=8)
    if title:
        fig.suptitle(title, fontsize=11)
    return fig


def theorem1_frame(M: int, a: float, a_min: float, a_grid=None, gamma_c_grid=None, margin=None,
                   ylim=None, gamma_c=None) -> Figure:
    """One frame of the Theorem 1 explorer for the horizon M and the decay rate a.

    When a >= ``a_min`` (:func:`orrc.theory.min_decay_rate`): left, γ_c = b((M-1)(1-a)+1)/(1-a)²
    against a (``a_grid``, ``gamma_c_grid``: the admissible range at this M) with the chosen
    a marked; right, R^p_t(γ_c) along a trajectory under Theorem 1's explicit ceiling C_t
    (``margin`` from :func:`orrc.checks.theorem1_margin` at γ = γ_c(a): ``actual`` is
    R^p_t, ``bound`` is C_t, against t = ``margin.t``). When a < a_min the theorem does
    not apply and the frame says so. ``ylim``: fixed limits of the right panel.
    ``gamma_c``: the exact γ_c at a (:func:`orrc.theory.gamma_c`, the γ of ``margin``), for
    the dot on the left and the legend on the right; without it, γ_c is interpolated in
    the grid, which is off between grid points.
    """
    M, a, a_min, fig, (ax, ax2) = _admissible_frame(M, a, a_min, "Theorem 1", "no guarantee",
                                                    margins={"top": 0.80, "wspace": 0.28})
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
    fig.suptitle(f"M = {M}, a = {a:g} (a_min = {a_min:.4f}): smallest margin C_t - R_t = {margin.margin.min():.4g}",
                 fontsize=11)
    return fig


def attenuation_vs_T(Ts, levels: dict, limits: dict | None = None, title: str | None = None) -> Figure:
    """The exact finite-T worst-case attenuation (:func:`orrc.certify.worst_case_attenuation`)
    against the horizon T (``levels``: label -> values aligned with ``Ts``), with its T → ∞
    limits as horizontal lines (``limits``: label -> number, from
    :func:`orrc.certify.worst_case_attenuation_limit` with ``start="cold"`` or
    ``"stationary"``; dashed when the label contains "stationary"). Log-scale T axis."""
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
