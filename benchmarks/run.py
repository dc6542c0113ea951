"""Entry point of ``make bench``: ``python -m benchmarks.run [--quick] [--only NAME]``.

Runs, with one BLAS thread for every tool (``benchmarks/common.py``), the closed-loop comparison
with the peers (``benchmarks/peers.py``: bare CasADi, do-mpc, acados, python-control;
CPU and wall time), the performance benchmarks (see ``benchmarks/pendulum.py``,
``benchmarks/closed_loop.py`` and ``benchmarks/lq_path.py``), the comparison chapter's table and
the min-max benchmark (``benchmarks/minmax.py``), the explorers' re-draw times in a live
kernel (``benchmarks/widgets.py``), prints the machine and a Markdown table of results,
and exits with status 1 if a target is missed or a correctness check fails
(status 0 otherwise). ``--quick`` runs tiny sizes: it checks that the benchmarks
work, and its timings mean nothing.
"""
from __future__ import annotations

import argparse
import sys
import time

from . import closed_loop, comparison, lq_path, minmax, peers, pendulum, regret, widgets
from .common import CheckFailed, blas_threads, machine, markdown_table, one_thread

FULL = {"peers": {}, "regret": {}, "pendulum": {}, "closed_loop": {}, "lq": {}, "comparison": {}, "minmax": {}, "widgets": {}}  # the defaults of each module's run()
QUICK = {
    "peers": dict(T=10, M=5, reps=1, reps_control=1, peers=()),
    "regret": dict(sizes=((8, 2, 1, 5.0),), sdp_size=(5, 2, 1)),
    "pendulum": dict(M=5, thetas=(0.5,), reps_orrc=2, reps_peer=1),
    "closed_loop": dict(T=12, reps=1, reps_ipopt=1),
    "lq": dict(T=40, M=5, reps=2),
    "comparison": dict(T=10, M=4),
    "minmax": dict(Ms=(4, 5), reps=1, M_pendulum=5, T=4),
    "widgets": dict(demo=True),
}
MODULES = {"peers": peers, "regret": regret, "pendulum": pendulum, "closed_loop": closed_loop, "lq": lq_path, "comparison": comparison,
           "minmax": minmax, "widgets": widgets}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.run", description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny sizes (a smoke run; timings mean nothing)")
    ap.add_argument("--only", choices=sorted(MODULES), action="append",
                    help="run only this benchmark (repeatable)")
    args = ap.parse_args(argv)
    sizes = QUICK if args.quick else FULL
    names = args.only or list(MODULES)
    print(f"machine: {machine()}")
    print(f"command: python -m benchmarks.run{' --quick' if args.quick else ''}"
          + "".join(f" --only {n}" for n in (args.only or [])))
    rows, failures = [], []
    t0 = time.perf_counter()
    with one_thread():  # every tool with one BLAS thread; the peers' child processes too
        print(f"BLAS thread pools (threadpoolctl): {blas_threads()}")
        for name in names:
            try:
                rows += MODULES[name].run(**sizes[name])
            except CheckFailed as exc:
                failures.append(f"correctness check failed: {exc}")
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
    print(f"total benchmark time: {time.perf_counter() - t0:.1f} s")
    for f in failures:
        print(f"FAIL {f}", file=sys.stderr)
    if not failures:
        print("all correctness checks passed" + (" (targets not judged: --quick)" if args.quick
                                                  else ", all targets met"))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
