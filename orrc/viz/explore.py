"""One plotting function, two front ends: a live ipywidgets slider and static frames.

``explore(plot, M=[5, 10, 20], gamma=[1, 2, 4])`` calls ``plot(M=..., gamma=...)``
(a function returning a matplotlib Figure) for every combination of the listed
values, and returns an :class:`Explorer` whose notebook output carries

* ``application/vnd.jupyter.widget-view+json``: live ipywidgets sliders that re-draw
  with the same ``plot`` in a running kernel (JupyterLab shows this one), and
* ``text/html``: the precomputed frames with HTML range sliders and a few lines
  of JavaScript that flip between them, no kernel needed (the rendered book shows
  this one: ``_config.yml`` drops the widget mime type for the HTML builder).

Because both come from the same ``plot`` function, they cannot drift apart. Every
frame is rendered twice by :func:`orrc.viz.figures.render`, at 100 dpi with fonts of
at least 9 pt: wide, and narrow for a phone (panels stacked); the page shows the one
that fits its column (:func:`orrc.viz.figures.picture_html`).

The HTML contract (used by the browser tests): a ``div.orrc-frames`` holding one
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
from .figures import DPI, figure_to_png, picture_html, render  # noqa: F401 (figure_to_png: re-exported)

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
    if (narrow && frames.narrow) { narrow.src = head + frames.narrow[k]; }
  }
  sliders.forEach(function (s) { s.addEventListener('input', update); });
})();
"""


def _fmt(v) -> str:
    return f"{v:g}" if isinstance(v, float) else str(v)


class Explorer:
    """The result of :func:`explore`: displays as live widget or static frames."""

    def __init__(self, plot, params: dict, initial: dict, dpi: int, live: bool):
        self.plot, self.params, self.initial, self.dpi = plot, params, initial, dpi
        self.frames = self._render_frames()
        self.html = self._html()
        self.widget = self._widget() if live else None

    def _render_frames(self) -> dict:
        """``{"images": key -> wide PNG (base64), "narrow": key -> narrow PNG or None}``."""
        from matplotlib.figure import Figure

        names = list(self.params)
        wide, narrow = {}, {}
        for idx in itertools.product(*(range(len(self.params[k])) for k in names)):
            kwargs = {k: self.params[k][i] for k, i in zip(names, idx)}
            key = "_".join(map(str, idx))
            fig = self.plot(**kwargs)
            if not isinstance(fig, Figure):
                raise OrrcValueError(f"plot must return a matplotlib Figure; plot({kwargs}) returned "
                                     f"{type(fig).__name__}")
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
        data = json.dumps({"mime": "image/png", **self.frames})
        narrow = self.frames["narrow"]
        first = picture_html(base64.b64decode(self.frames["images"][key]),
                             None if narrow is None else base64.b64decode(narrow[key]),
                             alt="figure", cls="orrc-frame", uid=f"{uid}-fig")
        return (f'<div class="orrc-frames" id="{uid}">'
                + "".join(rows) + first
                + f'<script type="application/json" class="orrc-frame-data">{data}</script>'
                + f"<script>{_JS % {'id': json.dumps(uid)}}</script></div>")

    def _widget(self):
        import ipywidgets as widgets
        import matplotlib.pyplot as plt
        from IPython.display import display

        out = widgets.Output()
        sliders = {k: widgets.SelectionSlider(options=[(_fmt(v), v) for v in vals], value=self.initial[k],
                                              description=k, continuous_update=False)
                   for k, vals in self.params.items()}

        def redraw(_=None):
            with out:
                out.clear_output(wait=True)
                fig = self.plot(**{k: s.value for k, s in sliders.items()})
                display(fig)
                plt.close(fig)

        for s in sliders.values():
            s.observe(redraw, names="value")
        redraw()
        return widgets.VBox([*sliders.values(), out])

    def _repr_mimebundle_(self, include=None, exclude=None):
        bundle = {"text/plain": f"<orrc explorer over {', '.join(self.params)}>", "text/html": self.html}
        if self.widget is not None:
            wb = self.widget._repr_mimebundle_()
            if isinstance(wb, tuple):
                wb = wb[0]
            bundle.update({k: v for k, v in wb.items() if k != "text/plain"})
        return bundle


def explore(plot, dpi: int = DPI, live: bool = True, initial: dict | None = None, **params) -> Explorer:
    """Precompute ``plot(**kwargs)`` on the grid of ``params`` and return an :class:`Explorer`.

    ``params``: name -> list of values (e.g. ``M=[2, 5, 10]``); ``initial``: the
    values shown first (default: the first of each list); ``dpi``: at least 100 (below
    it tick labels are illegible). Keep grids small (a few values each): every
    combination is two precomputed images (wide and narrow).
    """
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
    return Explorer(plot, params, initial, dpi, live)
