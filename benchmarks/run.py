"""Entry point of ``make bench``: ``python -m benchmarks.run [--quick] [--only NAME]``.

Runs, with one BLAS thread for every tool (``benchmarks/common.py``), the closed-loop comparison
with the peers (``benchmarks/peers.py``: bare CasADi, do-mpc, acados, python-control;
CPU and wall time), the performance benchmarks (see ``benchmarks/pendulum.py``,
``benchmarks/closed_loop.py`` and ``benchmarks/lq_path.py``), how a closed-loop step grows with the
horizon and the state dimension (``benchmarks/scaling.py``, ``benchmarks/scaling_lq.py``;
``benchmarks/structure.py``: SQP's QP solver, general or structure-exploiting), the comparison chapter's table and
the min-max benchmark (``benchmarks/minmax.py``), the explorers' re-draw times in a live
kernel (``benchmarks/widgets.py``), prints the machine and a Markdown table of results,
writes every row, the machine, the library versions (the peers' included) and the load average to a
results file (``benchmarks/results.json`` unless ``--results PATH`` says otherwise; the book's
benchmarks page reads it), and exits with status 1 if a target is missed or a correctness check fails
(status 0 otherwise). ``--quick`` runs tiny sizes: it checks that the benchmarks work, and its
timings mean nothing, so it writes a results file only where ``--results`` names one.
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import sys
import time
from dataclasses import fields
from pathlib import Path

from . import closed_loop, comparison, lq_path, minmax, peers, pendulum, regret, scaling, scaling_lq, structure, widgets
from .common import CheckFailed, blas_threads, machine, machine_info, markdown_table, one_thread, parse_time

#: where a full run writes its results (read by the book's benchmarks page, book/benchmarks.md)
RESULTS = Path(__file__).resolve().parent / "results.json"

FULL = {"peers": {}, "regret": {}, "pendulum": {}, "closed_loop": {}, "lq": {}, "comparison": {}, "minmax": {}, "widgets": {},
        "scaling": {}, "scaling_lq": {}, "structure": {}}  # the defaults of each module's run()
QUICK = {
    "peers": dict(T=10, M=5, reps=1, reps_control=1, peers=()),
    "regret": dict(sizes=((8, 2, 1, 5.0),), sdp_size=(5, 2, 1)),
    "pendulum": dict(M=5, thetas=(0.5,), reps_orrc=2, reps_peer=1),
    "closed_loop": dict(T=12, reps=1, reps_ipopt=1),
    "lq": dict(T=40, M=5, reps=2),
    "comparison": dict(T=10, M=4),
    "minmax": dict(Ms=(4, 5), reps=1, M_pendulum=5, T=4),
    "widgets": dict(demo=True),
    "scaling": dict(T=5, Ms=(3, 4), ks=(1, 2), M_chain=3, reps=1, tools=(), compile=False, M_quadrotor=3),
    "scaling_lq": dict(ns=(4, 6), M=3, T=10, reps=1),
    "structure": dict(T=4, Ms=(3, 4), reps=1, fatrop=False),
}
MODULES = {"peers": peers, "regret": regret, "pendulum": pendulum, "closed_loop": closed_loop, "lq": lq_path, "comparison": comparison,
           "minmax": minmax, "widgets": widgets, "scaling": scaling, "scaling_lq": scaling_lq,
           "structure": structure}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.run", description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes (a smoke run; timings mean nothing)")
    ap.add_argument("--only", choices=sorted(MODULES), action="append",
                    help="run only this benchmark (repeatable)")
    ap.add_argument("--results", type=Path, default=None,
                    help=f"write the results file here (default: {RESULTS.relative_to(RESULTS.parents[1])} "
                         "for a full run, none for --quick)")
    args = ap.parse_args(argv)
    sizes = QUICK if args.quick else FULL
    names = args.only or list(MODULES)
    print(f"machine: {machine()}")
    print(f"command: python -m benchmarks.run{' --quick' if args.quick else ''}"
          + "".join(f" --only {n}" for n in (args.only or [])))
    rows, failures, names_of = [], [], []
    load_start = _load()
    t0 = time.perf_counter()
    with one_thread():  # every tool with one BLAS thread; the peers' child processes too
        threads = blas_threads()
        print(f"BLAS thread pools (threadpoolctl): {threads}")
        for name in names:
            try:
                new = MODULES[name].run(**sizes[name])
            except CheckFailed as exc:
                failures.append(f"correctness check failed: {exc}")
                continue
            rows += new
            names_of += [name] * len(new)
    if args.quick:  # tiny sizes: the timings mean nothing, only the correctness checks count
        for r in rows:
            if r.ok is not None:
                r.ok, r.target = None, r.target + " (not judged: --quick)"
    print()
    print(markdown_table(rows))
    print()
    missed = [r for r in rows if r.ok is False]
    for r in missed:
        failures.append(f"target missed: {r.benchmark} [{r.case}]: {r.ratio} (target {r.target})")
    total = time.perf_counter() - t0
    print(f"total benchmark time: {total:.1f} s")
    out = args.results if (args.results or args.quick) else RESULTS
    if out is not None:
        write_results(out, rows, names_of, failures, quick=args.quick, argv=argv, threads=threads,
                      load=(load_start, _load()), seconds=total)
        print(f"results written to {out}")
    for f in failures:
        print(f"FAIL {f}", file=sys.stderr)
    if not failures:
        print("all correctness checks passed" + (" (targets not judged: --quick)" if args.quick
                                                  else ", all targets met"))
    return 1 if failures else 0


def _load():
    """The 1-minute load average (None where the platform has none)."""
    try:
        return round(os.getloadavg()[0], 2)
    except OSError:  # pragma: no cover - not Unix
        return None


def _plain(value):
    """``value`` as JSON data: numbers, strings, lists and dicts kept, anything else as its text."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if value is None or isinstance(value, (bool, int, str)):
        return value
    try:
        x = float(value)
    except (TypeError, ValueError):
        return str(value)
    return x if x == x and abs(x) != float("inf") else str(x)


def write_results(path, rows, names, failures, *, quick, argv, threads, load, seconds):
    """Write the results file: every row (its text cells, the seconds read from the orrc and peer cells,
    the benchmark module it came from, its data), the machine, the versions, the load average."""
    info = machine_info()
    versions = dict(info.pop("versions"))
    for r in rows:  # the peers' versions, as each peer's environment reported them
        if isinstance(r.data, dict) and "peer" in r.data and "version" in r.data:
            versions[r.data["peer"]] = r.data["version"]
    doc = {
        "command": "python -m benchmarks.run" + "".join(f" {a}" for a in (sys.argv[1:] if argv is None else argv)),
        "quick": bool(quick),
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "machine": info | {"blas_threads": threads, "load_average": {"start": load[0], "end": load[1]}},
        "versions": versions,
        "seconds": round(seconds, 1),
        "failures": failures,
        # the fields as they are (no deep copy: a row's data may hold timings that do not copy), then as JSON data
        "rows": [{f.name: getattr(r, f.name) for f in fields(r)}
                 | {"module": name, "orrc_seconds": parse_time(r.orrc), "peer_seconds": parse_time(r.peer)}
                 for r, name in zip(rows, names)],
    }
    Path(path).write_text(json.dumps(_plain(doc), indent=1, ensure_ascii=False) + "\n", encoding="utf-8")


if __name__ == "__main__":
    sys.exit(main())
