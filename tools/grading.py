"""Grade notebooks with an otter-grader autograder, one ``otter run`` each or many in one process.

:func:`grade` grades one notebook with the ``otter run`` command. :func:`grade_many` grades many
with the same results, paying otter's start-up once: it runs this file as a script,

    python -I tools/grading.py JOBS.json [--workers N]

with the interpreter whose otter grades, e.g. one of a fresh environment built from an autograder
zip alone. ``JOBS.json`` is a list of jobs, each ``{"notebook", "autograder", "output_dir"}``
(absolute paths; ``output_dir`` exists) and optionally ``"time_limit"`` (seconds) and
``"memory_mb"``. As a script this file imports only the standard library and ``otter.run``
(otter-grader 7's local grading, what ``otter run`` calls); ``-I`` keeps its folder and
``PYTHONPATH`` off the path (the kernels that run the notebooks still inherit the environment).

The script imports otter once; then every job runs in a process of its own, forked from it (at
most ``--workers`` at a time): it starts a new session (its kernel and anything the notebook
starts are its children), takes the job's memory limit, writes its output to
``output_dir/otter-run.log``, and calls ``otter.run.main(notebook, autograder=...,
output_dir=..., no_logo=True)``, exactly what ``otter run -a AUTOGRADER -o OUTPUT_DIR --no-logo
NOTEBOOK`` calls: otter unpacks the autograder in a temporary folder of its own, copies the
notebook there, executes it in a kernel of its own and writes ``results.json`` to ``output_dir``.
A job past its time limit is killed with its process group (its kernel, whose parent then is
gone, shuts itself down). Each job's outcome is written to ``output_dir/otter-batch.json``:
``{"returncode", "timed_out", "seconds", "cpu_seconds"}``, the return code being ``otter run``'s
(0, or 1 when otter raised; minus the signal's number when the process was killed), ``timed_out``
whether the time limit killed it, ``seconds`` its wall time and ``cpu_seconds`` the CPU time of
its process and of the processes it waited for (its kernel).
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import traceback
from pathlib import Path

SCRIPT = Path(__file__).resolve()
LOG = "otter-run.log"
OUTCOME = "otter-batch.json"


def _bin(tool: str) -> str:
    return str(Path(sys.executable).parent / tool)


def _grading_env(python: str | None) -> dict:
    """The environment variables of a grading: another interpreter grades with its own packages
    only, so nothing of this checkout goes on its path."""
    return {k: v for k, v in os.environ.items() if not (python and k in ("PYTHONPATH", "VIRTUAL_ENV"))}


def _fresh_workdir(workdir: Path) -> Path:
    if workdir.exists():
        shutil.rmtree(workdir)
    workdir.mkdir(parents=True)
    return workdir


def read_results(workdir: Path, notebook: Path, log: str = "") -> dict:
    """The grade otter wrote into ``workdir`` (its ``results.json``) for ``notebook``:
    {"score", "points", "questions"}; ``log``: otter's output, quoted when it wrote no results."""
    results = Path(workdir) / "results.json"
    if not results.is_file():
        raise RuntimeError(f"otter run wrote no results for {notebook}:\n{log[-4000:]}")
    tests = json.loads(results.read_text())["tests"]
    questions = {t["name"]: (float(t.get("score") or 0.0), float(t["max_score"]), t.get("output", ""))
                 for t in tests if t.get("max_score") is not None}
    if not questions:  # otter's "Autograder Failed": the notebook or a test file did not run at all
        raise RuntimeError(f"otter run graded no question of {notebook}: "
                           + "; ".join(str(t.get("output", ""))[-1500:] for t in tests))
    return {"score": sum(s for s, _, _ in questions.values()), "points": sum(p for _, p, _ in questions.values()),
            "questions": questions}


def grade(notebook: Path, autograder: Path, workdir: Path, python: str | None = None) -> dict:
    """Grade one notebook with ``otter run`` (local, no container): {"score", "points", "questions"}.

    ``questions`` maps each question to (score, max score) and its output (which test failed, why).
    ``python``: the interpreter whose otter grades (default: this environment's), e.g. one of a
    fresh environment built from the autograder zip alone. :func:`grade_many` grades many
    notebooks with the same results, paying otter's start-up once.
    """
    workdir = _fresh_workdir(Path(workdir))
    cmd = [python, "-m", "otter"] if python else [_bin("otter")]
    proc = subprocess.run([*cmd, "run", "-a", str(Path(autograder).resolve()), "-o", str(workdir.resolve()), "--no-logo",
                           str(Path(notebook).resolve())], capture_output=True, text=True, cwd=workdir,
                          env=_grading_env(python))
    return read_results(workdir, notebook, proc.stdout[-2000:] + "\n" + proc.stderr[-2000:])


