"""Frames drawn ahead in a worker process, so that the kernel stays free for the reader's moves.

A live explorer (:class:`orrc.viz.live.LiveView`) draws the frames the reader has not asked for yet
while the kernel is idle. Drawn on the kernel's own thread, a frame in progress delays a slider move
that arrives meanwhile by up to one drawing (0.1 to 0.3 s for the book's three-panel figures, more
on a busy machine). :func:`start` draws them in a child process instead:

* the child is **forked** from the kernel (``os.fork``) when the explorer is made: it holds the
  plotting function and its data as they were then, nothing is pickled, and the plotting function
  never runs inside the kernel beside a cell (the child is another process, on a copy of the
  kernel's memory);
* it draws one grid point after the other in the order the view gives (nearest the current view
  first); the view sends it every new view and the frames it drew itself (:meth:`Worker.show`), and
  the child orders what is left again around that view;
* it runs at a lower CPU priority than the kernel (``os.nice``), so a move drawn on the spot in the
  kernel comes first;
* it sends each PNG through a pipe that the kernel's event loop reads while it is idle
  (``loop.add_reader``; while the kernel runs a cell, the frames wait in the child's memory and
  the child draws on); a plotting error is sent as a frame that failed (the view draws that grid
  point on the move and shows the error);
* it prints nothing (its output streams are ``os.devnull``), ignores the kernel's interrupt (meant
  for a cell), and leaves with ``os._exit`` (none of the kernel's clean-up, no message on its
  sockets) when every frame is sent, when its pipe closes (the kernel is gone) or on an error.

Nothing in the kernel ever waits for the child (a move to a frame not drawn yet draws it on the
spot), and no child outlives what it works for:

* **a watchdog** (:meth:`Worker._watch`, every :data:`WATCH_SECONDS` of the kernel's loop) kills a
  child that has shown no sign of life for :data:`SILENCE_SECONDS`: no byte of a frame and, where
  Linux's ``/proc`` tells, no CPU time used (a child that is stuck, e.g. on a lock another thread of
  the kernel held when it forked, or stopped, uses none; one drawing slowly on a loaded machine uses
  some), or that has sent nothing for :data:`FRAME_SECONDS`; the view then draws the frames left on
  the kernel's thread between cells (the fallback below);
* a worker that is stopped (:meth:`Worker.stop`: the view was closed, replaced by a re-run of its
  cell, or forgot its frames) is killed at once, not asked to leave, and reaped (no zombie);
* when the kernel exits, every worker left is killed and reaped (``atexit``); when it is killed
  outright, Linux's parent-death signal (``prctl(PR_SET_PDEATHSIG)``, armed in the child) kills
  the child with it (the signal comes when the thread that forked it ends: the kernel's main
  thread, which runs the cells).

Why ``fork`` and not ``multiprocessing``'s ``forkserver`` or ``spawn``: both start the worker from a
fresh interpreter and must pickle what it draws, and a chapter's plotting function is defined in
the notebook (``__main__``, which a fresh interpreter does not have) over the chapter's results;
a fresh interpreter also imports matplotlib and ``orrc.viz`` again (1.2 s of CPU here) before its
first frame. A fork copies both at once. Its hazard, a lock held by another of the kernel's
threads (ZMQ's, the heartbeat's, IPython's history) at the fork, is small here: the child runs only
the plotting function and matplotlib, which only the kernel's main thread (the one that forks)
uses; CPython re-initialises its own locks (imports, logging) in a forked child, OpenBLAS its
threads. What is left is what the watchdog is for.

Where ``os.fork`` or the loop's ``add_reader`` is missing (Windows), :func:`start` returns None and
the view draws ahead on the kernel's thread, as before.
"""
from __future__ import annotations

import atexit
import ctypes
import gc
import os
import pickle
import select
import signal
import struct
import sys
import time
import warnings

__all__ = ["Worker", "start", "running", "NICE", "SILENCE_SECONDS", "FRAME_SECONDS"]

#: how much lower the child's CPU priority is than the kernel's (``os.nice`` increment)
NICE = 10
#: the longest a live worker may show no sign of life while the kernel's loop turns before the
#: kernel kills it: no byte of a frame and, where the system tells (Linux), no CPU time used (a
#: stuck or stopped child uses none; a child drawing slowly on a loaded machine uses some)
SILENCE_SECONDS = 10.0
#: the longest a live worker may send no byte at all, working or not (one frame takes 0.05 to 2 s)
FRAME_SECONDS = 60.0
#: how often the kernel's loop looks at its workers (the watchdog's period)
WATCH_SECONDS = 0.5
_HEAD = struct.Struct("!I")   # every message: its length, then a pickle
_OPEN: set[int] = set()       # the kernel's ends of every worker's pipes (a new child closes them)
_LIVE: dict[int, Worker] = {}  # every worker not reaped yet, by pid (killed when the kernel exits)
_PR_SET_PDEATHSIG = 1         # prctl(2): the signal a process gets when its parent dies (Linux)


def _pack(obj) -> bytes:
    body = pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)
    return _HEAD.pack(len(body)) + body


