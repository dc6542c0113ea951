"""Figures of Lemmas 3 and 4 (the plan's Lipschitz dependence on the model, and the value's decrease
along the control phase of Algorithm 2 under a model error), and of what a wrong model costs per
step. Gathered with the other unknown-system figures in :mod:`orrc.viz.unknown_plots`.
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .._validate import OrrcValueError, as_array, as_float
from ..checks import Margins
from ._unknown_common import _COLORS, _decade, _dict, _fig, _style, _vector

__all__ = ["lipschitz_quotients", "lemma4_terms", "loss_vs_error"]


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
        # two decades of head room over the line: the legend in the upper left corner
        # sits above it instead of across it
        top = max(float(np.max(a * line)), float(np.max(y[ok], initial=0.0)))
        ax.set_ylim(top=100.0 * top)
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
