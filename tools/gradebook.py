"""Grade a class at once: a folder of submissions of one assignment into a gradebook and feedback.

    .venv/bin/python -m tools.gradebook a1_preview_rhc submissions/ -o grades/a1

grades every file of ``submissions/`` (one per student, the student named by the file's stem: a
notebook, or the zip that the notebook's export cell writes)
with the assignment's autograder (what ``otter run`` does, locally, two at a time, in one process
that imports otter once: :mod:`tools.grading`) and writes, in the output folder (created),

- ``gradebook.csv``: one row per student, one column per question (points), ``total``,
  ``possible`` and ``note`` (what stopped the grading of a submission, else empty);
- ``feedback/STUDENT.md``: the student's points per question and, for each failed check, the
  message the assignment wrote for it (what to check), never the tests' source: otter's own
  output, which quotes the hidden tests' code in its tracebacks, is not copied;
- ``otter/STUDENT/``: otter's raw results and output, for the instructor only (they hold hidden
  test source);
- ``written/STUDENT.pdf``: the student's answers to the written questions, with the code-graded
  score, to grade by hand (:mod:`tools.written_answers`); the CSV's ``written`` column is left
  for those points (out of ``written_possible``).

Each notebook runs in a sandbox (:func:`grade_sandboxed`): a process and session of its own,
killed with its kernel after ``--time-limit`` seconds (an endless loop costs that submission
only), a memory limit (``--memory``), and, where the machine allows unprivileged namespaces
(``unshare``), no network (a network namespace with only its own loopback, which the kernel's
channels need). Running the command again grades only what changed: a file graded before in
the same output folder with the same bytes, autograder and limits keeps its results (delete
``otter/STUDENT/`` to grade it again). One student
with several files (``alice.ipynb`` and ``alice.zip``) is one row: the newest file is graded
and the note names the others. ``--roster roster.csv`` (columns ``id``, ``name``, ``email``; a
file's stem is the student's id) adds the name and email to each row and a row for each student
who submitted nothing; ``--deadline 2026-03-01T17:00`` flags a file modified after it as late
(the ``late`` column: how late).

A submission that cannot be graded gets zero for what it breaks and a note, and the batch goes
on: a file that is not a notebook, a notebook without cells, another assignment's notebook (its
otter assignment name differs), a notebook whose cells raise (the questions whose answers are
then missing get zero; the note names them). The autograder is found in
``_build/assignments/NAME/dist/autograder/`` (``make assignments``), or given with ``--autograder``.
"""
from __future__ import annotations

import argparse
import ast
import csv
import datetime as dt
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import zipfile
from functools import lru_cache
from pathlib import Path

from tools import grading, written_answers
from tools.assignments import OUT

_NAME_ERROR = re.compile(r"NameError: name '(\w+)' is not defined")
_UNDEFINED = re.compile(r"NoneType'? object (?:is not callable|is not subscriptable|is not iterable|has no attribute)")


def autograder_zip(name: str, out: Path = OUT) -> Path:
    """The autograder zip ``make assignments`` wrote for assignment ``name``."""
    zips = sorted((Path(out) / name / "dist" / "autograder").glob(f"{name}-autograder_*.zip"))
    if not zips:
        raise FileNotFoundError(f"no autograder for {name!r} in {Path(out) / name / 'dist' / 'autograder'}: "
                                "run `make assignments` first")
    return zips[-1]


def questions_of(zip_path: Path) -> dict[str, list[dict]]:
    """``{question: [{"points", "hidden", "message"}, ...]}`` in test-case order, read from the
    autograder zip's test files (otter's exception-based format: ``@test_case(...)`` decorators)."""
    out = {}
    with zipfile.ZipFile(zip_path) as zf:
        for item in sorted(zf.namelist()):
            if not re.fullmatch(r"tests/[^/]+\.py", item):
                continue
            tree = ast.parse(zf.read(item).decode("utf-8"))
            cases = []
            for fn in (n for n in tree.body if isinstance(n, ast.FunctionDef)):
                for dec in fn.decorator_list:
                    if isinstance(dec, ast.Call) and getattr(dec.func, "id", "") == "test_case":
                        kw = {k.arg: ast.literal_eval(k.value) for k in dec.keywords}
                        cases.append({"points": float(kw.get("points") or 0), "hidden": bool(kw.get("hidden")),
                                      "message": str(kw.get("failure_message") or "")})
            name = Path(item).stem
            for node in tree.body:
                if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", "") == "name":
                    name = ast.literal_eval(node.value)
            out[name] = cases
    return out


