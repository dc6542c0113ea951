"""One plotting function, two front ends: a live ipywidgets slider and static frames.

``explore(plot, M=[5, 10, 20], gamma=[1, 2, 4])`` makes an :class:`Explorer` over the grid of
``plot(M=..., gamma=...)`` (a function returning a matplotlib Figure). What it renders depends on
where it runs, decided from explicit signals, not guessed:

* **in a live kernel** (JupyterLab, a notebook; ``live``): only the live widget,
  :class:`orrc.viz.live.LiveView`: sliders whose moves show the frame of the new grid point, drawn
  by the same ``plot``, cached per grid point and drawn ahead of the reader (in a worker process
  forked from the kernel, :mod:`orrc.viz.ahead`, or while the kernel is idle). Its notebook output
  is ``application/vnd.jupyter.widget-view+json``.
* **in the book's build** (``orrc.config.book_build()``: ``ORRC_BOOK_BUILD=1``, set when the
  HTML book is built), and outside a kernel (a plain Python script), where no widget could be
  shown: the static frames (``static``), ``text/html`` with the precomputed frames, HTML range
  sliders and a few lines of JavaScript that flip between them, no kernel needed (the rendered book
  shows this one).

Because both come from the same ``plot`` function, they cannot drift apart. Every static frame
is rendered twice by :func:`orrc.viz.figures.render`, at 100 dpi with fonts of at least 9 pt:
wide, and narrow for a phone (panels stacked); the page shows the one that fits its column
(:func:`orrc.viz.figures.picture_html`). The live widget shows the wide rendering.

The HTML it writes (for a page's own styles and scripts): a ``div.orrc-frames`` holding one
``input.orrc-slider[type=range]`` per parameter and a ``div.orrc-figure`` with an
``img.orrc-frame[data-variant=wide]`` and (for a frame wider than a phone's column) an
``img.orrc-frame[data-variant=narrow]``; the frame data (``script.orrc-frame-data``, JSON)
holds ``images`` (wide) and ``narrow`` (or null), one PNG per combination, keyed by the
slider positions joined with ``_``.
"""
from __future__ import annotations

import base64
import html
import itertools
import json
import math
import uuid

from .._validate import OrrcValueError, as_int, check_size
from .describe import frame_description
from .figures import DPI, figure_to_png, picture_html, render  # noqa: F401 (figure_to_png: re-exported)
from .kernel import in_kernel
from .live import _fmt, check_figure

_JS = """
(function () {
  var root = document.getElementById(%(id)s);
  if (!root) { return; }
  var frames = JSON.parse(root.querySelector('script.orrc-frame-data').textContent);
  var wide = root.querySelector('img.orrc-frame[data-variant=wide]');
  var narrow = root.querySelector('img.orrc-frame[data-variant=narrow]');
  var sliders = root.querySelectorAll('input.orrc-slider');
  function update() {
    var key = [];
    sliders.forEach(function (s) {
      key.push(s.value);
      var out = root.querySelector('output[for="' + s.id + '"]');
      if (out) { out.textContent = s.dataset.labels.split('|')[Number(s.value)]; }
    });
    var k = key.join('_'), head = 'data:' + frames.mime + ';base64,';
    wide.src = head + frames.images[k];
    wide.alt = frames.alts[k];
    if (narrow && frames.narrow) { narrow.src = head + frames.narrow[k]; narrow.alt = frames.alts[k]; }
  }
  sliders.forEach(function (s) { s.addEventListener('input', update); });
})();
"""


def _as_switch(name: str, value) -> bool:
    if not isinstance(value, bool):
        raise OrrcValueError(f"{name} must be True, False or None (decided from where it runs); got {value!r}")
    return value


