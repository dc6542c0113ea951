"""Entry point of ``make bench``: ``python -m benchmarks.run [--quick] [--only NAME]``.

Runs the performance benchmarks of issue 2 (see ``benchmarks/pendulum.py`` and
``benchmarks/lq_path.py``), prints the machine and a Markdown table of results,
and exits with status 1 if a target is missed or a correctness check fails
(status 0 otherwise). ``--quick`` runs tiny sizes: it checks that the benchmarks
work, and its timings mean nothing.
"""
from __future__ import annotations

import argparse
import sys
import time

from . import comparison, lq_path, pendulum
from .common import CheckFailed, machine, markdown_table

FULL = {"pendulum": {}, "lq": {}, "comparison": {}}  # the defaults of pendulum.run and lq_path.run
QUICK = {
    "pendulum": dict(M=5, thetas=(0.5,), reps_orrc=2, reps_peer=1),
    "lq": dict(T=40, M=5, reps=2),
    "comparison": dict(T=10, M=4),
}
MODULES = {"pendulum": pendulum, "lq": lq_path, "comparison": comparison}


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
