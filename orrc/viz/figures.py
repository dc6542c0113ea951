"""Figures a reader can read at a laptop's width (1366 px) and at a phone's (390 px).

The book's text column is 757 px wide at 1366 px and 358 px at 390 px. A figure is
legible when its fonts are at least 9 pt *as displayed*: at least 9 pt in the figure,
shown at 100 px per figure inch or more (9 pt = 12.5 px). So every figure is rendered
twice, at 100 dpi:

* a **wide** rendering, at most :data:`WIDE_IN` inches wide (wider figures are narrowed
  to it), shown at its natural size where the column has room for it;
* a **narrow** rendering for a phone (:class:`narrowed`): the panels of a row stacked in one
  column, :data:`NARROW_IN` inches wide, legends in one column, long titles wrapped.

:func:`figure_html` puts both in one ``div.orrc-figure`` whose CSS container query shows
the wide one when the column is at least as wide as it, and the narrow one otherwise.
:func:`legible` raises every font below :data:`MIN_FONT_PT` to it, and tidies tick
labels (no 2.5 steps such as 42.5, no "3×10⁰" on a log axis spanning less than two
decades) before either rendering.

In a Jupyter kernel, importing :mod:`orrc.viz` registers :func:`figure_html` as the HTML
form of every matplotlib Figure (:func:`install`), so that a cell whose value is a figure,
and every frame of :func:`orrc.viz.explore`, shows both renderings: in the book (which
prefers ``text/html``) and in JupyterLab alike.
"""
from __future__ import annotations

import base64
import contextlib
import html
import io
import math
import re
import uuid

from matplotlib.ticker import LogFormatterSciNotation

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


__all__ = ["DPI", "MIN_FONT_PT", "WIDE_IN", "NARROW_IN", "figure_to_png", "legible", "legend_below", "narrowed",
           "render", "render_live", "figure_html", "picture_html", "install"]


def figure_to_png(fig, dpi: int = DPI, close: bool = True, tight: bool = True, fast: bool = False) -> bytes:
    """Render a matplotlib figure to PNG bytes with an adaptive 256-colour palette (a third
    of the bytes, no visible change for line plots); ``tight``: crop to the drawn artists
    (else exactly the figure's size); ``close``: close it afterwards (a figure made with
    pyplot); ``fast``: full colour and the lightest compression instead (about twice as fast,
    twice the bytes: for a live widget, where the image never leaves the machine)."""
    from .._validate import as_int

    fig = _figure_arg("fig", fig)
    dpi = as_int("dpi", dpi, minimum=DPI)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight" if tight else None,
                **({"pil_kwargs": {"compress_level": 1}} if fast else {}))
    if close:
        import matplotlib.pyplot as plt

        plt.close(fig)
    if fast:
        return buf.getvalue()
    from PIL import Image

    img = Image.open(io.BytesIO(buf.getvalue())).convert("RGB").quantize(colors=256,
                                                                         method=Image.Quantize.FASTOCTREE)
    out = io.BytesIO()
    img.save(out, format="PNG", dpi=(dpi, dpi))
    return out.getvalue()


def legend_below(ax, fontsize: float = MIN_FONT_PT + 1, ncol: int = 1, **kw):
    """A frameless legend centred under the axes, below its tick labels and x label: the drop is
    in points (from their font sizes), not a fraction of the axes, so the legend clears the
    label at every figure height (the wide and the narrow rendering). Extra keywords go to
    ``ax.legend`` (e.g. ``handles``)."""
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
    Returns the figure."""
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


# ---------------------------------------------------------------- the narrow rendering

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
    narrowed."""

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


# ---------------------------------------------------------------- rendering and HTML

@contextlib.contextmanager
def _wide(fig):
    """Inside the block ``fig`` is laid out for the wide rendering: :func:`legible`, the constrained
    layout when it has no layout engine, at most :data:`WIDE_IN` wide, axes titles wrapped to that
    width; its layout engine and size are restored afterwards (its fonts and wrapped titles stay)."""
    legible(fig)
    size, engine = tuple(fig.get_size_inches()), fig.get_layout_engine()
    if engine is None:
        fig.set_layout_engine("constrained")
    fig.set_size_inches(min(size[0], WIDE_IN), size[1])
    for ax in fig.axes:   # a title longer than the figure is wide would be cut at its edge: wrap it
        if ax.get_title():
            ax.title.set_text(_wrap(ax.get_title(), _chars(fig.get_size_inches()[0] - 0.6, ax.title.get_fontsize())))
    try:
        yield fig
    finally:
        fig.set_layout_engine(engine or "none")
        fig.set_size_inches(*size)


def _close(fig, close: bool) -> None:
    if close:
        import matplotlib.pyplot as plt

        plt.close(fig)


