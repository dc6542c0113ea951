"""The style and the input checks shared by the figures of the unknown-system chapters (:mod:`orrc.viz.unknown_plots`,
:mod:`orrc.viz.lemma34_plots`, :mod:`orrc.viz.theorem2_plots`): narrow figures (4.8 in) with 12 pt
text, so that they stay legible on a phone.
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .._validate import OrrcValueError, as_array
from .figures import legend_below

__all__ = ["WIDTH", "FONT", "_COLORS", "_fig", "_style", "_decade", "_dict", "_vector", "_shade"]


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


def _shade(ax, N: int) -> None:
    ax.axvspan(-0.5, N - 0.5, color="0.9", zorder=0)
