"""Legible figures: fonts of at least 9 pt and tidy tick labels, the sizes of the book's two renderings.

The book's text column is 757 px wide at 1366 px and 358 px at 390 px. A figure is legible when
its fonts are at least :data:`MIN_FONT_PT` (9 pt) *as displayed*: shown at :data:`DPI` (100) px per
figure inch or more, 9 pt is 12.5 px. :func:`legible` raises every smaller font and tidies the tick
labels (no 2.5 steps such as 42.5, no "3×10⁰" on a log axis spanning less than two decades);
:func:`legend_below` puts a legend under its axes at a drop that holds at every figure height.
:mod:`orrc.viz.figures` renders the result wide and narrow.
"""
from __future__ import annotations

import math

from matplotlib.ticker import LogFormatterSciNotation

__all__ = ["DPI", "MIN_FONT_PT", "WIDE_IN", "NARROW_IN", "PANEL_IN", "legible", "legend_below"]

DPI = 100                  # the rendering resolution: 100 px per figure inch
MIN_FONT_PT = 9.0          # the smallest font in any figure
WIDE_IN = 7.4              # 740 px at 100 dpi: fits the 757 px column at 1366 px
NARROW_IN = 3.4            # 340 px at 100 dpi: fits the 358 px column at 390 px
PANEL_IN = 2.5             # height of one stacked panel in the narrow rendering

def _figure_arg(name: str, fig):
    """``fig`` when it is a matplotlib Figure, else a clear error."""
    from matplotlib.figure import Figure

    from .._validate import OrrcValueError

    if not isinstance(fig, Figure):
        raise OrrcValueError(f"{name} must be a matplotlib Figure (what the plotting functions return); "
                             f"got {type(fig).__name__}")
    return fig


def legend_below(ax, fontsize: float = MIN_FONT_PT + 1, ncol: int = 1, **kw):
    """A frameless legend centred under the axes, below its tick labels and x label: the drop is
    in points (from their font sizes), not a fraction of the axes, so the legend clears the
    label at every figure height (the wide and the narrow rendering). Extra keywords go to
    ``ax.legend`` (e.g. ``handles``).

    Parameters
    ----------
    ax : the axes.
    fontsize : the legend's font size.
    ncol : the number of columns.
    **kw : further arguments of ``Axes.legend``.

    Returns
    -------
    matplotlib.legend.Legend
        the legend.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> fig = Figure(figsize=(7, 3))
    >>> ax = fig.add_subplot()
    >>> _ = ax.plot([0, 1, 2], [1, 0, 2], label="cost")
    >>> _ = ax.set(xlabel="t", title="A run")
    >>> _ = ax.legend()
    >>> from orrc.viz.legibility import legend_below
    >>> legend_below(ax).get_frame_on()
    False
    """
    from matplotlib.transforms import ScaledTranslation

    ticks = [t.get_fontsize() for t in ax.get_xticklabels()] or [ax.xaxis.label.get_fontsize()]
    label = ax.xaxis.label.get_fontsize() if ax.get_xlabel() else 0.0
    drop = 1.3 * (max(ticks) + label) + 10.0          # points: two text lines, the ticks and the pads
    to_anchor = ax.transAxes + ScaledTranslation(0, -drop / 72, ax.figure.dpi_scale_trans)
    leg = ax.legend(loc="upper center", bbox_to_anchor=(0.5, 0.0), bbox_transform=to_anchor, ncol=ncol,
                    frameon=False, fontsize=fontsize, **kw)
    leg._orrc_below = True   # narrowed() re-makes it in one column with the same drop
    return leg


# ---------------------------------------------------------------- legibility

class _PlainLogFormatter(LogFormatterSciNotation):
    """The log formatter's choice of which ticks to label, printed as plain numbers between
    0.001 and 10 000 (0.6, 3, 40, 2500) and as m×10ᵏ beyond."""

    def __call__(self, x, pos=None):
        text = super().__call__(x, pos)
        if text and 1e-3 <= abs(x) < 1e4:
            return f"{x:.4g}"
        return text


#: at most this many labelled decades on a symmetric-log axis (more overlap on a phone's figure)
SYMLOG_MAX_TICKS = 7


