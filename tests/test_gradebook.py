"""The grading commands as an instructor runs them: every grading command of the README
and of the instructor's guide, verbatim, and the class gradebook they write.

The commands are read from the documents (every ``bash`` block that runs ``otter run`` or
``tools.gradebook``) and run, as written, with bash in a folder laid out like a fresh clone after
``make assignments``: the repository's ``tools`` and ``.venv``, the session's built assignments as
``_build/assignments``, one student's ``submission.ipynb`` and a class folder ``submissions/``
with one file of each kind: right, one question wrong (and late), broken (a cell raises), an
endless loop, empty, another assignment's, not a notebook, and a student with two files (a blank
notebook, then a right one that tries the network, handed in as the export cell's zip); a roster
adds a student with no file. The gradebook must hold one row per student with the right points,
a second run of the command over the same files grades nothing again, and nothing handed back
may quote a hidden test. (That a blank notebook scores at most a quarter of the points is
checked on every assignment by ``tests/test_assignments.py``.)
"""
from __future__ import annotations

import atexit
import csv
import datetime as dt
import os
import re
import shutil
import subprocess
import tempfile
import time
import zipfile
from pathlib import Path

import nbformat
import pytest

from conftest import after, background
from tools import assignments

ROOT = Path(__file__).resolve().parents[1]
DOCS = (ROOT / "README.md", ROOT / "book" / "instructors.md")
FIRST = "a1_preview_rhc"        # the assignment the documented commands grade
DEADLINE = dt.datetime(2026, 3, 1, 17, 0, tzinfo=dt.timezone.utc)   # the documented command's --deadline
LOOP_LIMIT = 60                 # seconds a notebook may run in these gradings (a right one takes 10-20 s)
NETWORK_MARK = Path(tempfile.gettempdir()) / f"orrc-network-mark-{os.getpid()}"


def documented_commands() -> list[tuple[str, str]]:
    """(document, block) for every bash block of the docs that grades (otter run, tools.gradebook)."""
    out = []
    for doc in DOCS:
        for block in re.findall(r"```bash\n(.*?)```", doc.read_text(encoding="utf-8"), re.S):
            if "otter run" in block or "tools.gradebook" in block:
                out.append((doc.name, block))
    return out


def test_the_docs_document_grading_commands():
    blocks = documented_commands()
    assert {d for d, _ in blocks} == {"README.md", "instructors.md"}, blocks
    assert any("tools.gradebook" in b for _, b in blocks) and any("otter run" in b for _, b in blocks)


