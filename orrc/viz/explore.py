"""One plotting function, two front ends: a live ipywidgets slider and static frames.

``explore(plot, M=[5, 10, 20], gamma=[1, 2, 4])`` calls ``plot(M=..., gamma=...)``
(a function returning a matplotlib Figure) for every combination of the listed
values, and returns an :class:`Explorer` whose notebook output carries

* ``application/vnd.jupyter.widget-view+json``: live ipywidgets sliders that re-draw
  with the same ``plot`` in a running kernel (JupyterLab shows this one), and
* ``text/html``: the precomputed frames with HTML range sliders and a few lines
  of JavaScript that flip between them, no kernel needed (the rendered book shows
  this one: ``_config.yml`` drops the widget mime type for the HTML builder).

Because both come from the same ``plot`` function, they cannot drift apart.
The HTML contract (used by the browser tests): a ``div.orrc-frames`` holding one
``input[type=range]`` per parameter and one ``img.orrc-frame``.
"""
from __future__ import annotations

import base64
import html
import io
import itertools
import json
import math
import uuid

from .._validate import OrrcValueError, as_int, check_size

_JS = """
(function () {
  var root = document.getElementById(%(id)s);
  if (!root) { return; }
  var frames = JSON.parse(root.querySelector('script.orrc-frame-data').textContent);
  var img = root.querySelector('img.orrc-frame');
  var sliders = root.querySelectorAll('input.orrc-slider');
  function update() {
    var key = [];
    sliders.forEach(function (s) {
      key.push(s.value);
      var out = root.querySelector('output[for="' + s.id + '"]');
      if (out) { out.textContent = s.dataset.labels.split('|')[Number(s.value)]; }
    });
    img.src = 'data:' + frames.mime + ';base64,' + frames.images[key.join('_')];
  }
  sliders.forEach(function (s) { s.addEventListener('input', update); });
})();
"""


def figure_to_png(fig, dpi: int = 80) -> bytes:
    """Render a matplotlib figure to PNG bytes and close it."""
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    if not isinstance(fig, Figure):
        raise OrrcValueError(f"fig must be a matplotlib Figure (what the plotting function returns); got "
                             f"{type(fig).__name__}")
    dpi = as_int("dpi", dpi, minimum=1)

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


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
        from matplotlib.figure import Figure

        names = list(self.params)
        frames = {}
        for idx in itertools.product(*(range(len(self.params[k])) for k in names)):
            kwargs = {k: self.params[k][i] for k, i in zip(names, idx)}
            fig = self.plot(**kwargs)
            if not isinstance(fig, Figure):
                raise OrrcValueError(f"plot must return a matplotlib Figure; plot({kwargs}) returned "
                                     f"{type(fig).__name__}")
            frames["_".join(map(str, idx))] = base64.b64encode(figure_to_png(fig, self.dpi)).decode("ascii")
        return frames

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
        data = json.dumps({"mime": "image/png", "images": self.frames})
        return (f'<div class="orrc-frames" id="{uid}">'
                + "".join(rows)
                + f'<img class="orrc-frame" style="max-width:100%" alt="figure" '
                  f'src="data:image/png;base64,{self.frames[key]}">'
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


def explore(plot, dpi: int = 80, live: bool = True, initial: dict | None = None, **params) -> Explorer:
    """Precompute ``plot(**kwargs)`` on the grid of ``params`` and return an :class:`Explorer`.

    ``params``: name -> list of values (e.g. ``M=[2, 5, 10]``); ``initial``: the
    values shown first (default: the first of each list). Keep grids small
    (a few values each): every combination is one precomputed image.
    """
    if not callable(plot):
        raise OrrcValueError(f"plot must be a function returning a matplotlib Figure; got {type(plot).__name__}")
    if not params:
        raise OrrcValueError("explore needs at least one parameter, e.g. explore(plot, M=[5, 10])")
    dpi = as_int("dpi", dpi, minimum=1)
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
