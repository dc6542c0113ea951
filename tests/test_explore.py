"""The contract of orrc.viz.explore: one plotting function, live widget + static frames.

The static HTML (what the rendered book shows) must hold one ``div.orrc-frames`` with
one ``input.orrc-slider[type=range]`` per parameter, as many positions as values, and
an ``img.orrc-frame[data-variant=wide]`` (plus a ``narrow`` one for a frame wider than a
phone's column) showing the frame of the initial values; the frame data holds one PNG
per combination and variant, each drawn by the same ``plot`` function at 100 dpi. The
browser test (tests/test_book.py) checks that moving a slider flips the image in Chromium.
"""
from __future__ import annotations

import base64
import html.parser
import io
import json

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from orrc.viz import explore  # noqa: E402
from orrc.viz.explore import figure_to_png  # noqa: E402


class _Frames(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.divs, self.sliders, self.imgs, self.outputs, self.variants = [], [], [], [], []
        self.data, self._in_data = "", False

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        cls = (a.get("class") or "").split()
        if tag == "div" and "orrc-frames" in cls:
            self.divs.append(a)
        if tag == "input" and "orrc-slider" in cls:
            self.sliders.append(a)
        if tag == "img" and "orrc-frame" in cls:
            self.imgs.append(a)
            self.variants.append(a.get("data-variant"))
        if tag == "output":
            self.outputs.append(a)
        self._in_data = tag == "script" and "orrc-frame-data" in cls

    def handle_endtag(self, tag):
        if tag == "script":
            self._in_data = False

    def handle_data(self, data):
        if self._in_data:
            self.data += data


def parse(html_text: str) -> _Frames:
    p = _Frames()
    p.feed(html_text)
    return p


def line_plot(calls, width=2.0):
    def plot(M, gamma):
        calls.append((M, gamma))
        fig, ax = plt.subplots(figsize=(width, 1.5))
        ax.plot([0, 1], [M, gamma])  # a different picture for every (M, gamma)
        ax.set_ylim(0, 12)
        return fig
    return plot


def test_static_frames_follow_the_contract():
    calls = []
    Ms, gammas = [2, 5, 10], [1.0, 2.0]
    ex = explore(line_plot(calls), M=Ms, gamma=gammas, live=False)
    # the plot function was called once per combination, with exactly the grid's values
    assert sorted(calls) == sorted((M, g) for M in Ms for g in gammas)
    p = parse(ex.html)
    assert len(p.divs) == 1 and p.variants == ["wide"]   # a 2-inch frame needs no narrow variant
    assert len(p.sliders) == 2
    for s, (name, vals) in zip(p.sliders, [("M", Ms), ("gamma", gammas)]):
        assert s["type"] == "range" and s["data-name"] == name
        assert (int(s["min"]), int(s["max"]), int(s["step"])) == (0, len(vals) - 1, 1)
        assert s["value"] == "0"  # the first value by default
        assert s["data-labels"].split("|") == [f"{v:g}" if isinstance(v, float) else str(v) for v in vals]
    assert [o["for"] for o in p.outputs] == [s["id"] for s in p.sliders]
    data = json.loads(p.data)
    assert data["mime"] == "image/png"
    assert sorted(data["images"]) == sorted(f"{i}_{j}" for i in range(3) for j in range(2))
    assert len(set(data["images"].values())) == 6, "every combination is its own image"
    assert data["narrow"] is None
    # the image shown first is the frame of the initial values
    assert p.imgs[0]["src"] == "data:image/png;base64," + data["images"]["0_0"]
    from PIL import Image

    for b64 in data["images"].values():
        img = Image.open(io.BytesIO(base64.b64decode(b64)))
        assert img.format == "PNG" and img.size == (200, 150)    # 2 x 1.5 inches at 100 dpi
        assert img.info["dpi"] == pytest.approx((100, 100), abs=0.1)
    # the text/html of the notebook output is exactly this HTML (the book shows it)
    bundle = ex._repr_mimebundle_()
    assert bundle["text/html"] == ex.html
    assert "application/vnd.jupyter.widget-view+json" not in bundle


def test_initial_values_choose_the_slider_positions_and_the_first_frame():
    ex = explore(line_plot([]), M=[2, 5, 10], gamma=[1.0, 2.0], initial={"M": 5, "gamma": 2.0},
                 live=False)
    p = parse(ex.html)
    assert [s["value"] for s in p.sliders] == ["1", "1"]
    assert p.imgs[0]["src"].endswith(json.loads(p.data)["images"]["1_1"])
    assert [s["id"] for s in p.sliders][0] != [s["id"] for s in p.sliders][1]


def test_two_explorers_on_one_page_do_not_share_ids():
    a = parse(explore(line_plot([]), M=[1, 2], gamma=[1.0], live=False).html)
    b = parse(explore(line_plot([]), M=[1, 2], gamma=[1.0], live=False).html)
    assert a.divs[0]["id"] != b.divs[0]["id"]


def test_live_widget_uses_the_same_plot_function_and_caches_its_frames():
    calls = []
    ex = explore(line_plot(calls), M=[2, 5], gamma=[1.0], live=True)
    bundle = ex._repr_mimebundle_()
    # a live widget only: no static frames rendered (a live kernel never shows them)
    assert "application/vnd.jupyter.widget-view+json" in bundle and "text/html" not in bundle
    assert ex.frames is None and ex.html is None
    assert calls == [(2, 1.0)], "the first view only, drawn by the same plot function"
    view = ex.view
    first = bytes(view.image.value)
    assert first.startswith(b"\x89PNG")
    view.sliders["M"].value = 5                  # a move draws the new grid point
    assert calls[-1] == (5, 1.0) and bytes(view.image.value) != first
    view.sliders["M"].value = 2                  # and a move back shows the cached frame
    assert len(calls) == 2 and bytes(view.image.value) == first
    assert view.stats == {"on_move": 1, "ahead": 0, "cached": 1}


def test_the_live_frame_is_the_wide_static_frame():
    ex = explore(line_plot([], width=9.0), M=[2], gamma=[1.0], live=True, static=True)
    from PIL import Image

    live = Image.open(io.BytesIO(bytes(ex.view.image.value)))
    wide = Image.open(io.BytesIO(base64.b64decode(ex.frames["images"]["0_0"])))
    assert live.size == wide.size == (740, 150)           # narrowed to WIDE_IN = 7.4 in, at 100 dpi
    bundle = ex._repr_mimebundle_()                        # both asked for: both shown
    assert "text/html" in bundle and "application/vnd.jupyter.widget-view+json" in bundle


@pytest.mark.parametrize("pyplot", [False, True])
def test_a_frame_drawn_once_has_the_pixels_of_savefig(pyplot):
    """``figure_to_png(tight=False)`` draws the figure once (its constrained layout inside that draw)
    instead of savefig's two draws: the same pixels, in full colour for a live frame (``fast``) and in
    the same palette as savefig's image for a static one, and the figure keeps its canvas."""
    import numpy as np
    from matplotlib.figure import Figure
    from PIL import Image

    def make():
        fig = plt.figure(figsize=(7, 3), layout="constrained") if pyplot else Figure(figsize=(7, 3),
                                                                                  layout="constrained")
        axes = fig.subplots(1, 3)
        for i, ax in enumerate(axes):
            ax.plot(np.arange(200), np.cumsum(np.sin(np.arange(200) * (i + 1))), label="a line")
            ax.set_ylabel(rf"$R^p_t(\gamma)$, $\gamma={10 ** i}$")
        axes[0].legend(fontsize=9)
        fig.suptitle("three panels")
        return fig

    ref = make()
    buf = io.BytesIO()
    ref.savefig(buf, format="png", dpi=120)
    fig = make()
    canvas = fig.canvas
    png = figure_to_png(fig, dpi=120, close=False, tight=False, fast=True)
    assert fig.canvas is canvas and fig.get_layout_engine() is not None
    a, b = (np.asarray(Image.open(io.BytesIO(p)).convert("RGBA")) for p in (buf.getvalue(), png))
    assert a.shape == b.shape == (360, 840, 4) and (a == b).all()
    static = figure_to_png(make(), dpi=120, close=False, tight=False)
    palette = Image.open(io.BytesIO(buf.getvalue())).convert("RGB").quantize(
        colors=256, method=Image.Quantize.FASTOCTREE)
    assert (np.asarray(palette.convert("RGBA")) == np.asarray(Image.open(io.BytesIO(static)).convert("RGBA"))).all()
    plt.close("all")


def test_in_a_live_kernel_only_the_widget_and_in_the_book_build_only_the_frames(monkeypatch):
    import importlib

    import orrc

    ex_mod = importlib.import_module("orrc.viz.explore")   # the module (orrc.viz.explore is the function)
    monkeypatch.setattr(ex_mod, "in_kernel", lambda: True)
    monkeypatch.delenv("ORRC_BOOK_BUILD", raising=False)
    calls = []
    live = explore(line_plot(calls), M=[2, 5, 10], gamma=[1.0])
    assert live.widget is not None and live.html is None and calls == [(2, 1.0)]
    monkeypatch.setenv("ORRC_BOOK_BUILD", "1")
    assert orrc.config.book_build()
    calls.clear()
    built = explore(line_plot(calls), M=[2, 5, 10], gamma=[1.0])
    assert built.widget is None and 'class="orrc-frames"' in built.html
    assert sorted(calls) == [(2, 1.0), (5, 1.0), (10, 1.0)]
    monkeypatch.setattr(ex_mod, "in_kernel", lambda: False)   # outside a kernel: the frames, build or not
    monkeypatch.delenv("ORRC_BOOK_BUILD")
    plain = explore(line_plot([]), M=[2, 5], gamma=[1.0])
    assert plain.widget is None and plain.html is not None


def test_in_a_real_kernel_the_build_signal_decides_what_is_shown():
    """The same explorer cell in a Jupyter kernel: without ORRC_BOOK_BUILD only the live widget is
    output (no static frames rendered); with ORRC_BOOK_BUILD=1 (what tools/build_book.py sets) only
    the static frames."""
    from benchmarks.widgets import DEMO_CELLS, ROOT, Kernel, kernel_env

    k = Kernel(ROOT / "book", kernel_env(quick=False))
    try:
        k.run(DEMO_CELLS[0])
        bundles = []
        for setup in ("", "import os; os.environ['ORRC_BOOK_BUILD'] = '1'\n"):
            msgs = k.run(setup + DEMO_CELLS[1])
            (result,) = [m["content"]["data"] for m in msgs if m["msg_type"] == "execute_result"]
            bundles.append(result)
    finally:
        k.close()
    live, built = bundles
    assert "application/vnd.jupyter.widget-view+json" in live and "text/html" not in live
    assert "application/vnd.jupyter.widget-view+json" not in built and 'class="orrc-frames"' in built["text/html"]
    assert len(parse(built["text/html"]).sliders) == 2


@pytest.mark.parametrize("value, expected", [("1", True), ("true", True), (" YES ", True), ("", False),
                                             ("0", False), ("no", False)])
def test_the_book_build_signal_is_read_from_the_environment(monkeypatch, value, expected):
    import orrc

    monkeypatch.setenv("ORRC_BOOK_BUILD", value)
    assert orrc.config.book_build() is expected


def _in_a_loop(make_view, until=lambda view: view.pending == 0, seconds: float = 60.0):
    """The view ``make_view()`` made inside an asyncio loop of its own, in a thread (as a kernel runs
    its cells in its loop), once the loop has run until ``until(view)`` (at most ``seconds``: a
    worker process's first start on a fresh clone compiles its imports first)."""
    import asyncio
    import threading

    out = {}

    async def main():
        try:
            view = make_view()
            for _ in range(int(seconds / 0.01)):
                await asyncio.sleep(0.01)
                if until(view):
                    break
            out["view"] = view
        except BaseException as e:  # noqa: BLE001 - raised again in the test's thread
            out["error"] = e

    thread = threading.Thread(target=lambda: asyncio.run(main()))
    thread.start()
    thread.join(timeout=120)
    if "error" in out:
        raise out["error"]
    return out["view"]


def test_live_view_draws_ahead_in_the_kernels_event_loop():
    """In a kernel the frames not yet drawn are drawn while the loop is idle (here without a worker
    process: on the loop's thread), the neighbours of the first view first; afterwards every move
    is from the cache."""
    from orrc.viz import LiveView

    calls = []
    grid = {"M": [2, 5, 10], "gamma": [1.0, 2.0]}
    view = _in_a_loop(lambda: LiveView(line_plot(calls), grid, {"M": 5, "gamma": 1.0}, 100, ahead=True,
                                       worker=False))
    assert view.worker is None
    assert calls[0] == (5, 1.0) and set(calls[1:3]) == {(10, 1.0), (2, 1.0)} and calls[3] == (5, 2.0)
    assert sorted(calls) == sorted((M, g) for M in grid["M"] for g in grid["gamma"])
    assert view.stats["ahead"] == 5 and view.pending == 0
    for M in (2, 10, 5):
        view.sliders["M"].value = M
    assert len(calls) == 6 and view.stats["on_move"] == 0 and view.stats["cached"] == 3


def _left(pid: int, seconds: float = 10.0) -> bool:
    """Has the child process ``pid`` ended within ``seconds`` (reaped by its view, or now)?"""
    import os
    import time

    t0 = time.monotonic()
    while time.monotonic() - t0 < seconds:
        try:
            if os.waitpid(pid, os.WNOHANG)[0]:
                return True
        except ChildProcessError:        # reaped already
            return True
        time.sleep(0.05)
    return False


def test_a_worker_process_draws_the_other_frames_the_same(monkeypatch):
    """With a worker (the default in a kernel where the platform forks), the explorer's cell draws the
    first view and its neighbours; every other frame comes from the child process, byte for byte the
    frame the kernel would draw, and the plotting function never runs in the kernel for it. (The
    cell's time for the neighbours is raised from its 1 s, so that a loaded machine draws them all.)"""
    import os

    from orrc.viz import LiveView, live

    monkeypatch.setattr(live, "NEIGHBOURS_SECONDS", 60.0)

    calls, pids = [], []
    grid = {"M": [2, 5, 10], "gamma": [1.0, 2.0, 3.0]}

    def make():
        view = LiveView(line_plot(calls), grid, {"M": 5, "gamma": 1.0}, 100, ahead=True)
        pids.append(view.worker.pid)
        return view

    view = _in_a_loop(make, until=lambda view: view.pending == 0 and view.worker is None)
    assert sorted(calls) == [(2, 1.0), (5, 1.0), (5, 2.0), (10, 1.0)], "the first view and its neighbours only"
    assert len(view.frames) == 9 and view.pending == 0 and view.stats["ahead"] == 8
    for key, png in view.frames.items():
        assert png == view._draw_png(key), key
    assert view.worker is None and pids[0] != os.getpid() and _left(pids[0])


def test_the_worker_draws_on_while_the_kernel_runs_a_cell(tmp_path, monkeypatch):
    """A cell that keeps the kernel's loop busy does not hold the worker up: it draws every frame
    meanwhile (here 100 kB of frames through a pipe that holds 4 kB; each drawing is noted in a
    file), and the kernel takes them all once idle."""
    import time

    from orrc.viz import LiveView, ahead

    monkeypatch.setattr(ahead, "PIPE_BYTES", 4096)

    log = tmp_path / "drawn.txt"

    def plot(M, gamma):
        with open(log, "a") as f:
            f.write(f"{M}\n")
        return line_plot([], width=6.0)(M, gamma)

    def make():
        view = LiveView(plot, {"M": list(range(1, 13)), "gamma": [1.0]}, {"M": 1, "gamma": 1.0}, 100,
                        ahead=True)
        t0 = time.monotonic()           # the "cell": the loop is busy until the worker has drawn all
        while len(log.read_text().split()) < 12 and time.monotonic() - t0 < 60:
            time.sleep(0.05)
        assert sorted(map(int, log.read_text().split())) == list(range(1, 13))
        assert view.stats["ahead"] == 1 and len(view.frames) == 2   # nothing read during the "cell"
        return view

    view = _in_a_loop(make, until=lambda view: view.pending == 0 and view.worker is None)
    assert len(view.frames) == 12 and view.stats["ahead"] == 11 and view.stats["on_move"] == 0


def test_after_a_move_the_worker_draws_around_the_new_view_first():
    from orrc.viz import LiveView

    def slow(M, gamma):
        import time

        time.sleep(0.1)
        return line_plot([])(M, gamma)

    moved = []

    def until(view):
        if not moved and view.stats["ahead"] >= 3:    # the cell's neighbour and two from the worker
            moved.append(list(view.frames))
            view.sliders["M"].value = 12               # a jump to the far end (drawn on the move)
        return view.pending == 0 and view.worker is None

    view = _in_a_loop(lambda: LiveView(slow, {"M": list(range(1, 13)), "gamma": [1.0]}, {"M": 1, "gamma": 1.0},
                                       100, ahead=True), until)
    before = len(moved[0])
    after = [k[0] for k in list(view.frames)[before + 1:]]      # the worker's frames after the move
    # the frames in progress or on their way at the move come first, then the rest from the new view
    # outwards (the old order went on upwards: 4, 5, 6, ...)
    assert 10 in after[:3] and after[2:] == sorted(after[2:], reverse=True), after
    assert view.stats["on_move"] == 1 and len(view.frames) == 12


def test_a_plotting_error_in_the_worker_is_shown_on_the_move():
    from orrc.viz import LiveView

    def plot(M):
        if M == 3:
            raise RuntimeError("no frame for M = 3")
        return line_plot([])(M, 1.0)

    view = _in_a_loop(lambda: LiveView(plot, {"M": [1, 2, 3]}, {"M": 1}, 100, ahead=True),
                      until=lambda view: view.pending == 0 and view.worker is None)
    assert view.failed == {(2,)} and sorted(view.frames) == [(0,), (1,)]
    with pytest.raises(RuntimeError, match="no frame for M = 3"):   # drawn on the move: its error shown
        view.sliders["M"].value = 3


def test_a_stopped_worker_leaves_and_forget_draws_nothing_ahead():
    from orrc.viz import LiveView

    def slow(M):   # slow enough that the worker is still drawing when the loop sees two frames
        import time

        time.sleep(0.5)
        return line_plot([])(M, 1.0)

    view = _in_a_loop(lambda: LiveView(slow, {"M": list(range(12))}, {"M": 0}, 100, ahead=True),
                      until=lambda view: view.stats["ahead"] >= 2)
    worker = view.worker
    assert worker is not None and worker.alive and view.pending > 0
    view.forget()
    assert not worker.alive and view.worker is None and view.frames == {} and view.pending == 0
    assert _left(worker.pid), "the stopped worker leaves at its next frame"


def test_outside_a_kernel_nothing_is_drawn_ahead():
    calls = []
    ex = explore(line_plot(calls), M=[2, 5, 10], gamma=[1.0], live=True)
    assert ex.view.pending == 2 and calls == [(2, 1.0)]


def test_a_plotting_error_on_a_move_leaves_the_last_frame():
    def plot(M):
        if M == 3:
            raise RuntimeError("no frame for M = 3")
        return line_plot([])(M, 1.0)

    ex = explore(plot, M=[1, 3], live=True)
    before = bytes(ex.view.image.value)
    with pytest.raises(RuntimeError, match="no frame for M = 3"):   # in a kernel: shown in view.messages
        ex.view.sliders["M"].value = 3
    assert bytes(ex.view.image.value) == before and (1,) not in ex.view.frames


def test_wide_frames_carry_a_narrow_variant_for_phones():
    ex = explore(line_plot([], width=7.0), M=[1, 2], gamma=[1.0], live=False)
    p = parse(ex.html)
    assert p.variants == ["wide", "narrow"]
    data = json.loads(p.data)
    assert sorted(data["narrow"]) == sorted(data["images"]) == ["0_0", "1_0"]
    from PIL import Image

    sizes = {v: Image.open(io.BytesIO(base64.b64decode(d["0_0"]))).size
             for v, d in (("wide", data["images"]), ("narrow", data["narrow"]))}
    assert sizes["wide"][0] == 700 and sizes["narrow"][0] == 340   # 7 in and 3.4 in at 100 dpi
    wide, narrow = p.imgs
    assert wide["src"].endswith(data["images"]["0_0"]) and narrow["src"].endswith(data["narrow"]["0_0"])
    # the page's CSS shows the narrow frame when the column is narrower than the wide one
    assert "@container (max-width: 699px)" in ex.html


def test_frames_below_100_dpi_are_refused():
    with pytest.raises(ValueError, match="dpi must be an integer >= 100; got 70"):
        explore(line_plot([]), M=[1], gamma=[1.0], live=False, dpi=70)


def test_figure_to_png_closes_the_figure():
    fig, _ = plt.subplots()
    n = len(plt.get_fignums())
    png = figure_to_png(fig)
    assert png.startswith(b"\x89PNG") and len(plt.get_fignums()) == n - 1


@pytest.mark.parametrize("args, kwargs, match", [
    (("not a function",), {"M": [1]}, "plot must be a function"),
    ((lambda M: None,), {}, "at least one parameter"),
    ((lambda M: None,), {"M": []}, "'M' has no values"),
    ((lambda M: None,), {"M": [1, 2], "initial": {"M": 3}}, "initial value 3 of 'M'"),
])
def test_bad_input_is_a_clear_value_error(args, kwargs, match):
    with pytest.raises(ValueError, match=match):
        explore(*args, live=False, **kwargs)