class Explorer:
    """The result of :func:`explore`: displays as the live widget (``live``) or the static frames
    (``static``), or both when both were asked for.

    ``frames``: ``{"images": ..., "narrow": ...}`` of the static frames, ``alts`` their text
    alternatives (key -> :func:`orrc.viz.describe.frame_description`: the frame's parameter values and
    what the figure shows) and ``html`` their HTML (None without static frames); ``view``: the :class:`orrc.viz.live.LiveView` and ``widget`` its
    ipywidget (None without the live widget).

    Parameters
    ----------
    plot, params, initial, dpi, live, static : as :func:`explore` resolves them.

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
    >>> explorer = orrc.viz.explore(plot, M=[2, 5])
    >>> type(explorer).__name__, sorted(explorer.frames)
    ('Explorer', ['images', 'narrow'])
    """

    def __init__(self, plot, params: dict, initial: dict, dpi: int, live: bool, static: bool):
        self.plot, self.params, self.initial, self.dpi = plot, params, initial, dpi
        self.alts: dict | None = {} if static else None
        self.frames = self._render_frames() if static else None
        self.html = self._html() if static else None
        if live:
            from .live import LiveView

            self.view = LiveView(plot, params, initial, dpi)
            self.widget = self.view.widget
        else:
            self.view = self.widget = None

    def _render_frames(self) -> dict:
        """``{"images": key -> wide PNG (base64), "narrow": key -> narrow PNG or None}``."""
        names = list(self.params)
        wide, narrow = {}, {}
        for idx in itertools.product(*(range(len(self.params[k])) for k in names)):
            kwargs = {k: self.params[k][i] for k, i in zip(names, idx)}
            key = "_".join(map(str, idx))
            fig = check_figure(self.plot(**kwargs), kwargs)
            self.alts[key] = frame_description(kwargs, fig)   # before rendering, which closes the figure
            w, n = render(fig, self.dpi)
            wide[key] = base64.b64encode(w).decode("ascii")
            narrow[key] = None if n is None else base64.b64encode(n).decode("ascii")
        has_narrow = all(v is not None for v in narrow.values())
        return {"images": wide, "narrow": narrow if has_narrow else None}

    def _html(self) -> str:
        uid = "orrc-" + uuid.uuid4().hex[:10]
        names = list(self.params)
        start = [self.params[k].index(self.initial[k]) for k in names]
        rows = []
        for j, k in enumerate(names):
            labels = [_fmt(v) for v in self.params[k]]
            sid = f"{uid}-{j}"
            rows.append(
                f'<label style="display:flex;align-items:center;gap:0.6em;margin:0.2em 0">'
                f'<span style="min-width:5em">{html.escape(k)}</span>'
                f'<input class="orrc-slider" id="{sid}" type="range" min="0" max="{len(labels) - 1}" '
                f'step="1" value="{start[j]}" data-name="{html.escape(k)}" '
                f'data-labels="{html.escape("|".join(labels))}" aria-label="{html.escape(k)}">'
                f'<output for="{sid}">{html.escape(labels[start[j]])}</output></label>')
        key = "_".join(map(str, start))
        data = json.dumps({"mime": "image/png", **self.frames, "alts": self.alts})
        narrow = self.frames["narrow"]
        first = picture_html(base64.b64decode(self.frames["images"][key]),
                             None if narrow is None else base64.b64decode(narrow[key]),
                             alt=self.alts[key], cls="orrc-frame", uid=f"{uid}-fig")
        return (f'<div class="orrc-frames" id="{uid}">'
                + "".join(rows) + first
                + f'<script type="application/json" class="orrc-frame-data">{data}</script>'
                + f"<script>{_JS % {'id': json.dumps(uid)}}</script></div>")

    def _repr_mimebundle_(self, include=None, exclude=None):
        bundle = {"text/plain": f"<orrc explorer over {', '.join(self.params)}>"}
        if self.html is not None:
            bundle["text/html"] = self.html
        if self.widget is not None:
            wb = self.widget._repr_mimebundle_()
            if isinstance(wb, tuple):
                wb = wb[0]
            bundle.update({k: v for k, v in wb.items() if k != "text/plain"})
        return bundle


def explore(plot, dpi: int = DPI, live: bool | None = None, initial: dict | None = None,
            static: bool | None = None, **params) -> Explorer:
    """An :class:`Explorer` of ``plot(**kwargs)`` over the grid of ``params``.

    ``params``: name -> list of values (e.g. ``M=[2, 5, 10]``); ``initial``: the values shown
    first (default: the first of each list); ``dpi``: at least 100 (below it tick labels are
    illegible). ``live``: make the live widget (default: in a Jupyter kernel, except in the book's
    build); ``static``: render the static frames (default: in the book's build,
    ``orrc.config.book_build()``, and wherever there is no live widget). Keep grids small (a few
    values each): every combination is two precomputed images (wide and narrow) in the book.

    Parameters
    ----------
    plot : a function of the grid's parameters returning a matplotlib figure.
    dpi : the resolution, >= 100.
    live : make the live widget (default: in a Jupyter kernel, not in the book's build).
    initial : the values shown first.
    static : render the static frames (default: in the book's build and wherever there is no widget).
    **params : name -> the list of its values.

    Returns
    -------
    Explorer
        displays as the live widget or the precomputed frames.

    Raises
    ------
    orrc.OrrcValueError
        When ``plot`` is not callable, a grid is empty, ``initial`` names a value not in its grid, or
        the frames exceed the size limits.

    Examples
    --------
    Outside a kernel the frames are precomputed, two renderings each:

    >>> from matplotlib.figure import Figure
    >>> import orrc.viz
    >>> def plot(M):
    ...     fig = Figure(figsize=(4, 3))
    ...     ax = fig.add_subplot()
    ...     ax.plot(range(M))
    ...     ax.set_title(f"M = {M}")
    ...     return fig
    >>> explorer = orrc.viz.explore(plot, M=[2, 5])
    >>> len(explorer.frames["images"]), explorer.view is None
    (2, True)
    """
    from .. import config

    dpi = as_int("dpi", dpi, minimum=DPI)
    if not callable(plot):
        raise OrrcValueError(f"plot must be a function returning a matplotlib Figure; got {type(plot).__name__}")
    if not params:
        raise OrrcValueError("explore needs at least one parameter, e.g. explore(plot, M=[5, 10])")
    for k, v in params.items():
        if isinstance(v, (str, bytes)) or not hasattr(v, "__iter__"):
            raise OrrcValueError(f"parameter {k!r} must be a list of values; got {type(v).__name__}")
    params = {k: list(v) for k, v in params.items()}
    for k, v in params.items():
        if not v:
            raise OrrcValueError(f"parameter {k!r} has no values")
    frames = math.prod(len(v) for v in params.values())
    check_size(f"explore over {frames} frames ({' x '.join(f'{k}: {len(v)}' for k, v in params.items())})",
               nbytes=frames * 2e5, ops=frames * 2e8, hint="keep each parameter to a few values")
    if initial is not None and not isinstance(initial, dict):
        raise OrrcValueError(f"initial must be a dict parameter -> value or None; got {type(initial).__name__}")
    initial = dict(initial or {})
    for k, v in params.items():
        initial.setdefault(k, v[0])
        if initial[k] not in v:
            raise OrrcValueError(f"initial value {initial[k]!r} of {k!r} is not among its values {v}")
    build = config.book_build()
    live = (in_kernel() and not build) if live is None else _as_switch("live", live)
    static = (build or not live) if static is None else _as_switch("static", static)
    if not (live or static):
        raise OrrcValueError("explore with live=False and static=False shows nothing; ask for at least one")
    return Explorer(plot, params, initial, dpi, live, static)
