"""The live widget of an explorer: sliders over the grid, the figure as an image, frames cached.

A slider move in a live kernel shows the frame of the new grid point. Drawing a frame (the
chapter's plotting function, then one PNG) takes 0.05 to 0.5 s; showing a PNG already drawn takes
milliseconds. So :class:`LiveView` keeps every frame it has drawn (one PNG per grid point, keyed
by the slider positions) and draws the frames not yet drawn *ahead* of the reader, nearest first:
the neighbours of the current view along each slider (the moves a reader makes next), then the
rest of the grid; after every move what is left is ordered again around the new view.

* **In a worker process** (:mod:`orrc.viz.ahead`, where the platform can fork): a child forked from
  the kernel when the explorer is made draws them beside the kernel, at a lower CPU priority, and
  sends each PNG back; the kernel's thread stays free, so a move never waits behind a frame drawn
  ahead, nor for the worker (a worker that stops answering is killed by the kernel's watchdog and
  the frames left are drawn as below). One worker per explorer at most: a re-run of the
  explorer's cell (a new explorer in its place: the kernel's request names the cell), a closed
  widget or :meth:`LiveView.close` stops the old one's worker, and that explorer draws nothing
  ahead any more (a move there still draws its frame).
* **Else on the kernel's own thread**: one frame per turn of the kernel's event loop while it is
  idle (the plotting function never runs concurrently with a cell or with itself); a move that
  arrives meanwhile waits for that frame.

In a kernel the neighbours of the first view (one step along each slider: the first move a reader
makes) are drawn before the explorer's cell returns, for at most :data:`NEIGHBOURS_SECONDS`, so that
a move made right after a chapter ran finds its frame (the worker draws the others meanwhile). A
move to a frame not yet drawn draws it on the spot.

The figure is an ``ipywidgets.Image`` whose value is replaced in place (no flicker, no clearing
of an output area); errors of the plotting function appear in an ``Output`` below it. Each PNG is
:func:`orrc.viz.figures.render_live`: the wide rendering of the book's frames (same size, fonts,
layout and pixels), in full colour with light compression, drawn once.
"""
from __future__ import annotations

import itertools
import time
import weakref

from .._validate import OrrcValueError
from . import ahead as _ahead
from .figures import render_live

__all__ = ["LiveView"]

#: the most time the explorer's cell spends drawing the first view's neighbours (in a kernel)
NEIGHBOURS_SECONDS = 1.0
#: the explorers made by the last run of each notebook cell: {cell id: (that run's message id, [views])}
_BY_CELL: dict[str, tuple[str, list]] = {}


def _fmt(v) -> str:
    return f"{v:g}" if isinstance(v, float) else str(v)


def _running_loop():
    """The kernel's asyncio event loop when this runs inside one (ipykernel runs cells in it), else None."""
    import asyncio

    try:
        return asyncio.get_running_loop()
    except RuntimeError:
        return None


def _running_cell() -> tuple[str | None, str | None]:
    """The notebook cell running now and this run of it, ``(cell id, message id)`` from the kernel's
    request (JupyterLab and Notebook 7 send the cell's id); ``(None, None)`` outside a kernel."""
    try:
        from IPython import get_ipython

        parent = get_ipython().kernel.get_parent("shell")
    except Exception:  # noqa: BLE001 - no IPython, no kernel, or an older kernel: no cell known
        return None, None
    return (parent.get("metadata") or {}).get("cellId"), (parent.get("header") or {}).get("msg_id")


def _replaces(view) -> None:
    """``view`` replaces the explorers made by an earlier run of the same cell: they draw nothing
    ahead any more and their workers are stopped (a re-run chapter leaves one worker per explorer)."""
    cell, run = _running_cell()
    if cell is None or run is None:
        return
    last_run, views = _BY_CELL.get(cell, (None, []))
    if last_run != run:
        for old in views:
            old = old()
            if old is not None:
                old.close()
        views = []
    views.append(weakref.ref(view))
    _BY_CELL[cell] = (run, views)


def check_figure(fig, kwargs: dict):
    """``fig`` when the plotting function returned a matplotlib Figure, else a clear error."""
    from matplotlib.figure import Figure

    if not isinstance(fig, Figure):
        raise OrrcValueError(f"plot must return a matplotlib Figure; plot({kwargs}) returned {type(fig).__name__}")
    return fig