def _class_folder(graded, folder: Path) -> dict[str, str]:
    """The fixture class: {student: kind}. Each file that reaches otter tests a case no other one
    does (a full mark with no note and the roster's name; one wrong question and a late file; a
    raising cell; the time limit; two files of one student, the export cell's zip and the network),
    so that the class costs as few gradings as its checks need."""
    r = graded[FIRST]
    folder.mkdir(parents=True)
    shutil.copy(r["paths"]["solution"], folder / "right.ipynb")
    label = sorted(k for k in r["submissions"] if k.startswith("wrong"))[0]
    shutil.copy(Path(r["paths"]["student"]).parents[2] / "submissions" / f"{label}.ipynb", folder / "one_wrong.ipynb")
    nb = nbformat.read(r["paths"]["solution"], as_version=4)
    first = next(c for c in nb.cells if c.cell_type == "code" and "def preview_plan" in c.source)
    first.source = "raise RuntimeError('my plan is not finished')\n"
    nbformat.write(nb, folder / "broken.ipynb")
    empty = nbformat.v4.new_notebook()
    nbformat.write(empty, folder / "empty.ipynb")
    other = next(n for n in graded if n != FIRST)
    shutil.copy(graded[other]["paths"]["solution"], folder / "foreign.ipynb")
    (folder / "not_a_notebook.ipynb").write_text("my answers are in the PDF\n", encoding="utf-8")
    # an endless loop in one answer; it waits rather than spins, so that the LOOP_LIMIT seconds it runs
    # take no core from the rest of the session (the time limit is on wall-clock time either way)
    looping = nbformat.read(r["paths"]["solution"], as_version=4)
    next(c for c in looping.cells if c.cell_type == "code" and "def R_curve" in c.source).source = (
        "import time\nwhile True:\n    time.sleep(0.5)\n")
    nbformat.write(looping, folder / "looping.ipynb")
    # one student, two files: a blank notebook, then (newer) the export cell's zip of a right notebook
    # that first tries the network and records what it got
    shutil.copy(r["paths"]["student"], folder / "alice.ipynb")
    net = nbformat.read(r["paths"]["solution"], as_version=4)
    cell = next(c for c in net.cells if c.cell_type == "code" and "def R_curve" in c.source)
    cell.source = (f"import socket\ntry:\n    socket.create_connection(('pypi.org', 443), timeout=5).close()\n"
                   f"    _seen = 'reached'\nexcept OSError:\n    _seen = 'blocked'\n"
                   f"open({str(NETWORK_MARK)!r}, 'w').write(_seen)\n" + cell.source)
    with zipfile.ZipFile(folder / "alice.zip", "w") as zf:   # what the export cell writes
        zf.writestr(f"{FIRST}.ipynb", nbformat.writes(net))
        zf.writestr(".OTTER_LOG", b"")
    before = DEADLINE.timestamp() - 86400
    for f in folder.iterdir():
        os.utime(f, (before, before))
    os.utime(folder / "alice.zip", (before + 3600, before + 3600))
    os.utime(folder / "one_wrong.ipynb", (DEADLINE.timestamp() + 7500, DEADLINE.timestamp() + 7500))  # 2 h 5 min late
    return {"right": "right", "one_wrong": label, "broken": "broken", "empty": "empty",
            "foreign": other, "not_a_notebook": "text", "looping": "an endless loop",
            "alice": "blank, then right as the export cell's zip, after trying the network",
            "absent": "on the roster, no file"}


def _roster(path: Path, students) -> None:
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(["id", "name", "email"])
        for s in sorted(students):
            w.writerow([s, f"Student {s.title()}", f"{s}@example.edu"])


@pytest.fixture(scope="module")
def clone(graded):
    """A folder laid out like a fresh clone after make assignments, with the documented commands run in
    it (in the background as soon as the gradings are done, ``conftest.after``)."""
    return background("clone")


