"""The narrow rendering of a figure, for a phone's column (:class:`narrowed`).

The panels of a row are stacked in one column, :data:`~orrc.viz.legibility.NARROW_IN` inches wide,
legends in one column, long titles wrapped (never inside a ``$...$`` span); everything is restored
when the block ends. :mod:`orrc.viz.figures` draws the narrow PNG inside it.
"""
from __future__ import annotations

import re

from .legibility import NARROW_IN, PANEL_IN, WIDE_IN, _figure_arg, legend_below

__all__ = ["narrowed"]

def _words(line: str) -> list[str]:
    """The words of ``line``, a $...$ math span kept in one piece."""
    words, cur, inside = [], "", False
    for tok in line.split(" "):
        cur = f"{cur} {tok}" if inside else tok
        inside ^= tok.count("$") % 2 == 1
        if not inside:
            words.append(cur)
    if inside:
        words.append(cur)
    return words


def _shown(word: str) -> int:
    """Roughly how many characters a (mathtext) word shows: commands, braces, $, ^ and _ dropped."""
    return max(1, len(re.sub(r"\\[a-zA-Z]+|[{}$^_]", "", word)))


def _wrap(text: str, width: int) -> str:
    """Wrap ``text`` at about ``width`` shown characters per line, never inside a $...$ span."""
    lines = []
    for line in text.split("\n"):
        cur, n = "", 0
        for w in _words(line):
            if cur and n + 1 + _shown(w) > width:
                lines.append(cur)
                cur, n = w, _shown(w)
            else:
                cur, n = (f"{cur} {w}", n + 1 + _shown(w)) if cur else (w, _shown(w))
        lines.append(cur)
    return "\n".join(lines)


def _chars(width_in: float, fontsize: float) -> int:
    """About how many characters of ``fontsize`` points fit on a line ``width_in`` inches long."""
    return max(12, int(width_in * 72 / (0.6 * fontsize)))


class narrowed:
    """``with narrowed(fig): ...`` re-lays ``fig`` for a phone inside the block and restores
    it afterwards: the grid of panels stacked in one column (reading order; twin axes follow
    their panel), ``width`` inches wide and about ``panel_height`` inches per panel (plus room
    for titles and for legends below the axes), under the constrained layout; legends in one
    column; titles and the figure title wrapped to the width. A one-panel figure is only
    narrowed.

    Parameters
    ----------
    fig : a matplotlib figure.
    width : the narrow width, inches.
    panel_height : the height per panel, inches.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> fig = Figure(figsize=(7, 3))
    >>> ax = fig.add_subplot()
    >>> _ = ax.plot([0, 1, 2], [1, 0, 2], label="cost")
    >>> _ = ax.set(xlabel="t", title="A run")
    >>> _ = ax.legend()
    >>> from orrc.viz.narrow import narrowed
    >>> with narrowed(fig):
    ...     print(fig.get_size_inches())
    [3.4 2.5]
    >>> print(fig.get_size_inches())
    [7. 3.]
    """

    def __init__(self, fig, width: float = NARROW_IN, panel_height: float = PANEL_IN):
        from .._validate import as_float

        self.fig = _figure_arg("fig", fig)
        self.width = as_float("width", width, minimum=1.0, maximum=WIDE_IN)
        self.panel_height = as_float("panel_height", panel_height, minimum=0.5, maximum=10.0)
        self._undo: list = []

    def _set(self, setter, old, new) -> None:
        """Call ``setter(new)`` now and ``setter(old)`` on exit."""
        self._undo.append((setter, old))
        setter(new)

    def __enter__(self):
        from matplotlib.gridspec import GridSpec

        fig = self.fig
        groups: dict = {}  # (gridspec, first row, first column) -> the axes drawn there
        for ax in fig.axes:
            spec = ax.get_subplotspec()
            if spec is not None:
                groups.setdefault((id(spec.get_gridspec()), spec.rowspan.start, spec.colspan.start), []).append(ax)
        panels = [groups[k] for k in sorted(groups, key=lambda k: (k[1], k[2]))]
        stack = GridSpec(len(panels), 1, figure=fig) if len(panels) > 1 else None
        extra = 0.0
        for i, group in enumerate(panels):
            for ax in group:
                spec = ax.get_subplotspec()
                self._set(ax.set_subplotspec, spec, stack[i] if stack is not None else spec)
                shared = len(ax.get_shared_y_axes().get_siblings(ax)) > 1
                ticks = ax.yaxis.get_major_ticks()
                if stack is not None and shared and ticks and not ticks[0].label1.get_visible():
                    self._set(lambda v, a=ax: a.yaxis.set_tick_params(labelleft=v), False, True)
                if ax.get_title():  # over the axes, which leave room for the tick labels
                    extra += self._wrap(ax.title, self.width - 0.6)
                leg = ax.get_legend()
                if leg is not None:
                    anchor = leg.get_bbox_to_anchor().transformed(ax.transAxes.inverted())
                    if leg._ncols > 1:
                        self._one_column(ax, leg)
                    if anchor.y1 < 0.05:  # a legend below the axes: room for its rows
                        extra += 0.19 * len(leg.get_texts()) + 0.15
        sup = getattr(fig, "_suptitle", None)
        if sup is not None and sup.get_text():
            extra += self._wrap(sup, self.width) + 0.22
        self._set(fig.set_layout_engine, fig.get_layout_engine() or "none", "constrained")
        size = (self.width, max(len(panels), 1) * self.panel_height + extra)
        self._set(lambda wh: fig.set_size_inches(*wh), tuple(fig.get_size_inches()), size)
        return fig

    def _one_column(self, ax, leg) -> None:
        """Replace the axes' legend by the same legend in one column (a legend's layout is fixed
        when it is made), and put the original back on exit."""
        texts = leg.get_texts()
        labels, size = [t.get_text() for t in texts], texts[0].get_fontsize() if texts else None
        if getattr(leg, "_orrc_below", False):   # made by legend_below: the same drop under the x label
            new = legend_below(ax, fontsize=size, handles=leg.legend_handles, labels=labels)
        else:
            anchor = leg.get_bbox_to_anchor().transformed(ax.transAxes.inverted())
            new = ax.legend(leg.legend_handles, labels, loc=leg._loc,
                            bbox_to_anchor=(anchor.x0, anchor.y0, anchor.width, anchor.height),
                            bbox_transform=ax.transAxes, ncols=1, frameon=leg.get_frame_on(), fontsize=size)
        self._undo.append((lambda old, a=ax: setattr(a, "legend_", old), leg))
        new.set_in_layout(leg.get_in_layout())

    def _wrap(self, text, width: float) -> float:
        """Wrap a Text to ``width`` inches; returns the height (inches) of the lines it gained."""
        old = text.get_text()
        new = _wrap(old, _chars(width, text.get_fontsize()))
        self._set(text.set_text, old, new)
        return 1.3 * text.get_fontsize() / 72 * (new.count("\n") - old.count("\n"))

    def __exit__(self, *exc):
        for setter, old in reversed(self._undo):
            setter(old)
        self._undo.clear()
        return False
