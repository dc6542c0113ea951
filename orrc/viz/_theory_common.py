"""What the theory figures share: argument checks, a message panel, the symmetric-log axis, legends."""
from __future__ import annotations

import math

import numpy as np

from .._validate import OrrcValueError
from .style import FONT


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
    tenth of the non-zero values, and at least 1e-6 of the largest). Labelled ticks: 0 and
    the powers of ten from ten times the linear part outwards (every other one when there
    are many), so that no labels pile up near 0."""
    from matplotlib.ticker import FixedLocator, NullLocator

    v = np.concatenate([np.ravel(a) for a in arrays])
    v = v[np.isfinite(v)]
    mags = np.abs(v[v != 0])
    lin = max(float(np.quantile(mags, 0.1)), 1e-6 * float(mags.max())) if len(mags) else 1.0
    ax.set_yscale("symlog", linthresh=lin, linscale=0.5)
    first = math.ceil(math.log10(lin)) + 1
    ticks = [0.0]
    for sign, top in ((1.0, v.max(initial=0.0)), (-1.0, -v.min(initial=0.0))):
        if top > lin:
            ks = list(range(first, math.ceil(math.log10(top)) + 1)) or [first]
            step = 2 if len(ks) > 4 else 1
            ticks += [sign * 10.0 ** k for k in ks[len(ks) % step::step]]
    ax.yaxis.set_major_locator(FixedLocator(sorted(ticks)))
    ax.yaxis.set_minor_locator(NullLocator())


def _legend_below(ax, ncol: int = 2, offset: float = -0.2) -> None:
    """A frameless legend centred under the axes, its top ``offset`` (axes fraction) below them."""
    ax.legend(fontsize=FONT, loc="upper center", bbox_to_anchor=(0.5, offset), ncol=ncol, frameon=False)


def _finish(ax, xlabel: str, ylabel: str, title: str | None = None, legend: str = "best", ncol: int = 2,
            offset: float = -0.2) -> None:
    """The common tail of a one-panel figure: the axis labels, the legend ("best": inside the
    axes; "below": :func:`_legend_below` with ``ncol`` and ``offset``) and the title when given."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if legend == "below":
        _legend_below(ax, ncol=ncol, offset=offset)
    else:
        ax.legend(fontsize=FONT, loc="best")
    if title:
        ax.set_title(title, fontsize=10)