def _unpack(buf: bytearray) -> list:
    """The complete messages at the start of ``buf`` (removed from it)."""
    out = []
    while len(buf) >= _HEAD.size:
        (n,) = _HEAD.unpack_from(buf)
        if len(buf) < _HEAD.size + n:
            break
        out.append(pickle.loads(bytes(buf[_HEAD.size:_HEAD.size + n])))
        del buf[:_HEAD.size + n]
    return out


def _read_available(fd: int, buf: bytearray) -> bool:
    """Append what ``fd`` (non-blocking) holds now to ``buf``; False when its other end is closed."""
    while True:
        try:
            chunk = os.read(fd, 1 << 16)
        except BlockingIOError:
            return True
        if not chunk:
            return False
        buf += chunk


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


def _flush(fd: int, outbox: bytearray) -> None:
    """Write what the pipe ``fd`` (non-blocking) takes now from the start of ``outbox``."""
    while outbox:
        try:
            n = os.write(fd, outbox)
        except BlockingIOError:
            return
        del outbox[:n]


def _prctl():
    """The C library's ``prctl`` (Linux), looked up in the kernel before any fork; else None."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        return ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return None


def _die_with(parent: int, prctl) -> None:
    """Have the system kill this child when the kernel's process ends, however it ends (Linux's
    parent-death signal): a child stuck in a frame is never left behind by a killed kernel."""
    if prctl is not None:
        prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:   # the kernel ended before the signal was armed
        os._exit(0)


def _child(draw, order, out_fd: int, in_fd: int, parent: int) -> None:
    """The child's work: draw the keys of ``order(view)`` not drawn yet, send each frame."""
    gc.freeze()                  # the kernel's objects are never collected here (no widget's __del__ runs)
    sys.stdout = sys.stderr = open(os.devnull, "w")   # noqa: SIM115 - the child's whole life
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    os.nice(NICE)
    os.set_blocking(in_fd, False)
    os.set_blocking(out_fd, False)   # frames wait in the outbox while the kernel runs a cell
    todo, inbox, outbox = list(order(None)), bytearray(), bytearray()
    while todo and os.getppid() == parent:
        if not _read_available(in_fd, inbox):
            return               # the view stopped the worker
        for view, drawn in _unpack(inbox):
            left = set(todo) - set(drawn)
            todo = [k for k in order(view) if k in left]
        if not todo:
            break
        key = todo.pop(0)
        try:
            png = draw(key)
        except Exception:  # noqa: BLE001 - the view draws this grid point on the move and shows the error
            png = None
        outbox += _pack((key, png))
        _flush(out_fd, outbox)
    os.set_blocking(out_fd, True)
    _write_all(out_fd, outbox)


