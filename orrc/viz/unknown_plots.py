"""Figures of the unknown-system chapters (Algorithm 2, Lemmas 3-5, Theorem 2).

Every function takes the data it draws (errors of :mod:`orrc.estimation`, trajectories of
:func:`orrc.simulate`, margins of :mod:`orrc.checks`, a :class:`orrc.tradeoff.Tradeoff`) and returns a
:class:`matplotlib.figure.Figure` built without pyplot; none of them computes an estimate, a
constant or a bound. The figures are narrow (4.8 in) with 12 pt text and stack their panels, so
that they stay legible on a phone; ``fast=True`` uses fixed margins (quicker: explorer frames).

Functions (the statement they illustrate):

* :func:`estimation_errors` -- g(N) = ‖θ̂ - θ‖ against N on log-log axes, with fitted slopes;
* :func:`prediction_errors` -- EDMD's h-step prediction error on fresh data against N, beside references;
* :func:`phase_frame` -- Algorithm 2 against Algorithm 1 on the true system: state and cumulative
  excess cost, the estimation phase shaded (an explorer frame);
* :func:`lipschitz_quotients` -- Lemma 3: measured |ΔV| and ‖Δκ‖ against ‖θ̂ - θ‖ under α_V, α_κ;
* :func:`lemma4_terms` -- Lemma 4 along the control phase: increments under the bound, split into
  Lemma 1's part and the Γ^θ_V ‖θ̂ - θ‖ part;
* :func:`loss_vs_error` -- what a wrong model costs per step, against ‖θ̂ - θ‖ (log-log);
* :func:`theorem2_parts` -- Theorem 2's bound in its three parts against T, and the actual R^p_T;
* :func:`excess_vs_T` -- the cost of not knowing θ against T for several N (an explorer frame);
* :func:`tradeoff_curves` -- the measured and fitted trade-off Δ(N, T) against N for several T;
* :func:`best_N` -- the best N against T on log-log axes, its fitted slope beside 2/3.
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .._validate import OrrcValueError, as_array, as_float
from .figures import legend_below

__all__ = ["estimation_errors", "prediction_errors", "phase_frame", "lipschitz_quotients", "lemma4_terms",
           "loss_vs_error", "theorem2_parts", "excess_vs_T", "tradeoff_curves", "best_N"]

WIDTH = 4.8           # inches: 480 px at 100 dpi, shown at >= 0.75 scale on a 390 px phone screen
FONT = 12             # pt, every text of a figure
_COLORS = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive"]


def _fig(nrows: int = 1, height: float = 3.4, fast: bool = False, sharex: bool = False):
    fig = Figure(figsize=(WIDTH, height), layout=None if fast else "constrained")
    axes = fig.subplots(nrows, 1, squeeze=False, sharex=sharex)[:, 0]
    if fast:
        fig.subplots_adjust(left=0.17, right=0.97, top=0.9 if nrows == 1 else 0.94, bottom=0.14 if nrows == 1
                            else 0.08, hspace=0.12 if sharex else 0.4)
    return fig, list(axes)


def _style(ax, xlabel: str | None = None, ylabel: str | None = None, title: str | None = None, legend=True,
           loc: str = "best") -> None:
    from matplotlib.ticker import NullFormatter

    ax.tick_params(labelsize=FONT)
    if ax.get_xscale() == "log":
        ax.xaxis.set_minor_formatter(NullFormatter())
    if xlabel:
        ax.set_xlabel(xlabel, fontsize=FONT)
    if ylabel:
        ax.set_ylabel(ylabel, fontsize=FONT)
    if title:
        ax.set_title(title, fontsize=FONT)
    if legend and ax.get_legend_handles_labels()[0]:
        if loc == "below":
            legend_below(ax, fontsize=FONT - 1,
                         ncol=1 if max(len(t) for t in ax.get_legend_handles_labels()[1]) > 28 else 2)
        else:
            ax.legend(fontsize=FONT - 1, loc=loc, frameon=False)
    ax.grid(True, which="major", alpha=0.3)


def _decade(values, q: float) -> float:
    """The power of ten at or below the q-quantile of the non-zero |values| (a symlog axis's linear range)."""
    v = np.abs(np.asarray(values, dtype=float))
    v = v[v > 0]
    if not v.size:
        return 1.0
    return float(10.0 ** np.floor(np.log10(np.quantile(v, q))))


def _dict(name: str, d) -> dict:
    if not isinstance(d, dict) or not d:
        raise OrrcValueError(f"{name} must be a non-empty dict label -> data; got "
                             f"{type(d).__name__ if not isinstance(d, dict) else 'an empty dict'}")
    return d


def _vector(name: str, v, length: int | None = None) -> np.ndarray:
    v = as_array(name, v)
    if v.ndim == 2:
        v = v.mean(axis=0)
    if v.ndim != 1 or (length is not None and v.size != length):
        raise OrrcValueError(f"{name} must have {length if length is not None else 'k'} entries (or shape (S, k): "
                             f"averaged over its rows); got shape {np.shape(v)}")
    return v


def estimation_errors(Ns, errors: dict, floor: float = 1e-15, fit_from: float | None = None,
                      title: str | None = None) -> Figure:
    """The estimation error g(N) = ‖θ̂ − θ‖ of Algorithm 2's first phase against the number N of
    exciting steps, on log-log axes, one curve per label.

    Values below ``floor`` (exact up to rounding) are drawn at the floor. Each curve whose errors
    all exceed 1e3·floor gets its log-log slope in the legend.

    Parameters
    ----------
    Ns : (k,) the numbers of exciting steps N.
    errors : dict label -> (k,) errors, or (S, k) errors per seed (averaged over the seeds).
    floor : the smallest error drawn, > 0.
    fit_from : the smallest N the slope is fitted over (default: all N).
    title : optional title.

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.viz import unknown_plots
    >>> Ns = np.array([10, 20, 40, 80])
    >>> fig = unknown_plots.estimation_errors(Ns, {"not given w": 1 / np.sqrt(Ns)})
    >>> fig.axes[0].get_legend().get_texts()[0].get_text()
    'not given w (slope -0.50)'
    """
    Ns = as_array("Ns", Ns, ndim=1)
    errors = _dict("errors", errors)
    sel = Ns >= (Ns[0] if fit_from is None else as_float("fit_from", fit_from))
    if sel.sum() < 2:
        raise OrrcValueError(f"fit_from={fit_from} leaves fewer than two N to fit a slope")
    fig, (ax,) = _fig()
    for i, (label, e) in enumerate(errors.items()):
        e = _vector(f"errors[{label!r}]", e, Ns.size)
        shown = np.maximum(e, floor)
        if np.all(e > 1e3 * floor):
            slope = np.polyfit(np.log(Ns[sel]), np.log(e[sel]), 1)[0]
            label = f"{label} (slope {slope:.2f})"
        ax.loglog(Ns, shown, "o-", color=_COLORS[i % 8], label=label, ms=4)
    ax.axhline(floor, color="0.6", lw=0.8, ls=":")
    _style(ax, "N (exciting steps)", r"$\Vert\hat\theta - \theta\Vert$", title)
    return fig


def prediction_errors(Ns, errors: dict, references: dict | None = None, horizon: int = 20,
                      title: str | None = None) -> Figure:
    """The h-step prediction error of a learned model on fresh data against the number N of training
    transitions, on log-log axes, with horizontal reference levels (e.g. the linearisation's error).

    Parameters
    ----------
    Ns : (k,) the numbers of training transitions.
    errors : dict label -> (k,) prediction errors, one curve each.
    references : optional dict label -> a number, drawn as a horizontal line.
    horizon : the prediction horizon h, named on the axis.
    title : optional title.

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> from orrc.viz import unknown_plots
    >>> fig = unknown_plots.prediction_errors([50, 100, 200], {"EDMD": [0.3, 0.1, 0.05]},
    ...                                       references={"linearisation": 0.4}, horizon=10)
    >>> fig.axes[0].get_ylabel()
    '10-step error'
    """
    Ns = as_array("Ns", Ns, ndim=1)
    errors = _dict("errors", errors)
    fig, (ax,) = _fig()
    for i, (label, e) in enumerate(errors.items()):
        ax.loglog(Ns, _vector(f"errors[{label!r}]", e, Ns.size), "o-", color=_COLORS[i % 8], label=label, ms=4)
    for j, (label, v) in enumerate((references or {}).items()):
        ax.axhline(as_float(f"references[{label!r}]", v), color="0.3", ls=["--", ":", "-."][j % 3], label=label)
    _style(ax, "N (training transitions)", f"{horizon}-step error", title)
    return fig


def _shade(ax, N: int) -> None:
    ax.axvspan(-0.5, N - 0.5, color="0.9", zorder=0)


def phase_frame(traj, reference, state: int = 0, title: str | None = None, fast: bool = False,
                label: str = "Algorithm 2") -> Figure:
    """A closed loop of Algorithm 2 against Algorithm 1 with the true model on the same
    disturbances: first, one state coordinate; second, the accumulated excess cost
    Σ_{s<=t} (c_s − c_s^ref). The estimation phase (the trajectory's ``info['N']`` steps) is
    shaded.

    Parameters
    ----------
    traj : the :class:`orrc.Trajectory` of the controller (e.g. Algorithm 2).
    reference : the :class:`orrc.Trajectory` of the reference (Algorithm 1 on the true system).
    state : the state coordinate drawn.
    title : optional title above the panels.
    fast : fixed margins instead of the constrained layout (for explorer frames).
    label : the legend's label of ``traj``.

    Returns
    -------
    matplotlib.figure.Figure
        Two panels.

    Examples
    --------
    >>> import orrc
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> w = orrc.disturbances.uniform_ball(60, 1, 0.5, seed=0)
    >>> alg2 = orrc.EstimateThenControl(orrc.ParametricSystem.linear(1, 1), ex.cost, M=8,
    ...                                 N=5, theta_true=[1.2, 1.0])
    >>> traj = orrc.simulate(ex.system, alg2, ex.x0, w, 50)
    >>> alg1 = orrc.simulate(ex.system, orrc.PreviewRHC(ex.system, ex.cost, 8), ex.x0,
    ...                      w, 50)
    >>> from orrc.viz import unknown_plots
    >>> fig = unknown_plots.phase_frame(traj, alg1, title="N = 5")
    >>> len(fig.axes)
    2
    """
    from ..simulate import Trajectory

    for name, t in (("traj", traj), ("reference", reference)):
        if not isinstance(t, Trajectory):
            raise OrrcValueError(f"{name} must be an orrc Trajectory; got {type(t).__name__}")
    if reference.T != traj.T:
        raise OrrcValueError(f"reference must have the same T = {traj.T}; got {reference.T}")
    N = int(traj.info.get("N", 0))
    fig, (ax1, ax2) = _fig(2, 5.6, fast, sharex=True)
    t = np.arange(traj.T + 1)
    if N > 0:
        for ax in (ax1, ax2):
            _shade(ax, N)
    ax1.plot(t, reference.x[:, state], color="black", lw=1.2, ls="--", label="Algorithm 1, θ known")
    ax1.plot(t, traj.x[:, state], color="tab:blue", lw=1.4, label=label)
    lo, hi = ax1.get_ylim()
    ax1.set_ylim(lo, hi + 0.55 * (hi - lo))          # room for the legend above the curves
    _style(ax1, None, f"state $x_{{{state + 1}}}$", title, loc="upper right")
    excess = np.cumsum(traj.costs - reference.costs)
    ax2.plot(np.arange(traj.T), excess, color="tab:red", lw=1.5,
             label="excess cost" + (f" (shaded: N = {N})" if N > 0 else ""))
    lo, hi = ax2.get_ylim()
    ax2.set_ylim(lo, hi + 0.45 * (hi - lo))          # room for the legend above the curve
    _style(ax2, "t", r"$\sum_{s \leq t}\,(c_s - c_s^{\rm known})$", loc="upper left")
    return fig


def lipschitz_quotients(dtheta, dV, dkappa, alpha_V: float, alpha_kappa: float, title: str | None = None) -> Figure:
    """Lemma 3 on samples: the changes |V(θ̂) − V(θ)| of the value and ‖κ(θ̂) − κ(θ)‖ of the first
    input against ‖θ̂ − θ‖, on log-log axes, under the lines α_V ‖θ̂ − θ‖ and α_κ ‖θ̂ − θ‖.

    Parameters
    ----------
    dtheta : (k,) the parameter errors ‖θ̂ − θ‖ of the samples, > 0.
    dV : (k,) the changes of the value.
    dkappa : (k,) the changes of the first input.
    alpha_V, alpha_kappa : Lemma 3's constants α_V and α_κ.
    title : optional title above the panels.

    Returns
    -------
    matplotlib.figure.Figure
        Two panels: the value and the input.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.viz import unknown_plots
    >>> d = np.array([0.01, 0.03, 0.1])
    >>> fig = unknown_plots.lipschitz_quotients(d, 0.5 * d, 0.8 * d, alpha_V=1.0,
    ...                                         alpha_kappa=2.0)
    >>> len(fig.axes)
    2
    """
    d = as_array("dtheta", dtheta, ndim=1)
    dV = as_array("dV", dV, (d.size,))
    dk = as_array("dkappa", dkappa, (d.size,))
    fig, axes = _fig(2, 6.0)
    line = np.geomspace(d.min(), d.max(), 50)
    for ax, y, a, name in ((axes[0], dV, alpha_V, r"\alpha_V"), (axes[1], dk, alpha_kappa, r"\alpha_\kappa")):
        ok = y > 0
        ax.loglog(d[ok], y[ok], "o", ms=3, color="tab:blue", alpha=0.6, label="samples")
        ax.loglog(line, a * line, color="tab:red",
                  label=rf"${name}\,\Vert\hat\theta-\theta\Vert$, ${name} = {a:.3g}$")
    _style(axes[0], None, "|V(θ̂) − V(θ)|", title, loc="upper left")
    _style(axes[1], "‖θ̂ − θ‖", "‖κ(θ̂) − κ(θ)‖", loc="upper left")
    return fig


def lemma4_terms(margins, theta_part: float, title: str | None = None) -> Figure:
    """Lemma 4 along the control phase of Algorithm 2: the increments V^{t+1}(θ̂) − V^t(θ̂) of the
    value on the estimated model under Lemma 4's bound, and the same bound without its θ-term
    Γ^θ_V ‖θ̂ − θ‖ (Lemma 1's part), on a symmetric log axis.

    Parameters
    ----------
    margins : the margins of :func:`orrc.checks.lemma4_margins`.
    theta_part : the θ-term Γ^θ_V ‖θ̂ − θ‖ of the bound (:func:`orrc.theory.Gamma_V_theta`
        times the error).
    title : optional title.

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> import orrc
    >>> ex = orrc.examples.scalar_unstable(A=1.2, B=1.0)
    >>> w = orrc.disturbances.uniform_ball(60, 1, 0.5, seed=0)
    >>> alg2 = orrc.EstimateThenControl(orrc.ParametricSystem.linear(1, 1), ex.cost, M=8,
    ...                                 N=5, theta_true=[1.2, 1.0])
    >>> traj = orrc.simulate(ex.system, alg2, ex.x0, w, 50)
    >>> from orrc import certify, checks, theory
    >>> from orrc.viz import unknown_plots
    >>> k = certify.lq_constants(ex.system, ex.cost, M=8)
    >>> L = certify.lq_lipschitz(ex.system, ex.cost, M=8, radius=0.05, rho=5.0)
    >>> at = theory.alpha_f_tilde(L.alpha_f_S, 8)
    >>> m = checks.lemma4_margins(traj, 8, k.alpha_lo, k.alpha_hi, k.gamma_bar, L.alpha_V,
    ...                           L.alpha_kappa, L.alpha_c, at)
    >>> G = theory.Gamma_V_theta(8, k.alpha_lo, k.alpha_hi, L.alpha_V, L.alpha_kappa,
    ...                          L.alpha_c, at)
    >>> fig = unknown_plots.lemma4_terms(m, G * traj.info["theta_error"])
    >>> fig.axes[0].get_yscale()
    'symlog'
    """
    from ..checks import Margins

    if not isinstance(margins, Margins):
        raise OrrcValueError(f"margins must be orrc.checks.Margins; got {type(margins).__name__}")
    theta_part = as_float("theta_part", theta_part, minimum=0.0)
    fig, (ax,) = _fig(1, 4.6)
    ax.plot(margins.t, margins.bound, color="tab:red", lw=1.5, label="Lemma 4 bound")
    ax.plot(margins.t, margins.bound - theta_part, color="tab:orange", lw=1.2, ls="--",
            label=r"without $\Gamma^\theta_V\,\Vert\hat\theta-\theta\Vert$")
    ax.plot(margins.t, margins.actual, color="tab:blue", lw=1.0,
            label=r"$V(x_{t+1};\hat\theta) - V(x_t;\hat\theta)$")
    ax.set_yscale("symlog", linthresh=_decade(np.concatenate([margins.bound, margins.actual]), 0.25), linscale=1.5)
    _style(ax, "t", "increment", title, loc="below")
    return fig


def loss_vs_error(errors, losses: dict, title: str | None = None) -> Figure:
    """The mean excess cost per step of Algorithm 1 planning with a wrong model against the model
    error ‖θ̂ − θ‖, on log-log axes, each curve with its fitted slope (1: first order, as Lemma 4
    charges it; 2: second order).

    Parameters
    ----------
    errors : (k,) the model errors ‖θ̂ − θ‖, > 0.
    losses : dict label -> (k,) mean excess costs per step (e.g. one per stage cost).
    title : optional title.

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.viz import unknown_plots
    >>> e = np.array([0.01, 0.03, 0.1, 0.3])
    >>> fig = unknown_plots.loss_vs_error(e,
    ...                                   {"quadratic": 2 * e ** 2, "Lipschitz": 0.5 * e})
    >>> [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    ['quadratic: slope 2.00', 'Lipschitz: slope 1.00']
    """
    e = as_array("errors", errors, ndim=1)
    losses = _dict("losses", losses)
    fig, (ax,) = _fig(1, 4.2)   # the legend below the axes
    for i, (label, y) in enumerate(losses.items()):
        y = _vector(f"losses[{label!r}]", y, e.size)
        ok = y > 0
        slope = np.polyfit(np.log(e[ok]), np.log(y[ok]), 1)[0] if ok.sum() >= 2 else float("nan")
        ax.loglog(e[ok], y[ok], "o-", ms=4, color=_COLORS[i % 8], label=f"{label}: slope {slope:.2f}")
    _style(ax, r"$\Vert\hat\theta - \theta\Vert$", "excess cost per step", title, loc="below")
    return fig


def theorem2_parts(Ts, parts: dict, actual, title: str | None = None) -> Figure:
    """Theorem 2's bound on R^p_T(γ) split into its parts (estimation, known system, model error),
    their sum, and the actual R^p_T(γ), against T on a symmetric log axis.

    Parameters
    ----------
    Ts : (k,) the lengths T.
    parts : dict label -> (k,) one part of the bound against ``Ts``.
    actual : (k,) the measured R^p_T(γ).
    title : optional title.

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.viz import unknown_plots
    >>> T = np.arange(10, 60, 10)
    >>> parts = {"estimation (O(N))": np.full(5, 40.0), "model error": 0.5 * T}
    >>> fig = unknown_plots.theorem2_parts(T, parts, actual=0.1 * T)
    >>> fig.axes[0].get_xlabel()
    'T'
    """
    Ts = as_array("Ts", Ts, ndim=1)
    parts = _dict("parts", parts)
    actual = as_array("actual", actual, (Ts.size,))
    fig, (ax,) = _fig(1, 4.6)
    total = np.zeros(Ts.size)
    for i, (label, y) in enumerate(parts.items()):
        y = as_array(f"parts[{label!r}]", y, (Ts.size,))
        total = total + y
        ax.plot(Ts, y, color=_COLORS[i % 8], lw=1.2, ls="--", label=label)
    ax.plot(Ts, total, color="tab:red", lw=1.6, label="bound (sum)")
    ax.plot(Ts, actual, color="black", lw=1.4, label=r"$R^p_T(\gamma)$")
    ax.set_yscale("symlog", linthresh=_decade(np.concatenate([total, actual]), 0.05), linscale=1.5)
    _style(ax, "T", None, title, loc="below")
    return fig


def excess_vs_T(curves: dict, T: int | None = None, title: str | None = None, fast: bool = False) -> Figure:
    """The cost of not knowing θ, Σ_{t<T} (c_t − c_t^known), against T for several runs (e.g. one
    per estimation length N of Algorithm 2).

    Parameters
    ----------
    curves : dict label -> (L,) cumulative excess cost.
    T : optional last T drawn (the whole curves by default).
    title : optional title.
    fast : fixed margins instead of the constrained layout (for explorer frames).

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> import numpy as np
    >>> from orrc.viz import unknown_plots
    >>> t = np.arange(100)
    >>> fig = unknown_plots.excess_vs_T({"N = 10": 0.5 * t, "N = 40": 10 + 0.1 * t}, T=80)
    >>> len(fig.axes[0].get_lines()) >= 2
    True
    """
    curves = _dict("curves", curves)
    fig, (ax,) = _fig(1, 3.6, fast)
    for i, (label, y) in enumerate(curves.items()):
        y = as_array(f"curves[{label!r}]", y, ndim=1)
        L = y.size if T is None else min(int(T), y.size)
        ax.plot(np.arange(1, L + 1), y[:L], color=_COLORS[i % 8], lw=1.4, label=label)
    _style(ax, "T", r"$\sum_{t<T}\,(c_t - c_t^{\rm known})$", title, loc="upper left")
    return fig


def tradeoff_curves(tradeoff, Ts, title: str | None = None) -> Figure:
    """The exploration trade-off Δ(N, T) of Theorem 2 against the estimation length N, on log-log
    axes, for each T: the measured seed means (dots), the fitted curve (line) and its minimiser
    (star); the raw minimiser is the lowest dot.

    Parameters
    ----------
    tradeoff : the :class:`orrc.tradeoff.Tradeoff` of :func:`orrc.tradeoff.exploration_tradeoff`.
    Ts : the lengths T, one curve each.
    title : optional title.

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> import orrc
    >>> from orrc import tradeoff
    >>> from orrc.viz import unknown_plots
    >>> di = orrc.examples.double_integrator()
    >>> study = tradeoff.exploration_tradeoff(di.system, orrc.ParametricSystem.linear(2, 1),
    ...                                       di.cost, M=5, Ns=[3, 6, 12], seeds=2,
    ...                                       window=30, backend="serial")
    >>> fig = unknown_plots.tradeoff_curves(study, [100, 1000])
    >>> fig.axes[0].get_xscale(), fig.axes[0].get_yscale()
    ('log', 'log')
    """
    from ..tradeoff import Tradeoff

    if not isinstance(tradeoff, Tradeoff):
        raise OrrcValueError(f"tradeoff must be an orrc.tradeoff.Tradeoff; got {type(tradeoff).__name__}")
    Ts = as_array("Ts", Ts, ndim=1)
    fig, (ax,) = _fig(1, 4.8)   # the legend below the axes
    grid = np.geomspace(tradeoff.Ns[0], tradeoff.Ns[-1], 300)
    best = tradeoff.best_N(Ts)
    for i, (T, b) in enumerate(zip(Ts, best)):
        c = _COLORS[i % 8]
        ax.loglog(tradeoff.Ns, tradeoff.excess(T), "o", ms=4, color=c)
        ax.loglog(grid, tradeoff.fitted_excess(grid, T), color=c, lw=1.2, label=f"T = {T:,.0f}")
        ax.loglog([b], tradeoff.fitted_excess(np.array([b]), T), "*", ms=12, color=c, mec="black")
    _style(ax, "N (exciting steps)", r"$\Delta(N, T)$", title, loc="below")
    return fig


def best_N(tradeoff, Ts, title: str | None = None) -> Figure:
    """The best estimation length N against T, on log-log axes: the fitted curve's minimisers with
    their fitted slope, the raw minimisers over the grid of N, and a line of the slope 2/3 of the
    remark after Theorem 2 through the first point.

    Parameters
    ----------
    tradeoff : the :class:`orrc.tradeoff.Tradeoff` of :func:`orrc.tradeoff.exploration_tradeoff`.
    Ts : the lengths T.
    title : optional title.

    Returns
    -------
    matplotlib.figure.Figure
        One panel.

    Examples
    --------
    >>> import orrc
    >>> from orrc import tradeoff
    >>> from orrc.viz import unknown_plots
    >>> di = orrc.examples.double_integrator()
    >>> study = tradeoff.exploration_tradeoff(di.system, orrc.ParametricSystem.linear(2, 1),
    ...                                       di.cost, M=5, Ns=[3, 6, 12], seeds=2,
    ...                                       window=30, backend="serial")
    >>> fig = unknown_plots.best_N(study, [100, 300, 1000])
    >>> fig.axes[0].get_xlabel()
    'T'
    """
    from ..tradeoff import Tradeoff

    if not isinstance(tradeoff, Tradeoff):
        raise OrrcValueError(f"tradeoff must be an orrc.tradeoff.Tradeoff; got {type(tradeoff).__name__}")
    Ts = as_array("Ts", Ts, ndim=1)
    b = tradeoff.best_N(Ts)
    raw = tradeoff.best_N(Ts, fitted=False)
    slope = tradeoff.slope(Ts)
    fig, (ax,) = _fig(1, 4.4)   # the legend below the axes
    ax.loglog(Ts, b, "o-", color="tab:blue", ms=5, label=f"best N (fitted curve), slope {slope:.2f}")
    ax.loglog(Ts, raw, "s", color="tab:orange", ms=5, mfc="none", label="best N on the grid (raw)")
    ax.loglog(Ts, b[0] * (Ts / Ts[0]) ** (2 / 3), color="0.3", ls="--", label="slope 2/3")
    _style(ax, "T", "best N", title, loc="below")
    return fig
