"""The coursework tools fail loudly on input outside their formats.

The solution-free edition strips solutions by the format reader (tools/solutions.py), so a
solution it misread would leak: each malformed chapter below is refused with a FormatError
naming the line and the problem. The assignment reader (tools.assignments.read_assignment,
behind the instructor's guide) refuses a source without its metadata, a question without
tests (or, graded by hand, without points), and a test message that would break the test file
otter assign writes. The class gradebook (tools.gradebook) refuses an assignment without a built
autograder and a submissions path that is not a folder, naming them.
"""
import atexit
import shutil
import tempfile
from pathlib import Path

import pytest

from bad_input import assert_bad_input, case, params
from tools.assignments import read_assignment
from tools.solutions import FormatError, parse, strip_solutions

EX = "```{exercise}\n:label: ex-a\n\nDo it.\n```\n"
EX_B = "```{exercise}\n:label: ex-b\n\nAnd this.\n```\n"
GATED = ("```{solution-start} ex-a\n:class: dropdown\n```\nThe answer is {glue:text}`ex-a-x`.\n"
         "```{code-cell} ipython3\nx = 6 * 7\n```\n```{solution-end}\n```\n")
PLAIN = "````{solution} ex-b\n:class: dropdown\n\nBecause 42 is 6 times 7.\n````\n"

HEADER = "---\nkernelspec:\n  display_name: Python 3\n  language: python\n  name: python3\n{meta}---\n\n"
META = "orrc_assignment:\n  chapters: [book/problem]\n  minutes: 30\n"
TEST = ('```{{code-cell}} ipython3\n""" # BEGIN TEST CONFIG\npoints: 1\nfailure_message: {msg}\n""" # END TEST CONFIG\n'
        "def test_it(x):\n    assert x\n```\n")
QUESTION = ("```{{raw-cell}}\n# BEGIN QUESTION\nname: q1\n```\n\n```{{raw-cell}}\n# BEGIN TESTS\n```\n\n{tests}\n"
            "```{{raw-cell}}\n# END TESTS\n```\n\n```{{raw-cell}}\n# END QUESTION\n```\n")


def _assignment(text: str) -> Path:
    folder = Path(tempfile.mkdtemp(prefix="orrc-assign-"))
    atexit.register(shutil.rmtree, folder, True)
    path = folder / "a0_test.md"
    path.write_text(text, encoding="utf-8")
    return path


ASSIGNMENT_CASES = [
    case("assignment-no-metadata", lambda: read_assignment(_assignment(HEADER.format(meta="") + "# A0\n")),
         "orrc_assignment", "chapters", "minutes", exc=ValueError),
    case("assignment-question-without-tests", lambda: read_assignment(_assignment(
        HEADER.format(meta=META) + QUESTION.format(tests=""))), "q1", "no tests", exc=ValueError),
    case("assignment-quote-in-message", lambda: read_assignment(_assignment(
        HEADER.format(meta=META) + QUESTION.format(tests=TEST.format(msg='keys "a" and "b"')))),
         "test_it", "double quote", exc=ValueError),
    case("assignment-manual-without-points", lambda: read_assignment(_assignment(
        HEADER.format(meta=META) + QUESTION.format(tests="").replace("name: q1\n", "name: q1\nmanual: true\n"))),
         "q1", "manual", "points", exc=ValueError),
    case("assignment-test-without-message", lambda: read_assignment(_assignment(
        HEADER.format(meta=META) + QUESTION.format(tests=TEST.format(msg="m").replace("failure_message: m\n", "")))),
         "test_it", "failure_message", exc=ValueError),
]

F = {"exc": FormatError}  # a ValueError: the format reader refuses, naming the line or the label
CASES = [
    case("unclosed-fence", lambda: parse(EX + "````{solution} ex-a\n:class: dropdown\nno end\n"),
         "never closed", ":6", **F),
    case("start-without-end", lambda: parse(EX + "```{solution-start} ex-a\n:class: dropdown\n```\ntext\n"),
         "ex-a", "no solution-end", **F),
    case("end-without-start", lambda: parse(EX + "```{solution-end}\n```\n"),
         "solution-end without a solution-start", **F),
    case("nested-start", lambda: parse(EX + EX_B + GATED.replace("```{solution-end}\n```\n", "")
                                       + GATED.replace("ex-a", "ex-b")),
         "inside the solution of 'ex-a'", **F),
    case("unknown-label", lambda: parse(EX + PLAIN), "'ex-b'", "no exercise has", **F),
    case("two-solutions", lambda: parse(EX + GATED + GATED), "second solution", "ex-a", **F),
    case("no-dropdown", lambda: parse(EX + "```{solution} ex-a\n\nText.\n```\n"), ":class: dropdown", "ex-a", **F),
    case("no-label", lambda: parse("```{exercise}\n\nDo it.\n```\n"), "without a :label:", **F),
    case("no-argument", lambda: parse(EX + "```{solution}\n:class: dropdown\n\nText.\n```\n"),
         "needs the exercise's label", **F),
    case("content-in-start", lambda: parse(EX + "```{solution-start} ex-a\n:class: dropdown\nhidden text\n```\n"
                                                "```{solution-end}\n```\n"), "takes no content", **F),
    case("duplicate-exercise", lambda: parse(EX + EX), "two exercises", "ex-a", **F),
    case("strip-unclosed", lambda: strip_solutions(EX + "```{solution-start} ex-a\n:class: dropdown\n```\n", "ch.md"),
         "ch.md", "no solution-end", **F),
]


