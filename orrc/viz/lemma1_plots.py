"""Figures of Lemma 1 (Section 5.1): the admissible pairs (ᾱ, γ̄) and the horizon threshold, and
Lemma 1's two inequalities along a trajectory.

* :func:`pareto_curves` -- the admissible pairs of V_M <= ᾱ σ + γ̄ Σ‖w‖², measured against the threshold, and γ_c along them;
* :func:`horizon_threshold` -- M > ᾱ²/α_lo² + 1 when ᾱ itself depends on M;
* :func:`lemma1_check` -- V_M between its bounds, and its increments under Lemma 1's bound.
"""
from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from .. import theory
from .._validate import OrrcValueError, as_array, as_float, as_int
from ._theory_common import _constants, _legend_below, _margins, _message, _symlog
from .style import FONT, WIDTH, _figure, _nonempty_dict

__all__ = ["pareto_curves", "horizon_threshold", "lemma1_check"]


def pareto_curves(constants: dict, title: str | None = None, gamma_c: bool = True) -> Figure:
    """The admissible pairs (γ̄, ᾱ) of the class condition V_M(x, W) <= ᾱ σ(x) + γ̄ Σ_k ‖w_k‖²
    (Section 5.1, Lemma 1), measured against the horizon threshold.

    Left: the Pareto curve as ᾱ(γ̄) / (α_lo √(M-1)) against γ̄ on log-log axes (every pair on or
    above the curve is admissible): Lemma 1's Γ_V is negative, and Lemma 2 and Theorem 1 apply,
    exactly where it is below 1 (M > ᾱ²/α_lo² + 1). The curves of different M then separate,
    although ᾱ(γ̄) itself hardly changes with M. The star is the chosen pair (the one that
    minimises γ_c; the knee, the smallest product ᾱ γ̄, when no pair is below 1). Right: Theorem
    1's γ_c along each curve (with a = min_decay_rate), finite only below 1.

    Parameters
    ----------
    constants : dict label -> :class:`orrc.certify.Constants`, one per horizon M (with their
        Pareto curves, as :func:`orrc.certify.lq_constants` returns them).
    title : optional title above the panels.
    gamma_c : draw the right panel (Theorem 1's γ_c); False leaves it out, for a page that has
        not met Theorem 1 yet.

    Returns
    -------
    matplotlib.figure.Figure
        Two panels, or one with ``gamma_c=False``.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify
    >>> from orrc.viz import theory_plots
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> ks = {f"M = {M}": certify.lq_constants(ex.system, ex.cost, M=M) for M in (4, 8)}
    >>> fig = theory_plots.pareto_curves(ks, gamma_c=False)
    >>> len(fig.axes), fig.axes[0].get_xscale()
    (1, 'log')
    """
    from matplotlib.ticker import LogLocator, NullFormatter

    constants = _nonempty_dict("constants", constants)
    cs = {label: _constants(f"constants[{label!r}]", c) for label, c in constants.items()}
    if not isinstance(gamma_c, bool):
        raise OrrcValueError(f"gamma_c must be True or False; got {gamma_c!r}")
    fig, axes = _figure(1, 2 if gamma_c else 1, width=WIDTH if gamma_c else 5.2, height=3.6)
    ax, ax2 = (axes[0, 0], axes[0, 1]) if gamma_c else (axes[0, 0], None)
    styles = ["-", "--", "-.", ":"]
    # x range: from the left end of the curves to a decade past the stars and the plateaus
    x_lo = min(c.pareto[0, 0] for c in cs.values())
    x_hi = x_lo
    for c in cs.values():
        gb, ah = c.pareto[:, 0], c.pareto[:, 1]
        flat = gb[ah <= 1.01 * ah.min()]
        x_hi = max(x_hi, c.gamma_bar, flat[0] if len(flat) else gb[-1])
    x_hi = min(10.0 * x_hi, max(c.pareto[-1, 0] for c in cs.values()))
    rel = {label: c.pareto[:, 1] / (c.alpha_lo * math.sqrt(c.M - 1)) for label, c in cs.items()}
    y_lo = min(r.min() for r in rel.values()) / 1.2
    y_hi = 3.0 * max(r.min() for r in rel.values())
    any_gc = estimate = False
    for i, (label, c) in enumerate(cs.items()):
        estimate |= c.estimate
        col, ls = f"C{i}", styles[i % len(styles)]
        gb, r = c.pareto[:, 0], rel[label]
        ax.plot(gb, r, color=col, linestyle=ls, linewidth=1.6, label=label)
        ax.vlines(gb[0], r[0], y_hi, color=col, linestyle=ls, linewidth=1.6)  # left end of a sampled curve
        ax.plot([c.gamma_bar], [c.alpha_hi / (c.alpha_lo * math.sqrt(c.M - 1))], marker="*", markersize=11,
                color=col, markeredgecolor="k", linestyle="none")
        fin = np.isfinite(c.pareto_gamma_c)
        if ax2 is not None and fin.any():
            any_gc = True
            ax2.loglog(gb[fin], c.pareto_gamma_c[fin], color=col, linestyle=ls, label=label)
            ax2.plot([c.gamma_bar], [c.gamma_c], marker="*", markersize=11, color=col, markeredgecolor="k")
    ax.axhline(1.0, color="k", linewidth=1.0)
    ax.axhspan(y_lo, 1.0, color="tab:green", alpha=0.08, linewidth=0)
    ax.text(0.03, 0.04, r"below 1: $\Gamma_V < 0$", transform=ax.transAxes, fontsize=FONT, color="tab:green",
            va="bottom")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(x_lo / 1.3, x_hi)
    ax.set_ylim(y_lo, y_hi)
    ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
    for a in (ax, ax2) if gamma_c else (ax,):
        a.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel(r"$\overline{\gamma}$")
    ax.set_ylabel(r"$\overline{\alpha}(\overline{\gamma})\,/\,\underline{\alpha}\sqrt{M-1}$")
    ax.set_title("admissible pairs: on or above each curve\n(star: the chosen pair)", fontsize=FONT + 1)
    ax.legend(fontsize=FONT, loc="upper right")
    if ax2 is None:
        pass
    elif any_gc:
        ax2.set_xlim(x_lo / 1.3, x_hi)
        ax2.set_xlabel(r"$\overline{\gamma}$ (pair on the curve)")
        ax2.set_ylabel(r"$\gamma_c$ of Theorem 1")
        ax2.set_title(r"$\gamma_c$ along the curve (star: the best)", fontsize=FONT + 1)
        ax2.legend(fontsize=FONT)
    else:
        _message(ax2, "no pair is below the\nhorizon threshold:\nTheorem 1 certifies\nnothing at these M")
    if title or estimate:
        fig.suptitle((title or "") + ("  [ESTIMATED constants: sampled, not certified]" if estimate else ""),
                     fontsize=FONT + 2)
    return fig


