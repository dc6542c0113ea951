"""Benchmark 6: how fast the book's explorers re-draw in a live kernel.

For every notebook chapter of ``_toc.yml`` (or those given): start a Python kernel (jupyter_client,
the ``python3`` kernel of this environment, working directory ``book/``, matplotlib's default
backend of a kernel, as in JupyterLab; no ``ORRC_BOOK_BUILD``, so the chapter runs as in a live
notebook), execute the chapter cell by cell (jupytext reads it), and collect every live widget a
cell displayed (``application/vnd.jupyter.widget-view+json`` in its outputs) that holds sliders:
each is one explorer of :func:`orrc.viz.explore`. Then drive it as a reader does: for each slider in
turn (the others at their initial values), move it through each of its other values and back to its
initial one, by sending the kernel the message a browser sends when a slider is released (a
``comm_msg`` with the new ``index``), and time from sending it until the kernel is idle again with the
new figure published: a ``display_data`` carrying an image into the explorer's output widget, or an
update of an image widget's ``value``. The time covers the kernel's work and the messages, not the
browser's decoding of the PNG.

Reported per explorer: the median and the maximum time per move (target: below 0.2 s and 0.4 s),
and separately the *first moves*, made right after the chapter ran, while the frames are still being
drawn ahead (one move of each slider to its first other value, and back; the same targets), with how
many of them found no frame drawn and drew it on the move. Times are wall time: the latency a reader
waits for (the kernel is another process); the check: every move published a new figure. The chapters run at full size (the explorers, their
grids and data, are the book's); ``--quick`` drives one small explorer of its own (:data:`DEMO_CELLS`)
and only says that the benchmark works.
"""
from __future__ import annotations

import os
import statistics
import sys
import time
from pathlib import Path

from .common import CheckFailed, Row, fmt_time

ROOT = Path(__file__).resolve().parents[1]
TARGET_MEDIAN = 0.2
TARGET_MAX = 0.4
CELL_TIMEOUT = 600.0
MOVE_TIMEOUT = 120.0
#: the first moves of each slider, made right after the chapter ran (before the frames are drawn ahead)
FIRST_MOVES = 1

# run in the kernel: the sliders and the output of the widget with this model id (an explorer's
# VBox: its SelectionSliders and the widget the figure is drawn into), and the explorers' live views
_INSPECT = r"""
def _orrc_bench_views():
    import gc
    from orrc.viz.live import LiveView
    # type(), not isinstance(): gc also holds dead weakref proxies, which raise ReferenceError on any use
    return {v.widget.model_id: v for v in gc.get_objects() if type(v) is LiveView}

def _orrc_bench_pending():
    print(sum(v.pending for v in _orrc_bench_views().values()))

def _orrc_bench_inspect(model_id):
    import json
    from ipywidgets import widgets as _w
    box = _w.widget._instances.get(model_id)      # None: closed since (a progress bar, leave=False)
    kids = list(getattr(box, "children", ()))
    sliders = [k for k in kids if isinstance(k, _w.SelectionSlider)]
    others = [k for k in kids if not isinstance(k, _w.SelectionSlider)]
    view = _orrc_bench_views().get(model_id)
    print(json.dumps({"sliders": [{"name": s.description, "model_id": s.model_id, "n": len(s.options),
                                   "index": s.index} for s in sliders],
                      "outputs": [{"model_id": o.model_id, "kind": type(o).__name__} for o in others],
                      "stats": None if view is None else dict(view.stats)}))

def _orrc_bench_forget(model_id):
    _orrc_bench_views()[model_id].forget()     # the frames drawn so far forgotten: every move draws its frame
"""


# a notebook of one small explorer: what ``--quick`` drives (the machinery works; its timings mean nothing)
DEMO_CELLS = [
    "from matplotlib.figure import Figure\nimport orrc.viz\n\n\ndef plot(M, a):\n"
    "    fig = Figure(figsize=(4, 2.5))\n    fig.subplots().plot(range(M + 1), [a ** t for t in range(M + 1)])\n"
    "    return fig",
    "orrc.viz.explore(plot, M=[2, 5, 10], a=[0.5, 0.9])",
]