def grade_many(items: list[tuple[Path, Path, Path]], python: str | None = None, workers: int = 2) -> list[dict]:
    """Grade many notebooks, each as :func:`grade` does, in one Python process of ``python``.

    ``items``: (notebook, autograder zip, working folder) triples; each notebook is graded with its
    autograder, by otter's ``otter run`` code, in a kernel and a process of its own
    (:func:`grade_all`, this file run as a script by ``python``: otter is imported once, each
    grading a fork of that process), its results in its own working folder (made empty first),
    ``workers`` at a time. Returns one grade
    per item, in order, each as :func:`grade` returns it with "seconds" and "cpu_seconds" (its wall
    and CPU time, its kernel's included) added.
    """
    if not items:
        return []
    jobs = []
    for notebook, autograder, workdir in items:
        jobs.append({"notebook": str(Path(notebook).resolve()), "autograder": str(Path(autograder).resolve()),
                     "output_dir": str(_fresh_workdir(Path(workdir)).resolve())})
    with tempfile.TemporaryDirectory(prefix="orrc-grading-") as tmp:
        listing = Path(tmp) / "jobs.json"
        listing.write_text(json.dumps(jobs), encoding="utf-8")
        proc = subprocess.run([python or sys.executable, "-I", str(SCRIPT), str(listing), "--workers", str(workers)],
                              capture_output=True, text=True, cwd=tmp, env=_grading_env(python))
    grades = []
    for (notebook, _, _), job in zip(items, jobs):
        out = Path(job["output_dir"])
        outcome = json.loads((out / OUTCOME).read_text()) if (out / OUTCOME).is_file() else {}
        log = (out / LOG).read_text(errors="replace") if (out / LOG).is_file() else ""
        if not outcome:
            log += f"\n(the batch exited {proc.returncode}: {proc.stderr[-2000:]})"
        grades.append({**read_results(out, notebook, log), "seconds": float(outcome.get("seconds", 0.0)),
                       "cpu_seconds": float(outcome.get("cpu_seconds", 0.0))})
    return grades


def _grade_in_child(job: dict, run) -> None:
    """The forked process of one job: never returns."""
    code = 1
    try:
        os.setsid()
        if job.get("memory_mb"):
            cap = int(job["memory_mb"]) * 2 ** 20
            resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
        out = os.open(os.path.join(job["output_dir"], LOG), os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        os.dup2(out, 1)
        os.dup2(out, 2)
        os.close(out)
        os.chdir(job["output_dir"])
        run(job["notebook"], autograder=job["autograder"], output_dir=job["output_dir"], no_logo=True)
        code = 0
    except BaseException:  # noqa: BLE001 -- as the otter CLI does: the traceback, exit code 1
        traceback.print_exc()
    finally:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)


def grade_all(jobs: list[dict], workers: int = 1, poll: float = 0.1) -> list[dict]:
    """Grade every job in this process's otter (see the module's docstring): the script's work.
    Returns each job's outcome, in order."""
    from otter.run import main as run   # the one import of otter; every job's process inherits it

    outcomes: list[dict | None] = [None] * len(jobs)
    pending = list(range(len(jobs)))
    running: dict[int, tuple[int, float, float | None]] = {}   # pid -> (job, start, deadline)
    killed: set[int] = set()
    while pending or running:
        while pending and len(running) < max(1, workers):
            i = pending.pop(0)
            sys.stdout.flush()
            sys.stderr.flush()
            pid = os.fork()
            if pid == 0:
                _grade_in_child(jobs[i], run)
            start = time.monotonic()
            limit = jobs[i].get("time_limit")
            running[pid] = (i, start, start + float(limit) if limit else None)
        pid, status, usage = os.wait4(-1, os.WNOHANG)
        if pid:
            i, start, _ = running.pop(pid)
            outcomes[i] = {"returncode": os.waitstatus_to_exitcode(status), "timed_out": pid in killed,
                           "seconds": time.monotonic() - start, "cpu_seconds": usage.ru_utime + usage.ru_stime}
            killed.discard(pid)
            continue
        now = time.monotonic()
        for pid, (i, start, deadline) in list(running.items()):
            if deadline is not None and now > deadline and pid not in killed:
                killed.add(pid)
                try:
                    os.killpg(pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
        time.sleep(poll)
    for job, outcome in zip(jobs, outcomes):
        with open(os.path.join(job["output_dir"], OUTCOME), "w", encoding="utf-8") as f:
            json.dump(outcome, f)
    return outcomes


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Grade many notebooks, each as one `otter run` does, in one process.")
    ap.add_argument("jobs", help="a JSON file: a list of {notebook, autograder, output_dir[, time_limit, memory_mb]}")
    ap.add_argument("--workers", type=int, default=1, help="jobs graded at once")
    args = ap.parse_args(argv)
    with open(args.jobs, encoding="utf-8") as f:
        jobs = json.load(f)
    grade_all(jobs, args.workers)
    return 0


if __name__ == "__main__":
    sys.exit(main())
