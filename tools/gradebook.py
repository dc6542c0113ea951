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
- ``otter/STUDENT/``: otter's raw results, for the instructor only (they hold hidden test source).

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
import json
import re
import shutil
import subprocess
import sys
import zipfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

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


def _failed_cases(question: str, output: str) -> set[int]:
    return {int(i) for i in re.findall(rf"{re.escape(question)} - (\d+) result:\s*\n\s*❌", output)}


def grade_one(path: Path, zip_path: Path, work: Path, expected: str, cases: dict) -> dict:
    """Grade one submission: {"student", "scores": {question: points}, "note", "feedback": text}."""
    student = path.stem
    scores = {q: 0.0 for q in cases}
    path, note = unpacked(path, work)
    note = note or precheck(path, expected)
    failed: dict[str, list[str]] = {}
    missing: set[str] = set()
    undefined: list[str] = []
    if not note:
        for old in work.glob("results*"):
            shutil.rmtree(old) if old.is_dir() else old.unlink()
        proc = subprocess.run([_bin("otter"), "run", "-a", str(zip_path), "-o", str(work), "--no-logo", str(path)],
                              capture_output=True, text=True)
        results = work / "results.json"
        tests = json.loads(results.read_text()).get("tests", []) if results.is_file() else []
        graded = [t for t in tests if t.get("name") in cases and t.get("max_score") is not None]
        if not graded:
            note = ("the autograder could not run this notebook (otter: "
                    + (proc.stderr.strip().splitlines() or ["no results"])[-1][:200] + "); nothing was graded")
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


def grade_folder(name: str, submissions: Path, out: Path, zip_path: Path | None = None, workers: int = 2) -> list[dict]:
    """Grade every file of ``submissions`` (see the module's docstring); returns the rows, in student order."""
    zip_path = Path(zip_path or autograder_zip(name)).resolve()
    cases = questions_of(zip_path)
    expected = assignment_name(zip_path) or name
    files = sorted(p for p in Path(submissions).iterdir() if p.is_file() and not p.name.startswith("."))
    out = Path(out)
    (out / "feedback").mkdir(parents=True, exist_ok=True)
    with ThreadPoolExecutor(max_workers=workers) as pool:
        rows = list(pool.map(lambda p: grade_one(p.resolve(), zip_path, out / "otter" / p.stem, expected, cases), files))
    with open(out / "gradebook.csv", "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f)
        writer.writerow(["student", *cases, "total", "possible", "note"])
        for r in rows:
            writer.writerow([r["student"], *(f"{r['scores'][q]:g}" for q in cases), f"{sum(r['scores'].values()):g}",
                             f"{sum(r['possible'].values()):g}", r["note"]])
    for r in rows:
        (out / "feedback" / f"{r['student']}.md").write_text(r["feedback"], encoding="utf-8")
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Grade a folder of submissions of one assignment into a gradebook "
                                             "CSV and one feedback file per student.")
    ap.add_argument("name", help="the assignment, e.g. a1_preview_rhc")
    ap.add_argument("submissions", type=Path, help="a folder with one submission per student (STUDENT.ipynb)")
    ap.add_argument("-o", "--out", type=Path, default=None, help="output folder (default: grades/NAME)")
    ap.add_argument("--autograder", type=Path, default=None, help="the autograder zip (default: make assignments')")
    args = ap.parse_args(argv)
    if not args.submissions.is_dir():
        print(f"gradebook: {args.submissions} is not a folder of submissions", file=sys.stderr)
        return 2
    out = args.out or Path("grades") / args.name
    try:
        zip_path = args.autograder or autograder_zip(args.name)
    except FileNotFoundError as exc:
        print(f"gradebook: {exc}", file=sys.stderr)
        return 2
    rows = grade_folder(args.name, args.submissions, out, zip_path)
    print(f"{len(rows)} submissions graded: {out / 'gradebook.csv'}, feedback in {out / 'feedback'}/"
          + "".join(f"\n  {r['student']}: {r['note']}" for r in rows if r["note"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