def horizon_threshold(Ms, alpha_hi, alpha_lo, M_star: int | None = None) -> Figure:
    """The horizon condition of Lemma 1, M > ᾱ²/α_lo² + 1 (Γ_V < 0; Lemma 2, Theorem 1), when ᾱ
    depends on M: the required horizon ᾱ(M)²/α_lo² + 1 against M with the diagonal. M is
    certified where the curve is below the diagonal.

    Parameters
    ----------
    Ms : the horizons M.
    alpha_hi : the smallest admissible ᾱ at each horizon, aligned with ``Ms``.
    alpha_lo : the lower constant α_lo of Lemma 1, > 0.
    M_star : optional smallest certified M, marked.

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> from orrc.viz import theory_plots
    >>> fig = theory_plots.horizon_threshold([2, 4, 8, 16], [3.0, 2.6, 2.4, 2.3],
    ...                                      1.0, M_star=8)
    >>> fig.axes[0].get_xlabel()
    'horizon $M$'
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
    # under the axes: in a corner it covered the required horizon's plateau on a phone's figure
    _legend_below(ax, ncol=2, offset=-0.22)
    return fig


def _spread_ticks(ax, gap: float = 0.1) -> None:
    """Keep the labelled ticks of a symmetric-log y axis at least ``gap`` (a fraction of the axis
    height) apart: 0 first, then the largest magnitudes, so that no labels crowd near 0."""
    from matplotlib.ticker import FixedLocator

    lo, hi = ax.get_ylim()
    to_axis = ax.yaxis.get_transform().transform
    span = float(to_axis(np.array([hi]))[0] - to_axis(np.array([lo]))[0]) or 1.0
    ticks = [t for t in ax.get_yticks() if lo <= t <= hi]
    kept: list[float] = []
    for t in sorted(ticks, key=lambda v: (v != 0.0, -abs(v))):
        pos = float(to_axis(np.array([t]))[0] - to_axis(np.array([lo]))[0]) / span
        if all(abs(pos - q) >= gap for q in (float(to_axis(np.array([k]))[0] - to_axis(np.array([lo]))[0]) / span
                                             for k in kept)):
            kept.append(t)
    ax.yaxis.set_major_locator(FixedLocator(sorted(kept)))


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
    """Lemma 1 along a trajectory: the value V^t_M(x_t) between its bounds, and its increments
    under the bound Γ_V σ(x_t) + Γ^γ_V Σ_{k=t}^{t+M-1} ‖w_k‖².

    Left: V^t_M(x_t) with its lower bound α_lo σ(x_t) (Lemma 1, first part) and, when
    ``value_bound`` is given, the upper bound ᾱ σ(x_t) + γ̄ Σ_k ‖w_k‖² of the class condition;
    log scale. Right: the increments V^{t+1}_M − V^t_M and their bound (symmetric log scale:
    increments are often negative). The title gives Γ_V, Γ^γ_V and the smallest margin.

    Parameters
    ----------
    lemma1 : the margins of :func:`orrc.checks.lemma1_margins`.
    value_bound : optional margins of :func:`orrc.checks.value_bound_margins` (the upper bound).
    title : optional title above the panels.
    fast : fixed margins instead of the constrained layout (for explorer frames).
    labels : optional dict replacing some of the legend's and title's labels (keys value, upper,
        bound, increment, Gamma, Gamma_gamma), for the same check of another lemma (Lemma 6:
        :func:`orrc.viz.minmax_plots.lemma6_check`).
    stacked : the two panels one above the other instead of side by side.

    Returns
    -------
    matplotlib.figure.Figure
        Two panels.

    Examples
    --------
    >>> import orrc
    >>> from orrc import certify, checks
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)
    >>> w = orrc.disturbances.uniform_ball(60, 1, 0.5, seed=0)
    >>> traj = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 8), ex.x0,
    ...                      w, 50)
    >>> from orrc.viz import theory_plots
    >>> lemma1 = checks.lemma1_margins(traj, 8, k.alpha_lo, k.alpha_hi, k.gamma_bar)
    >>> bound = checks.value_bound_margins(traj, 8, k.alpha_hi, k.gamma_bar)
    >>> fig = theory_plots.lemma1_check(lemma1, bound, title="scalar system, M = 8")
    >>> len(fig.axes)
    2
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
        fig, axes = _figure(1, 2, height=4.0, fast=fast,
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
    ax.set_title("the value between its bounds", fontsize=FONT + 1)
    _legend_below(ax, ncol=2 if stacked else 3, offset=-0.25 if stacked else -0.2)
    inc = lemma1.increment
    ax2.plot(inc.t, inc.bound, color="tab:red", linewidth=1.2, label=lab["bound"])
    ax2.plot(inc.t, inc.actual, color="tab:blue", linewidth=1.4, marker=".", markersize=3, label=lab["increment"])
    ax2.axhline(0.0, color="k", linewidth=0.7)
    _symlog(ax2, inc.bound, inc.actual)
    _spread_ticks(ax2)
    ax2.set_xlabel("$t$")
    ax2.set_title(rf"increments: ${lab['Gamma']} = {lemma1.Gamma_V:.3g}$, "
                  rf"${lab['Gamma_gamma']} = {lemma1.Gamma_V_gamma:.3g}$", fontsize=FONT + 1)
    _legend_below(ax2, ncol=1, offset=-0.25 if stacked else -0.2)
    m = min(float(inc.margin.min()), float(low.margin.min()))
    head = (title + "\n") if title else ""
    fig.suptitle(f"{head}smallest margin (bound minus actual): {m:.3g}", fontsize=FONT + 1)
    return fig
