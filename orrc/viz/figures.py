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
import re
import uuid

# the sizes and the legibility pass, and the narrow rendering, live in modules of their own; their
# names stay importable from here
from .legibility import (DPI, MIN_FONT_PT, NARROW_IN, PANEL_IN, SYMLOG_MAX_TICKS, WIDE_IN,  # noqa: F401
                         _figure_arg, _symlog_ticks, _tidy_ticks, legend_below, legible)
from ._raster import agg_rgba, palette
from .narrow import _chars, _wrap, narrowed  # noqa: F401

__all__ = ["DPI", "MIN_FONT_PT", "WIDE_IN", "NARROW_IN", "figure_to_png", "legible", "legend_below", "narrowed",
           "render", "render_live", "figure_html", "picture_html", "install"]


def figure_to_png(fig, dpi: int = DPI, close: bool = True, tight: bool = True, fast: bool = False) -> bytes:
    """Render a matplotlib figure to PNG bytes with an adaptive 256-colour palette (a third
    of the bytes, no visible change for line plots); ``tight``: crop to the drawn artists
    (else exactly the figure's size, drawn once instead of savefig's twice);
    ``close``: close it afterwards (a figure made with pyplot); ``fast``: full colour and the
    lightest compression instead (about twice as fast, twice the bytes: for a live widget, where
    the image never leaves the machine).

    Parameters
    ----------
    fig : a matplotlib figure.
    dpi : the resolution, >= 100.
    close, tight, fast : see above.

    Returns
    -------
    bytes
        the PNG file's bytes.

    Raises
    ------
    orrc.OrrcValueError
        When ``fig`` is not a matplotlib figure or ``dpi`` is below 100.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> import orrc.viz
    >>> def plot(M):
    ...     fig = Figure(figsize=(4, 3))
    ...     ax = fig.add_subplot()
    ...     ax.plot(range(M))
    ...     ax.set_title(f"M = {M}")
    ...     return fig
    >>> png = orrc.viz.figure_to_png(plot(3), close=False)
    >>> png[:8] == b"\\x89PNG\\r\\n\\x1a\\n"
    True
    """
    from .._validate import as_int

    fig = _figure_arg("fig", fig)
    dpi = as_int("dpi", dpi, minimum=DPI)
    if tight:
        from PIL import Image

        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
        image = Image.open(buf)
    else:   # at the figure's size: drawn once
        image = agg_rgba(fig, dpi)
    _close(fig, close)
    out = io.BytesIO()
    if fast:
        image.save(out, format="PNG", dpi=(dpi, dpi), compress_level=1)
    else:
        palette(image).save(out, format="PNG", dpi=(dpi, dpi))
    return out.getvalue()


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
    fonts stay raised, titles longer than the figure stay wrapped); it is closed when ``close``.

    Parameters
    ----------
    fig : a matplotlib figure.
    dpi : the resolution, >= 100.
    close : close the figure afterwards.

    Returns
    -------
    tuple
        (wide PNG bytes, narrow PNG bytes or None).

    Raises
    ------
    orrc.OrrcValueError
        When ``fig`` is not a matplotlib figure or ``dpi`` is below 100.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> fig = Figure(figsize=(7, 3))
    >>> ax = fig.add_subplot()
    >>> _ = ax.plot([0, 1, 2], [1, 0, 2], label="cost")
    >>> _ = ax.set(xlabel="t", title="A run")
    >>> _ = ax.legend()
    >>> from orrc.viz import figures
    >>> wide, narrow = figures.render(fig, close=False)
    >>> # pixels: 7 in and 3.4 in at 100 dpi
    >>> figures._png_width(wide), figures._png_width(narrow)
    (700, 340)
    """
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
    phone readers). Same layout, size and fonts as the wide PNG of :func:`render`.

    Parameters
    ----------
    fig : a matplotlib figure.
    dpi : the resolution, >= 100.
    close : close the figure afterwards.

    Returns
    -------
    bytes
        the wide PNG.

    Raises
    ------
    orrc.OrrcValueError
        When ``fig`` is not a matplotlib figure or ``dpi`` is below 100.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> fig = Figure(figsize=(7, 3))
    >>> ax = fig.add_subplot()
    >>> _ = ax.plot([0, 1, 2], [1, 0, 2], label="cost")
    >>> _ = ax.set(xlabel="t", title="A run")
    >>> _ = ax.legend()
    >>> from orrc.viz import figures
    >>> figures.render_live(fig, close=False)[:4]
    b'\\x89PNG'
    """
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
    (``orrc-frame`` for the explorer).

    Returns
    -------
    str
        the ``div.orrc-figure``.

    Raises
    ------
    orrc.OrrcValueError
        When an image is not PNG bytes, ``alt`` is not a string, or ``uid`` is not an HTML id.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> fig = Figure(figsize=(7, 3))
    >>> ax = fig.add_subplot()
    >>> _ = ax.plot([0, 1, 2], [1, 0, 2], label="cost")
    >>> _ = ax.set(xlabel="t", title="A run")
    >>> _ = ax.legend()
    >>> from orrc.viz import figures
    >>> wide, narrow = figures.render(fig, close=False)
    >>> figures.picture_html(wide, narrow, alt="A run", uid="run")[:40]
    '<div class="orrc-figure" id="run"><style'
    """
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
    alternative :func:`orrc.viz.describe.describe` writes from the figure.

    Parameters
    ----------
    fig : a matplotlib figure.
    dpi : the resolution, >= 100.
    close : close the figure afterwards.

    Returns
    -------
    str
        the ``div.orrc-figure`` with both images.

    Raises
    ------
    orrc.OrrcValueError
        When ``fig`` is not a matplotlib figure or ``dpi`` is below 100.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> fig = Figure(figsize=(7, 3))
    >>> ax = fig.add_subplot()
    >>> _ = ax.plot([0, 1, 2], [1, 0, 2], label="cost")
    >>> _ = ax.set(xlabel="t", title="A run")
    >>> _ = ax.legend()
    >>> from orrc.viz import figures
    >>> html = figures.figure_html(fig, close=False)
    >>> html.startswith('<div class="orrc-figure"')
    True
    >>> 'alt="A run: t on the horizontal axis' in html
    True
    """
    from .describe import describe

    alt = describe(fig)
    return picture_html(*render(fig, dpi, close=close), alt=alt)


def install(ip=None) -> bool:
    """Make :func:`figure_html` the ``text/html`` form of every matplotlib Figure in the
    IPython shell ``ip`` (the running one by default) and drop the plain PNG form, so a
    figure cell's output is the wide and narrow pair. Returns False outside IPython.

    Parameters
    ----------
    ip : an IPython shell (default: the running one).

    Returns
    -------
    bool
        True when installed, False outside IPython.

    Examples
    --------
    >>> from orrc.viz import figures
    >>> figures.install()      # outside IPython, nothing to do
    False
    """
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