@pytest.mark.parametrize("call, exc, words", params(CASES + ASSIGNMENT_CASES))
def test_malformed_solutions_and_assignments_are_refused(call, exc, words):
    assert issubclass(exc, ValueError)
    assert_bad_input(call, exc, words)


def test_strip_removes_both_forms_and_keeps_the_rest():
    text = "# Title\n\n" + EX + EX_B + GATED + "Between.\n\n" + PLAIN + "After.\n"
    ch = parse(text)
    assert [s.kind for s in ch.solutions] == ["gated", "plain"]
    assert ch.solution_for("ex-a").code == ["x = 6 * 7"]
    assert ch.solution_for("ex-a").prose == ["The answer is {glue:text}`ex-a-x`."]
    out = strip_solutions(text)
    for gone in ("solution", "6 * 7", "The answer is", "Because 42"):
        assert gone not in out
    for kept in ("# Title", "Do it.", "And this.", "Between.", "After.", ":label: ex-b"):
        assert kept in out
    assert parse(out).solutions == [] and len(parse(out).exercises) == 2


def test_a_shorter_inner_fence_does_not_close_the_solution():
    text = EX + "````{solution} ex-a\n:class: dropdown\n\n```python\nprint(1)\n```\nStill the solution.\n````\nOut.\n"
    sol = parse(text).solution_for("ex-a")
    assert sol.code_in_prose == ["print(1)"]
    assert "Still the solution." in sol.prose
    assert strip_solutions(text).endswith("```\nOut.\n") and "Still" not in strip_solutions(text)


def test_the_gradebook_refuses_what_it_cannot_grade(tmp_path, capsys):
    from tools import gradebook

    (tmp_path / "subs").mkdir()
    assert gradebook.main(["a9_nowhere", str(tmp_path / "subs"), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "a9_nowhere" in err and "make assignments" in err
    assert gradebook.main(["a9_nowhere", str(tmp_path / "missing")]) == 2
    assert "not a folder" in capsys.readouterr().err


def test_the_gradebook_refuses_a_bad_roster_deadline_or_limit(tmp_path, capsys):
    from tools import gradebook

    (tmp_path / "subs").mkdir()
    base = ["a1_preview_rhc", str(tmp_path / "subs"), "-o", str(tmp_path / "out")]
    assert gradebook.main(base + ["--deadline", "next friday"]) == 2
    err = capsys.readouterr().err
    assert "next friday" in err and "ISO" in err
    roster = tmp_path / "roster.csv"
    roster.write_text("student,mail\nx,y\n", encoding="utf-8")
    assert gradebook.main(base + ["--roster", str(roster)]) == 2
    err = capsys.readouterr().err
    assert "id, name, email" in err and "roster.csv" in err
    assert gradebook.main(base + ["--roster", str(tmp_path / "nowhere.csv")]) == 2
    assert "nowhere.csv" in capsys.readouterr().err
    assert gradebook.main(base + ["--time-limit", "0"]) == 2
    assert "--time-limit" in capsys.readouterr().err


def test_a_test_cell_gets_the_prelude_and_loses_the_students_numpy():
    from tools.grading_prelude import PRELUDE, with_prelude

    src = '""" # BEGIN TEST CONFIG\npoints: 1\n""" # END TEST CONFIG\ndef test_q(f, np, orrc):\n    assert close(f(1.0), 2.0)\n'
    out = with_prelude(src)
    assert "def test_q(f):" in out and PRELUDE.strip() in out and out.startswith('""" # BEGIN TEST CONFIG')
    ns = {}
    exec(out.split("# END TEST CONFIG", 1)[1], ns)
    ns["test_q"](lambda x: 2 * x)
    import numpy as np
    saved = np.isclose
    try:
        np.isclose = lambda *a, **k: True
        with pytest.raises(AssertionError, match="replaced numpy.isclose"):
            ns["test_q"](lambda x: 2 * x)
    finally:
        np.isclose = saved


def test_a_forbidden_package_function_raises_wherever_it_is_held_and_comes_back():
    """While a student's function is graded, a package function the question asks for raises, even
    through a reference taken before (``from orrc.theory import gamma_c``); afterwards it works."""
    import orrc
    from orrc.theory import gamma_c as held
    from tools.grading_prelude import with_prelude

    ns = {}
    exec(with_prelude("def tools():\n    return forbidden, close\n"), ns)
    forbidden, close = ns["tools"]()
    before = held(30, 0.99, 1.0, 2.0, 1.0)
    with forbidden(orrc.theory):
        with pytest.raises(RuntimeError, match="write yourself"):
            held(30, 0.99, 1.0, 2.0, 1.0)
        with pytest.raises(RuntimeError, match="write yourself"):
            orrc.theory.gamma_c(30, 0.99, 1.0, 2.0, 1.0)
    assert held(30, 0.99, 1.0, 2.0, 1.0) == before
    assert close([1.0, 2.0], [1.0, 2.0 + 1e-9]) and not close([1.0, 2.0], [1.0, 2.1]) and not close([1.0], [1.0, 2.0, 3.0])