def assignment_name(zip_path: Path) -> str:
    """The assignment's name, as otter records it in the autograder's config."""
    with zipfile.ZipFile(zip_path) as zf:
        return json.loads(zf.read("otter_config.json")).get("assignment_name", "")


def precheck(path: Path, expected: str) -> str:
    """Why ``path`` cannot be graded as a notebook of assignment ``expected`` ("" when it can)."""
    import nbformat

    try:
        nb = nbformat.read(path, as_version=4)
    except Exception as exc:  # noqa: BLE001 -- any unreadable file is "not a notebook"
        return f"not a Jupyter notebook ({type(exc).__name__}); nothing could be graded"
    if not nb.cells:
        return "the notebook has no cells; nothing could be graded"
    found = (nb.metadata.get("otter") or {}).get("assignment_name")
    if found and expected and found != expected:
        return f"this is the notebook of assignment {found}, not of {expected}; nothing was graded"
    return ""


def unpacked(path: Path, work: Path) -> tuple[Path, str]:
    """The notebook to grade and a note: ``path`` itself, or the one notebook of the zip that otter's
    export cell writes (unpacked into ``work/submission/``)."""
    if not zipfile.is_zipfile(path):
        return path, ""
    with zipfile.ZipFile(path) as zf:
        inside = [n for n in zf.namelist() if n.endswith(".ipynb") and "/" not in n.strip("/")]
        if len(inside) != 1:
            return path, f"a zip with {len(inside)} notebooks at its top level (one expected); nothing was graded"
        target = work / "submission" / inside[0]
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(zf.read(inside[0]))
    return target, ""


#: seconds a notebook may run, its tests included (``ORRC_GRADING_TIME_LIMIT`` overrides it)
TIME_LIMIT = float(os.environ.get("ORRC_GRADING_TIME_LIMIT", 600))
MEMORY_MB = 4096      # address space a notebook's processes may take
GRADED = "graded.json"   # in otter/STUDENT/: what was graded there (see grading_key) and how it ended


@lru_cache(maxsize=1)
def network_isolation() -> bool:
    """Whether this machine can run a process without network (``unshare -rn`` works)."""
    try:
        return subprocess.run(["unshare", "-rn", "sh", "-c", "ip link set lo up"], capture_output=True,
                              timeout=20).returncode == 0
    except (OSError, subprocess.SubprocessError):
        return False


def sandboxed(cmd: list[str]) -> list[str]:
    """``cmd`` run without network where the machine allows it: in a new user and network
    namespace whose only interface is its own loopback (brought up first)."""
    if not network_isolation():
        return list(cmd)
    return ["unshare", "-rn", "sh", "-c", 'ip link set lo up && exec "$@"', "sandbox", *cmd]


def grading_key(path: Path, zip_path: Path, time_limit: float, memory_mb: int) -> str:
    """What a grading depends on, hashed: the submission's and the autograder's bytes, the limits
    and whether the network was cut. A file graded before under the same key is not graded again."""
    h = hashlib.sha256()
    for f in (path, zip_path):
        h.update(Path(f).read_bytes() + b"\0")
    h.update(f"{time_limit:g} {memory_mb} {network_isolation()}".encode())
    return h.hexdigest()