class Kernel:
    """One kernel and its client; :meth:`run` executes code, :meth:`comm_update` sends a widget update."""

    def __init__(self, cwd: Path, env: dict):
        import tempfile

        from jupyter_client.manager import KernelManager

        self._sockets = tempfile.TemporaryDirectory(prefix="orrc-bench-")   # local sockets, not TCP
        self.km = KernelManager(kernel_name="python3", transport="ipc", ip=str(Path(self._sockets.name) / "k"))
        self.km.start_kernel(cwd=str(cwd), env=env)
        self.kc = self.km.client()
        self.kc.start_channels()
        try:
            self.kc.wait_for_ready(timeout=120)
        except RuntimeError:
            self.close()
            raise

    def _until_idle(self, msg_id: str, timeout: float) -> list[dict]:
        """Every iopub message of the request ``msg_id`` up to the kernel's idle status."""
        import queue

        msgs, deadline = [], time.monotonic() + timeout
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                raise CheckFailed(f"the kernel did not finish a request within {timeout:.0f} s")
            try:
                msg = self.kc.get_iopub_msg(timeout=left)
            except queue.Empty:
                continue
            if msg["parent_header"].get("msg_id") != msg_id:
                continue
            if msg["msg_type"] == "status" and msg["content"]["execution_state"] == "idle":
                return msgs
            msgs.append(msg)

    def run(self, code: str, timeout: float = CELL_TIMEOUT, what: str = "a cell") -> list[dict]:
        msg_id = self.kc.execute(code, store_history=True, allow_stdin=False)
        msgs = self._until_idle(msg_id, timeout)
        for m in msgs:
            if m["msg_type"] == "error":
                raise CheckFailed(f"{what} raised {m['content']['ename']}: {m['content']['evalue']}")
        return msgs

    def comm_update(self, model_id: str, state: dict, timeout: float = MOVE_TIMEOUT) -> tuple[float, list[dict]]:
        """Send a widget state update as a browser does; (seconds until idle, the messages)."""
        msg = self.kc.session.msg("comm_msg", {"comm_id": model_id,
                                               "data": {"method": "update", "state": state, "buffer_paths": []}})
        t0 = time.perf_counter()
        self.kc.shell_channel.send(msg)
        msgs = self._until_idle(msg["header"]["msg_id"], timeout)
        return time.perf_counter() - t0, msgs

    def close(self) -> None:
        self.kc.stop_channels()
        self.km.shutdown_kernel(now=True)
        self._sockets.cleanup()


def _redrawn(msgs: list[dict], outputs: list[dict]) -> bool:
    """Did the kernel publish a new figure in answer to one move?"""
    ids = {o["model_id"] for o in outputs}
    for m in msgs:
        c = m["content"]
        if m["msg_type"] == "display_data" and {"image/png", "text/html"} & set(c.get("data", {})):
            return True
        if (m["msg_type"] == "comm_msg" and c.get("comm_id") in ids and m.get("buffers")
                and ["value"] in c.get("data", {}).get("buffer_paths", [])):   # an Image's new PNG
            return True
    return False


def chapter_cells(page: str) -> list[str]:
    import jupytext

    nb = jupytext.read(ROOT / f"{page}.md")
    return [c.source for c in nb.cells if c.cell_type == "code"]


def kernel_env(quick: bool) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("MPLBACKEND", "ORRC_BOOK_BUILD", "ORRC_QUICK")}
    if quick:
        env["ORRC_QUICK"] = "1"
    env["PYDEVD_DISABLE_FILE_VALIDATION"] = "1"
    return env


def _printed(msgs: list[dict]) -> str:
    return "".join(m["content"]["text"] for m in msgs if m["msg_type"] == "stream" and m["content"]["name"] == "stdout")