@after("built", "clone")   # the built notebooks only: beside the gradings, not after them
def run_the_documented_commands(graded):
    here = Path(tempfile.mkdtemp(prefix="orrc-clone-"))     # outside the repository, removed at exit
    atexit.register(shutil.rmtree, here, True)
    atexit.register(NETWORK_MARK.unlink, missing_ok=True)
    (here / "_build").mkdir()
    (here / "_build" / "assignments").symlink_to(Path(graded[FIRST]["paths"]["student"]).parents[3])
    (here / ".venv").symlink_to(ROOT / ".venv")
    shutil.copytree(ROOT / "tools", here / "tools", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(graded[FIRST]["paths"]["solution"], here / "submission.ipynb")
    kinds = _class_folder(graded, here / "submissions")
    _roster(here / "roster.csv", kinds)
    runs = []
    env = dict(os.environ, ORRC_GRADING_TIME_LIMIT=str(LOOP_LIMIT))   # the endless loop costs LOOP_LIMIT s only
    for doc, block in documented_commands():
        started = time.time()
        proc = subprocess.run(["bash", "-e", "-c", block], cwd=here, capture_output=True, text=True, timeout=900,
                              env=env)
        runs.append((doc, block, proc, started))
    return {"dir": here, "kinds": kinds, "runs": runs}


@pytest.mark.slow
def test_every_documented_grading_command_works_as_written(clone):
    for doc, block, proc, _ in clone["runs"]:
        assert proc.returncode == 0, f"{doc}:\n{block}\nexit {proc.returncode}\n{proc.stdout[-1500:]}\n{proc.stderr[-1500:]}"
    results = list(clone["dir"].glob("results/**/results.json"))
    assert results, "the documented otter run wrote no results.json"


@pytest.mark.slow
def test_the_gradebook_of_a_class(clone, graded):
    book = clone["dir"] / "grades" / FIRST / "gradebook.csv"
    assert book.is_file(), "the documented gradebook command wrote no gradebook.csv"
    rows = {r["student"]: r for r in csv.DictReader(book.open(encoding="utf-8"))}
    assert set(rows) == set(clone["kinds"]), "one row per student"
    questions = [q["name"] for q in assignments.read_assignment(assignments.SOURCES / FIRST / f"{FIRST}.md")["questions"]
                 if q["tests"]]
    columns = [c for c in rows["right"] if c not in ("student", "name", "email")]
    assert columns[:len(questions)] == questions, "one column per question, in order"
    possible = float(rows["right"]["possible"])
    assert float(rows["right"]["total"]) == possible and not rows["right"]["note"]
    wrong_q = [q for q in questions if float(rows["one_wrong"][q]) < graded[FIRST]["grades"]["solution"]["questions"][q][1]]
    assert len(wrong_q) == 1 and float(rows["one_wrong"]["total"]) < possible
    assert "not defined" in rows["broken"]["note"] and "q1_plan" in rows["broken"]["note"]
    assert float(rows["broken"]["q1_plan"]) == 0 and "q4_regret" not in rows["broken"]["note"]
    assert float(rows["broken"]["q4_regret"]) > 0, "a broken Q1 costs Q1 only"
    assert "no cells" in rows["empty"]["note"] and float(rows["empty"]["total"]) == 0
    assert clone["kinds"]["foreign"] in rows["foreign"]["note"] and float(rows["foreign"]["total"]) == 0
    assert "not a Jupyter notebook" in rows["not_a_notebook"]["note"]
    for student in set(rows) - {"absent"}:
        assert (clone["dir"] / "grades" / FIRST / "feedback" / f"{student}.md").is_file(), student


@pytest.mark.slow
def test_a_class_graded_safely(clone):
    """An endless loop, a student with two files (the newer one tries the network), a late file and
    a student with no file: one row each, with the roster's name and email, and the batch goes on."""
    from tools import gradebook

    book = clone["dir"] / "grades" / FIRST / "gradebook.csv"
    rows = {r["student"]: r for r in csv.DictReader(book.open(encoding="utf-8"))}
    possible = float(rows["right"]["possible"])
    assert rows["right"]["name"] == "Student Right" and rows["right"]["email"] == "right@example.edu"
    assert "time limit" in rows["looping"]["note"] and float(rows["looping"]["total"]) == 0
    # the export cell's zip, the newer of two files, graded in full: the note names both files, nothing else
    assert float(rows["alice"]["total"]) == possible
    assert rows["alice"]["note"] == "2 files handed in (alice.ipynb, alice.zip): the newest, alice.zip, is graded"
    assert rows["absent"]["note"] == "no submission" and float(rows["absent"]["total"]) == 0
    assert rows["one_wrong"]["late"] == "late by 2 h 5 min"
    assert all(not r["late"] for s, r in rows.items() if s != "one_wrong")
    written = clone["dir"] / "grades" / FIRST / "written"
    for student in ("right", "alice", "one_wrong"):   # one PDF of written answers per submission
        pdf = written / f"{student}.pdf"
        assert pdf.is_file() and pdf.read_bytes()[:5] == b"%PDF-", student
    assert float(rows["right"]["written_possible"]) > 0 and rows["right"]["written"] == ""
    if gradebook.network_isolation():
        assert NETWORK_MARK.read_text() == "blocked", "a student's notebook reached the network"


@pytest.mark.slow
def test_running_the_command_again_grades_nothing_again(clone):
    """The documented gradebook command, run once more over the same files, reuses every result:
    no notebook is executed again (otter's results keep their times) and the gradebook is the same."""
    block = [b for _, b, _, _ in clone["runs"] if "tools.gradebook" in b][-1]
    out = clone["dir"] / "grades" / FIRST
    graded = sorted(out.glob("otter/*/graded.json"))
    assert {p.parent.name for p in graded} == {"right", "one_wrong", "broken", "looping", "alice"}, graded
    before = {p: p.stat().st_mtime_ns for f in graded for p in (f, f.with_name("results.json")) if p.is_file()}
    csv_before = (out / "gradebook.csv").read_text(encoding="utf-8")
    env = dict(os.environ, ORRC_GRADING_TIME_LIMIT=str(LOOP_LIMIT))
    proc = subprocess.run(["bash", "-e", "-c", block], cwd=clone["dir"], capture_output=True, text=True, timeout=300,
                          env=env)
    assert proc.returncode == 0, proc.stderr[-1500:]
    assert {p: p.stat().st_mtime_ns for p in before} == before, "a submission graded before was graded again"
    assert (out / "gradebook.csv").read_text(encoding="utf-8") == csv_before


def test_a_changed_file_autograder_or_limit_is_graded_again(tmp_path):
    """What decides whether a file graded before is graded again: its bytes, the autograder's, the limits."""
    from tools import gradebook

    sub, zip_path = tmp_path / "alice.ipynb", tmp_path / "autograder.zip"
    sub.write_text("{}", encoding="utf-8")
    zip_path.write_bytes(b"PK")
    key = gradebook.grading_key(sub, zip_path, 600, 4096)
    assert key == gradebook.grading_key(sub, zip_path, 600, 4096)
    assert key != gradebook.grading_key(sub, zip_path, 90, 4096)
    assert key != gradebook.grading_key(sub, zip_path, 600, 2048)
    zip_path.write_bytes(b"PK2")
    assert gradebook.grading_key(sub, zip_path, 600, 4096) != key
    zip_path.write_bytes(b"PK")
    sub.write_text('{"cells": []}', encoding="utf-8")
    assert gradebook.grading_key(sub, zip_path, 600, 4096) != key


def test_the_output_folders_of_the_documented_commands_are_ignored_by_git():
    """Student work and hidden tests are never one `git add -A` away from a commit."""
    for folder in ("grades/a1_preview_rhc/gradebook.csv", "results/student1/results.json", "submissions/alice.ipynb",
                   "_build/assignments/x"):
        proc = subprocess.run(["git", "check-ignore", "-q", folder], cwd=ROOT)
        assert proc.returncode == 0, f"{folder} is not ignored by git"


def hidden_test_lines(name: str) -> list[str]:
    """The distinctive source lines of an assignment's hidden tests (12+ characters, not comments)."""
    import jupytext

    nb = jupytext.read(assignments.SOURCES / name / f"{name}.md", fmt="md:myst")
    out = []
    for cell in nb.cells:
        if cell.cell_type == "code" and "BEGIN TEST CONFIG" in cell.source and "hidden: true" in cell.source:
            body = cell.source.split("# END TEST CONFIG", 1)[1]
            out += [ln.strip() for ln in body.splitlines() if len(ln.strip()) >= 12 and not ln.strip().startswith("#")]
    return out


@pytest.mark.slow
def test_nothing_handed_back_quotes_a_hidden_test(clone):
    lines = hidden_test_lines(FIRST)
    assert len(lines) > 10
    out = clone["dir"] / "grades" / FIRST
    handed_back = [out / "gradebook.csv", *sorted((out / "feedback").glob("*.md"))]
    for f in handed_back:
        text = f.read_text(encoding="utf-8")
        hits = [ln for ln in lines if ln in text]
        assert not hits, f"{f.name} quotes hidden tests: {hits[:2]}"
    raw = "\n".join(p.read_text(encoding="utf-8") for p in (out / "otter").glob("*/results.json"))
    assert any(ln in raw for ln in lines), "otter's raw results (kept for the instructor) do quote them"

