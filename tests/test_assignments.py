"""The graded assignments (issue 15): otter-grader builds them, their solutions get full marks, and
neither an untouched student notebook nor a plausible wrong submission does.

One session fixture (``graded``, in conftest.py: it starts when the tests are collected and
runs beside the rest of the suite) builds every assignment of ``assignments/`` (``tools.assignments``: jupytext
to .ipynb, ``otter assign``, then ``otter run`` locally) and grades three notebooks of each: the
solution notebook, the blank student notebook, and the plausible wrong submission of
``tests/fixtures/assignments/NAME_wrong.md`` (its answer cells filled into the student notebook,
as a student fills them in). These are the checks ``make assignments`` prints.
Graded solutions stay out of the book: ``assignments/`` is excluded from it, and no solution
line or hidden test of an assignment is in the built HTML.
"""
from __future__ import annotations

import re
from pathlib import Path

import pytest
import yaml

from conftest import BOOK_OUT
from tools import assignments

ROOT = Path(__file__).resolve().parents[1]
FIXTURES = ROOT / "tests" / "fixtures" / "assignments"
NAMES = assignments.names()


def test_at_least_four_assignments_one_per_part_of_the_paper():
    assert len(NAMES) >= 4, NAMES
    chapters = {ch for n in NAMES for ch in assignments.read_assignment(assignments.SOURCES / n / f"{n}.md")["chapters"]}
    for part in ("book/preview_rhc", "book/theorem1", "book/unknown_systems", "book/comparison"):
        assert part in chapters, f"no assignment goes with {part}"


@pytest.mark.parametrize("name", NAMES)
def test_every_assignment_has_a_plausible_wrong_submission(name):
    assert (FIXTURES / f"{name}_wrong.md").is_file(), f"tests/fixtures/assignments/{name}_wrong.md is missing"


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_solution_gets_full_marks_and_blank_and_wrong_do_not(graded, name):
    r = graded[name]
    sol, blank, wrong = (r["grades"][k] for k in ("solution", "blank", "wrong"))
    assert sol["points"] > 0 and sol["score"] == sol["points"], assignments.summary([r])[0]
    assert blank["points"] == wrong["points"] == sol["points"]
    assert blank["score"] < blank["points"], f"{name}: the untouched student notebook gets full marks"
    assert wrong["score"] < wrong["points"], f"{name}: the plausible wrong submission gets full marks"
    assert re.fullmatch(rf"{name}: solution (\d+)/\1 points, blank \d+/\1 points", assignments.line(r))


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_a_hidden_test_catches_the_wrong_submission(graded, name):
    """The wrong submission fails a hidden test, not only the public ones students see.

    otter's output for a question numbers its test cases in order ("q - 2 result: ❌ ...")."""
    meta = assignments.read_assignment(assignments.SOURCES / name / f"{name}.md")
    failed_hidden = []
    for q in meta["questions"]:
        output = graded[name]["grades"]["wrong"]["questions"][q["name"]][2]
        failed = {int(i) for i in re.findall(rf"{re.escape(q['name'])} - (\d+) result:\s*\n\s*❌", output)}
        failed_hidden += [t["name"] for i, t in enumerate(q["tests"], 1) if i in failed and t["hidden"]]
    assert failed_hidden, f"{name}: the wrong submission fails no hidden test"


@pytest.mark.slow
def test_the_report_and_its_exit_code(graded):
    text, rc = assignments.summary(list(graded.values()))
    assert rc == 0 and len(text.splitlines()) == len(NAMES)
    bad = dict(graded[NAMES[0]], grades={**graded[NAMES[0]]["grades"], "solution": graded[NAMES[0]]["grades"]["wrong"]})
    assert assignments.summary([bad])[1] == 1, "a solution below full marks must fail make assignments"
    full = dict(graded[NAMES[0]], grades={**graded[NAMES[0]]["grades"], "blank": graded[NAMES[0]]["grades"]["solution"]})
    assert assignments.summary([full])[1] == 1, "a blank notebook at full marks must fail make assignments"


@pytest.mark.slow
def test_student_notebooks_hold_no_solution(graded):
    for name, r in graded.items():
        student = r["paths"]["student"]
        text = student.read_text(encoding="utf-8")
        assert "BEGIN SOLUTION" not in text and "BEGIN TESTS" not in text
        meta = assignments.read_assignment(assignments.SOURCES / name / f"{name}.md")
        for q in meta["questions"]:
            for t in q["tests"]:
                assert (f"def {t['name']}(" in text) == (not t["hidden"]), f"{name}: {t['name']}"


def test_a_solution_outside_a_solution_block_is_refused(tmp_path):
    """A solution cell left outside a BEGIN/END SOLUTION block would reach the students: the build stops."""
    src = assignments.SOURCES / NAMES[0] / f"{NAMES[0]}.md"
    text = src.read_text(encoding="utf-8")
    first = text.index("```{raw-cell}\n# BEGIN SOLUTION\n```\n")
    text = text[:first] + text[first:].replace("```{raw-cell}\n# BEGIN SOLUTION\n```\n", "", 1).replace(
        "```{raw-cell}\n# END SOLUTION\n```\n", "", 1)
    (tmp_path / NAMES[0]).mkdir()
    (tmp_path / NAMES[0] / f"{NAMES[0]}.md").write_text(text, encoding="utf-8")
    with pytest.raises(RuntimeError, match="still holds solution"):
        assignments.build(NAMES[0], tmp_path / "out", tmp_path)


def test_assignments_are_excluded_from_the_book():
    cfg = yaml.safe_load((ROOT / "_config.yml").read_text(encoding="utf-8"))
    assert "assignments" in cfg["exclude_patterns"]


@pytest.mark.slow
def test_no_assignment_solution_in_the_built_book(book, tmp_path):
    assert book["rc"] == 0
    lines = []
    for name in NAMES:
        master = assignments.to_ipynb(assignments.SOURCES / name / f"{name}.md", tmp_path / f"{name}.ipynb")
        lines += [ln for ln in assignments._solution_text(master) if len(ln) >= 12]
    book_sources = "\n".join(p.read_text(encoding="utf-8") for p in (ROOT / "book").rglob("*.md"))
    lines = [ln for ln in lines if ln not in book_sources]  # what the book itself also says is no leak
    assert len(lines) > 20
    html = BOOK_OUT / "_build" / "html"
    files = [p for p in html.rglob("*") if p.is_file() and p.suffix in (".html", ".js", ".txt", ".md", ".ipynb", ".json")]
    for p in files:
        text = p.read_text(encoding="utf-8", errors="replace")
        hits = [ln for ln in lines if ln in text]
        assert not hits, f"{p.relative_to(html)} holds assignment solution text: {hits[:2]}"