def _drive(k: Kernel, info: dict, max_moves: int | None) -> tuple[list[float], int]:
    """Move every slider of one explorer through its other values and back; (seconds per move, moves
    that published a new figure)."""
    times, redrawn = [], 0
    for s in info["sliders"]:
        if s["n"] < 2:          # a slider with one value cannot move
            continue
        path = [i for i in range(s["n"]) if i != s["index"]][:max_moves] + [s["index"]]
        for idx in path:
            dt, msgs = k.comm_update(s["model_id"], {"index": idx})
            times.append(dt)
            redrawn += _redrawn(msgs, info["outputs"])
    return times, redrawn


def drive_cells(cells: list[str], quick: bool = False, max_moves: int | None = None, what: str = "notebook",
                ready_timeout: float = 600.0) -> list[dict]:
    """Execute ``cells`` in a fresh kernel (as a reader runs a chapter), wait until the explorers have
    drawn their frames ahead, then drive every explorer displayed, twice: as a reader does (the
    frames drawn ahead shown from the cache), and with the frames forgotten (each move draws its
    frame: what a move costs before the frames are ready). One dict per explorer: ``index``,
    ``params`` (name -> number of values), ``times`` and ``cold`` (seconds per move), ``redrawn`` and
    ``cold_redrawn`` (moves that published a figure), ``first``, ``first_redrawn`` and ``first_on_move``
    (the first moves: seconds, re-drawn, drawn on the move), ``stats`` (the live view's counts after the
    first pass), ``exec_seconds`` (the cells' execution; ``cell_seconds`` per cell) and ``ready_seconds`` (from the end of the
    execution until every frame was drawn ahead)."""
    import json

    k = Kernel(ROOT / "book", kernel_env(quick))
    try:
        found, cell_seconds = [], []
        t0 = time.perf_counter()
        for i, code in enumerate(cells):
            t_cell = time.perf_counter()
            msgs = k.run(code, what=f"{what}, code cell {i + 1}")
            cell_seconds.append(time.perf_counter() - t_cell)
            for m in msgs:
                data = m["content"].get("data", {})
                view = data.get("application/vnd.jupyter.widget-view+json")
                if m["msg_type"] in ("execute_result", "display_data") and view:
                    found.append(view["model_id"])
        exec_seconds = time.perf_counter() - t0
        k.run(_INSPECT, what="the inspection helper")
        first = {}  # the first moves, right after the chapter ran: the frames are still being drawn ahead
        for model_id in found:
            info = json.loads(_printed(k.run(f"_orrc_bench_inspect({model_id!r})", what="the inspection")))
            if info["sliders"]:
                times, redrawn = _drive(k, info, FIRST_MOVES)
                stats = json.loads(_printed(k.run(f"_orrc_bench_inspect({model_id!r})")))["stats"]
                first[model_id] = times, redrawn, None if stats is None else stats["on_move"]
        t0 = time.perf_counter()
        while int(_printed(k.run("_orrc_bench_pending()")) or 0) > 0:
            if time.perf_counter() - t0 > ready_timeout:
                raise CheckFailed(f"{what}: the explorers had not drawn their frames {ready_timeout:.0f} s "
                                  "after the execution")
            time.sleep(0.25)
        ready_seconds = time.perf_counter() - t0
        results = []
        for model_id in found:
            info = json.loads(_printed(k.run(f"_orrc_bench_inspect({model_id!r})", what="the inspection")))
            if not info["sliders"]:
                continue
            times, redrawn = _drive(k, info, max_moves)
            stats = json.loads(_printed(k.run(f"_orrc_bench_inspect({model_id!r})")))["stats"]
            cold, cold_redrawn = [], 0
            if stats is not None:
                k.run(f"_orrc_bench_forget({model_id!r})")
                cold, cold_redrawn = _drive(k, info, max_moves)
            results.append({"index": len(results) + 1, "exec_seconds": exec_seconds, "ready_seconds": ready_seconds,
                            "first": first[model_id][0], "first_redrawn": first[model_id][1],
                            "first_on_move": first[model_id][2],
                            "cell_seconds": cell_seconds,
                            "params": {s["name"]: s["n"] for s in info["sliders"]}, "times": times,
                            "redrawn": redrawn, "cold": cold, "cold_redrawn": cold_redrawn, "stats": stats})
        return results
    finally:
        k.close()