def grade_sandboxed(jobs: list[dict], workers: int = 2) -> list[dict]:
    """Grade ``jobs`` (each ``{"notebook", "autograder", "output_dir", "time_limit", "memory_mb"}``)
    with this environment's otter, in one sandboxed process (:func:`sandboxed`, :mod:`tools.grading`:
    otter imported once; each notebook in a process and a session of its own with its memory
    limit, killed with its kernel after its time limit), ``workers`` at a time. Returns each job's
    outcome (``{"returncode", "timed_out", "seconds", "cpu_seconds"}``); a job the batch left
    without one gets ``returncode`` None and ``error``, what the batch said."""
    if not jobs:
        return []
    with tempfile.TemporaryDirectory(prefix="orrc-gradebook-") as tmp:
        listing = Path(tmp) / "jobs.json"
        listing.write_text(json.dumps(jobs), encoding="utf-8")
        cmd = [sys.executable, "-I", str(grading.SCRIPT), str(listing), "--workers", str(workers)]
        proc = subprocess.run(sandboxed(cmd), capture_output=True, text=True, cwd=tmp)
    outcomes = []
    for job in jobs:
        f = Path(job["output_dir"]) / grading.OUTCOME
        outcomes.append(json.loads(f.read_text()) if f.is_file() else
                        {"returncode": None, "timed_out": False, "seconds": 0.0,
                         "error": (proc.stderr.strip().splitlines() or [f"exit {proc.returncode}"])[-1][:200]})
    return outcomes


def _failed_cases(question: str, output: str) -> set[int]:
    return {int(i) for i in re.findall(rf"{re.escape(question)} - (\d+) result:\s*\n\s*❌", output)}


def graded_row(student: str, expected: str, cases: dict, work: Path, outcome: dict | None, note: str,
               time_limit: float) -> dict:
    """One student's row from otter's results in ``work`` and the grading's ``outcome`` (None when
    ``note`` says why nothing was graded): {"student", "scores": {question: points}, "possible",
    "note", "feedback": text}."""
    scores = {q: 0.0 for q in cases}
    failed: dict[str, list[str]] = {}
    missing: set[str] = set()
    undefined: list[str] = []
    if outcome is not None and not note:
        results = work / "results.json"
        timed_out = outcome.get("timed_out", False)
        tests = json.loads(results.read_text()).get("tests", []) if results.is_file() and not timed_out else []
        graded = [t for t in tests if t.get("name") in cases and t.get("max_score") is not None]
        if timed_out:
            note = f"the notebook ran longer than the time limit ({time_limit:g} s; an endless loop?); nothing was graded"
        elif not graded:
            log = work / grading.LOG
            printed = log.read_text(errors="replace").strip().splitlines() if log.is_file() else []
            said = outcome.get("error") or (printed or ["no results"])[-1][:200]
            note = f"the autograder could not run this notebook (otter: {said}); nothing was graded"
        for t in graded:
            q, output = t["name"], str(t.get("output", ""))
            scores[q] = float(t.get("score") or 0.0)
            failed[q] = [cases[q][i - 1]["message"] for i in sorted(_failed_cases(q, output)) if i <= len(cases[q])]
            missing |= set(_NAME_ERROR.findall(output))
            if _UNDEFINED.search(output):  # otter passes None for a name the notebook never defined
                undefined.append(q)
        if missing or undefined:
            note = ("an answer was not defined when the tests ran (its cell raised an error, was deleted or left unanswered): "
                    + ", ".join(sorted(missing) + [f"a name {q} needs" for q in undefined]))
    possible = {q: sum(c["points"] for c in cs) for q, cs in cases.items()}
    lines = [f"# Feedback: {student}, {expected}", "",
             f"Total: {sum(scores.values()):g} / {sum(possible.values()):g} points", ""]
    if note:
        lines += [f"Note: {note}", ""]
    for q in cases:
        lines.append(f"- **{q}**: {scores[q]:g} / {possible[q]:g}")
        lines += [f"  - check: {m}" for m in failed.get(q, []) if m]
    return {"student": student, "scores": scores, "possible": possible, "note": note,
            "feedback": "\n".join(lines) + "\n"}


