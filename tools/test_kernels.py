"""Run the test suite once per OpenBLAS kernel: the suite must not depend on which BLAS kernel runs.

numpy and scipy each ship an OpenBLAS built for many CPUs (DYNAMIC_ARCH); it picks the kernel
for the CPU it finds, and the environment variable ``OPENBLAS_CORETYPE`` forces another one.
Kernels differ in blocking and summation order, so results differ in the last bits: a test
whose tolerance is not derived from the problem's conditioning passes on one machine and fails
on another. This runs the fast part of the suite (``-m "not slow and not browser"``, or the whole
suite with ``--full``) under each kernel the CPU can execute and prints a Markdown table.

    make test-kernels                               # = python -m tools.test_kernels
    .venv/bin/python -m tools.test_kernels --full   # the whole suite (book build included)
    .venv/bin/python -m tools.test_kernels --kernels Prescott SkylakeX

A local check, not part of ``make test`` or CI: the variable is set only for the child pytest.
Before each run, threadpoolctl reports the kernel both libraries actually loaded; a run whose
kernel is not the one asked for counts as a failure (OpenBLAS silently falls back to the
default for an unknown name). Exit status 1 if any run failed.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# kernel -> (CPU flags it needs, names threadpoolctl may report for it). OpenBLAS's DYNAMIC_ARCH
# builds alias some kernels: Prescott's is reported as "Katmai" (the first alias of that kernel
# table) and Zen uses the Haswell kernels in the builds numpy and scipy ship.
KERNELS = {
    "Prescott": ({"sse2", "pni"}, {"Prescott", "Katmai"}),
    "Nehalem": ({"sse4_2", "popcnt"}, {"Nehalem"}),
    "Sandybridge": ({"avx"}, {"Sandybridge"}),
    "Haswell": ({"avx2", "fma"}, {"Haswell"}),
    "SkylakeX": ({"avx512f", "avx512bw", "avx512vl", "avx512dq"}, {"SkylakeX"}),
    "Zen": ({"avx2", "fma"}, {"Zen", "Haswell"}),
}

PROBE = ("import json, numpy, scipy.linalg\n"
         "from threadpoolctl import threadpool_info\n"
         "print(json.dumps(sorted({(d['filepath'].rsplit('/', 1)[-1], d.get('architecture'))\n"
         "                         for d in threadpool_info() if d.get('internal_api') == 'openblas'})))\n")


def cpu_flags() -> set[str]:
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return set()
    for line in text.splitlines():
        if line.startswith("flags"):
            return set(line.split(":", 1)[1].split())
    return set()


def loaded_kernels(env: dict) -> list[tuple[str, str]]:
    """(library file, kernel name) for every OpenBLAS numpy and scipy load under ``env``."""
    out = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True, text=True, check=True)
    return [tuple(x) for x in json.loads(out.stdout)]


def run(kernel: str | None, full: bool) -> dict:
    env = dict(os.environ)
    env.pop("OPENBLAS_CORETYPE", None)
    if kernel is not None:
        env["OPENBLAS_CORETYPE"] = kernel
    env.setdefault("ORRC_QUICK", "1")
    libs = loaded_kernels(env)
    names = {name for _, name in libs}
    ok_kernel = kernel is None or (bool(names) and names <= KERNELS[kernel][1])
    cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "tests"]
    if not full:
        cmd[4:4] = ["-m", "not slow and not browser"]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - t0
    lines = [ln.strip("= ") for ln in proc.stdout.splitlines() if ln.strip()]
    summary = lines[-1] if lines else "(no output)"
    failed = [ln.split()[1] for ln in proc.stdout.splitlines() if ln.startswith(("FAILED", "ERROR"))]
    return {"kernel": kernel or "default", "loaded": ", ".join(sorted(names)) or "?", "ok_kernel": ok_kernel,
            "rc": proc.returncode, "summary": summary, "failed": failed, "seconds": seconds}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--full", action="store_true", help="the whole suite, not only its fast part")
    ap.add_argument("--kernels", nargs="+", choices=sorted(KERNELS), default=list(KERNELS),
                    help="the kernels to run (default: all the CPU can execute)")
    ap.add_argument("--no-default", action="store_true", help="skip the run without OPENBLAS_CORETYPE")
    args = ap.parse_args(argv)
    flags = cpu_flags()
    rows, bad = [], False
    for kernel in ([] if args.no_default else [None]) + args.kernels:
        need = KERNELS[kernel][0] if kernel else set()
        if flags and not need <= flags:
            rows.append((kernel, "—", f"skipped: the CPU lacks {', '.join(sorted(need - flags))}", "—"))
            continue
        r = run(kernel, args.full)
        print(f"{r['kernel']}: {r['summary']} ({r['seconds']:.0f} s)", file=sys.stderr, flush=True)
        result = r["summary"] if r["ok_kernel"] else f"kernel not honoured (loaded {r['loaded']}); {r['summary']}"
        if r["failed"]:
            result += " — " + ", ".join(r["failed"])
        bad |= r["rc"] != 0 or not r["ok_kernel"]
        rows.append((r["kernel"], r["loaded"], result, f"{r['seconds']:.0f} s"))
    part = "whole suite" if args.full else 'fast suite (-m "not slow and not browser")'
    print(f"\n{part}, ORRC_QUICK=1\n")
    print("| OPENBLAS_CORETYPE | kernel loaded (numpy, scipy) | result | time |")
    print("|---|---|---|---|")
    for row in rows:
        print("| " + " | ".join(str(c) for c in row) + " |")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