def drive_chapter(page: str, quick: bool = False, max_moves: int | None = None) -> list[dict]:
    """:func:`drive_cells` on the code cells of the chapter ``page`` (e.g. ``book/lemma1``)."""
    return [{"page": page, **r} for r in drive_cells(chapter_cells(page), quick, max_moves, what=page)]


def run(chapters=None, quick: bool = False, max_moves: int | None = None, demo: bool = False) -> list[Row]:
    """One row per explorer of ``chapters`` (default: every notebook page of ``_toc.yml``); ``demo``:
    only the small explorer of :data:`DEMO_CELLS` (what ``--quick`` runs)."""
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    from tools.toc import notebook_pages

    pages = ["demo"] if demo else list(chapters) if chapters else notebook_pages()
    rows, failures = [], []
    for page in pages:
        results = ([{"page": page, **r} for r in drive_cells(DEMO_CELLS, quick, max_moves, what=page)] if demo
                   else drive_chapter(page, quick=quick, max_moves=max_moves))
        for r in results:
            t, cold = r["times"], r["cold"]
            med, worst = statistics.median(t), max(t)
            ok = med < TARGET_MEDIAN and worst < TARGET_MAX
            params = ", ".join(f"{k}: {n}" for k, n in r["params"].items())
            check = f"{r['redrawn']}/{len(t)} moves re-drew the figure"
            if r["redrawn"] != len(t) or r["cold_redrawn"] != len(cold):
                failures.append(f"{page} explorer {r['index']}: {check}, {r['cold_redrawn']}/{len(cold)} without "
                                "the frames drawn ahead")
            peer = (f"{fmt_time(statistics.median(cold))} (max {fmt_time(max(cold))}) each move drawing its frame"
                    if cold else "—")
            first = r["first"]
            if first:
                f_med, f_max = statistics.median(first), max(first)
                rows.append(Row("widgets (live kernel), first moves right after the chapter ran",
                                f"{page.removeprefix('book/')} #{r['index']} ({params})", fmt_time(f_med), "—",
                                f"max {fmt_time(f_max)} over {len(first)} moves",
                                f"median < {TARGET_MEDIAN * 1e3:.0f} ms, max < {TARGET_MAX * 1e3:.0f} ms",
                                f_med < TARGET_MEDIAN and f_max < TARGET_MAX,
                                f"{r['first_redrawn']}/{len(first)} moves re-drew the figure, "
                                f"{'?' if r['first_on_move'] is None else r['first_on_move']} drawn on the move "
                                "(wall time, as a reader waits)",
                                dict(median=f_med, max=f_max, times=first, on_move=r["first_on_move"])))
                if r["first_redrawn"] != len(first):
                    failures.append(f"{page} explorer {r['index']}: {r['first_redrawn']}/{len(first)} first moves "
                                    "re-drew the figure")
            rows.append(Row("widgets (live kernel, per slider move)",
                            f"{page.removeprefix('book/')} #{r['index']} ({params})",
                            fmt_time(med), peer, f"max {fmt_time(worst)} over {len(t)} moves",
                            f"median < {TARGET_MEDIAN * 1e3:.0f} ms, max < {TARGET_MAX * 1e3:.0f} ms", ok,
                            check + f"; frames ready {r['ready_seconds']:.1f} s after the chapter ran",
                            dict(median=med, max=worst, times=t, cold=cold, stats=r["stats"],
                                 exec_seconds=r["exec_seconds"], ready_seconds=r["ready_seconds"])))
    if failures:
        raise CheckFailed("; ".join(failures))
    return rows
