"""The frames worker of a live explorer (orrc.viz.ahead) never holds a kernel up and never outlives
what it works for: a worker that stops answering is killed by the kernel's watchdog and the kernel
draws the rest; a re-run of the explorer's cell, a closed widget and the kernel's end each leave no
worker behind."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from test_explore import _in_a_loop, _left, line_plot

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="the worker is forked (not on Windows)")


def _gone(pid: int, seconds: float = 10.0) -> bool:
    """Has process ``pid`` (not our child) ended within ``seconds`` (gone, or a zombie not yet
    reaped by the process that adopted it)?"""
    if not os.path.exists(f"/proc/{os.getpid()}/stat"):
        pytest.skip("another process's state is read from Linux's /proc")
    t0 = time.monotonic()
    while time.monotonic() - t0 < seconds:
        try:
            with open(f"/proc/{pid}/stat") as f:
                state = f.read().rsplit(")", 1)[1].split()[0]
        except FileNotFoundError:
            return True
        if state in ("Z", "X"):
            return True
        time.sleep(0.05)
    return False


def slow_plot(seconds: float):
    def plot(M):
        time.sleep(seconds)
        return line_plot([])(M, 1.0)
    return plot


def test_a_stopped_worker_is_killed_by_the_watchdog_and_the_kernel_draws_the_rest(monkeypatch):
    """A worker that sends nothing (stopped with SIGSTOP right after the explorer is made) is killed
    once it has been silent for SILENCE_SECONDS; meanwhile a move shows its frame without waiting
    for it (the worker is still alive then); afterwards the kernel draws every frame left."""
    from orrc.viz import LiveView, ahead

    monkeypatch.setattr(ahead, "SILENCE_SECONDS", 0.5)
    monkeypatch.setattr(ahead, "WATCH_SECONDS", 0.05)
    seen = {}

    def make():
        view = LiveView(slow_plot(0.02), {"M": list(range(10))}, {"M": 0}, 100, ahead=True)
        seen["worker"] = view.worker
        os.kill(view.worker.pid, signal.SIGSTOP)
        view.sliders["M"].value = 7                  # a frame the worker was to draw: drawn on the move
        seen["alive at the move"] = view.worker is not None and view.worker.alive
        seen["image"] = view.image.value
        return view

    view = _in_a_loop(make, until=lambda view: view.pending == 0 and view.worker is None)
    worker = seen["worker"]
    assert seen["alive at the move"] and seen["image"] == view.frames[(7,)]
    assert worker.killed and not worker.alive and view.worker is None
    assert _left(worker.pid), "the killed worker is reaped"
    assert len(view.frames) == 10 and view.pending == 0 and view.stats["on_move"] == 1


def test_a_working_worker_is_not_killed(monkeypatch):
    """The watchdog counts silence, not slowness: a worker whose frame takes longer than
    SILENCE_SECONDS (here a plotting function that computes for 3 s in the worker) but uses CPU
    time meanwhile is left to send it."""
    from orrc.viz import LiveView, ahead

    if ahead._cpu_ticks(os.getpid()) is None:
        pytest.skip("the CPU time of a process is read from Linux's /proc")
    monkeypatch.setattr(ahead, "SILENCE_SECONDS", 1.5)
    monkeypatch.setattr(ahead, "WATCH_SECONDS", 0.05)
    kernel, seen = os.getpid(), {}

    def plot(M):
        t0 = time.monotonic()
        while os.getpid() != kernel and time.monotonic() - t0 < 3.0:   # computing, in the worker only
            pass
        return line_plot([])(M, 1.0)

    def make():
        view = LiveView(plot, {"M": [0, 1, 2]}, {"M": 0}, 100, ahead=True)
        seen["worker"] = view.worker
        return view

    view = _in_a_loop(make, until=lambda view: view.pending == 0 and view.worker is None)
    assert not seen["worker"].killed and view.stats == {"on_move": 0, "ahead": 2, "cached": 0}


def test_a_rerun_of_the_cell_leaves_one_worker_per_explorer(monkeypatch):
    """Two explorers made by one run of a cell keep their workers; the next run of that cell stops
    both (their explorers draw nothing ahead any more) and its explorer has the only worker."""
    from orrc.viz import LiveView, ahead, live

    runs = iter([("cell-a", "run-1"), ("cell-a", "run-1"), ("cell-a", "run-2")])
    monkeypatch.setattr(live, "_running_cell", lambda: next(runs))
    seen = {}

    def make():
        first = [LiveView(slow_plot(0.1), {"M": list(range(30))}, {"M": 0}, 100, ahead=True) for _ in range(2)]
        seen["pids before"] = [v.worker.pid for v in first]
        seen["running before"] = ahead.running()
        again = LiveView(slow_plot(0.1), {"M": list(range(30))}, {"M": 0}, 100, ahead=True)
        seen.update(first=first, again=again, running=ahead.running())
        return again

    _in_a_loop(make, until=lambda view: True)
    assert all(pid in seen["running before"] for pid in seen["pids before"])
    assert all(v.closed and v.worker is None and v.pending == 0 for v in seen["first"])
    assert seen["again"].worker.pid in seen["running"]
    assert not set(seen["running"]) & set(seen["pids before"]), "the replaced workers are stopped"
    assert all(_left(pid) for pid in seen["pids before"]), "the replaced explorers' workers are reaped"
    seen["again"].close()
    assert _left(seen["running"][0])


def test_closing_the_widget_stops_its_worker():
    from orrc.viz import LiveView

    seen = {}

    def make():
        view = LiveView(slow_plot(0.1), {"M": list(range(30))}, {"M": 0}, 100, ahead=True)
        seen["pid"] = view.worker.pid
        view.widget.close()
        return view

    view = _in_a_loop(make, until=lambda view: True)
    assert view.closed and view.worker is None and view.pending == 0
    assert _left(seen["pid"])


KERNEL = textwrap.dedent("""
    import asyncio, os, signal, sys
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from orrc.viz import LiveView

    def plot(M):
        fig, ax = plt.subplots(figsize=(2, 1.5))
        ax.plot([0, 1], [M, 1])
        return fig

    async def main():
        view = LiveView(plot, {"M": list(range(40))}, {"M": 0}, 100, ahead=True)
        os.kill(view.worker.pid, signal.SIGSTOP)     # stuck: it would never leave by itself
        print(view.worker.pid, flush=True)
        if sys.argv[1] == "killed":
            os.kill(os.getpid(), signal.SIGKILL)
        await asyncio.sleep(0.1)

    asyncio.run(main())
