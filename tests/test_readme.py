"""The README is a front door that tells the truth: its example prints what the README shows, its
set-up commands are the ones CI runs, and it stays one screenful of orientation (about 150 lines)."""
import contextlib
import io
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"


def fenced_blocks(text: str) -> list[tuple[str, str]]:
    """(language, body) of every fenced code block of a Markdown text, in order."""
    return [(m.group(1), m.group(2)) for m in re.finditer(r"^```(\w*)\n(.*?)^```\s*$", text, re.S | re.M)]


def example_and_output() -> tuple[str, str]:
    """The README's first example (the first ``python`` block) and the ``text`` block right after it."""
    blocks = fenced_blocks(README.read_text(encoding="utf-8"))
    i = next(i for i, (lang, _) in enumerate(blocks) if lang == "python")
    assert i + 1 < len(blocks) and blocks[i + 1][0] == "text", "the example's output block must follow it"
    return blocks[i][1], blocks[i + 1][1]


def test_readme_example_prints_what_the_readme_shows():
    code, shown = example_and_output()
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, str(README), "exec"), {"__name__": "readme_example"})
    assert out.getvalue().rstrip("\n") == shown.rstrip("\n")


def test_readme_example_is_short_and_uses_the_public_api():
    code, _ = example_and_output()
    lines = [ln for ln in code.splitlines() if ln.strip()]
    assert len(lines) <= 10, f"the first example has {len(lines)} lines"
    for needed in ("orrc.examples.", "orrc.PreviewRHC(", "orrc.simulate(", "orrc.attenuation_regret("):
        assert needed in code, f"the first example does not call {needed}"
    assert not re.search(r"orrc\._|\._[a-z]", code), "the first example reaches into private names"


def test_readme_is_a_front_door():
    text = README.read_text(encoding="utf-8")
    assert len(text.splitlines()) <= 150
    for command in ("make book", "make test", "make lab"):
        assert command in text
    # CI runs exactly the README's test command
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert [ln.strip() for ln in ci.splitlines() if ln.strip().startswith("make")] == ["make test"]


def test_readme_links_resolve():
    text = README.read_text(encoding="utf-8")
    for target in re.findall(r"\]\(([^)#:]+)\)", text):
        assert (ROOT / target).exists(), f"README links to {target}, which does not exist"