class Worker:
    """The kernel's side of a child drawing frames (see the module docstring). ``pid``: the child's
    process id; ``alive``: False once it has ended (all frames sent, stopped, killed by the watchdog,
    or failed); ``killed``: True when the watchdog killed it (no sign of life for
    :data:`SILENCE_SECONDS`, or no frame for :data:`FRAME_SECONDS`)."""

    def __init__(self, pid: int, out_r: int, cmd_w: int, loop, on_frame, on_end):
        self.pid, self._out, self._cmd, self._loop = pid, out_r, cmd_w, loop
        self._on_frame, self._on_end = on_frame, on_end
        self._inbox = bytearray()
        self.alive, self.killed, self._reaped = True, False, False
        # seconds without a sign of life (a byte, CPU time) and without a byte from the child
        self._silent, self._quiet, self._looked, self._cpu = 0.0, 0.0, time.monotonic(), _cpu_ticks(pid)
        os.set_blocking(out_r, False)
        os.set_blocking(cmd_w, False)
        loop.add_reader(out_r, self._readable)
        _LIVE[pid] = self
        loop.call_later(WATCH_SECONDS, self._watch)

    def _readable(self) -> None:
        if not self.alive:
            return
        n = len(self._inbox)
        more = _read_available(self._out, self._inbox)
        if len(self._inbox) != n or not more:
            self._silent = self._quiet = 0.0
        for key, png in _unpack(self._inbox):
            self._on_frame(key, png)
        if not more:
            self._end()

    def _watch(self) -> None:
        """The watchdog, every :data:`WATCH_SECONDS` of the kernel's loop: what the child sent is
        read first; a child that showed no sign of life for :data:`SILENCE_SECONDS` (stuck, stopped)
        or sent nothing for :data:`FRAME_SECONDS` is killed, and the view draws what is left itself.
        A cell that keeps the loop busy counts as one period at most (the child may have been
        starved meanwhile)."""
        if not self.alive:
            return
        now, cpu = time.monotonic(), _cpu_ticks(self.pid)
        period = min(now - self._looked, WATCH_SECONDS)
        self._quiet += period
        self._silent = 0.0 if cpu != self._cpu else self._silent + period
        self._looked, self._cpu = now, cpu
        self._readable()
        if not self.alive:
            return
        if self._silent >= SILENCE_SECONDS or self._quiet >= FRAME_SECONDS:
            self.killed = True
            self._end()
        elif not self._loop.is_closed():
            self._loop.call_later(WATCH_SECONDS, self._watch)

    def _end(self) -> None:
        self.stop()
        self._on_end()

    def show(self, view: tuple, drawn) -> None:
        """Tell the child the reader's view now and the frames the view has (it draws the rest,
        nearest ``view`` first)."""
        if not self.alive:
            return
        message = _pack((view, sorted(drawn)))
        if len(message) > select.PIPE_BUF:     # only a message this short is written whole or not at all
            message = _pack((view, []))        # the view alone: the child may draw a frame twice
        try:
            os.write(self._cmd, message)
        except (BlockingIOError, BrokenPipeError):   # the child is busy with a frame or gone: it ends soon
            pass

    def stop(self) -> None:
        """End the child now (killed: the frames it has not sent are not wanted), close the pipes
        and reap it; nothing waits for it."""
        if not self.alive:
            return
        self.alive = False
        self._kill()
        if not self._loop.is_closed():
            self._loop.remove_reader(self._out)
        for fd in (self._out, self._cmd):
            _OPEN.discard(fd)
            os.close(fd)
        self._reap(wait=0.2)       # a killed process ends at once (else: reaped later in the loop)

    def _kill(self) -> None:
        if not self._reaped:                   # (an unreaped child's pid is never another process's)
            try:
                os.kill(self.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass

    def _reap(self, wait: float = 0.0) -> None:
        """Collect the child's exit status (at once, or in the loop every 0.05 s; ``wait``: seconds
        to wait here at most), so that no zombie is left."""
        t0 = time.monotonic()
        while not self._reaped:
            try:
                self._reaped = os.waitpid(self.pid, os.WNOHANG)[0] != 0
            except ChildProcessError:          # reaped elsewhere
                self._reaped = True
            if self._reaped or time.monotonic() - t0 >= wait:
                break
            time.sleep(0.01)
        if self._reaped:
            _LIVE.pop(self.pid, None)
        elif not self._loop.is_closed():
            self._loop.call_later(0.05, self._reap)


def _cpu_ticks(pid: int) -> int | None:
    """The CPU time process ``pid`` has used (clock ticks, from Linux's ``/proc``); None elsewhere."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            fields = f.read().rsplit(b")", 1)[1].split()
        return int(fields[11]) + int(fields[12])       # utime + stime
    except (OSError, IndexError, ValueError):
        return None


def running() -> list[int]:
    """The process ids of this process's workers that are drawing (not ended, stopped or killed)."""
    return sorted(pid for pid, worker in _LIVE.items() if worker.alive)


@atexit.register
def _stop_all() -> None:
    """When the kernel exits: every worker killed and reaped (none is left behind)."""
    for worker in list(_LIVE.values()):
        worker.alive = False
        worker._kill()
        worker._reap(wait=1.0)


#: the frames' pipe holds this many bytes where the system allows (Linux): a whole explorer's frames
#: (20 to 50 kB each) are read in one turn of the kernel's loop, not one 64 kB pipe-full per turn
PIPE_BYTES = 1 << 20


def _widen(fd: int) -> None:
    import fcntl

    try:
        fcntl.fcntl(fd, fcntl.F_SETPIPE_SZ, PIPE_BYTES)
    except (AttributeError, OSError):   # not Linux, or above the system's limit: the default size
        pass


def start(draw, order, loop, on_frame, on_end) -> Worker | None:
    """Fork a child that draws ``draw(key)`` (PNG bytes) for every key of ``order(view)`` (``view``
    None at first), and returns its :class:`Worker`; ``on_frame(key, png)`` receives each frame in
    ``loop`` (``png`` None: the plotting function raised), ``on_end()`` is called when the child has
    ended. None where the platform cannot fork or the loop cannot watch a pipe."""
    if not hasattr(os, "fork") or not hasattr(loop, "add_reader"):
        return None
    out_r, out_w = os.pipe()
    cmd_r, cmd_w = os.pipe()
    _widen(out_w)
    parent, prctl = os.getpid(), _prctl()
    with warnings.catch_warnings():    # Python 3.12 warns on fork with threads; the child uses none of them
        warnings.simplefilter("ignore", DeprecationWarning)
        pid = os.fork()
    if pid == 0:                       # the child: never returns to the kernel's code
        code = 0
        try:
            _die_with(parent, prctl)
            for fd in (*_OPEN, out_r, cmd_w):
                os.close(fd)
            _child(draw, order, out_w, cmd_r, parent)
        except BaseException:  # noqa: BLE001 - nothing of the kernel may run in the child
            code = 1
        finally:
            os._exit(code)
    os.close(out_w)
    os.close(cmd_r)
    _OPEN.update((out_r, cmd_w))
    try:
        return Worker(pid, out_r, cmd_w, loop, on_frame, on_end)
    except NotImplementedError:        # a loop without add_reader (the Windows proactor)
        for fd in (out_r, cmd_w):
            _OPEN.discard(fd)
            os.close(fd)
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
        return None
