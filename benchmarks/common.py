"""Shared helpers of the benchmarks: timing, a result row, the Markdown table, the machine.

Benchmarks are not timed unit tests: each one measures orrc against a peer in the
same run (so the machine's speed and load cancel in the ratio), reports medians of
several repetitions, and says whether its target is met.

**What is measured**. A peer comparison states CPU time (``time.process_time``: the
time this process computed, which another process's load does not inflate) and wall time
(``time.perf_counter``), with the BLAS thread count equal on both sides: :func:`one_thread`
limits every BLAS/OpenMP pool to one thread (threadpoolctl) for the whole run, and
:func:`blas_threads` reports what threadpoolctl sees, so that a ratio does not measure thread
contention in one of the tools. Peers that run in their own virtual environment get the same
limit through the environment variables of :data:`ONE_THREAD_ENV` and report their own count.
"""
from __future__ import annotations

import gc
import os
import platform
import re
import sys
import time
from dataclasses import dataclass, field

import numpy as np

#: the environment of a peer's child process: one thread for every BLAS / OpenMP pool
ONE_THREAD_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
                  "BLIS_NUM_THREADS": "1", "VECLIB_MAXIMUM_THREADS": "1"}


def one_thread():
    """A context in which every BLAS / OpenMP thread pool of this process has one thread."""
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1)


def blas_threads() -> str:
    """The thread pools threadpoolctl finds in this process, "openblas: 1, openmp: 1" (or "no BLAS
    pool loaded")."""
    from threadpoolctl import threadpool_info

    pools = {}
    for info in threadpool_info():
        pools.setdefault(info.get("internal_api", info.get("user_api", "?")), set()).add(info["num_threads"])
    return ", ".join(f"{k}: {'/'.join(map(str, sorted(v)))}" for k, v in sorted(pools.items())) or "no BLAS pool loaded"


def cpu_and_wall(fn, *args, **kwargs):
    """(result, CPU seconds, wall seconds) of one call (``process_time`` and ``perf_counter``), with the
    garbage collector paused as ``timeit`` does."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        c0, t0 = time.process_time(), time.perf_counter()
        out = fn(*args, **kwargs)
        return out, time.process_time() - c0, time.perf_counter() - t0
    finally:
        if enabled:
            gc.enable()


class Seconds(float):
    """CPU seconds of a call (its value), with the wall seconds of the same call as ``.wall``."""

    def __new__(cls, cpu: float, wall: float):
        obj = super().__new__(cls, cpu)
        obj.wall = wall
        return obj


def timed(fn, *args, **kwargs):
    """(result, seconds) of one call, with the garbage collector paused as ``timeit`` does: the seconds
    are CPU time (``process_time``; a :class:`Seconds`, its wall time as ``.wall``)."""
    out, cpu, wall = cpu_and_wall(fn, *args, **kwargs)
    return out, Seconds(cpu, wall)


def wall_median(times) -> float:
    """The median wall time of :class:`Seconds` measurements."""
    return float(np.median([t.wall for t in times]))


def fmt_time(seconds: float) -> str:
    """A duration with a unit that keeps 3 significant digits (µs, ms or s)."""
    if seconds < 1e-3:
        return f"{seconds * 1e6:.3g} µs"
    if seconds < 1.0:
        return f"{seconds * 1e3:.3g} ms"
    return f"{seconds:.3g} s"


@dataclass
class Row:
    """One line of the results table.

    ``ratio`` is defined per row (e.g. peer time / orrc time for a speed-up, orrc
    time / floor time for an overhead); ``target`` says what it must satisfy and
    ``ok`` whether it did (None: an informational row with no target).
    """

    benchmark: str
    case: str
    orrc: str
    peer: str
    ratio: str
    target: str
    ok: bool | None
    check: str = ""
    data: dict = field(default_factory=dict)


def markdown_table(rows: list[Row]) -> str:
    head = ["benchmark", "case", "orrc (median)", "peer (median)", "ratio", "target", "met", "correctness check"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        met = "—" if r.ok is None else ("yes" if r.ok else "**NO**")
        cells = [r.benchmark, r.case, r.orrc, r.peer, r.ratio, r.target, met, r.check]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def machine_info() -> dict:
    """The machine and the library versions, as a dict (the results file's ``machine`` and ``versions``)."""
    import casadi
    import control
    import scipy

    import orrc

    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        cores = os.cpu_count()
    return {"cpu": cpu, "cores": cores, "platform": platform.platform(),
            "versions": {"python": sys.version.split()[0], "orrc": orrc.__version__, "numpy": np.__version__,
                         "scipy": scipy.__version__, "casadi": casadi.__version__,
                         "python-control": control.__version__}}


def machine() -> str:
    """A one-line description of the machine and the library versions."""
    info = machine_info()
    v = info["versions"]
    return (f"{info['cpu']}, {info['cores']} cores available; Python {v['python']}, numpy {v['numpy']}, "
            f"scipy {v['scipy']}, casadi {v['casadi']}, python-control {v['python-control']}")


def parse_time(text: str) -> float | None:
    """The seconds of the duration that starts ``text`` as :func:`fmt_time` writes it ("77.2 µs (...)"),
    or None where it starts with none ("skipped", "—")."""
    m = _TIME.match(text.strip())
    return float(m.group(1)) * _UNIT[m.group(2)] if m else None


_TIME = re.compile(r"([0-9]+(?:\.[0-9]*)?(?:e[+-]?[0-9]+)?) (µs|ms|s)\b")
_UNIT = {"µs": 1e-6, "ms": 1e-3, "s": 1.0}


class CheckFailed(AssertionError):
    """A benchmark's correctness check failed (the two computations disagree)."""
