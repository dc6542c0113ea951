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

The figures of Lemmas 3-4 live in :mod:`orrc.viz.lemma34_plots`, those of Theorem 2 in
:mod:`orrc.viz.theorem2_plots`, their shared style in ``_unknown_common``; this module gathers them.
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .._validate import OrrcValueError, as_array, as_float
from ._unknown_common import FONT, WIDTH, _COLORS, _dict, _fig, _shade, _style, _vector  # noqa: F401 (FONT, WIDTH)
from .lemma34_plots import lemma4_terms, lipschitz_quotients, loss_vs_error  # noqa: F401 (Lemmas 3-4)
from .theorem2_plots import best_N, excess_vs_T, theorem2_parts, tradeoff_curves  # noqa: F401 (Theorem 2)

__all__ = ["estimation_errors", "prediction_errors", "phase_frame", "lipschitz_quotients", "lemma4_terms",
           "loss_vs_error", "theorem2_parts", "excess_vs_T", "tradeoff_curves", "best_N"]


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
        # the shading named in the legend, one short entry each (one long label ran past the
        # right edge of a phone's figure)
        ax2.fill_between([], [], [], color="0.9", label=f"estimation, N = {N}")
    ax1.plot(t, reference.x[:, state], color="black", lw=1.2, ls="--", label="Algorithm 1, θ known")
    ax1.plot(t, traj.x[:, state], color="tab:blue", lw=1.4, label=label)
    lo, hi = ax1.get_ylim()
    ax1.set_ylim(lo, hi + 0.55 * (hi - lo))          # room for the legend above the curves
    _style(ax1, None, f"state $x_{{{state + 1}}}$", title, loc="upper right")
    excess = np.cumsum(traj.costs - reference.costs)
    ax2.plot(np.arange(traj.T), excess, color="tab:red", lw=1.5, label="excess cost")
    lo, hi = ax2.get_ylim()
    ax2.set_ylim(lo, hi + 0.8 * (hi - lo))           # room for the legend (two rows) above the curve
    _style(ax2, "t", r"$\sum_{s \leq t}\,(c_s - c_s^{\rm known})$", loc="upper left")
    return fig