def grade_students(chosen: dict[str, Path], zip_path: Path, out: Path, expected: str, cases: dict,
                   workers: int = 2, time_limit: float = TIME_LIMIT, memory_mb: int = MEMORY_MB) -> dict[str, dict]:
    """Grade each student's file (``{student: path}``) into ``out/otter/STUDENT/``: {student: row}
    (:func:`graded_row`, with "written", the written answers). A file that cannot be graded gets a
    note instead (:func:`unpacked`, :func:`precheck`); the others are graded together
    (:func:`grade_sandboxed`); a file graded before with the same key (:func:`grading_key`: the
    same bytes, autograder and limits) keeps its results and is not graded again."""
    import nbformat

    prepared, jobs = {}, []
    for student, path in sorted(chosen.items()):
        work = out / "otter" / student
        key = grading_key(path, zip_path, time_limit, memory_mb)
        before = json.loads((work / GRADED).read_text()) if (work / GRADED).is_file() else {}
        outcome = before.get("outcome") if before.get("key") == key else None
        if outcome is None:
            if work.exists():
                shutil.rmtree(work)
            work.mkdir(parents=True)
        notebook, note = unpacked(path, work)
        note = note or precheck(notebook, expected)
        written = [] if note else written_answers.read(nbformat.read(notebook, as_version=4))
        if not note and outcome is None:
            jobs.append((student, key, {"notebook": str(Path(notebook).resolve()), "autograder": str(zip_path),
                                        "output_dir": str(work.resolve()), "time_limit": time_limit,
                                        "memory_mb": memory_mb}))
        prepared[student] = (work, outcome, note, written)
    for (student, key, _), outcome in zip(jobs, grade_sandboxed([j for _, _, j in jobs], workers)):
        work, _, note, written = prepared[student]
        prepared[student] = (work, outcome, note, written)
        if "error" not in outcome:   # graded (a grading that never ran is tried again next time)
            (work / GRADED).write_text(json.dumps({"key": key, "outcome": outcome}), encoding="utf-8")
    return {student: {**graded_row(student, expected, cases, work, outcome, note, time_limit), "written": written}
            for student, (work, outcome, note, written) in prepared.items()}


def newest_per_student(files: list[Path]) -> dict[str, tuple[Path, str]]:
    """{student: (the file to grade, a note)}: one file per student (a file's stem), the newest
    when a student handed in several, with a note naming the others."""
    by: dict[str, list[Path]] = {}
    for f in files:
        by.setdefault(f.stem, []).append(f)
    out = {}
    for student, fs in sorted(by.items()):
        fs.sort(key=lambda f: (f.stat().st_mtime, f.name))
        note = (f"{len(fs)} files handed in ({', '.join(f.name for f in fs)}): the newest, {fs[-1].name}, is graded"
                if len(fs) > 1 else "")
        out[student] = (fs[-1], note)
    return out


def read_roster(path: Path) -> dict[str, dict]:
    """{id: {"name", "email"}} from a CSV with the columns id, name, email."""
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    if rows and not {"id", "name", "email"} <= set(rows[0]):
        raise ValueError(f"{path}: a roster needs the columns id, name, email; it has {sorted(rows[0])}")
    return {r["id"].strip(): {"name": r["name"].strip(), "email": r["email"].strip()} for r in rows}


def lateness(path: Path, deadline: dt.datetime | None) -> str:
    """How late a file was handed in (its modification time after ``deadline``), or ""."""
    if deadline is None:
        return ""
    when = dt.datetime.fromtimestamp(path.stat().st_mtime, tz=dt.timezone.utc)
    late = when - (deadline if deadline.tzinfo else deadline.replace(tzinfo=dt.timezone.utc))
    if late.total_seconds() <= 0:
        return ""
    hours, rest = divmod(int(late.total_seconds()), 3600)
    return f"late by {hours} h {rest // 60} min"


