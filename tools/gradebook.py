"""Grade a class at once: a folder of submissions of one assignment into a gradebook and feedback.

    .venv/bin/python -m tools.gradebook a1_preview_rhc submissions/ -o grades/a1

grades every file of ``submissions/`` (one per student, the student named by the file's stem: a
notebook, or the zip that the notebook's export cell writes)
with the assignment's autograder (``otter run``, locally, two at a time) and writes, in the
output folder (created),

- ``gradebook.csv``: one row per student, one column per question (points), ``total``,
  ``possible`` and ``note`` (what stopped the grading of a submission, else empty);
- ``feedback/STUDENT.md``: the student's points per question and, for each failed check, the
  message the assignment wrote for it (what to check), never the tests' source: otter's own
  output, which quotes the hidden tests' code in its tracebacks, is not copied;
- ``otter/STUDENT/``: otter's raw results, for the instructor only (they hold hidden test source);
- ``written/STUDENT.pdf``: the student's answers to the written questions, with the code-graded
  score, to grade by hand (:mod:`tools.written_answers`); the CSV's ``written`` column is left
  for those points (out of ``written_possible``).

Each notebook runs in a sandbox (:func:`sandboxed`): its own process group, killed after
``--time-limit`` seconds (an endless loop costs that submission only), a memory limit
(``--memory``), and, where the machine allows unprivileged namespaces (``unshare``), no network
(a network namespace with only its own loopback, which the kernel's channels need). One student
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
import json
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import zipfile
from functools import lru_cache
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from tools import written_answers
from tools.assignments import OUT, _bin

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
    export cell writes (unpacked into ``work``, which is made empty first)."""
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    if not zipfile.is_zipfile(path):
        return path, ""
    with zipfile.ZipFile(path) as zf:
        inside = [n for n in zf.namelist() if n.endswith(".ipynb") and "/" not in n.strip("/")]
        if len(inside) != 1:
            return path, f"a zip with {len(inside)} notebooks at its top level (one expected); nothing was graded"
        target = work / "submission" / inside[0]
        target.parent.mkdir()
        target.write_bytes(zf.read(inside[0]))
    return target, ""


#: seconds a notebook may run, its tests included (``ORRC_GRADING_TIME_LIMIT`` overrides it)
TIME_LIMIT = float(os.environ.get("ORRC_GRADING_TIME_LIMIT", 600))
MEMORY_MB = 4096      # address space a notebook's processes may take


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


def run_limited(cmd: list[str], time_limit: float = TIME_LIMIT, memory_mb: int = MEMORY_MB) -> tuple[int | None, str]:
    """Run ``cmd`` in its own process group with a memory limit; kill the group after
    ``time_limit`` seconds. (return code, or None when killed; stderr)."""
    def limits():
        cap = memory_mb * 2 ** 20
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))

    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=limits)
    try:
        _, err = proc.communicate(timeout=time_limit)
        return proc.returncode, err
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        return None, ""


def _failed_cases(question: str, output: str) -> set[int]:
    return {int(i) for i in re.findall(rf"{re.escape(question)} - (\d+) result:\s*\n\s*❌", output)}


def grade_one(path: Path, zip_path: Path, work: Path, expected: str, cases: dict,
              time_limit: float = TIME_LIMIT, memory_mb: int = MEMORY_MB) -> dict:
    """Grade one submission: {"student", "scores": {question: points}, "note", "feedback": text}."""
    student = path.stem
    scores = {q: 0.0 for q in cases}
    path, note = unpacked(path, work)
    note = note or precheck(path, expected)
    written = []
    if not note:
        import nbformat

        written = written_answers.read(nbformat.read(path, as_version=4))
    failed: dict[str, list[str]] = {}
    missing: set[str] = set()
    undefined: list[str] = []
    if not note:
        for old in work.glob("results*"):
            shutil.rmtree(old) if old.is_dir() else old.unlink()
        rc, err = run_limited(sandboxed([_bin("otter"), "run", "-a", str(zip_path), "-o", str(work), "--no-logo",
                                         str(path)]), time_limit, memory_mb)
        results = work / "results.json"
        tests = json.loads(results.read_text()).get("tests", []) if results.is_file() and rc is not None else []
        graded = [t for t in tests if t.get("name") in cases and t.get("max_score") is not None]
        if rc is None:
            note = f"the notebook ran longer than the time limit ({time_limit:g} s; an endless loop?); nothing was graded"
        elif not graded:
            note = ("the autograder could not run this notebook (otter: "
                    + (err.strip().splitlines() or ["no results"])[-1][:200] + "); nothing was graded")
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
    return {"student": student, "scores": scores, "possible": possible, "note": note, "written": written,
            "feedback": "\n".join(lines) + "\n"}


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

    def one(student):
        path, dup = chosen[student]
        row = grade_one(path.resolve(), zip_path, out / "otter" / student, expected, cases, time_limit, memory_mb)
        row["note"] = "; ".join(n for n in (dup, row["note"]) if n)
        row["late"] = lateness(path, deadline)
        return row

    with ThreadPoolExecutor(max_workers=workers) as pool:
        rows = list(pool.map(one, sorted(chosen)))
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