""")


@pytest.mark.parametrize("end", ["exits", "killed"])
def test_no_worker_outlives_its_kernel(end):
    """A kernel that exits kills and reaps its workers (atexit); one killed outright takes them with
    it (Linux's parent-death signal), even a worker that is stuck."""
    if end == "killed" and not sys.platform.startswith("linux"):
        pytest.skip("the parent-death signal is Linux's")
    run = subprocess.run([sys.executable, "-c", KERNEL, end], capture_output=True, text=True, timeout=120)
    assert run.stdout.strip(), run.stderr[-2000:]
    pid = int(run.stdout.split()[0])
    assert _gone(pid), f"the worker {pid} outlived its kernel ({end})"


SLOW_EXPLORER = textwrap.dedent("""
    import os, time
    import orrc
    import orrc.viz
    from matplotlib.figure import Figure
    kernel = os.getpid()

    def plot(M):
        if os.getpid() != kernel:
            time.sleep(0.5)                   # the worker takes its time: it is still drawing below
        fig = Figure(figsize=(3, 2))
        fig.subplots().plot([0, 1], [0, M])
        return fig
""")


def test_in_a_kernel_a_rerun_of_the_cell_and_the_kernels_end_leave_no_worker():
    """In a Jupyter kernel, as JupyterLab runs a notebook (each request names its cell): running the
    explorer's cell again leaves one worker (the first is killed and reaped by the kernel); after
    the kernel shuts down none is left."""
    from benchmarks.widgets import ROOT, Kernel, _printed, kernel_env

    k = Kernel(ROOT / "book", kernel_env(quick=True))

    def run_cell(code: str, cell: str) -> str:
        msg = k.kc.session.msg("execute_request", {"code": code, "silent": False, "store_history": True,
                                                   "user_expressions": {}, "allow_stdin": False,
                                                   "stop_on_error": True}, metadata={"cellId": cell})
        k.kc.shell_channel.send(msg)
        msgs = k._until_idle(msg["header"]["msg_id"], 120)
        errors = [m["content"]["evalue"] for m in msgs if m["msg_type"] == "error"]
        assert not errors, errors
        return _printed(msgs)

    try:
        run_cell(SLOW_EXPLORER, "setup")
        workers = []
        for _ in range(2):
            run_cell("ex = orrc.viz.explore(plot, M=list(range(40)))", "explorer")
            workers.append(eval(run_cell("print(orrc.viz.ahead.running())", "probe")))
    finally:
        k.km.shutdown_kernel(now=False)       # as JupyterLab shuts a kernel down (a request, then exit)
        k.kc.stop_channels()
        k._sockets.cleanup()
    (first,), (second,) = workers
    assert first != second
    assert _gone(first), "the worker of the explorer's first run is left"
    assert _gone(second), "a worker outlived its kernel's shutdown"