def grade_folder(name: str, submissions: Path, out: Path, zip_path: Path | None = None, workers: int = 2,
                 roster: dict | None = None, deadline: dt.datetime | None = None,
                 time_limit: float = TIME_LIMIT, memory_mb: int = MEMORY_MB) -> list[dict]:
    """Grade every file of ``submissions`` (see the module's docstring); returns the rows, in student order."""
    zip_path = Path(zip_path or autograder_zip(name)).resolve()
    cases = questions_of(zip_path)
    expected = assignment_name(zip_path) or name
    files = sorted(p for p in Path(submissions).iterdir() if p.is_file() and not p.name.startswith("."))
    chosen = newest_per_student(files)
    out = Path(out)
    (out / "feedback").mkdir(parents=True, exist_ok=True)

    graded = grade_students({s: p.resolve() for s, (p, _) in chosen.items()}, zip_path, out, expected, cases,
                            workers, time_limit, memory_mb)
    rows = []
    for student, (path, dup) in sorted(chosen.items()):
        row = graded[student]
        rows.append({**row, "note": "; ".join(n for n in (dup, row["note"]) if n), "late": lateness(path, deadline)})
    roster = roster or {}
    possible = {q: sum(c["points"] for c in cs) for q, cs in cases.items()}
    for student in sorted(set(roster) - set(chosen)):
        rows.append({"student": student, "scores": {q: 0.0 for q in cases}, "possible": possible, "late": "",
                     "note": "no submission", "feedback": ""})
    written_possible = max((sum(q["points"] for q in r.get("written", [])) for r in rows), default=0.0)
    for r in rows:
        if r.get("written"):
            score = f"{sum(r['scores'].values()):g} / {sum(r['possible'].values()):g} points"
            written_answers.write_pdf(out / "written" / f"{r['student']}.pdf", r["student"], expected, score,
                                      r["written"], r["note"])
    with open(out / "gradebook.csv", "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f)
        writer.writerow(["student", *(["name", "email"] if roster else []), *cases, "total", "possible",
                         "written", "written_possible", "late", "note"])
        for r in rows:
            who = roster.get(r["student"], {"name": "", "email": ""}) if roster else None
            note = r["note"] if (not roster or r["student"] in roster) else "; ".join(
                n for n in ("not on the roster", r["note"]) if n)
            writer.writerow([r["student"], *([who["name"], who["email"]] if roster else []),
                             *(f"{r['scores'][q]:g}" for q in cases), f"{sum(r['scores'].values()):g}",
                             f"{sum(r['possible'].values()):g}", "", f"{written_possible:g}", r["late"], note])
    for r in rows:
        if r["feedback"]:
            (out / "feedback" / f"{r['student']}.md").write_text(r["feedback"], encoding="utf-8")
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Grade a folder of submissions of one assignment into a gradebook "
                                             "CSV and one feedback file per student.")
    ap.add_argument("name", help="the assignment, e.g. a1_preview_rhc")
    ap.add_argument("submissions", type=Path, help="a folder with one submission per student (STUDENT.ipynb)")
    ap.add_argument("-o", "--out", type=Path, default=None, help="output folder (default: grades/NAME)")
    ap.add_argument("--autograder", type=Path, default=None, help="the autograder zip (default: make assignments')")
    ap.add_argument("--roster", type=Path, default=None, help="a CSV with the columns id, name, email")
    ap.add_argument("--deadline", default=None, help="ISO date and time (UTC unless given), e.g. 2026-03-01T17:00")
    ap.add_argument("--time-limit", type=float, default=TIME_LIMIT, help="seconds one notebook may run")
    ap.add_argument("--memory", type=int, default=MEMORY_MB, help="megabytes one notebook may take")
    args = ap.parse_args(argv)
    if not args.time_limit > 0 or args.memory < 256:
        print(f"gradebook: --time-limit must be positive seconds (given {args.time_limit:g}) and --memory at least "
              f"256 MB (given {args.memory})", file=sys.stderr)
        return 2
    try:
        deadline = dt.datetime.fromisoformat(args.deadline) if args.deadline else None
    except ValueError:
        print(f"gradebook: --deadline {args.deadline!r} is not an ISO date and time (e.g. 2026-03-01T17:00)",
              file=sys.stderr)
        return 2
    try:
        roster = read_roster(args.roster) if args.roster else None
    except (OSError, ValueError) as exc:
        print(f"gradebook: {exc}", file=sys.stderr)
        return 2
    if not args.submissions.is_dir():
        print(f"gradebook: {args.submissions} is not a folder of submissions", file=sys.stderr)
        return 2
    out = args.out or Path("grades") / args.name
    try:
        zip_path = args.autograder or autograder_zip(args.name)
    except FileNotFoundError as exc:
        print(f"gradebook: {exc}", file=sys.stderr)
        return 2
    rows = grade_folder(args.name, args.submissions, out, zip_path, roster=roster, deadline=deadline,
                        time_limit=args.time_limit, memory_mb=args.memory)
    print(f"{len(rows)} submissions graded: {out / 'gradebook.csv'}, feedback in {out / 'feedback'}/"
          + "".join(f"\n  {r['student']}: {r['note']}" for r in rows if r["note"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