def _symlog_ticks(axis, lim) -> list[float]:
    """0 and the decades ±10^k outside the linear band of a symlog axis, thinned to every j-th
    decade (counted from the largest on each side) so that at most SYMLOG_MAX_TICKS remain."""
    lo, hi = sorted(lim)
    linthresh = axis.get_transform().linthresh
    sides = []
    for sign, bound in ((1.0, hi), (-1.0, -lo)):
        if bound > linthresh:
            top = math.floor(math.log10(bound))
            sides.append((sign, list(range(top, math.ceil(math.log10(linthresh)) - 1, -1))))
    count = sum(len(ks) for _, ks in sides) + (lo <= 0 <= hi)
    step = max(1, math.ceil(count / SYMLOG_MAX_TICKS))
    ticks = [sign * 10.0 ** k for sign, ks in sides for k in ks[::step]]
    return sorted(ticks + ([0.0] if lo <= 0 <= hi else []))


def _tidy_ticks(ax) -> None:
    """Linear axes: ticks in steps of 1, 2 or 5 (never 2.5: no 42.5, 47.5). Log axes that span
    less than two decades: plain labels (3, 30) instead of 3×10⁰. Symmetric-log axes: at most
    SYMLOG_MAX_TICKS labelled decades (:func:`_symlog_ticks`)."""
    from matplotlib.ticker import AutoLocator, FixedLocator, MaxNLocator, SymmetricalLogLocator

    for axis, lim in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
        scale = axis.get_scale()
        if scale == "symlog" and type(axis.get_major_locator()) is SymmetricalLogLocator:
            axis.set_major_locator(FixedLocator(_symlog_ticks(axis, lim)))
            axis.set_view_interval(*lim, ignore=True)
        elif scale == "linear" and type(axis.get_major_locator()) is AutoLocator:
            axis.set_major_locator(MaxNLocator(nbins="auto", steps=[1, 2, 5, 10]))
        elif scale == "log":
            lo, hi = sorted(abs(v) for v in lim)
            if lo > 0 and hi / lo < 100:
                for which, fmt in (("major", axis.get_major_formatter()), ("minor", axis.get_minor_formatter())):
                    if type(fmt) is LogFormatterSciNotation:
                        plain = _PlainLogFormatter(labelOnlyBase=which == "major" and hi / lo >= 10,
                                                   minor_thresholds=(1, 0.4))
                        (axis.set_major_formatter if which == "major" else axis.set_minor_formatter)(plain)


def _tick_label_pt(axis, which: str) -> float:
    """The size (points) of an axis's tick labels, read from its settings (creating no ticks)."""
    import matplotlib as mpl
    from matplotlib.font_manager import FontProperties

    kw = axis._major_tick_kw if which == "major" else axis._minor_tick_kw
    size = kw.get("labelsize", mpl.rcParams[f"{axis.axis_name}tick.labelsize"])
    return FontProperties(size=size).get_size_in_points()


def legible(fig, min_pt: float = MIN_FONT_PT):
    """Raise every font of ``fig`` below ``min_pt`` points to ``min_pt`` (titles, labels,
    legends, annotations and tick labels) and tidy the tick labels (:func:`_tidy_ticks`).
    Returns the figure.

    Parameters
    ----------
    fig : a matplotlib figure.
    min_pt : the smallest font size, in points.

    Returns
    -------
    matplotlib.figure.Figure
        ``fig`` itself.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> fig = Figure(figsize=(7, 3))
    >>> ax = fig.add_subplot()
    >>> _ = ax.plot([0, 1, 2], [1, 0, 2], label="cost")
    >>> _ = ax.set(xlabel="t", title="A run")
    >>> _ = ax.legend()
    >>> from orrc.viz.legibility import legible
    >>> _ = ax.set_xlabel("t", fontsize=6)
    >>> legible(fig).axes[0].xaxis.label.get_fontsize()
    9.0
    """
    from matplotlib.text import Text

    from .._validate import as_float

    fig = _figure_arg("fig", fig)
    min_pt = as_float("min_pt", min_pt, minimum=1.0, maximum=72.0)
    texts = list(fig.texts) + [getattr(fig, "_suptitle", None)]
    texts += [t for leg in fig.legends for t in [*leg.get_texts(), leg.get_title()]]
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            for which in ("major", "minor"):
                if _tick_label_pt(axis, which) < min_pt:
                    axis.set_tick_params(which=which, labelsize=min_pt)
            texts += [axis.label, axis.get_offset_text()]
        _tidy_ticks(ax)
        texts += [ax.title, ax._left_title, ax._right_title, *ax.texts]
        texts += [c for c in ax.get_children() if isinstance(c, Text)]     # annotations, table cells
        leg = ax.get_legend()
        if leg is not None:
            texts += [*leg.get_texts(), leg.get_title()]
    for t in texts:   # every text but the tick labels (set above), without walking every artist
        if t is not None and t.get_fontsize() < min_pt:
            t.set_fontsize(min_pt)
    return fig
