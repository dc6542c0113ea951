"""The exercise/solution format reader (tools/solutions.py) fails loudly on anything outside the fixed format.

The solution-free edition strips solutions by this reader, so a solution it misread would leak:
each malformed chapter below is refused with a FormatError naming the line and the problem.
"""
import pytest

from tools.solutions import FormatError, parse, strip_solutions

EX = "```{exercise}\n:label: ex-a\n\nDo it.\n```\n"
EX_B = "```{exercise}\n:label: ex-b\n\nAnd this.\n```\n"
GATED = ("```{solution-start} ex-a\n:class: dropdown\n```\nThe answer is {glue:text}`ex-a-x`.\n"
         "```{code-cell} ipython3\nx = 6 * 7\n```\n```{solution-end}\n```\n")
PLAIN = "````{solution} ex-b\n:class: dropdown\n\nBecause 42 is 6 times 7.\n````\n"

CASES = [
    ("unclosed-fence", lambda: parse(EX + "````{solution} ex-a\n:class: dropdown\nno end\n"), ["never closed", ":6"]),
    ("start-without-end", lambda: parse(EX + "```{solution-start} ex-a\n:class: dropdown\n```\ntext\n"),
     ["ex-a", "no solution-end"]),
    ("end-without-start", lambda: parse(EX + "```{solution-end}\n```\n"), ["solution-end without a solution-start"]),
    ("nested-start", lambda: parse(EX + EX_B + GATED.replace("```{solution-end}\n```\n", "") + GATED.replace("ex-a", "ex-b")),
     ["inside the solution of 'ex-a'"]),
    ("unknown-label", lambda: parse(EX + PLAIN), ["'ex-b'", "no exercise has"]),
    ("two-solutions", lambda: parse(EX + GATED + GATED), ["second solution", "ex-a"]),
    ("no-dropdown", lambda: parse(EX + "```{solution} ex-a\n\nText.\n```\n"), [":class: dropdown", "ex-a"]),
    ("no-label", lambda: parse("```{exercise}\n\nDo it.\n```\n"), ["without a :label:"]),
    ("no-argument", lambda: parse(EX + "```{solution}\n:class: dropdown\n\nText.\n```\n"), ["needs the exercise's label"]),
    ("content-in-start", lambda: parse(EX + "```{solution-start} ex-a\n:class: dropdown\nhidden text\n```\n"
                                            "```{solution-end}\n```\n"), ["takes no content"]),
    ("duplicate-exercise", lambda: parse(EX + EX), ["two exercises", "ex-a"]),
    ("strip-unclosed", lambda: strip_solutions(EX + "```{solution-start} ex-a\n:class: dropdown\n```\n", "ch.md"),
     ["ch.md", "no solution-end"]),
]


@pytest.mark.parametrize("call, words", [(c, w) for _, c, w in CASES], ids=[i for i, _, _ in CASES])
def test_malformed_solutions_are_refused(call, words):
    with pytest.raises(FormatError) as err:
        call()
    assert isinstance(err.value, ValueError)
    for word in words:
        assert word in str(err.value), f"{word!r} not in {err.value}"


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
