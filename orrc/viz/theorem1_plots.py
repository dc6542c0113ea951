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
from .lemma2_plots import _admissible_frame
from .style import FONT, _axes, _figure, _nonempty_dict

__all__ = ["gamma_c_map", "attenuation_levels", "regret_growth", "adversary", "theorem1_frame",
           "attenuation_vs_T"]


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
        ax.text(0.5 * (Ms.min() + threshold_M - 1), 0.97, "Theorem 1\nsilent", transform=ax.get_xaxis_transform(),
                ha="center", va="top", fontsize=FONT, color="0.3")
    _finish(ax, "horizon $M$", r"attenuation level $\gamma$", title, legend="below", offset=-0.16)
    return fig


def regret_growth(t, R: dict, ceiling=None, title: str | None = None, ylim=None, ax=None) -> Figure:
    """R^p_t(γ) = Σ_{s<t} c_s - γ Σ_{s<t} ‖w_s‖² against t (Eq. 2), one curve per label of
    ``R`` (label -> array aligned with ``t``), and, when given, Theorem 1's explicit
    ceiling C_t (``ceiling``: array aligned with t, from :func:`orrc.checks.theorem1_margin`)."""
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
    """Worst-case disturbances (``ws``: label -> (T, n) array, e.g. the ``w`` of
    :func:`orrc.certify.worst_case_attenuation`; the norm ‖w_t‖ is drawn when n > 1) and
    the stage costs they cause (``costs``: label -> (T,) array, same labels): the
    adversary of R^p_T(γ) (Eq. 2) made explicit."""
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
    ax.legend(fontsize=FONT)
    ax2.set_xlabel("$t$")
    ax2.set_ylabel("stage cost $c_t$")
    ax2.set_title("the cost it causes (from $x_0 = 0$)", fontsize=10)
    ax2.legend(fontsize=FONT)
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
