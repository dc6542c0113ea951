"""Shared helpers of the benchmarks: timing, a result row, the Markdown table, the machine.

Benchmarks are not timed unit tests: each one measures orrc against a peer in the
same run (so the machine's speed and load cancel in the ratio), reports medians of
several repetitions, and says whether the target of issue 2 is met.
"""
from __future__ import annotations

import gc
import os
import platform
import sys
import time
from dataclasses import dataclass, field

import numpy as np


def timed(fn, *args, **kwargs):
    """(result, seconds) of one call, with the garbage collector paused as ``timeit`` does."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        t0 = time.perf_counter()
        out = fn(*args, **kwargs)
        return out, time.perf_counter() - t0
    finally:
        if enabled:
            gc.enable()


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


def machine() -> str:
    """A one-line description of the machine and the library versions."""
    import casadi
    import control
    import scipy

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
    return (f"{cpu}, {cores} cores available; Python {sys.version.split()[0]}, numpy {np.__version__}, "
            f"scipy {scipy.__version__}, casadi {casadi.__version__}, python-control {control.__version__}")


class CheckFailed(AssertionError):
    """A benchmark's correctness check failed (the two computations disagree)."""