def render(fig, dpi: int = DPI, close: bool = True) -> tuple[bytes, bytes | None]:
    """The wide and the narrow PNG of ``fig``, each exactly its figure's size (a figure
    without a layout engine is given the constrained layout; fixed margins are tuned for
    one size only). :func:`legible` first; a figure wider than :data:`WIDE_IN` is drawn at
    that width. The narrow PNG (:class:`narrowed`) is None for a figure already
    :data:`NARROW_IN` wide or less. Afterwards ``fig`` has its layout and size back (its
    fonts stay raised, titles longer than the figure stay wrapped); it is closed when ``close``."""
    from .._validate import as_int

    fig = _figure_arg("fig", fig)
    dpi = as_int("dpi", dpi, minimum=DPI)
    with _wide(fig):
        wide = figure_to_png(fig, dpi, close=False, tight=False)
        small = None
        if fig.get_size_inches()[0] > NARROW_IN + 0.05:
            with narrowed(fig):
                small = figure_to_png(fig, dpi, close=False, tight=False)
    _close(fig, close)
    return wide, small


def render_live(fig, dpi: int = DPI, close: bool = True) -> bytes:
    """The wide PNG of :func:`render` alone, rendered fast (``figure_to_png(fast=True)``): the image a
    live widget shows (a notebook's column is a laptop's; the narrow variant is for the book's
    phone readers). Same layout, size and fonts as the wide PNG of :func:`render`."""
    from .._validate import as_int

    fig = _figure_arg("fig", fig)
    dpi = as_int("dpi", dpi, minimum=DPI)
    with _wide(fig):
        png = figure_to_png(fig, dpi, close=False, tight=False, fast=True)
    _close(fig, close)
    return png


_PNG = b"\x89PNG\r\n\x1a\n"


def _png_width(png: bytes) -> int:
    return int.from_bytes(png[16:20], "big")  # the IHDR chunk: width, height as 4-byte integers


def picture_html(wide: bytes, small: bytes | None, alt: str | None = None, cls: str = "",
                 uid: str | None = None) -> str:
    """One ``div.orrc-figure`` holding ``img[data-variant=wide]`` and, when ``small`` is given,
    ``img[data-variant=narrow]``; a container query shows the wide image only where the
    container is at least as wide as the wide image's natural width. ``alt``: the text
    alternative of both images (required: :func:`orrc.viz.describe.describe` writes one from the
    figure; ``""`` marks a decorative image). ``cls``: extra classes of both images
    (``orrc-frame`` for the explorer)."""
    from .._validate import OrrcValueError


    for name, png in (("wide", wide), ("small", small)):
        if (png is not None or name == "wide") and not (isinstance(png, bytes) and png[:8] == _PNG):
            raise OrrcValueError(f"{name} must be the bytes of a PNG image (from render); got "
                                 + (f"{len(png)} bytes not starting with the PNG signature"
                                    if isinstance(png, bytes) else type(png).__name__))
    uid = uid or "orrc-fig-" + uuid.uuid4().hex[:10]
    if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_-]*", uid):
        raise OrrcValueError(f"uid must be an HTML id (a letter, then letters, digits, - or _); got {uid!r}")
    if not isinstance(alt, str):
        raise OrrcValueError("alt must be the figure's text alternative, a string (describe(fig) writes one; "
                             f'"" marks a decorative image); got {type(alt).__name__}')
    extra = f" {cls}" if cls else ""
    src = "data:image/png;base64,"
    imgs = (f'<img class="orrc-img{extra}" data-variant="wide" alt="{html.escape(alt)}" '
            f'style="max-width:100%;height:auto" src="{src}{base64.b64encode(wide).decode("ascii")}">')
    style = ""
    if small is not None:
        imgs += (f'<img class="orrc-img{extra}" data-variant="narrow" alt="{html.escape(alt)}" '
                 f'style="max-width:100%;height:auto" src="{src}{base64.b64encode(small).decode("ascii")}">')
        px = _png_width(wide)
        style = (f"<style>#{uid}{{container-type:inline-size}}"
                 f"#{uid} img[data-variant=narrow]{{display:none}}"
                 f"@container (max-width: {px - 1}px){{#{uid} img[data-variant=wide]{{display:none}}"
                 f"#{uid} img[data-variant=narrow]{{display:block}}}}</style>")
    return f'<div class="orrc-figure" id="{uid}">{style}{imgs}</div>'


def figure_html(fig, dpi: int = DPI, close: bool = True) -> str:
    """The HTML form of a figure: :func:`render` into :func:`picture_html`, with the text
    alternative :func:`orrc.viz.describe.describe` writes from the figure."""
    from .describe import describe

    alt = describe(fig)
    return picture_html(*render(fig, dpi, close=close), alt=alt)


def install(ip=None) -> bool:
    """Make :func:`figure_html` the ``text/html`` form of every matplotlib Figure in the
    IPython shell ``ip`` (the running one by default) and drop the plain PNG form, so a
    figure cell's output is the wide and narrow pair. Returns False outside IPython."""
    if ip is None:
        try:
            from IPython import get_ipython
        except ImportError:  # pragma: no cover - IPython comes with the book's dependencies
            return False
        ip = get_ipython()
    if ip is None or not hasattr(ip, "display_formatter"):
        return False
    from matplotlib.figure import Figure

    def _reassert(*_):
        formatters = ip.display_formatter.formatters
        formatters["text/html"].for_type(Figure, lambda fig: figure_html(fig, close=False))
        formatters["image/png"].pop(Figure, None)  # %matplotlib inline registers it (again)

    _reassert()
    if _reassert.__qualname__ not in {getattr(f, "__qualname__", "") for f in ip.events.callbacks["pre_run_cell"]}:
        ip.events.register("pre_run_cell", _reassert)
    return True
