"""The style of the book's figures: one colour per controller, line styles, figure sizes.

Every plotting module of :mod:`orrc.viz` draws with these: a controller keeps its colour across the
book (:func:`controller_color`), and a new figure is at most :data:`WIDTH` inches wide (740 px at
100 dpi, inside the book's 757 px column) under the constrained layout (``_figure``).
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .._validate import OrrcValueError, as_float

__all__ = ["controller_color", "FONT", "WIDTH"]

# the first key a label contains decides: "feedback min-max" before "min-max"
_NAMED = {"feedback min-max": "tab:brown", "min-max": "tab:red", "game": "tab:purple", "h∞": "tab:purple",
          "zero": "0.55", "lqr": "tab:orange", "rhc": "tab:blue", "preview": "tab:blue", "clairvoyant": "black", "optimum": "black"}
_CYCLE = ["tab:blue", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan"]


def controller_color(label: str, index: int = 0) -> str:
    """A stable colour per controller, so a controller looks the same in every figure of the book:
    zero input grey, LQR orange, preview RHC (Algorithm 1) blue, min-max RHC (Algorithm 3) red and
    its feedback form brown, a game or H∞ controller purple, the clairvoyant optimum black; other
    labels cycle through a fixed palette.

    Parameters
    ----------
    label : the controller's label; matched case-insensitively by the words above ("LQR",
        "preview", "min-max", "clairvoyant", ...).
    index : the label's position among the others, which picks the palette colour of a label
        none of the words match.

    Returns
    -------
    str
        A matplotlib colour.

    Examples
    --------
    >>> from orrc.viz.plots import controller_color
    >>> [controller_color(label) for label in ("LQR", "preview RHC, M = 10")]
    ['tab:orange', 'tab:blue']
    >>> [controller_color(label) for label in ("open-loop min-max", "feedback min-max")]
    ['tab:red', 'tab:brown']
    >>> controller_color("mine", 1)
    'tab:green'
    """
    low = str(label).lower()
    for key, colour in _NAMED.items():
        if key in low:
            return colour
    return _CYCLE[index % len(_CYCLE)]


def _style(label: str) -> dict:
    low = str(label).lower()
    if "clairvoyant" in low or "optimum" in low:
        return {"linestyle": "--", "linewidth": 1.3}
    return {"linewidth": 1.5}


def _nonempty_dict(name: str, d, what: str = "data") -> dict:
    """``d`` when it is a non-empty dict, else an error naming ``name`` (and ``what`` its
    values should be)."""
    if not isinstance(d, dict) or not d:
        raise OrrcValueError(f"{name} must be a non-empty dict label -> {what}; got "
                             + (f"{type(d).__name__}" if not isinstance(d, dict) else "an empty dict"))
    return d


def _trajs(trajs) -> dict:
    from ..simulate import Trajectory

    trajs = _nonempty_dict("trajs", trajs, "Trajectory")
    for k, v in trajs.items():
        if not isinstance(v, Trajectory):
            raise OrrcValueError(f"trajs[{k!r}] must be an orrc Trajectory; got {type(v).__name__}")
    return trajs


FONT = 9          # legends, annotations and small titles: the smallest size of the book's figures
WIDTH = 7.4       # the widest figure (inches): 740 px at 100 dpi fits the book's 757 px column


_FAST_MARGINS = {"left": 0.09, "right": 0.98, "bottom": 0.17, "top": 0.86, "wspace": 0.32}


def _figure(nrows: int = 1, ncols: int = 1, width: float = WIDTH, height: float = 3.2, fast: bool = False,
            margins: dict | None = None, **kw):
    """A new Figure with a grid of axes, at most :data:`WIDTH` inches wide, under the constrained
    layout. ``fast``: fixed margins instead (``margins``: keywords of ``Figure.subplots_adjust``
    that replace the defaults), for a figure drawn on screen at this one size;
    :func:`orrc.viz.figures.render`, which draws the book's figures at two sizes, lays a
    fixed-margin figure out with the constrained engine anyway."""
    fig = Figure(figsize=(min(width, WIDTH), height), layout=None if fast else "constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False, **kw)
    if fast:
        fig.subplots_adjust(**{**_FAST_MARGINS, **(margins or {})})
    return fig, axes


def _axes(ax, width: float, height: float, fast: bool = False):
    """``(figure, axes)`` to draw on: ``ax`` and its figure when ``ax`` is given (a panel
    of a larger figure), else a new one-panel :func:`_figure` of that size."""
    if ax is not None:
        return ax.figure, ax
    fig, axes = _figure(width=width, height=height, fast=fast)
    return fig, axes[0, 0]


def _gammas(gammas) -> list[float]:
    gammas = list(np.atleast_1d(gammas))
    if not gammas:
        raise OrrcValueError("gammas must list at least one attenuation level γ >= 0; got none")
    return [as_float("gamma", g, minimum=0.0) for g in gammas]