class LiveView:
    """Sliders (one ``SelectionSlider`` per parameter), the frame as an ``Image``, frames cached per
    grid point and drawn ahead of the reader (see the module docstring).

    ``ahead``: draw the frames ahead in the running asyncio loop (default: when in a Jupyter kernel).
    ``worker``: draw them in a worker process (:mod:`orrc.viz.ahead`; default: where the platform
    can fork), else on the loop's thread. ``widget``: the ``VBox`` to display. ``stats``: how many
    frames were drawn on a move (``on_move``), ahead of the reader (``ahead``) and shown from the cache
    (``cached``). The attribute ``worker``: the :class:`orrc.viz.ahead.Worker` drawing ahead (None:
    none, or it is done); ``closed``: True once it draws nothing ahead any more (:meth:`close`).

    Parameters
    ----------
    plot : the plotting function of :func:`orrc.viz.explore`.
    params : name -> the list of its values.
    initial : the values shown first.
    dpi : the resolution.
    ahead, worker : see above.

    Examples
    --------
    Made by :func:`orrc.viz.explore` in a live kernel; by hand, without drawing ahead:

    >>> from matplotlib.figure import Figure
    >>> import orrc.viz
    >>> def plot(M):
    ...     fig = Figure(figsize=(4, 3))
    ...     ax = fig.add_subplot()
    ...     ax.plot(range(M))
    ...     ax.set_title(f"M = {M}")
    ...     return fig
    >>> from orrc.viz.live import LiveView
    >>> view = LiveView(plot, {"M": [2, 5]}, {"M": 2}, 100, ahead=False, worker=False)
    >>> type(view.widget).__name__
    'VBox'
    """

    def __init__(self, plot, params: dict, initial: dict, dpi: int, ahead: bool | None = None,
                 worker: bool | None = None):
        import ipywidgets as widgets

        self.plot, self.params, self.dpi = plot, params, dpi
        self.names = list(params)
        self.frames: dict[tuple, bytes] = {}
        self.failed: set[tuple] = set()
        self.stats = {"on_move": 0, "ahead": 0, "cached": 0}
        self.sliders = {k: widgets.SelectionSlider(options=[(_fmt(v), v) for v in vals], value=initial[k],
                                                   description=k, continuous_update=False)
                        for k, vals in params.items()}
        self.image = widgets.Image(format="png", layout=widgets.Layout(max_width="100%", height="auto"))
        self.messages = widgets.Output()
        self.widget = widgets.VBox([*self.sliders.values(), self.image, self.messages])
        start = self.key()
        self.image.value = self.frame(start)       # the first view: drawn now (a plotting error raises here)
        self.stats["on_move"] = 0
        for s in self.sliders.values():
            s.observe(self._moved, names="index")
        self._queue = self._order(start)
        if ahead is None:                           # in a Jupyter kernel: its event loop runs the cells
            from .kernel import in_kernel

            ahead = in_kernel()
        self._loop = _running_loop() if ahead else None
        self.worker, self.closed = None, False
        if self._loop is not None:
            _replaces(self)
            self.widget.observe(self._widget_closed, names="comm")
            if worker is None or worker:
                self.worker = _ahead.start(self._draw_png, self._worker_order, self._loop, self._received,
                                           self._worker_ended)
            self._draw_neighbours(start, NEIGHBOURS_SECONDS)
            if self.worker is None:
                self._loop.call_soon(self._draw_ahead)
            else:
                self.worker.show(start, self.frames)

    @property
    def pending(self) -> int:
        """How many frames are still to be drawn ahead (0: every move is shown from the cache)."""
        return sum(1 for k in self._queue if k not in self.frames and k not in self.failed)

    def key(self) -> tuple:
        """The slider positions, one index per parameter."""
        return tuple(self.sliders[k].index for k in self.names)

    def kwargs(self, key: tuple) -> dict:
        return {k: self.params[k][i] for k, i in zip(self.names, key)}

    def _order(self, start: tuple) -> list[tuple]:
        """The grid points to draw ahead: along each slider from the initial view outwards (nearest
        first: the moves a reader makes next), then the rest of the grid."""
        first = []
        for j, k in enumerate(self.names):
            n = len(self.params[k])
            for d in range(1, n):
                for i in (start[j] + d, start[j] - d):
                    if 0 <= i < n:
                        first.append(start[:j] + (i,) + start[j + 1:])
        rest = [key for key in itertools.product(*(range(len(self.params[k])) for k in self.names))
                if key != start and key not in first]
        return first + rest

    def _draw_png(self, key: tuple) -> bytes:
        """Draw the frame of grid point ``key`` (the plotting function, then one PNG)."""
        kwargs = self.kwargs(key)
        return render_live(check_figure(self.plot(**kwargs), kwargs), self.dpi)

    def frame(self, key: tuple) -> bytes:
        """The PNG of grid point ``key``: from the cache, or drawn now (and kept)."""
        png = self.frames.get(key)
        if png is None:
            png = self._draw_png(key)
            self.frames[key] = png
            self.stats["on_move"] += 1
        else:
            self.stats["cached"] += 1
        return png

    def _moved(self, _change=None) -> None:
        key = self.key()
        if self.pending:  # the frames still to draw: nearest the new view first (the worker told first)
            self._queue = [k for k in self._order(key) if k not in self.frames and k not in self.failed]
            if self.worker is not None:
                self.worker.show(key, self.frames)
        with self.messages:
            self.messages.clear_output()
            self.image.value = self.frame(key)

    def _neighbours(self, start: tuple) -> list[tuple]:
        """The grid points still to draw one step from ``start`` along one slider, in queue order."""
        return [k for k in self._queue if sum(abs(a - b) for a, b in zip(k, start)) == 1]

    def _worker_order(self, view: tuple | None) -> list[tuple]:
        """The worker's order: around ``view``; at first (None) the first view's neighbours last (the
        explorer's cell draws those itself)."""
        if view is not None:
            return self._order(view)
        start = self.key()
        near = self._neighbours(start)
        return [k for k in self._queue if k not in near] + near

    def _received(self, key: tuple, png: bytes | None) -> None:
        """A frame from the worker (None: its plotting function raised; drawn on the move there)."""
        if png is None:
            self.failed.add(key)
        elif key not in self.frames:
            self.frames[key] = png
            self.stats["ahead"] += 1

    def _worker_ended(self) -> None:
        """The worker has left: what it did not draw (it failed, or the watchdog killed it) is drawn
        here, on the kernel's thread between cells."""
        self.worker = None
        if self.pending and not self.closed:
            self._loop.call_soon(self._draw_ahead)

    def _widget_closed(self, change) -> None:
        if change["new"] is None:
            self.close()

    def close(self) -> None:
        """Draw nothing ahead any more (the widget was closed, or a re-run of its cell replaced the
        explorer): the worker is stopped; a move still draws its frame."""
        self.closed = True
        if self.worker is not None:
            self.worker.stop()
            self.worker = None
        self._queue = []

    def forget(self) -> None:
        """Forget every frame drawn and draw none ahead (each move then draws its frame)."""
        if self.worker is not None:
            self.worker.stop()
            self.worker = None
        self.frames.clear()
        self._queue = []

    def _draw_neighbours(self, start: tuple, budget: float) -> None:
        """Draw the frames one step from ``start`` along each slider now (nearest first), until ``budget``
        seconds have passed."""
        t0 = time.perf_counter()
        for key in self._neighbours(start):
            if time.perf_counter() - t0 > budget:
                break
            self._draw_one(key)

    def _draw_one(self, key: tuple) -> None:
        """Draw the frame of ``key`` ahead of the reader (a plotting error is kept for the move there)."""
        try:
            self.frames[key] = self._draw_png(key)
            self.stats["ahead"] += 1
        except Exception:  # noqa: BLE001 - shown when the reader moves there (drawn on the move, in messages)
            self.failed.add(key)

    def _draw_ahead(self) -> None:
        """Draw the next frame not yet drawn, then give the kernel back its loop (one frame per turn)."""
        while self._queue and (self._queue[0] in self.frames or self._queue[0] in self.failed):
            self._queue.pop(0)
        if not self._queue or self.closed:   # done, or the widget was closed or replaced
            return
        self._draw_one(self._queue.pop(0))
        self._loop.call_later(0.005, self._draw_ahead)

    def time_frame(self, key: tuple) -> float:
        """Seconds to draw grid point ``key`` from scratch (not cached): what a move costs without the cache."""
        t0 = time.perf_counter()
        self._draw_png(key)
        return time.perf_counter() - t0
